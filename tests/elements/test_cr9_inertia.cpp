// docs/theory.md §7.11 (mass identities, Lagrange-equation check of M q̈ + F_m), §7.2 (kinetic energy,
// momenta and strain energy are unchanged by a chart switch) and §5.4 momenta.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cstdio>

#include "element_fixtures.hpp"

namespace shelldyn::testing {
namespace {

// Flat a x b rectangle centred at the origin in the XY plane.
Geometry rectangle(double a, double b) {
  Geometry g;
  for (int k = 0; k < 9; ++k) {
    g.X0[k] = Eigen::Vector3d(0.5 * a * kNodeXi[k], 0.5 * b * kNodeEta[k], 0.0);
    g.p0[k] = Eigen::Vector3d::UnitZ();
  }
  g.name = "rectangle";
  return g;
}

// Rigid velocity field ḋ_i = v + ω × x_i, ṗ_i = ω × p_i (q̇ = S ṗ, exact because ṗ ⊥ p).
Vec45 rigid_velocity(const Geometry& g, const Vec45& u, const Charts& ch, const Eigen::Vector3d& v,
                     const Eigen::Vector3d& w) {
  Nodes x, p;
  configuration_from_dofs(g, u, ch, &x, &p);
  Vec45 ud;
  for (int k = 0; k < 9; ++k) {
    ud.segment<3>(5 * k) = v + w.cross(x[k]);
    ud.segment<2>(5 * k + 3) = chart_coordinates(w.cross(p[k]), ch[k]);
  }
  return ud;
}

TEST(CR9Inertia, MassIsSymmetricPositiveDefinite) {
  const Geometry g = make_geometry(Shape::Cylinder, Facing::Y);
  const CR9Shell e(g.X0, g.p0, test_material());
  Charts ch;
  const Vec45 u = random_state(g, 0.1, 1.0, 3, &ch);
  Mat45 M;
  e.mass(u, ch, &M);
  EXPECT_LT((M - M.transpose()).norm(), 1e-15 * M.norm());
  Eigen::LLT<Mat45> llt(M);
  EXPECT_EQ(llt.info(), Eigen::Success);
  // Σ_i N_i = 1 at every point, so Σ_ij m_ij = ∫ dA = area (partition of unity of the mass).
  EXPECT_NEAR(e.scalar_mass().sum(), e.area(), 1e-14 * e.area());
}

// Rigid translation and rotations of a flat a x b element give the exact thick-box kinetic energies;
// the director inertia ρh³/12 supplies the h² parts. Also checks L and J of §5.4.
TEST(CR9Inertia, RigidKineticEnergyAndMomentaAreExact) {
  const double a = 2.0, b = 1.0, h = 0.1, rho = 7.8;
  const Geometry g = rectangle(a, b);
  const ShellMaterial mat{1e6, 0.3, rho, h};
  const CR9Shell e(g.X0, g.p0, mat);
  EXPECT_NEAR(e.area(), a * b, 1e-14);
  const Charts ch = initial_charts(g);
  const Vec45 u = Vec45::Zero();
  const double m = rho * h * a * b;
  const Eigen::Vector3d v(0.3, -1.2, 0.7);
  Vec45 ud = rigid_velocity(g, u, ch, v, Eigen::Vector3d::Zero());
  EXPECT_NEAR(e.kinetic(u, ud, ch), 0.5 * m * v.squaredNorm(), 1e-14 * m * v.squaredNorm());
  Eigen::Vector3d L, J;
  e.momenta(u, ud, ch, &L, &J);
  EXPECT_LT((L - m * v).norm(), 1e-14 * m * v.norm());
  EXPECT_LT(J.norm(), 1e-14 * m * v.norm());  // centroid at the origin
  const double I[3] = {m * (b * b + h * h) / 12, m * (a * a + h * h) / 12, m * (a * a + b * b) / 12};
  for (int ax = 0; ax < 3; ++ax) {
    const double om = 1.7;
    ud = rigid_velocity(g, u, ch, Eigen::Vector3d::Zero(), om * Eigen::Vector3d::Unit(ax));
    const double K = e.kinetic(u, ud, ch), Kex = 0.5 * om * om * I[ax];
    e.momenta(u, ud, ch, &L, &J);
    std::printf("  rotation about axis %d: |K - K_exact|/K = %.1e  |J - I w|/|J| = %.1e\n", ax,
                std::abs(K - Kex) / Kex, (J - I[ax] * om * Eigen::Vector3d::Unit(ax)).norm() / (I[ax] * om));
    EXPECT_NEAR(K, Kex, 1e-14 * Kex);
    EXPECT_LT((J - I[ax] * om * Eigen::Vector3d::Unit(ax)).norm(), 1e-14 * I[ax] * om);
    EXPECT_LT(L.norm(), 1e-14 * m * om);
    // K = ½ u̇^T M u̇ (the assembled M agrees with kinetic()).
    Mat45 M;
    e.mass(u, ch, &M);
    EXPECT_NEAR(0.5 * ud.dot(M * ud), K, 1e-14 * K);
  }
}

// §5.3 / §7.11: d/dt(∂K/∂q̇) - ∂K/∂q (finite differences along q(t) = q0 + q1 t + q2 t²) = M q̈ + F_m.
TEST(CR9Inertia, LagrangeEquationMatchesMassAndInertialForce) {
  for (Shape shape : {Shape::Distorted, Shape::Cylinder}) {
    for (Facing facing : {Facing::Z, Facing::X, Facing::Y}) {
      const Geometry g = make_geometry(shape, facing);
      const CR9Shell e(g.X0, g.p0, test_material(0.2));
      Charts ch;
      const Vec45 u0 = random_state(g, 0.1, 0.8, 17, &ch);
      std::mt19937 rng(2);
      std::uniform_real_distribution<double> U(-1.0, 1.0);
      Vec45 u1, u2;
      for (int j = 0; j < 45; ++j) u1(j) = U(rng), u2(j) = U(rng);
      // Zero translational velocities: the translational kinetic energy does not depend on u and would
      // only add round-off (relative to the small director terms) to the finite differences.
      for (int k = 0; k < 9; ++k) u1.segment<3>(5 * k).setZero();
      auto M_of = [&](const Vec45& u) { Mat45 M; e.mass(u, ch, &M); return M; };
      Vec45 Fm;
      e.inertial(u0, u1, ch, &Fm);
      const Vec45 Mqdd = M_of(u0) * (2 * u2), rhs = Mqdd + Fm;
      // Director rows only: the translational rows are the trivial constant-mass part, and F_m lives in
      // the director rows.
      Vec45 mask = Vec45::Zero();
      for (int k = 0; k < 9; ++k) mask.segment<2>(5 * k + 3).setOnes();
      auto lagrange_error = [&](double h) {
        auto mom = [&](double t) { return Vec45(M_of(u0 + u1 * t + u2 * t * t) * (u1 + 2 * u2 * t)); };
        const Vec45 ddt = (mom(h) - mom(-h)) / (2 * h);
        Vec45 dKdq;
        for (int j = 0; j < 45; ++j) {
          Vec45 up = u0, um = u0;
          up(j) += h, um(j) -= h;
          dKdq(j) = (e.kinetic(up, u1, ch) - e.kinetic(um, u1, ch)) / (2 * h);
        }
        return (ddt - dKdq - rhs).cwiseProduct(mask).norm() / rhs.cwiseProduct(mask).norm();
      };
      const double e1 = lagrange_error(1e-5), e2 = lagrange_error(2e-5);
      const double fm_share = Fm.norm() / Mqdd.cwiseProduct(mask).norm();
      std::printf("  [%s_%s] Lagrange vs M qdd + F_m (director rows): %.1e (FD step 1e-5), %.1e (2e-5), ratio %.2f;"
                  " |F_m|/|M qdd| = %.2f\n", to_string(shape).c_str(), to_string(facing).c_str(), e1, e2, e2 / e1,
                  fm_share);
      // The residual is pure O(h^2) FD truncation (it quadruples when h doubles), i.e. the identity holds.
      EXPECT_LT(e1, 1e-8);
      EXPECT_NEAR(e2 / e1, 4.0, 0.3);
      EXPECT_GT(fm_share, 0.1);  // F_m is a sizeable part of the director rows, so the check sees it
    }
  }
}

// §7.2: after re-charting every node (p, ṗ, p̈ unchanged), K, L, J and U are unchanged.
TEST(CR9Inertia, ChartSwitchLeavesEnergiesAndMomentaUnchanged) {
  const Geometry g = make_geometry(Shape::Cylinder, Facing::Z);
  const CR9Shell e(g.X0, g.p0, test_material());
  // Turn the element by 75° about Y so that the normals now point mostly along X while the charts
  // still say Z.
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(1.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  Charts ch = initial_charts(g);
  Vec45 u, ud, udd;
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int k = 0; k < 9; ++k) {
    const Eigen::Vector3d p = (Q * (Eigen::AngleAxisd(0.05 * U(rng), Eigen::Vector3d::UnitX()) * g.p0[k]));
    u.segment<3>(5 * k) = Q * g.X0[k] - g.X0[k] + 0.02 * Eigen::Vector3d(U(rng), U(rng), U(rng));
    u.segment<2>(5 * k + 3) = chart_coordinates(p, ch[k]);
    // Director rates only, so that K and J are made of the chart-dependent director terms alone.
    ud.segment<5>(5 * k) << 0, 0, 0, U(rng), U(rng);
    udd.segment<5>(5 * k) << U(rng), U(rng), U(rng), U(rng), U(rng);
  }
  const double K0 = e.kinetic(u, ud, ch), U0 = e.internal(u, ch, nullptr, nullptr);
  Eigen::Vector3d L0, J0;
  e.momenta(u, ud, ch, &L0, &J0);
  int switched = 0;
  for (int k = 0; k < 9; ++k) {
    Eigen::Vector2d q = u.segment<2>(5 * k + 3), qd = ud.segment<2>(5 * k + 3), qdd = udd.segment<2>(5 * k + 3);
    switched += rechart(q, qd, qdd, ch[k]);
    u.segment<2>(5 * k + 3) = q, ud.segment<2>(5 * k + 3) = qd, udd.segment<2>(5 * k + 3) = qdd;
  }
  EXPECT_EQ(switched, 9);
  const double K1 = e.kinetic(u, ud, ch), U1 = e.internal(u, ch, nullptr, nullptr);
  Eigen::Vector3d L1, J1;
  e.momenta(u, ud, ch, &L1, &J1);
  std::printf("  after %d switches: |dK|/K = %.1e |dU|/U = %.1e |dJ|/|J| = %.1e\n", switched,
              std::abs(K1 - K0) / K0, std::abs(U1 - U0) / U0, (J1 - J0).norm() / J0.norm());
  EXPECT_LT(std::abs(K1 - K0), 1e-14 * K0);
  EXPECT_LT(std::abs(U1 - U0), 1e-13 * U0);
  EXPECT_LT((J1 - J0).norm(), 1e-14 * J0.norm());
}

}  // namespace
}  // namespace shelldyn::testing
