// ida-bdf on a constrained system: the index-2 stabilized (GGL) DAE of integrators/baselines/ida_bdf.hpp
// (docs/theory/multibody.md §7), on a heavy top (a rigid body on a fixed_point joint under gravity) against the
// independent RK45 reference of lib/multibody/rigid_reference.hpp.
#include "integrators/runs/registry.hpp"
#include "lib/io/case_file.hpp"
#include "lib/io/state_output.hpp"
#include "lib/model/problem.hpp"
#include "lib/multibody/rigid_reference.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

using namespace shelldyn;

namespace {

// The shell is a single clamped element far away (a case needs a mesh); the top: m = 2, J = (0.3, 0.3, 0.1),
// centre of mass 0.5 from the pivot along its axis d3, tilted 0.3 rad about x, spinning at 20 rad/s about d3.
std::string top_case(double rtol) {
  const double th = 0.3, s = std::sin(th), c = std::cos(th);
  char buf[2048];
  // d2 = (0, c, s), d3 = (0, −s, c); φ = 0.5 d3; ω = 20 d3, and the pivot at rest: v = −ω × (−φ) = ω × φ = 0.
  std::snprintf(buf, sizeof buf, R"(
name: top
mesh: {generator: rectangle, a: 0.1, b: 0.1, nx: 1, ny: 1, x0: 5, y0: 5}
material: {E: 1.0e6, nu: 0.3, rho: 1, thickness: 0.01}
boundary_conditions: [{set: all, fix: [ux, uy, uz, director]}]
gravity: [0, 0, -9.81]
rigid_bodies:
  top: {mass: 2, inertia: [0.3, 0.3, 0.1], position: [0, %.17g, %.17g], axes: [[1, 0, 0], [0, %.17g, %.17g]],
        angular_velocity: [0, %.17g, %.17g]}
joints:
  - {name: pivot, type: fixed_point, body: top, at: [0, 0, 0]}
integrator: {name: ida-bdf, rtol: %g}
time: {dt: 0.01, t_end: 0.5}
)",
                -0.5 * s, 0.5 * c, c, s, -20 * s, 20 * c, rtol);
  return buf;
}

struct TopRun {
  Eigen::VectorXd q;  // the body's (φ, d1, d2, d3) at t_end
  double max_g = 0.0, max_gdot = 0.0;
};

TopRun run_ida(double rtol, double t_end) {
  const Problem p = make_problem(load_case_from_string(top_case(rtol), "top.yaml"));
  char text[32];
  std::snprintf(text, sizeof text, "%g", rtol);
  IntegratorSettings settings("ida-bdf", {{"rtol", text}});
  auto integ = make_integrator(settings, 0.01);
  EXPECT_TRUE(integ->supports_constraints());
  State s = p.initial_state();
  integ->initialize(*p.model, s);
  TopRun r;
  for (int k = 1; k <= 10; ++k) {
    integ->advance(*p.model, s, t_end * k / 10);
    const auto [g, gd] = constraint_drift(*p.model, s);
    r.max_g = std::max(r.max_g, g);
    r.max_gdot = std::max(r.max_gdot, gd);
  }
  r.q = p.model->multibody()->body_q(0, s.u);
  return r;
}

Eigen::VectorXd reference(double t_end) {
  using namespace multibody;
  const double th = 0.3;
  ReferenceBody b;
  b.mass = 2.0;
  b.J = Eigen::Vector3d(0.3, 0.3, 0.1);
  b.R = Eigen::AngleAxisd(th, Eigen::Vector3d::UnitX()).toRotationMatrix();
  b.x = 0.5 * b.R.col(2);
  b.omega_body = Eigen::Vector3d(0, 0, 20);
  b.v = (b.R * b.omega_body).cross(b.x);
  const SphericalChainReference ref({b}, {{0, Eigen::Vector3d(0, 0, -0.5), -1, Eigen::Vector3d::Zero()}},
                                    Eigen::Vector3d(0, 0, -9.81));
  const auto out = dormand_prince([&](double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy) { ref.rhs(t, y, dy); }, 0.0,
                                  ref.initial_state(), {t_end});
  Eigen::VectorXd q(12);
  q.head<3>() = SphericalChainReference::position(out[0], 0);
  const Eigen::Matrix3d R = SphericalChainReference::rotation(out[0], 0);
  for (int i = 0; i < 3; ++i) q.segment<3>(3 + 3 * i) = R.col(i);
  return q;
}

}  // namespace

TEST(IdaGgl, HeavyTopMatchesTheRigidReferenceAndKeepsTheJoint) {
  const double t_end = 0.5;
  const Eigen::VectorXd q_ref = reference(t_end);
  const TopRun coarse = run_ida(1e-6, t_end), fine = run_ida(1e-9, t_end);
  const double e_coarse = (coarse.q - q_ref).cwiseAbs().maxCoeff(), e_fine = (fine.q - q_ref).cwiseAbs().maxCoeff();
  std::printf("ida-bdf GGL heavy top at t = %.2f: max error over phi, d_i %.3e (rtol 1e-6), %.3e (rtol 1e-9); "
              "max |g| %.2e, %.2e; max |G v + g_t| %.2e, %.2e\n",
              t_end, e_coarse, e_fine, coarse.max_g, fine.max_g, coarse.max_gdot, fine.max_gdot);
  EXPECT_LT(e_fine, 1e-5);
  EXPECT_LT(e_fine, 0.1 * e_coarse);  // the error follows the tolerance
  // GGL enforces g and G v + ∂g/∂t at every step (algebraic rows): drift at the Newton tolerance.
  EXPECT_LT(fine.max_g, 1e-8);
  EXPECT_LT(fine.max_gdot, 1e-6);
}

// A driven joint (prescribed_rotation) does work W_presc = ∫ λᵀ ∂g/∂t dt, which ida-bdf integrates as one more
// differential unknown of its GGL DAE. A free drum (J_z = 0.5) spun up from rest to ω = 2 rad/s about its axis
// by the spin_up angle: its kinetic energy ends at ½ J_z ω² = 1, all of it the driver's work, so
// K − W_presc stays at 0 along the way (the balance H of history.csv).
TEST(IdaGgl, DriverWorkBalancesTheSpunUpDrumsKineticEnergy) {
  const std::string text = R"(
name: drum
mesh: {generator: rectangle, a: 0.1, b: 0.1, nx: 1, ny: 1, x0: 5, y0: 5}
material: {E: 1.0e6, nu: 0.3, rho: 1, thickness: 0.01}
boundary_conditions: [{set: all, fix: [ux, uy, uz, director]}]
rigid_bodies:
  drum: {mass: 1.0, inertia: [0.3, 0.3, 0.5], position: [3, 0, 0]}
joints:
  - {name: drive, type: prescribed_rotation, body: drum, point: [3, 0, 0], axis: [0, 0, 1],
     angle: {type: spin_up, T_s: 1.0}, amplitude: 2.0}
integrator: {name: ida-bdf, rtol: 1e-8}
time: {dt: 0.01, t_end: 1.2}
)";
  const Problem p = make_problem(load_case_from_string(text, "drum.yaml"));
  IntegratorSettings settings("ida-bdf", {{"rtol", "1e-8"}});
  auto integ = make_integrator(settings, 0.01);
  State s = p.initial_state();
  integ->initialize(*p.model, s);
  double worst = 0.0;
  for (int k = 1; k <= 12; ++k) {
    integ->advance(*p.model, s, 0.1 * k);
    const Invariants inv = p.model->invariants(s);
    worst = std::max(worst, std::abs(inv.kinetic + inv.strain - integ->prescribed_work()));
  }
  const Invariants inv = p.model->invariants(s);
  std::printf("drum spun up by ida-bdf: K = %.10f (exact 1), W_presc = %.10f, max |K - W_presc| %.2e\n", inv.kinetic,
              integ->prescribed_work(), worst);
  EXPECT_NEAR(inv.kinetic, 1.0, 1e-5);
  EXPECT_NEAR(integ->prescribed_work(), 1.0, 1e-5);
  EXPECT_LT(worst, 1e-6);
}
