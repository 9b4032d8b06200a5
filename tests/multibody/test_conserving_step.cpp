// End-to-end check of the construction on rigid bodies (docs/theory/multibody.md §5, §8): the conserving
// director-form step with multipliers on the discrete gradient keeps the energy to solver tolerance, the
// momenta exactly where no ground joint breaks them, and g = 0 at every step end; its trajectory converges at
// second order to the independent RK45 reference; replacing Ḡ by the end-point Jacobian G(q_{n+1}) loses the
// energy (§8).
#include "director_step.hpp"
#include "lib/multibody/rigid_reference.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>

namespace shelldyn::multibody {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;
using testing::DirectorSystem;
using testing::GradientChoice;

struct RunSummary {
  double max_dH = 0.0, max_dL = 0.0, max_dJ = 0.0, max_dJz = 0.0, max_g = 0.0, work = 0.0;
  double H0 = 0.0;
  VectorXd q, v;
  int steps = 0, iterations = 0;
};

RunSummary integrate(const DirectorSystem& s, VectorXd q, VectorXd v, double dt, int steps,
                     GradientChoice c) {
  RunSummary r;
  r.H0 = s.energy(q, v);
  const Vector3d L0 = s.linear_momentum(v), J0 = s.angular_momentum(q, v);
  double t = 0.0;
  for (int k = 0; k < steps; ++k) {
    const auto st = testing::step(s, q, v, t, dt, c);
    q = st.q;
    v = st.v;
    t += dt;
    r.work += st.drive_work;
    r.iterations += st.iterations;
    r.max_dH = std::max(r.max_dH, std::abs(s.energy(q, v) - r.H0 - r.work));
    r.max_dL = std::max(r.max_dL, (s.linear_momentum(v) - L0).norm());
    r.max_dJ = std::max(r.max_dJ, (s.angular_momentum(q, v) - J0).norm());
    r.max_dJz = std::max(r.max_dJz, std::abs(s.angular_momentum(q, v)(2) - J0(2)));
    r.max_g = std::max(r.max_g, s.constraints.g(q, t).cwiseAbs().maxCoeff());
  }
  r.q = q;
  r.v = v;
  r.steps = steps;
  return r;
}

// ---- heavy symmetric top pivoted at the origin -----------------------------------------------------------
struct Top {
  double m = 2.0, l = 0.5;
  Vector3d J{0.3, 0.3, 0.1}, gravity{0, 0, -9.81};
  Matrix3d R0 = Eigen::AngleAxisd(0.3, Vector3d::UnitX()).toRotationMatrix();
  Vector3d w0 = R0 * Vector3d(0, 0, 20.0) + Vector3d(0, 0, 1.0);  // spatial angular velocity

  DirectorSystem system() const {
    DirectorSystem s({RigidBody("top", m, J)});
    s.gravity = gravity;
    s.constraints.add(orthonormality("top frame", 0));
    s.constraints.add(fixed_point("pivot", PointMap::body_point(0, Vector3d(0, 0, -l)), Vector3d::Zero()));
    return s;
  }
  VectorXd q0() const { return RigidBody::state(R0 * Vector3d(0, 0, l), R0); }
  VectorXd v0() const { return RigidBody::velocity(q0(), w0.cross(R0 * Vector3d(0, 0, l)), w0); }
  SphericalChainReference reference() const {
    ReferenceBody b;
    b.mass = m;
    b.J = J;
    b.R = R0;
    b.x = R0 * Vector3d(0, 0, l);
    b.v = w0.cross(b.x);
    b.omega_body = R0.transpose() * w0;
    return SphericalChainReference({b}, {{0, Vector3d(0, 0, -l), -1, Vector3d::Zero()}}, gravity);
  }
};

// ---- two bodies joined by a spherical joint, tumbling in free flight --------------------------------------
struct Pair {
  double mA = 3.0, mB = 1.5;
  Vector3d JA{0.4, 0.6, 0.8}, JB{0.2, 0.25, 0.3};
  Vector3d rA{0.5, 0.0, 0.1}, rB{-0.4, 0.1, 0.0};  // joint in each body's frame
  Matrix3d RA = Eigen::AngleAxisd(0.4, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Matrix3d RB = Eigen::AngleAxisd(-0.9, Vector3d(0, 1, 1).normalized()).toRotationMatrix();
  Vector3d xA{0.1, -0.2, 0.3}, vA{0.3, 0.1, -0.2}, wA{1.0, -2.0, 3.0}, wB{-2.5, 1.0, 0.5};
  Vector3d xB() const { return xA + RA * rA - RB * rB; }
  Vector3d vB() const { return vA + wA.cross(RA * rA) - wB.cross(RB * rB); }

  DirectorSystem system() const {
    DirectorSystem s({RigidBody("A", mA, JA), RigidBody("B", mB, JB)});
    s.constraints.add(orthonormality("A frame", 0));
    s.constraints.add(orthonormality("B frame", 12));
    s.constraints.add(spherical_joint("ball", PointMap::body_point(0, rA), PointMap::body_point(12, rB)));
    return s;
  }
  VectorXd q0() const {
    VectorXd q(24);
    q << RigidBody::state(xA, RA), RigidBody::state(xB(), RB);
    return q;
  }
  VectorXd v0() const {
    const VectorXd q = q0();
    VectorXd v(24);
    v << RigidBody::velocity(q.head<12>(), vA, wA), RigidBody::velocity(q.tail<12>(), vB(), wB);
    return v;
  }
  SphericalChainReference reference() const {
    ReferenceBody a, b;
    a.mass = mA, a.J = JA, a.R = RA, a.x = xA, a.v = vA, a.omega_body = RA.transpose() * wA;
    b.mass = mB, b.J = JB, b.R = RB, b.x = xB(), b.v = vB(), b.omega_body = RB.transpose() * wB;
    return SphericalChainReference({a, b}, {{0, rA, 1, rB}}, Vector3d::Zero());
  }
};

// Largest distance between the director-form state and the RK45 reference at time T (φ and every d_i).
double trajectory_error(const VectorXd& q, const SphericalChainReference& ref, double T) {
  const auto y = dormand_prince([&](double t, const VectorXd& yy, VectorXd& d) { ref.rhs(t, yy, d); }, 0.0,
                                ref.initial_state(), {T}, {})[0];
  double e = 0.0;
  for (int i = 0; i < ref.num_bodies(); ++i) {
    e = std::max(e, (q.segment<3>(12 * i) - SphericalChainReference::position(y, i)).norm());
    const Matrix3d R = SphericalChainReference::rotation(y, i);
    for (int k = 0; k < 3; ++k) e = std::max(e, (q.segment<3>(12 * i + 3 + 3 * k) - R.col(k)).norm());
  }
  return e;
}

TEST(ConservingStep, HeavyTopKeepsEnergyAndVerticalMomentumAndTheConstraints) {
  const Top top;
  const DirectorSystem s = top.system();
  ASSERT_TRUE(s.constraints.rank_check(top.q0(), 0.0).message.empty());
  const RunSummary r = integrate(s, top.q0(), top.v0(), 2e-3, 500, testing::default_choice());
  std::printf(
      "heavy top, 500 steps of 2e-3: max|H-H0|/H0 %.3e  max|dJz| %.3e  max|g| %.3e  Newton its/step %.2f\n",
      r.max_dH / std::abs(r.H0), r.max_dJz, r.max_g, double(r.iterations) / r.steps);
  EXPECT_LT(r.max_dH / std::abs(r.H0), 1e-12);
  EXPECT_LT(r.max_dJz, 1e-12);  // gravity and the pivot at the origin exert no torque about the vertical
  EXPECT_LT(r.max_g, 1e-14);
}

TEST(ConservingStep, EndPointJacobianLosesTheEnergy) {
  // The same run with G(q_{n+1}) in place of Ḡ: g still holds at the step ends, the energy does not.
  const Top top;
  const DirectorSystem s = top.system();
  const RunSummary d = integrate(s, top.q0(), top.v0(), 2e-3, 500, GradientChoice::discrete);
  const RunSummary e = integrate(s, top.q0(), top.v0(), 2e-3, 500, GradientChoice::endpoint);
  std::printf("heavy top energy error: discrete gradient %.3e, end-point Jacobian %.3e\n",
              d.max_dH / std::abs(d.H0), e.max_dH / std::abs(e.H0));
  EXPECT_LT(e.max_g, 1e-14);
  EXPECT_GT(e.max_dH / std::abs(e.H0), 1e4 * std::max(d.max_dH / std::abs(d.H0), 1e-15));
  EXPECT_GT(e.max_dH / std::abs(e.H0), 1e-8);
}

TEST(ConservingStep, HeavyTopConvergesAtSecondOrderToTheReference) {
  const Top top;
  const DirectorSystem s = top.system();
  const double T = 0.5;
  const double e1 = trajectory_error(
      integrate(s, top.q0(), top.v0(), T / 250, 250, GradientChoice::discrete).q, top.reference(), T);
  const double e2 = trajectory_error(
      integrate(s, top.q0(), top.v0(), T / 500, 500, GradientChoice::discrete).q, top.reference(), T);
  std::printf("heavy top vs RK45 at t = %.1f: error %.3e (dt = %.0e), %.3e (dt = %.0e), ratio %.3f\n", T, e1,
              T / 250, e2, T / 500, e1 / e2);
  EXPECT_NEAR(e1 / e2, 4.0, 0.4);
  EXPECT_LT(e2, 1e-2);
}

TEST(ConservingStep, FreeFlyingPairKeepsEnergyBothMomentaAndTheJoint) {
  const Pair p;
  const DirectorSystem s = p.system();
  ASSERT_TRUE(s.constraints.rank_check(p.q0(), 0.0).message.empty());
  const RunSummary r = integrate(s, p.q0(), p.v0(), 5e-3, 400, testing::default_choice());
  // Scales: the bodies' own momenta (the total L is a difference of them).
  const double L = p.mA * p.vA.norm() + p.mB * p.vB().norm(), J = s.angular_momentum(p.q0(), p.v0()).norm();
  std::printf("free pair, 400 steps of 5e-3: |dH|/H %.3e  |dL|/(sum m|v|) %.3e  |dJ|/|J| %.3e  max|g| %.3e\n",
              r.max_dH / r.H0, r.max_dL / L, r.max_dJ / J, r.max_g);
  EXPECT_LT(r.max_dH / r.H0, 1e-12);
  EXPECT_LT(r.max_dL / L, 1e-12);
  EXPECT_LT(r.max_dJ / J, 1e-12);
  EXPECT_LT(r.max_g, 1e-14);
}

TEST(ConservingStep, FreeFlyingPairConvergesAtSecondOrderToTheReference) {
  const Pair p;
  const DirectorSystem s = p.system();
  const double T = 1.0;
  const double e1 = trajectory_error(integrate(s, p.q0(), p.v0(), T / 200, 200, GradientChoice::discrete).q,
                                     p.reference(), T);
  const double e2 = trajectory_error(integrate(s, p.q0(), p.v0(), T / 400, 400, GradientChoice::discrete).q,
                                     p.reference(), T);
  std::printf("free pair vs RK45 at t = %.1f: error %.3e (dt = %.1e), %.3e (dt = %.2e), ratio %.3f\n", T, e1,
              T / 200, e2, T / 400, e1 / e2);
  EXPECT_NEAR(e1 / e2, 4.0, 0.4);
  EXPECT_LT(e2, 1e-2);
}

// §2.3: the pair joined by a massless rod (distance constraint, general kind) instead of the ball joint. Both
// discrete gradients keep energy and both momenta: on consistent states (g_n = g_{n+1} = 0) the correction of
// Gonzalez's formula (2.4) is −G(q_mid)Δq Δqᵀ/|Δq|², and G(q_mid)Δq = (|r1|² − |r0|²)/(2|r_mid|) = 0.
TEST(ConservingStep, RodBetweenFreeBodiesKeepsEnergyAndMomentaInBothForms) {
  const Pair p;
  auto run = [&](DistanceGradient form) {
    DirectorSystem s({RigidBody("A", p.mA, p.JA), RigidBody("B", p.mB, p.JB)});
    s.constraints.add(orthonormality("A frame", 0));
    s.constraints.add(orthonormality("B frame", 12));
    const VectorXd q0 = p.q0();
    const Vector3d XA(0.5, 0, 0.1), XB(-0.4, 0.1, 0.3);
    const double L = (RigidBody::point(q0.head<12>(), XA) - RigidBody::point(q0.tail<12>(), XB)).norm();
    s.constraints.add(distance("rod", PointMap::body_point(0, XA), PointMap::body_point(12, XB), L, form));
    // Velocities consistent with the rod: drop the relative velocity's component along it from body B.
    VectorXd v = p.v0();
    const Vector3d r = RigidBody::point(q0.head<12>(), XA) - RigidBody::point(q0.tail<12>(), XB);
    const Vector3d dr = RigidBody::point(v.head<12>(), XA) - RigidBody::point(v.tail<12>(), XB);
    v.segment<3>(12) += r.dot(dr) / r.squaredNorm() * r;
    EXPECT_LT(std::abs((s.constraints.G(q0, 0) * v)(12)), 1e-13);
    const RunSummary rs = integrate(s, q0, v, 5e-3, 400, GradientChoice::discrete);
    const double J = s.angular_momentum(q0, v).norm();
    std::printf("free pair with a rod, %s form: |dH|/H %.3e  |dJ|/|J| %.3e  max|g| %.3e\n",
                form == DistanceGradient::invariant ? "invariant" : "Gonzalez", rs.max_dH / rs.H0,
                rs.max_dJ / J, rs.max_g);
    EXPECT_LT(rs.max_dH / rs.H0, 1e-12);
    EXPECT_LT(rs.max_g, 1e-14);
    return rs.max_dJ / J;
  };
  EXPECT_LT(run(DistanceGradient::invariant), 1e-12);
  EXPECT_LT(run(DistanceGradient::gonzalez), 1e-12);
}

// §4.2: a free-flying gyrostat — a rotor (body B) whose centre and axis d3 are clamped to a carrier (body A)
// by a rigid connection with the aligned director form, so that B keeps its spin about the axis. Energy, L
// and J stay exact. The equal form (3 rows on the unit axis d3) repeats the unit length that B's frame rows
// already impose, and the rank check names both.
TEST(ConservingStep, FreeGyrostatWithAnAlignedRigidConnection) {
  const double mA = 4.0, mB = 1.0;
  const Vector3d JA(0.5, 0.7, 0.9), JB(0.05, 0.05, 0.08), X(0.3, -0.1, 0.2),
      a = Vector3d(1, 1, 2).normalized();
  const Matrix3d RA = Eigen::AngleAxisd(0.7, Vector3d(0.2, 1, 0.4).normalized()).toRotationMatrix();
  // B's d3 along the carrier's body vector a; its d1, d2 anywhere normal to it.
  Matrix3d Rb;
  Rb.col(2) = RA * a;
  Rb.col(0) = Rb.col(2).cross(Vector3d::UnitX()).normalized();
  Rb.col(1) = Rb.col(2).cross(Rb.col(0));
  const Vector3d xA(0.2, 0.1, -0.3), vA(0.4, -0.2, 0.1), wA(1.5, -0.5, 2.0);
  const Vector3d wB = wA + 30.0 * Rb.col(2);  // the rotor spins at 30 rad/s relative to the carrier
  VectorXd q(24), v(24);
  q << RigidBody::state(xA, RA), RigidBody::state(xA + RA * X, Rb);
  v << RigidBody::velocity(q.head<12>(), vA, wA),
      RigidBody::velocity(q.tail<12>(), vA + wA.cross(RA * X), wB);
  auto build = [&](DirectorCondition form) {
    DirectorSystem s({RigidBody("carrier", mA, JA), RigidBody("rotor", mB, JB)});
    s.constraints.add(orthonormality("carrier frame", 0));
    s.constraints.add(orthonormality("rotor frame", 12));
    s.constraints.add(rigid_connection("rotor mount", PointMap::body_point(12, Vector3d::Zero()),
                                       PointMap::body_vector(12, Vector3d::UnitZ()), 0, X, a, form));
    return s;
  };
  const DirectorSystem eq = build(DirectorCondition::equal);
  const RankReport r = eq.constraints.rank_check(q, 0.0);
  EXPECT_EQ(r.rows - r.rank, 1) << r.message;
  EXPECT_NE(r.message.find("rigid connection 'rotor mount'"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("orthonormality 'rotor frame'"), std::string::npos) << r.message;

  const DirectorSystem s = build(DirectorCondition::aligned);
  ASSERT_TRUE(s.constraints.rank_check(q, 0.0).message.empty());
  ASSERT_LT(s.constraints.g(q, 0.0).cwiseAbs().maxCoeff(), 1e-15);
  ASSERT_LT((s.constraints.G(q, 0.0) * v).cwiseAbs().maxCoeff(), 1e-13);
  const RunSummary rs = integrate(s, q, v, 2e-3, 500, testing::default_choice());
  const double Lsc = mA * vA.norm() + mB * (vA + wA.cross(RA * X)).norm(),
               J = s.angular_momentum(q, v).norm();
  std::printf(
      "free gyrostat, 500 steps of 2e-3: |dH|/H %.3e  |dL|/(sum m|v|) %.3e  |dJ|/|J| %.3e  max|g| %.3e\n",
      rs.max_dH / rs.H0, rs.max_dL / Lsc, rs.max_dJ / J, rs.max_g);
  EXPECT_LT(rs.max_dH / rs.H0, 1e-12);
  // L is rebuilt from v = 2Δq/Δt − v_n: rounding of q (ε|q| ≈ 2e-16) over Δt = 2e-3, accumulated over 500
  // steps as a random walk, is ≈ 1e-12 of Σm|v| here; the bound allows that rounding, not a drift.
  EXPECT_LT(rs.max_dL / Lsc, 1e-11);
  EXPECT_LT(rs.max_dJ / J, 1e-12);
  EXPECT_LT(rs.max_g, 1e-14);
  // An axisymmetric rotor on a frictionless mount keeps its axial spin ω_B·d3 = ḋ1·d2 (the mount's reaction
  // moments are normal to d3). The step keeps it up to its time-discretization error.
  const double s0 = v.segment<3>(15).dot(q.segment<3>(18)), s1 = rs.v.segment<3>(15).dot(rs.q.segment<3>(18));
  std::printf("rotor axial spin: %.9f -> %.9f rad/s\n", s0, s1);
  EXPECT_NEAR(s1, s0, 1e-5 * std::abs(s0));  // measured 3.5e-6
}

// A hub driven about the vertical through θ(t) with a pendulum hanging from its rim: the energy changes by
// the driver's discrete work λ·τ exactly (§4.4), and that work is not small.
TEST(ConservingStep, DrivenHubEnergyChangesByTheDriversWork) {
  DirectorSystem s(
      {RigidBody("hub", 5.0, Vector3d(1.0, 1.0, 1.5)), RigidBody("bob", 1.0, Vector3d(0.02, 0.02, 0.01))});
  s.gravity = Vector3d(0, 0, -9.81);
  const double alpha = 4.0;
  s.constraints.add(orthonormality("hub frame", 0));
  s.constraints.add(orthonormality("bob frame", 12));
  s.constraints.add(prescribed_rotation(
      "drive", 0, Vector3d::Zero(), Vector3d::UnitZ(), Vector3d::UnitX(), Vector3d::Zero(), Vector3d::UnitZ(),
      Vector3d::UnitX(),
      {[=](double t) { return 0.5 * alpha * t * t; }, [=](double t) { return alpha * t; }}));
  s.constraints.add(spherical_joint("rim", PointMap::body_point(0, Vector3d(0.6, 0, 0)),
                                    PointMap::body_point(12, Vector3d(0, 0, 0.3))));
  VectorXd q(24), v = VectorXd::Zero(24);
  q << RigidBody::state(Vector3d::Zero(), Matrix3d::Identity()),
      RigidBody::state(Vector3d(0.6, 0, -0.3), Matrix3d::Identity());
  ASSERT_LT(s.constraints.g(q, 0.0).norm(), 1e-15);
  ASSERT_TRUE(s.constraints.rank_check(q, 0.0).message.empty());
  const RunSummary r = integrate(s, q, v, 2e-3, 500, testing::default_choice());
  std::printf("driven hub, 500 steps of 2e-3: work %.6f, max|H - H0 - W| %.3e, max|g| %.3e\n", r.work,
              r.max_dH, r.max_g);
  EXPECT_GT(r.work, 1.0);
  EXPECT_LT(r.max_dH, 1e-11 * r.work);
  EXPECT_LT(r.max_g, 1e-14);
  // The hub follows θ(t): its d1 is at angle ½αT² at T = 1.
  EXPECT_NEAR(std::atan2(r.q(4), r.q(3)), std::remainder(0.5 * alpha, 2 * M_PI), 1e-12);
}

// Compound pendulum on a revolute joint to the ground: the period of the director-form step against the
// closed form T = 4K(sin(θ0/2))√(I_p/(m g l)); the error falls at second order in Δt.
TEST(ConservingStep, HingedPendulumHasTheClosedFormPeriod) {
  const double m = 2.0, l = 0.4, g = 9.81, th0 = 0.2;
  const Vector3d J(0.1, 0.15, 0.08);
  DirectorSystem s({RigidBody("plate", m, J)});
  s.gravity = Vector3d(0, 0, -g);
  s.constraints.add(orthonormality("plate frame", 0));
  s.constraints.add(revolute_joint("hinge", PointMap::body_point(0, Vector3d(0, 0, l)),
                                   PointMap::ground(Vector3d::Zero()), PointMap::ground(Vector3d::UnitY()),
                                   PointMap::body_vector(0, Vector3d::UnitX()),
                                   PointMap::body_vector(0, Vector3d::UnitZ())));
  const Matrix3d R0 = Eigen::AngleAxisd(th0, Vector3d::UnitY()).toRotationMatrix();
  const VectorXd q0 = RigidBody::state(-R0 * Vector3d(0, 0, l), R0), v0 = VectorXd::Zero(12);
  ASSERT_TRUE(s.constraints.rank_check(q0, 0.0).message.empty());
  const double Ip = J(1) + m * l * l, T = compound_pendulum_period(Ip, m, g, l, th0);
  auto measured_period = [&](int per_period) {
    const double dt = T / per_period;
    VectorXd q = q0, v = v0;
    std::vector<double> down;  // times the angle crosses zero going negative
    double th_prev = th0;
    for (int k = 1; k <= 2 * per_period + 10; ++k) {
      const auto st = testing::step(s, q, v, (k - 1) * dt, dt, GradientChoice::discrete);
      q = st.q;
      v = st.v;
      const double th = std::atan2(q(9), q(11));  // rotation about y by θ: d3 = (sin θ, 0, cos θ)
      if (th_prev > 0 && th <= 0) down.push_back((k - 1) * dt + dt * th_prev / (th_prev - th));
      th_prev = th;
    }
    EXPECT_GE(down.size(), 2u);
    return down.size() >= 2 ? down[1] - down[0] : 0.0;
  };
  const double e1 = std::abs(measured_period(100) / T - 1), e2 = std::abs(measured_period(200) / T - 1);
  std::printf(
      "hinged pendulum, θ0 = %.1f: closed-form period %.9f s (small-amplitude %.9f s); relative error %.3e "
      "(T/100), %.3e (T/200), ratio %.3f\n",
      th0, T, compound_pendulum_small_period(Ip, m, g, l), e1, e2, e1 / e2);
  EXPECT_LT(e2, 1e-4);
  EXPECT_NEAR(e1 / e2, 4.0, 0.4);
}

}  // namespace
}  // namespace shelldyn::multibody
