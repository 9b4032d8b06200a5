// The independent rigid-body reference: Dormand–Prince RK5(4) and the spherical-joint Newton–Euler equations
// (docs/theory/multibody.md §6).
#include "lib/multibody/rigid_reference.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>

namespace shelldyn::multibody {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;

TEST(DormandPrince, MatchesTheExactSolutionAndItsErrorFollowsTheTolerance) {
  // y'' = −y (as a system) and y' = t y (y = exp(t²/2)): exact at t = 10 and t = 2.
  const OdeRhs osc = [](double, const VectorXd& y, VectorXd& d) {
    d.resize(2);
    d << y(1), -y(0);
  };
  double prev = 0.0;
  for (double tol : {1e-6, 1e-9, 1e-12}) {
    Rk45Options o;
    o.rtol = tol;
    o.atol = tol * 1e-2;
    Rk45Stats st;
    const auto y = dormand_prince(osc, 0.0, (VectorXd(2) << 1.0, 0.0).finished(), {5.0, 10.0}, o, &st);
    const double e = std::hypot(y[1](0) - std::cos(10.0), y[1](1) + std::sin(10.0));
    EXPECT_LT(e, 300 * tol) << tol;  // global error ~ (number of steps) × tolerance
    if (prev > 0.0) {
      EXPECT_LT(e, prev / 30.0) << tol;
    }
    prev = e;
    EXPECT_NEAR(y[0](0), std::cos(5.0), 300 * tol);
    EXPECT_GT(st.accepted, 0);
  }
  const OdeRhs grow = [](double t, const VectorXd& y, VectorXd& d) { d = t * y; };
  const auto y = dormand_prince(grow, 0.0, VectorXd::Ones(1), {2.0}, {});
  EXPECT_NEAR(y[0](0) / std::exp(2.0), 1.0, 1e-11);
  EXPECT_THROW(dormand_prince(grow, 1.0, VectorXd::Ones(1), {0.5}, {}), std::invalid_argument);
}

// Heavy symmetric top pivoted on its axis: energy, the vertical angular momentum about the pivot and the spin
// component along the symmetry axis are invariants of the exact flow (Euler–Poisson with J1 = J2).
TEST(SphericalChainReference, HeavySymmetricTopKeepsItsThreeInvariants) {
  const double m = 2.0, l = 0.5;
  ReferenceBody b;
  b.mass = m;
  b.J = Vector3d(0.3, 0.3, 0.1);
  b.R = Eigen::AngleAxisd(0.3, Vector3d::UnitX()).toRotationMatrix();
  const Vector3d w = b.R * Vector3d(0, 0, 20.0) + Vector3d(0, 0, 1.0);  // spin + precession, spatial
  b.x = b.R * Vector3d(0, 0, l);
  b.v = w.cross(b.x);
  b.omega_body = b.R.transpose() * w;
  const SphericalChainReference top({b}, {{0, Vector3d(0, 0, -l), -1, Vector3d::Zero()}},
                                    Vector3d(0, 0, -9.81));
  const VectorXd y0 = top.initial_state();
  const auto ys = dormand_prince([&](double t, const VectorXd& y, VectorXd& d) { top.rhs(t, y, d); }, 0.0, y0,
                                 {1.0, 5.0}, {});
  auto spin = [&](const VectorXd& y) { return SphericalChainReference::omega_body(y, 0)(2); };
  for (const auto& y : ys) {
    EXPECT_NEAR(top.energy(y), top.energy(y0), 1e-9 * std::abs(top.energy(y0)));
    EXPECT_NEAR(top.angular_momentum(y)(2), top.angular_momentum(y0)(2), 1e-9);
    EXPECT_NEAR(spin(y), spin(y0), 1e-9);
    EXPECT_LT(top.joint_gap(y), 1e-9);
    const Matrix3d R = SphericalChainReference::rotation(y, 0);
    EXPECT_LT((R.transpose() * R - Matrix3d::Identity()).norm(), 1e-9);
  }
  // The motion is not trivial: the axis moved.
  EXPECT_GT((SphericalChainReference::rotation(ys[1], 0).col(2) - b.R.col(2)).norm(), 0.1);
}

// A body hanging from a spherical joint, released in a plane, is a compound pendulum: after the exact period
// (elliptic integral) the state returns to the start.
TEST(SphericalChainReference, PlanarSwingHasTheCompoundPendulumPeriod) {
  const double m = 1.5, l = 0.4, g = 9.81, th0 = 0.6;
  ReferenceBody b;
  b.mass = m;
  b.J = Vector3d(0.05, 0.07, 0.03);
  b.R = Eigen::AngleAxisd(th0, Vector3d::UnitY()).toRotationMatrix();
  b.x = b.R * Vector3d(0, 0, -l);
  const SphericalChainReference p({b}, {{0, Vector3d(0, 0, l), -1, Vector3d::Zero()}}, Vector3d(0, 0, -g));
  const double Ip = b.J(1) + m * l * l;
  const double T = compound_pendulum_period(Ip, m, g, l, th0);
  EXPECT_GT(T,
            compound_pendulum_small_period(Ip, m, g, l) * (1.0 + th0 * th0 / 16.0 - 1e-3));  // 1 + θ0²/16 + …
  const auto ys = dormand_prince([&](double t, const VectorXd& y, VectorXd& d) { p.rhs(t, y, d); }, 0.0,
                                 p.initial_state(), {0.5 * T, T}, {});
  auto angle = [](const VectorXd& y) {
    const Matrix3d R = SphericalChainReference::rotation(y, 0);
    return std::atan2(R(0, 2), R(2, 2));
  };
  EXPECT_NEAR(angle(ys[0]), -th0, 1e-9);
  EXPECT_NEAR(angle(ys[1]), th0, 1e-9);
  EXPECT_LT(SphericalChainReference::omega_body(ys[1], 0).norm(), 1e-8);
  EXPECT_THROW(compound_pendulum_period(Ip, m, g, l, 4.0), std::invalid_argument);
}

TEST(SphericalChainReference, BadJointReferencesAreRefused) {
  EXPECT_THROW(SphericalChainReference({ReferenceBody{}}, {{0, Vector3d::Zero(), 3, Vector3d::Zero()}},
                                       Vector3d::Zero()),
               std::invalid_argument);
}

}  // namespace
}  // namespace shelldyn::multibody
