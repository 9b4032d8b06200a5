// Element pieces of em-exact (elements/exact_energy.hpp; docs/theory/exact-energy-momentum.md §3):
// the corrected force F* = F + Rᵀa + βz has zero resultant, zero midpoint moment and does exactly the work
// ΔU on the step, on random pairs of states (flat, distorted and curved elements, every dependent director
// component), on finite rigid steps and on near-rigid steps; the paper's force F alone does not.
#include "element_fixtures.hpp"

#include "elements/exact_energy.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace shelldyn {
namespace {

using namespace shelldyn::testing;

struct Pair {
  Vec45 un, u1;
  Charts ch;
};

// u_{n+1} = u_n + a random increment of relative size `step` in the charts of u_n (same chart, as in a step).
Pair random_pair(const Geometry& g, double step, unsigned seed) {
  Pair p;
  p.un = random_state(g, 0.1, 0.7, seed, &p.ch);
  std::mt19937 rng(seed + 1000);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  p.u1 = p.un;
  for (int k = 0; k < 45; ++k) p.u1[k] += step * U(rng);
  return p;
}

// u_{n+1} = the finite rigid motion x → Q x + c of u_n (plus `noise` random deformation), same charts.
Pair rigid_pair(const Geometry& g, double angle, double noise, unsigned seed) {
  Pair p;
  p.un = random_state(g, 0.1, 0.4, seed, &p.ch);
  std::mt19937 rng(seed + 77);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const Eigen::Matrix3d Q = random_rotation(rng, angle);
  const Eigen::Vector3d c(0.2, -0.1, 0.3);
  Nodes x, d;
  configuration_from_dofs(g, p.un, p.ch, &x, &d);
  p.u1 = p.un;
  for (int k = 0; k < 9; ++k) {
    const Eigen::Vector3d x1 = Q * x[k] + c, p1 = Q * d[k];
    p.u1.segment<3>(5 * k) = x1 - g.X0[k];
    p.u1.segment<2>(5 * k + 3) = chart_coordinates(p1, p.ch[k]);
  }
  for (int k = 0; k < 45; ++k) p.u1[k] += noise * U(rng);
  return p;
}

struct Check {
  double resultant, moment, work, work_paper, beta_z;
  bool guard;
};

Check check_pair(const CR9Shell& el, const Geometry& g, const Pair& p, bool correct = true, double director_weight = 1.0) {
  Vec45 F;
  el.algorithmic_internal(p.un, p.u1, p.ch, 0.5, 0.0, &F, nullptr);
  const double dU = el.internal(p.u1, p.ch, nullptr, nullptr) - el.internal(p.un, p.ch, nullptr, nullptr);
  Nodes xn, pn, x1, p1, xm, pm;
  configuration_from_dofs(g, p.un, p.ch, &xn, &pn);
  configuration_from_dofs(g, p.u1, p.ch, &x1, &p1);
  for (int k = 0; k < 9; ++k) {
    xm[k] = 0.5 * (xn[k] + x1[k]);
    pm[k] = 0.5 * (pn[k] + p1[k]);
  }
  const MidpointRigidRows R(xm, pm, p.ch);
  const Vec45 du = p.u1 - p.un;
  Vec45 Fs = F;
  CorrectionInfo info;
  if (correct) info = energy_momentum_correction(R, du, dU, Fs, 1e-20, director_weight);
  // Resultant and moment about the origin computed directly from the nodal forces (not through R).
  Eigen::Vector3d res = Eigen::Vector3d::Zero(), mom = Eigen::Vector3d::Zero();
  for (int k = 0; k < 9; ++k) {
    const Eigen::Vector3d fd = Fs.segment<3>(5 * k);
    Eigen::Vector3d fp = Eigen::Vector3d::Zero();
    fp[p.ch[k].n] = Fs[5 * k + 3];
    fp[p.ch[k].m] = Fs[5 * k + 4];
    res += fd;
    mom += xm[k].cross(fd) + pm[k].cross(fp);
  }
  const double fn = F.norm();
  return {res.norm() / fn, mom.norm() / fn, std::abs(du.dot(Fs) - dU) / (fn * du.norm()),
          std::abs(du.dot(F) - dU) / (fn * du.norm()), info.correction_norm / fn,
          info.rigid_guard};
}

const Shape kShapes[] = {Shape::Flat, Shape::Distorted, Shape::Cylinder};
const Facing kFacings[] = {Facing::Z, Facing::X, Facing::Y};

TEST(ExactEnergy, CorrectedForceHasZeroResultantMomentAndExactWork) {
  const ShellMaterial mat = test_material();
  double worst_res = 0, worst_mom = 0, worst_work = 0, best_paper = 1;
  for (Shape s : kShapes)
    for (Facing f : kFacings) {
      const Geometry g = make_geometry(s, f);
      const CR9Shell el(g.X0, g.p0, mat);
      for (double step : {0.01, 0.05}) {
        for (unsigned seed = 1; seed <= 5; ++seed) {
          const Check c = check_pair(el, g, random_pair(g, step, seed));
          worst_res = std::max(worst_res, c.resultant);
          worst_mom = std::max(worst_mom, c.moment);
          worst_work = std::max(worst_work, c.work);
          best_paper = std::min(best_paper, c.work_paper);
          EXPECT_FALSE(c.guard);
        }
      }
    }
  std::printf("random pairs: max |resultant| %.2e, |moment| %.2e, work error %.2e (F*); min work error of F %.2e\n",
              worst_res, worst_mom, worst_work, best_paper);
  EXPECT_LT(worst_res, 1e-13);
  EXPECT_LT(worst_mom, 1e-13);
  EXPECT_LT(worst_work, 1e-13);
  EXPECT_GT(best_paper, 1e-8);  // the paper's force alone is not energy-consistent on these steps
}

// The correction in a weighted metric (director weight w, the Model uses h ℓ_e; theory §3): the same
// balances on the same random pairs and near-rigid steps, and a direction that is not the unweighted one.
TEST(ExactEnergy, WeightedCorrectionKeepsTheBalances) {
  const ShellMaterial mat = test_material();
  double worst_res = 0, worst_mom = 0, worst_work = 0, worst_bz = 0, min_diff = 1e300;
  for (double w : {1e-2, 1e-5}) {
    for (Shape s : kShapes)
      for (Facing f : kFacings) {
        const Geometry g = make_geometry(s, f);
        const CR9Shell el(g.X0, g.p0, mat);
        for (unsigned seed = 1; seed <= 4; ++seed) {
          for (const Pair& p : {random_pair(g, 0.02, seed), rigid_pair(g, 0.3, 1e-5, seed)}) {
            const Check c = check_pair(el, g, p, true, w);
            const bool rigid = (p.u1 - p.un).norm() > 0.2;  // the rigid pair (a 0.3 rad rotation)
            // Round-off amplified by about |Δu|/|z| on the near-rigid step (as unweighted, NearRigidSteps…).
            const double scale = rigid ? 1e-2 : 1.0;
            worst_res = std::max(worst_res, scale * c.resultant);
            worst_mom = std::max(worst_mom, scale * c.moment);
            worst_work = std::max(worst_work, scale * c.work);
            worst_bz = std::max(worst_bz, c.beta_z);
            EXPECT_FALSE(c.guard);
            const Check u = check_pair(el, g, p, true, 1.0);
            min_diff = std::min(min_diff, std::abs(c.beta_z - u.beta_z) / std::max(u.beta_z, 1e-300));
          }
        }
      }
  }
  std::printf("weighted (near-rigid errors / 100): max |resultant| %.2e, |moment| %.2e, work error %.2e, |beta z|/|F| %.2e; "
              "min rel. change %.2e\n",
              worst_res, worst_mom, worst_work, worst_bz, min_diff);
  EXPECT_LT(worst_res, 1e-13);
  EXPECT_LT(worst_mom, 1e-13);
  EXPECT_LT(worst_work, 1e-12);
  EXPECT_LT(worst_bz, 1e-1);
  EXPECT_GT(min_diff, 1e-6);  // the weight changes the correction (it is not ignored)
}

// The structured products of MidpointRigidRows (R f, Rᵀa and RRᵀ from nodal vectors) against the dense
// 6 × 45 rows, on midpoint configurations far from the origin (as on the flying plate, 70 m out) with every
// dependent director component. A wrong sign or slot in any one of them is an O(1) difference.
TEST(ExactEnergy, StructuredRigidRowsEqualTheDenseRows) {
  double worst = 0.0;
  for (Shape s : kShapes)
    for (Facing f : kFacings) {
      const Geometry g = make_geometry(s, f);
      for (unsigned seed = 1; seed <= 3; ++seed) {
        const Pair p = random_pair(g, 0.05, seed);
        Nodes xn, pn, x1, p1;
        configuration_from_dofs(g, p.un, p.ch, &xn, &pn);
        configuration_from_dofs(g, p.u1, p.ch, &x1, &p1);
        NodeVectors xm, pm;
        const Eigen::Vector3d far(70.0, -40.0, 25.0);
        for (int k = 0; k < 9; ++k) {
          xm[k] = far + 0.5 * (xn[k] + x1[k]);
          pm[k] = 0.5 * (pn[k] + p1[k]);
        }
        const MidpointRigidRows R(xm, pm, p.ch);
        const RigidRows D = R.dense();
        std::mt19937 rng(seed + 500);
        std::uniform_real_distribution<double> U(-1.0, 1.0);
        Vec45 v;
        MidpointRigidRows::Vec6 a;
        for (int k = 0; k < 45; ++k) v[k] = U(rng);
        for (int k = 0; k < 6; ++k) a[k] = U(rng);
        Vec45 y = v;
        R.subtract_transpose_times(a, y);
        const double e_times = (R.times(v) - D * v).norm() / (D.norm() * v.norm());
        const double e_transpose = ((v - y) - D.transpose() * a).norm() / (D.norm() * a.norm());
        const Eigen::Matrix<double, 6, 6> G = D * D.transpose();
        const double e_gram = (R.gram() - G).norm() / G.norm();
        worst = std::max({worst, e_times, e_transpose, e_gram});
        EXPECT_LT(e_times, 1e-15) << g.name << " seed " << seed;
        EXPECT_LT(e_transpose, 1e-15) << g.name << " seed " << seed;
        EXPECT_LT(e_gram, 1e-15) << g.name << " seed " << seed;
      }
    }
  std::printf("structured against dense rigid rows: max relative difference %.2e\n", worst);
}

TEST(ExactEnergy, WithoutTheCorrectionTheWorkIdentityFails) {
  const Geometry g = make_geometry(Shape::Cylinder, Facing::X);
  const CR9Shell el(g.X0, g.p0, test_material());
  const Check c = check_pair(el, g, random_pair(g, 0.05, 3), /*correct=*/false);
  EXPECT_GT(c.work, 1e-6);
}

TEST(ExactEnergy, FiniteRigidStepsAreInTheRowSpaceAndNeedNoEnergyTerm) {
  const ShellMaterial mat = test_material();
  for (Shape s : kShapes)
    for (Facing f : kFacings) {
      const Geometry g = make_geometry(s, f);
      const CR9Shell el(g.X0, g.p0, mat);
      for (unsigned seed = 1; seed <= 3; ++seed) {
        const Pair p = rigid_pair(g, 0.3, 0.0, seed);
        const Check c = check_pair(el, g, p);
        EXPECT_TRUE(c.guard) << g.name;  // Cayley: Δu = Rᵀ(·) exactly, so z = 0
        EXPECT_LT(c.resultant, 1e-13) << g.name;
        EXPECT_LT(c.moment, 1e-13) << g.name;
        EXPECT_LT(c.work, 1e-12) << g.name;
      }
    }
}

TEST(ExactEnergy, NearRigidStepsKeepTheCorrectionBounded) {
  const Geometry g = make_geometry(Shape::Distorted, Facing::Y);
  const CR9Shell el(g.X0, g.p0, test_material());
  for (double noise : {1e-4, 1e-7}) {
    double worst = 0, beta_z = 0;
    for (unsigned seed = 1; seed <= 5; ++seed) {
      const Check c = check_pair(el, g, rigid_pair(g, 0.3, noise, seed));
      EXPECT_FALSE(c.guard);
      worst = std::max({worst, c.resultant, c.moment, c.work});
      beta_z = std::max(beta_z, c.beta_z);
    }
    std::printf("rigid + %.0e deformation: identities %.2e, |beta z|/|F| %.2e\n", noise, worst, beta_z);
    EXPECT_LT(worst, noise > 1e-5 ? 1e-12 : 1e-9);  // round-off amplified by about 1/|z|
    EXPECT_LT(beta_z, 0.1);
  }
}

TEST(ExactEnergy, EmbeddedA1SpansTheTangentPlaneOfAnyVector) {
  const Eigen::Vector3d p(0.3, -0.2, 0.85);  // not unit
  const DirectorChart ch = select_chart(p);
  const auto A = embedded_A1(p, ch);
  EXPECT_LT((A.transpose() * p).norm(), 1e-15);
  EXPECT_NEAR(A(ch.n, 0), 1.0, 0);
  EXPECT_NEAR(A(ch.m, 1), 1.0, 0);
  // At a unit vector it is the chart's A1 (spec of director_A1).
  const Eigen::Vector3d pu = p.normalized();
  EXPECT_LT((embedded_A1(pu, ch) - director_A1(chart_coordinates(pu, ch), ch)).norm(), 1e-14);
}

TEST(ExactEnergy, EmbeddedKineticAndMomentaMatchTheElementForTangentVelocities) {
  const Geometry g = make_geometry(Shape::Cylinder, Facing::Z);
  const ShellMaterial mat = test_material();
  const CR9Shell el(g.X0, g.p0, mat);
  Charts ch;
  const Vec45 u = random_state(g, 0.1, 0.5, 4, &ch);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Vec45 v;
  for (int k = 0; k < 45; ++k) v[k] = U(rng);
  Nodes x, p, vd, w;
  configuration_from_dofs(g, u, ch, &x, &p);
  for (int k = 0; k < 9; ++k) {
    vd[k] = v.segment<3>(5 * k);
    w[k] = director_A1(Eigen::Vector2d(u.segment<2>(5 * k + 3)), ch[k]) * v.segment<2>(5 * k + 3);
  }
  const double rh = mat.rho * mat.thickness, rh3 = rh * mat.thickness * mat.thickness / 12.0;
  const double K = embedded_kinetic(el.scalar_mass(), rh, rh3, vd, w);
  EXPECT_NEAR(K, el.kinetic(u, v, ch), 1e-14 * K);
  Eigen::Vector3d L, J, Le, Je;
  embedded_momenta(el.scalar_mass(), rh, rh3, x, p, vd, w, &L, &J);
  el.momenta(u, v, ch, &Le, &Je);
  EXPECT_LT((L - Le).norm(), 1e-14 * Le.norm());
  EXPECT_LT((J - Je).norm(), 1e-13 * Je.norm());
}

}  // namespace
}  // namespace shelldyn
