// The constrained integrators on the shell Model (docs/theory/multibody.md §9): the shipped cases free-pair
// (a flexible plate and a rigid body joined by a spherical joint, free flight) and plate-pendulum (a plate hanging
// from a fixed_point joint under gravity), shortened to 0.1 s.
#include "integrators/integrator_settings.hpp"
#include "integrators/newmark/em_exact.hpp"
#include "integrators/newmark/em_generalized_alpha.hpp"
#include "lib/model/problem.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace shelldyn {
namespace {

struct Drift {
  double dH = 0, dL = 0, dJ = 0, g = 0, E0 = 0, L0 = 0, J0 = 0, W = 0;  // W: max |W_ext| (gravity's work)
};

Drift run(const std::string& case_name, const std::string& integrator, double t_end) {
  Problem p = load_problem(std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/" + case_name + ".yaml");
  IntegratorSettings set(integrator, {});
  const double dt = p.spec.time.dt;
  auto integ = integrator == "em-exact" ? make_em_exact(set, dt) : make_em_galpha(set, dt);
  EXPECT_TRUE(integ->supports_constraints());
  State s = p.initial_state();
  integ->initialize(*p.model, s);
  const Invariants i0 = p.model->invariants(s);
  Drift d;
  d.E0 = std::abs(i0.kinetic) + std::abs(i0.strain);
  d.L0 = i0.L.norm();
  d.J0 = i0.J.norm();
  Eigen::VectorXd g;
  const int steps = static_cast<int>(std::lround(t_end / dt));
  for (int k = 1; k <= steps; ++k) {
    integ->advance(*p.model, s, k * dt);
    const Invariants inv = p.model->invariants(s);
    const double H = inv.kinetic + inv.strain - integ->external_work() - integ->prescribed_work();
    d.dH = std::max(d.dH, std::abs(H - i0.kinetic - i0.strain));
    d.W = std::max(d.W, std::abs(integ->external_work()));
    d.dL = std::max(d.dL, (inv.L - i0.L).norm());
    d.dJ = std::max(d.dJ, (inv.J - i0.J).norm());
    p.model->constraint_values(s.t, s.u, s.charts, g);
    d.g = std::max(d.g, g.cwiseAbs().maxCoeff());
  }
  return d;
}

TEST(ModelConstrained, FreePairEmExactKeepsEnergyBothMomentaAndTheJoint) {
  const Drift d = run("free-pair", "em-exact", 0.1);
  std::printf("free-pair em-exact 0.1 s: |dH|/(K+V) %.3e |dL|/|L| %.3e |dJ|/|J| %.3e max|g| %.3e\n", d.dH / d.E0, d.dL / d.L0,
              d.dJ / d.J0, d.g);
  EXPECT_LT(d.dH / d.E0, 1e-10);
  EXPECT_LT(d.dL / d.L0, 1e-10);
  EXPECT_LT(d.dJ / d.J0, 1e-10);
  EXPECT_LT(d.g, 1e-12);
}

TEST(ModelConstrained, PlatePendulumEnergyBalanceAndJoint) {
  for (const std::string name : {"em-exact", "em-galpha"}) {
    const Drift d = run("plate-pendulum", name, 0.1);
    std::printf("plate-pendulum %s 0.1 s: max|K + V - W_ext - H0|/max|W_ext| %.3e max|g| %.3e\n", name.c_str(), d.dH / d.W, d.g);
    EXPECT_GT(d.W, 0.1) << name;  // it fell
    EXPECT_LT(d.g, 1e-12) << name;
    if (name == "em-exact") EXPECT_LT(d.dH / d.W, 1e-10) << name;
  }
}

}  // namespace
}  // namespace shelldyn
