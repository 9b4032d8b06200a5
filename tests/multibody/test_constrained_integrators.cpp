// The production integrators on constrained rigid-body systems (docs/theory/multibody.md §9): em-exact and
// em-galpha put the constraint force through the discrete gradient and keep energy (and, without ground joints,
// both momenta) to the solver tolerance with g = 0 at every step end; galpha and newmark use the end-point
// Jacobian (index 3) and keep g = 0 while the energy error is reported; all converge at second order to the
// independent RK45 reference (lib/multibody/rigid_reference).
//
// With SHELLDYN_TEST_ENDPOINT_G=1 the test system hands the integrators G(u_{n+1}) as its "discrete gradient";
// the conservation tests of em-exact and em-galpha below then fail (checked: multibody.md §9.5).
#include "director_step.hpp"
#include "integrators/integrator_settings.hpp"
#include "integrators/newmark/em_exact.hpp"
#include "integrators/newmark/em_generalized_alpha.hpp"
#include "lib/multibody/rigid_reference.hpp"
#include "rigid_system.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <functional>

namespace shelldyn::multibody {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;
using testing::RigidSystem;

std::unique_ptr<Integrator> make(const std::string& name, double dt, std::vector<std::pair<std::string, std::string>> kv = {}) {
  IntegratorSettings s(name, std::move(kv));
  if (name == "em-exact") return make_em_exact(s, dt);
  if (name == "em-galpha") return make_em_galpha(s, dt);
  if (name == "galpha") return make_galpha(s, dt);
  return make_newmark(s, dt);
}

struct Summary {
  double H0 = 0, max_dH = 0, max_dL = 0, max_dJ = 0, max_dJz = 0, max_g = 0, last_dH = 0;
  long iterations = 0, steps = 0;
  State s;
};

Summary run(RigidSystem& sys, const std::string& name, double dt, double T,
        std::vector<std::pair<std::string, std::string>> kv = {}) {
  if (testing::default_choice() == testing::GradientChoice::endpoint) sys.use_endpoint_gradient(true);
  auto integ = make(name, dt, std::move(kv));
  Summary r;
  r.s = sys.initial_state();
  integ->initialize(sys, r.s);
  const Invariants i0 = sys.invariants(r.s);
  r.H0 = i0.kinetic + i0.strain;
  const int steps = static_cast<int>(std::lround(T / dt));
  VectorXd g;
  for (int k = 1; k <= steps; ++k) {
    const StepReport rep = integ->advance(sys, r.s, k * dt);
    r.iterations += rep.nonlinear_iterations;
    r.steps += rep.steps;
    const Invariants inv = sys.invariants(r.s);
    const double dH = inv.kinetic + inv.strain - r.H0 - integ->external_work() - integ->prescribed_work();
    r.last_dH = dH;
    r.max_dH = std::max(r.max_dH, std::abs(dH));
    r.max_dL = std::max(r.max_dL, (inv.L - i0.L).norm());
    r.max_dJ = std::max(r.max_dJ, (inv.J - i0.J).norm());
    r.max_dJz = std::max(r.max_dJz, std::abs(inv.J.z() - i0.J.z()));
    sys.constraint_values(r.s.t, r.s.u, r.s.charts, g);
    r.max_g = std::max(r.max_g, g.cwiseAbs().maxCoeff());
  }
  return r;
}

// Heavy symmetric top pivoted at the origin (the configuration of test_conserving_step.cpp).
struct Top {
  double m = 2.0, l = 0.5;
  Vector3d J{0.3, 0.3, 0.1}, gravity{0, 0, -9.81};
  Matrix3d R0 = Eigen::AngleAxisd(0.3, Vector3d::UnitX()).toRotationMatrix();
  Vector3d w0 = R0 * Vector3d(0, 0, 20.0) + Vector3d(0, 0, 1.0);
  VectorXd q0() const { return RigidBody::state(R0 * Vector3d(0, 0, l), R0); }
  std::unique_ptr<RigidSystem> system() const {
    const VectorXd q = q0();
    auto s = std::make_unique<RigidSystem>(std::vector<RigidBody>{RigidBody("top", m, J)}, q,
                                           RigidBody::velocity(q, w0.cross(R0 * Vector3d(0, 0, l)), w0), gravity);
    s->constraints().add(orthonormality("top frame", 0));
    s->constraints().add(fixed_point("pivot", PointMap::body_point(0, Vector3d(0, 0, -l)), Vector3d::Zero()));
    return s;
  }
  SphericalChainReference reference() const {
    ReferenceBody b;
    b.mass = m, b.J = J, b.R = R0, b.x = R0 * Vector3d(0, 0, l), b.v = w0.cross(b.x), b.omega_body = R0.transpose() * w0;
    return SphericalChainReference({b}, {{0, Vector3d(0, 0, -l), -1, Vector3d::Zero()}}, gravity);
  }
};

// Two bodies joined by a spherical joint in free flight.
struct Pair {
  double mA = 3.0, mB = 1.5;
  Vector3d JA{0.4, 0.6, 0.8}, JB{0.2, 0.25, 0.3};
  Vector3d rA{0.5, 0.0, 0.1}, rB{-0.4, 0.1, 0.0};
  Matrix3d RA = Eigen::AngleAxisd(0.4, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Matrix3d RB = Eigen::AngleAxisd(-0.9, Vector3d(0, 1, 1).normalized()).toRotationMatrix();
  Vector3d xA{0.1, -0.2, 0.3}, vA{0.3, 0.1, -0.2}, wA{1.0, -2.0, 3.0}, wB{-2.5, 1.0, 0.5};
  Vector3d xB() const { return xA + RA * rA - RB * rB; }
  Vector3d vB() const { return vA + wA.cross(RA * rA) - wB.cross(RB * rB); }
  std::unique_ptr<RigidSystem> system() const {
    VectorXd q(24), v(24);
    q << RigidBody::state(xA, RA), RigidBody::state(xB(), RB);
    v << RigidBody::velocity(q.head<12>(), vA, wA), RigidBody::velocity(q.tail<12>(), vB(), wB);
    auto s = std::make_unique<RigidSystem>(std::vector<RigidBody>{RigidBody("A", mA, JA), RigidBody("B", mB, JB)}, q, v,
                                           Vector3d::Zero());
    s->constraints().add(orthonormality("A frame", 0));
    s->constraints().add(orthonormality("B frame", 12));
    s->constraints().add(spherical_joint("ball", PointMap::body_point(0, rA), PointMap::body_point(12, rB)));
    return s;
  }
  double L_scale() const { return mA * vA.norm() + mB * vB().norm(); }
  SphericalChainReference reference() const {
    ReferenceBody a, b;
    a.mass = mA, a.J = JA, a.R = RA, a.x = xA, a.v = vA, a.omega_body = RA.transpose() * wA;
    b.mass = mB, b.J = JB, b.R = RB, b.x = xB(), b.v = vB(), b.omega_body = RB.transpose() * wB;
    return SphericalChainReference({a, b}, {{0, rA, 1, rB}}, Vector3d::Zero());
  }
};

double trajectory_error(const RigidSystem& sys, const State& s, const SphericalChainReference& ref, double T) {
  const auto y = dormand_prince([&](double t, const VectorXd& yy, VectorXd& d) { ref.rhs(t, yy, d); }, 0.0,
                                ref.initial_state(), {T}, {})[0];
  const VectorXd q = sys.configuration(s.u);
  double e = 0.0;
  for (int i = 0; i < ref.num_bodies(); ++i) {
    e = std::max(e, (q.segment<3>(12 * i) - SphericalChainReference::position(y, i)).norm());
    const Matrix3d R = SphericalChainReference::rotation(y, i);
    for (int k = 0; k < 3; ++k) e = std::max(e, (q.segment<3>(12 * i + 3 + 3 * k) - R.col(k)).norm());
  }
  return e;
}

TEST(ConstrainedIntegrators, FreeFlyingPairEmExactKeepsEnergyBothMomentaAndTheJoint) {
  const Pair p;
  auto sys = p.system();
  const Summary r = run(*sys, "em-exact", 5e-3, 2.0);
  const double J = sys->invariants(sys->initial_state()).J.norm();
  std::printf("em-exact free pair, 400 steps of 5e-3: |dH|/H %.3e |dL|/(sum m|v|) %.3e |dJ|/|J| %.3e max|g| %.3e its/step %.2f\n",
              r.max_dH / r.H0, r.max_dL / p.L_scale(), r.max_dJ / J, r.max_g, double(r.iterations) / r.steps);
  EXPECT_LT(r.max_dH / r.H0, 1e-10);
  EXPECT_LT(r.max_dL / p.L_scale(), 1e-10);
  EXPECT_LT(r.max_dJ / J, 1e-10);
  EXPECT_LT(r.max_g, 1e-12);
}

TEST(ConstrainedIntegrators, FreeFlyingPairEmGalphaConservesAtRhoOneAndDissipatesBelow) {
  const Pair p;
  auto sys = p.system();
  const double J = sys->invariants(sys->initial_state()).J.norm();
  const Summary r1 = run(*sys, "em-galpha", 5e-3, 2.0);  // ρ∞ = 1: the trapezoidal/midpoint step, conserving
  std::printf("em-galpha (rho_inf 1) free pair: |dH|/H %.3e |dL| %.3e |dJ|/|J| %.3e max|g| %.3e\n", r1.max_dH / r1.H0,
              r1.max_dL / p.L_scale(), r1.max_dJ / J, r1.max_g);
  EXPECT_LT(r1.max_dH / r1.H0, 1e-10);
  EXPECT_LT(r1.max_dL / p.L_scale(), 1e-10);
  EXPECT_LT(r1.max_g, 1e-12);
  auto sys2 = p.system();
  const Summary r8 = run(*sys2, "em-galpha", 5e-3, 2.0, {{"rho_inf", "0.8"}});
  std::printf("em-galpha (rho_inf 0.8) free pair: H_end - H0 = %.3e (max |dH| %.3e), max|g| %.3e\n", r8.last_dH, r8.max_dH,
              r8.max_g);
  EXPECT_LE(r8.last_dH, 1e-10 * r8.H0);  // energy bounded: it decays (numerical dissipation), never grows
  EXPECT_LT(r8.max_g, 1e-12);
}

TEST(ConstrainedIntegrators, HeavyTopKeepsEnergyAndVerticalMomentumWithTheDiscreteGradient) {
  const Top top;
  for (const std::string name : {"em-exact", "em-galpha"}) {
    auto sys = top.system();
    const Summary r = run(*sys, name, 2e-3, 1.0);
    std::printf("%s heavy top, 500 steps of 2e-3: |dH|/H %.3e |dJz| %.3e max|g| %.3e its/step %.2f\n", name.c_str(),
                r.max_dH / std::abs(r.H0), r.max_dJz, r.max_g, double(r.iterations) / r.steps);
    EXPECT_LT(r.max_dH / std::abs(r.H0), 1e-10) << name;
    EXPECT_LT(r.max_dJz, 1e-10) << name;
    EXPECT_LT(r.max_g, 1e-12) << name;
  }
}

// galpha at ρ∞ = 1 is em-galpha here ((G(u_n) + G(u_{n+1}))/2 = G(u_mid) for quadratic constraints, and gravity is
// linear), so it is run dissipative; newmark with γ > ½ (the trapezoidal rule γ = ½ is unstable on index-3
// constraints, Cardona & Géradin 1989: its energy error grows by ~3× per 25 steps and exceeds 1e6 H by t = 0.9 here).
TEST(ConstrainedIntegrators, IndexThreeGalphaAndNewmarkHoldTheConstraintsAndReportTheirEnergyError) {
  const Top top;
  const std::vector<std::pair<std::string, std::vector<std::pair<std::string, std::string>>>> cases = {
      {"galpha", {{"rho_inf", "0.8"}}}, {"newmark", {{"gamma", "0.55"}, {"beta", "0.275625"}}}};
  for (const auto& [name, kv] : cases) {
    auto sys = top.system();
    const Summary r = run(*sys, name, 2e-3, 1.0, kv);
    std::printf("%s heavy top, 500 steps of 2e-3: |dH|/H %.3e (end %.3e) |dJz| %.3e max|g| %.3e its/step %.2f\n", name.c_str(),
                r.max_dH / std::abs(r.H0), r.last_dH / std::abs(r.H0), r.max_dJz, r.max_g, double(r.iterations) / r.steps);
    EXPECT_LT(r.max_g, 1e-12) << name;
    EXPECT_LT(r.max_dH / std::abs(r.H0), 1e-1) << name;  // bounded: not conserved
    EXPECT_LT(r.last_dH, 0.0) << name;                    // and decaying (numerical dissipation)
  }
  auto sys = top.system();
  const Summary tr = run(*sys, "newmark", 2e-3, 1.0);
  std::printf("newmark (gamma = 1/2) heavy top: max|dH|/H %.3e\n", tr.max_dH / std::abs(tr.H0));
  EXPECT_GT(tr.max_dH / std::abs(tr.H0), 1.0);  // the instability the comment describes (characterization)
}

// Second order against RK45 (tight) at two step sizes, for every integrator.
TEST(ConstrainedIntegrators, HeavyTopConvergesAtSecondOrderToTheRigidReference) {
  const Top top;
  const double T = 0.5;
  for (const std::string name : {"em-exact", "em-galpha", "galpha", "newmark"}) {
    auto s1 = top.system(), s2 = top.system();
    const std::vector<std::pair<std::string, std::string>> kv = name == "galpha" ? decltype(kv){{"rho_inf", "0.8"}} : decltype(kv){};
    const double e1 = trajectory_error(*s1, run(*s1, name, T / 250, T, kv).s, top.reference(), T);
    const double e2 = trajectory_error(*s2, run(*s2, name, T / 500, T, kv).s, top.reference(), T);
    std::printf("%s heavy top vs RK45 at t = %.1f: %.3e (dt = %.0e), %.3e (dt = %.0e), ratio %.3f\n", name.c_str(), T, e1,
                T / 250, e2, T / 500, e1 / e2);
    EXPECT_NEAR(e1 / e2, 4.0, 0.5) << name;
    EXPECT_LT(e2, 1e-2) << name;
  }
}

TEST(ConstrainedIntegrators, FreeFlyingPairConvergesAtSecondOrderToTheRigidReference) {
  const Pair p;
  const double T = 1.0;
  for (const std::string name : {"em-exact", "em-galpha", "galpha"}) {
    auto s1 = p.system(), s2 = p.system();
    const std::vector<std::pair<std::string, std::string>> kv = name == "em-exact" ? decltype(kv){} : decltype(kv){{"rho_inf", "0.8"}};
    const double e1 = trajectory_error(*s1, run(*s1, name, T / 200, T, kv).s, p.reference(), T);
    const double e2 = trajectory_error(*s2, run(*s2, name, T / 400, T, kv).s, p.reference(), T);
    std::printf("%s free pair vs RK45 at t = %.1f: %.3e, %.3e, ratio %.3f\n", name.c_str(), T, e1, e2, e1 / e2);
    EXPECT_NEAR(e1 / e2, 4.0, 0.5) << name;
  }
}

// Compound pendulum on a revolute joint to the ground: the period against the closed form (6.1) at T/100 and T/200,
// with the energy balance K + V (gravity) and the drift per integrator.
TEST(ConstrainedIntegrators, HingedPendulumHasTheClosedFormPeriodAtSecondOrder) {
  const double m = 2.0, l = 0.4, g = 9.81, th0 = 0.2;
  const Vector3d J(0.1, 0.15, 0.08);
  const Matrix3d R0 = Eigen::AngleAxisd(th0, Vector3d::UnitY()).toRotationMatrix();
  const VectorXd q0 = RigidBody::state(-R0 * Vector3d(0, 0, l), R0);
  auto system = [&] {
    auto s = std::make_unique<RigidSystem>(std::vector<RigidBody>{RigidBody("plate", m, J)}, q0, VectorXd::Zero(12),
                                           Vector3d(0, 0, -g));
    s->constraints().add(orthonormality("plate frame", 0));
    s->constraints().add(revolute_joint("hinge", PointMap::body_point(0, Vector3d(0, 0, l)), PointMap::ground(Vector3d::Zero()),
                                        PointMap::ground(Vector3d::UnitY()), PointMap::body_vector(0, Vector3d::UnitX()),
                                        PointMap::body_vector(0, Vector3d::UnitZ())));
    return s;
  };
  const double Ip = J(1) + m * l * l, T = compound_pendulum_period(Ip, m, g, l, th0);
  auto measured = [&](const std::string& name, int per_period, const std::vector<std::pair<std::string, std::string>>& kv,
                      double* dH, double* gmax) {
    auto sys = system();
    const double dt = T / per_period;
    auto integ = make(name, dt, kv);
    State s = sys->initial_state();
    integ->initialize(*sys, s);
    const Invariants i0 = sys->invariants(s);
    std::vector<double> down;  // times the angle crosses zero going negative
    double th_prev = th0;
    VectorXd gv;
    *dH = *gmax = 0.0;
    for (int k = 1; k <= 2 * per_period + 10; ++k) {
      integ->advance(*sys, s, k * dt);
      const VectorXd q = sys->configuration(s.u);
      const double th = std::atan2(q(9), q(11));  // rotation about y by θ: d3 = (sin θ, 0, cos θ)
      if (th_prev > 0 && th <= 0) down.push_back((k - 1) * dt + dt * th_prev / (th_prev - th));
      th_prev = th;
      const Invariants inv = sys->invariants(s);
      *dH = std::max(*dH, std::abs(inv.kinetic + inv.strain - i0.kinetic - i0.strain) / std::abs(i0.strain));
      sys->constraint_values(s.t, s.u, s.charts, gv);
      *gmax = std::max(*gmax, gv.cwiseAbs().maxCoeff());
    }
    EXPECT_GE(down.size(), 2u) << name;
    return down.size() >= 2 ? down[1] - down[0] : 0.0;
  };
  for (const std::string name : {"em-exact", "em-galpha", "galpha", "newmark"}) {
    const std::vector<std::pair<std::string, std::string>> kv =
        name == "galpha" ? decltype(kv){{"rho_inf", "0.8"}} : name == "newmark" ? decltype(kv){{"gamma", "0.5"}} : decltype(kv){};
    double dH1, g1, dH2, g2;
    const double e1 = std::abs(measured(name, 100, kv, &dH1, &g1) / T - 1), e2 = std::abs(measured(name, 200, kv, &dH2, &g2) / T - 1);
    std::printf("%s hinge, theta0 = %.1f, T = %.9f s: period error %.3e (T/100), %.3e (T/200), ratio %.3f; max|dH|/|V0| %.3e, %.3e; "
                "max|g| %.3e\n", name.c_str(), th0, T, e1, e2, e1 / e2, dH1, dH2, std::max(g1, g2));
    EXPECT_LT(e2, 1e-3) << name;
    EXPECT_NEAR(e1 / e2, 4.0, 0.5) << name;
    EXPECT_LT(std::max(g1, g2), 1e-12) << name;
    if (name == "em-exact" || name == "em-galpha") {
      EXPECT_LT(std::max(dH1, dH2), 1e-10) << name;
    }
  }
}

// A flat body (J3 = J1 + J2: E3 = 0, its d3 carries no mass) has a singular K̄ and mass matrix; the bordered solve
// augments them with Gᵀ W G of the frame rows (bordered_newton.cpp, multibody.md §9.2). Free spin: H, L, J kept.
TEST(ConstrainedIntegrators, FlatRigidBodySpinsFreelyWithItsFrameHeld) {
  const Vector3d J(0.1, 0.15, 0.25), w(1.0, 2.0, 3.0);
  const Matrix3d R = Eigen::AngleAxisd(0.3, Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const VectorXd q = RigidBody::state(Vector3d(0.1, 0.2, 0.3), R);
  for (const std::string name : {"em-exact", "em-galpha", "galpha"}) {
    RigidSystem sys({RigidBody("flat", 2.0, J)}, q, RigidBody::velocity(q, Vector3d(0.5, 0, 0), w), Vector3d::Zero());
    sys.constraints().add(orthonormality("flat frame", 0));
    ASSERT_EQ(sys.rigid_block(0).E[2], 0.0);
    const Summary r = run(sys, name, 5e-3, 1.0);
    const double J0 = sys.invariants(sys.initial_state()).J.norm();
    std::printf("%s flat body, 200 steps of 5e-3: |dH|/H %.3e |dJ|/|J| %.3e max|g| %.3e\n", name.c_str(), r.max_dH / r.H0,
                r.max_dJ / J0, r.max_g);
    EXPECT_LT(r.max_g, 1e-12) << name;
    EXPECT_LT(r.max_dH / r.H0, 1e-10) << name;  // galpha at ρ∞ = 1 is em-galpha here (see the index-3 test)
    EXPECT_LT(r.max_dJ / J0, 1e-10) << name;
  }
}

}  // namespace
}  // namespace shelldyn::multibody
