// The tying-point form of the MITC9 membrane strains and force (CR9ShellOptions::tying_membrane, docs/theory.md
// §4.4) against the Gauss-point matrices L_m, H_m of §4.5 (tying_membrane = false, the reference path kept for
// this test): energies, forces and tangents of every kernel agree to round-off. Relative tolerances: 1e-13 on the
// force and tangent norms, 1e-14 on energies (observed ~1e-15: the two paths sum the same terms in another order).
#include <gtest/gtest.h>

#include "element_fixtures.hpp"

namespace shelldyn::testing {
namespace {

Geometry sphere_patch() {
  Geometry g = make_geometry(Shape::Flat, Facing::Z);
  for (size_t i = 0; i < g.X0.size(); ++i) {
    const Eigen::Vector3d v(g.X0[i].x(), g.X0[i].y(), 2.0);
    g.p0[i] = v.normalized();
    g.X0[i] = 2.0 * g.p0[i];
  }
  g.name = "spherical patch";
  return g;
}

double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / b.norm(); }

TEST(CR9Kernel, TyingMembraneMatchesGaussPointReference) {
  std::vector<Geometry> geoms;
  for (Shape s : {Shape::Flat, Shape::Distorted, Shape::Cylinder})
    for (Facing f : {Facing::Z, Facing::X, Facing::MinusZ}) geoms.push_back(make_geometry(s, f));
  geoms.push_back(sphere_patch());
  CR9Shell::Options reference;
  reference.tying_membrane = false;
  double worst_f = 0.0, worst_k = 0.0, worst_u = 0.0;
  for (const Geometry& g : geoms) {
    const CR9Shell e(g.X0, g.p0, test_material()), r(g.X0, g.p0, test_material(), reference);
    for (unsigned seed = 1; seed <= 6; ++seed) {
      Charts ch;
      // Large rotations and strains (amplitude 0.05 on a unit element, rigid turn up to 0.6 rad): the membrane
      // force is a sizeable part of F.
      const Vec45 un = random_state(g, 0.05, 0.6, seed, &ch);
      const Vec45 u1 = un + random_vector(0.01, seed + 50);
      CR9Shell::StepState se, sr;
      e.step_state(un, ch, &se);
      r.step_state(un, ch, &sr);
      for (size_t k = 0; k < se.e.size(); ++k) EXPECT_LT(rel(se.e[k], sr.e[k]), 1e-12) << g.name << " gp " << k;
      Vec45 Fe, Fr;
      Mat45 Ke, Kr;
      // The residual of em-galpha (step state, F only).
      double Ue = e.algorithmic_internal(se, un, u1, ch, 0.5, 0.0, &Fe, nullptr);
      double Ur = r.algorithmic_internal(sr, un, u1, ch, 0.5, 0.0, &Fr, nullptr);
      worst_f = std::max(worst_f, rel(Fe, Fr)), worst_u = std::max(worst_u, std::abs(Ue - Ur) / std::abs(Ur));
      EXPECT_LT(rel(Fe, Fr), 1e-13) << g.name << " seed " << seed;
      EXPECT_LT(std::abs(Ue - Ur), 1e-14 * std::abs(Ur)) << g.name << " seed " << seed;
      // Its tangent, and internal() with and without K.
      e.algorithmic_internal(se, un, u1, ch, 0.5, 0.05, &Fe, &Ke);
      r.algorithmic_internal(sr, un, u1, ch, 0.5, 0.05, &Fr, &Kr);
      worst_k = std::max(worst_k, rel(Ke, Kr));
      EXPECT_LT(rel(Fe, Fr), 1e-13) << g.name << " seed " << seed;
      EXPECT_LT(rel(Ke, Kr), 1e-13) << g.name << " seed " << seed;
      Ue = e.internal(u1, ch, &Fe, nullptr);
      Ur = r.internal(u1, ch, &Fr, nullptr);
      EXPECT_LT(rel(Fe, Fr), 1e-13) << g.name << " seed " << seed;
      EXPECT_LT(std::abs(Ue - Ur), 1e-14 * std::abs(Ur)) << g.name << " seed " << seed;
      e.internal(u1, ch, &Fe, &Ke);
      r.internal(u1, ch, &Fr, &Kr);
      EXPECT_LT(rel(Fe, Fr), 1e-13) << g.name << " seed " << seed;
      EXPECT_LT(rel(Ke, Kr), 1e-13) << g.name << " seed " << seed;
      // The force-only path (membrane_force()) and the tangent path (membrane()) of one element agree too.
      Vec45 Fk;
      e.internal(u1, ch, &Fk, &Ke);
      e.internal(u1, ch, &Fe, nullptr);
      EXPECT_LT(rel(Fe, Fk), 1e-13) << g.name << " seed " << seed;
    }
  }
  std::printf("worst relative differences to the reference path: F %.1e, K %.1e, U %.1e\n", worst_f, worst_k, worst_u);
}

// The residual's compact K_bs w (kbs_times(): the active dense block of a flat or singly curved element, the packed
// symmetric vector pass of a doubly curved one) against the dense 45 × 45 product of the plain overload of
// algorithmic_internal() (F only: T(u_mid)ᵀ[K_bs (c1 w1 + c0 wn) + membrane]), which shares neither K_bs kernel
// nor the membrane kernel with the step-state residual. Forces of strained states, 1e-13 relative (observed
// ~1e-16: the same terms summed in another order).
TEST(CR9Kernel, ResidualKbsProductMatchesDenseProduct) {
  std::vector<Geometry> geoms;
  for (Shape s : {Shape::Flat, Shape::Distorted, Shape::Cylinder}) geoms.push_back(make_geometry(s, Facing::Y));
  geoms.push_back(sphere_patch());
  double worst = 0.0;
  for (const Geometry& g : geoms) {
    const CR9Shell e(g.X0, g.p0, test_material());
    for (unsigned seed = 1; seed <= 5; ++seed) {
      Charts ch;
      const Vec45 un = random_state(g, 0.05, 0.6, seed, &ch);
      const Vec45 u1 = un + random_vector(0.01, seed + 70);
      CR9Shell::StepState sn;
      e.step_state(un, ch, &sn);
      Vec45 Fs, Fd;
      e.algorithmic_internal(sn, un, u1, ch, 0.5, 0.0, &Fs, nullptr);
      e.algorithmic_internal(un, u1, ch, 0.5, 0.0, &Fd, nullptr);
      worst = std::max(worst, rel(Fs, Fd));
      EXPECT_LT(rel(Fs, Fd), 1e-13) << g.name << " seed " << seed;
    }
  }
  std::printf("step-state residual against the dense-K_bs plain overload: worst relative difference %.1e\n", worst);
}

// The compensated local translations t_i = Rᵀ((X_i − X_O) + (d_i − d_O)) − x_i0 (CorotationalFrame::local_variables
// with the reference offsets, a compensated dot product per component) against the same expression in binary128
// (__float128: every product of doubles and every sum here is exact or within 2^-113), with R, X_i − X_O, x_i0
// and d_i as the element has them. The translations are strain-sized (1e-6) differences of body-sized numbers
// (a far rigid translation and a large rotation), so the bound — one rounding of the result, 2^-52 |t|, plus
// 1e-28 — is ~1e-6 of the absolute noise of plain double arithmetic; the uncompensated local_variables(x_i0)
// must exceed it (the test can fail).
#ifdef __SIZEOF_FLOAT128__
TEST(CR9Kernel, CompensatedLocalTranslationsAreCorrectlyRounded) {
  using Q = __float128;
  double worst = 0.0, worst_plain = 0.0;  // max |t - t_ref| / bound
  for (Shape sh : {Shape::Flat, Shape::Distorted, Shape::Cylinder})
    for (Facing f : {Facing::Z, Facing::X}) {
      const Geometry g = make_geometry(sh, f);
      Charts ch;
      for (int i = 0; i < 9; ++i) ch[i] = select_chart(g.p0[i]);
      Eigen::Vector3d XO = Eigen::Vector3d::Zero();
      for (int k = 0; k < 4; ++k) XO += 0.25 * g.X0[k];
      Nodes rel0, xl0;
      const CorotationalFrame f0(g.X0, g.p0, ch);
      for (int i = 0; i < 9; ++i) rel0[i] = g.X0[i] - XO, xl0[i] = f0.R().transpose() * rel0[i];
      for (unsigned seed = 1; seed <= 8; ++seed) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> U(-1.0, 1.0);
        const Eigen::Matrix3d Qr = random_rotation(rng, 0.7);
        const Eigen::Vector3d c(1024.0 * U(rng), -2048.0, 512.0 * U(rng));
        Nodes d, x, p;
        for (int i = 0; i < 9; ++i) {
          d[i] = Qr * (g.X0[i] + 1e-6 * Eigen::Vector3d(U(rng), U(rng), U(rng))) - g.X0[i] + c;
          x[i] = g.X0[i] + d[i];
          p[i] = Qr * g.p0[i];
        }
        const CorotationalFrame fr(x, p, ch);
        const Vec45 t = fr.local_variables(xl0, rel0, d), tp = fr.local_variables(xl0);
        Q dO[3];
        for (int a = 0; a < 3; ++a) dO[a] = (Q(d[0](a)) + Q(d[1](a)) + Q(d[2](a)) + Q(d[3](a))) / 4;
        for (int i = 0; i < 9; ++i)
          for (int r = 0; r < 3; ++r) {
            Q tr = -Q(xl0[i](r));
            for (int a = 0; a < 3; ++a) tr += Q(fr.R()(a, r)) * ((Q(rel0[i](a)) + Q(d[i](a))) - dO[a]);
            const double ref = static_cast<double>(tr);
            const double bound = std::ldexp(std::abs(ref), -52) + 1e-28;
            const double err = static_cast<double>(Q(t(5 * i + r)) - tr), errp = static_cast<double>(Q(tp(5 * i + r)) - tr);
            worst = std::max(worst, std::abs(err) / bound), worst_plain = std::max(worst_plain, std::abs(errp) / bound);
            EXPECT_LE(std::abs(err), bound) << g.name << " seed " << seed << " node " << i << " row " << r;
          }
      }
    }
  std::printf("local translations: max error / bound %.2f compensated, %.1e plain double\n", worst, worst_plain);
  EXPECT_GT(worst_plain, 1e3);
}
#endif

// The residual frame is built without the directors' d²p_l/dq²: asking it for K_σ must not silently use zeros.
TEST(CR9Kernel, ResidualFrameRefusesGeometricStiffness) {
  const Geometry g = make_geometry(Shape::Cylinder, Facing::Z);
  Charts ch;
  const Vec45 u = random_state(g, 0.05, 0.6, 3, &ch);
  std::array<Eigen::Vector3d, 9> x, p;
  std::array<Eigen::Matrix<double, 3, 2>, 9> A1;
  for (int i = 0; i < 9; ++i) {
    x[i] = g.X0[i] + u.segment<3>(5 * i);
    p[i] = director(u.segment<2>(5 * i + 3), ch[i]);
    A1[i] = director_A1(u.segment<2>(5 * i + 3), ch[i]);
  }
  const CorotationalFrame fr(x, p, A1, ch);
  Mat45 K = Mat45::Zero();
  EXPECT_THROW(fr.add_geometric_stiffness(Vec45::Ones(), &K), std::logic_error);
  EXPECT_NO_THROW(fr.apply_transpose(Vec45::Ones()));
}

}  // namespace
}  // namespace shelldyn::testing
