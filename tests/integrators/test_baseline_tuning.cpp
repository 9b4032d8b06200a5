// The tuning of the SUNDIALS baselines (integrators/baselines/sundials_baseline.hpp, first_order_system.hpp):
// mass solves that reuse a factorization but still solve the CURRENT M(q), absolute tolerances per variable
// kind, the resolved tolerances in settings(), and progress lines inside long output intervals.
#include "integrators/baselines/first_order_system.hpp"
#include "integrators/integrator.hpp"
#include "integrators/runs/registry.hpp"

#include "tests/integrators/baseline_cases.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <map>
#include <sstream>

namespace shelldyn {
namespace {

using namespace baseline_cases;

// Director unknowns of every node turned by `angle` (radians, in chart coordinates).
State turned(const Model& model, const State& s0, double angle) {
  State s = s0;
  for (int i = 0; i < model.mesh().num_nodes(); ++i) {
    s.u[DofMap::dof(i, 3)] += angle;
    s.u[DofMap::dof(i, 4)] -= 0.5 * angle;
  }
  return s;
}

TEST(BaselineTuning, MassReuseSolvesTheCurrentMassMatrix) {
  omp_set_num_threads(1);
  auto model = flight_plate();
  const State s0 = flight_state(*model);
  FirstOrderSystem reuse(*model, "eigen-ldlt", true), direct(*model, "eigen-ldlt", false);
  Eigen::VectorXd a_reuse, a_direct;
  reuse.acceleration(0.0, s0, a_reuse);
  direct.acceleration(0.0, s0, a_direct);
  EXPECT_EQ(reuse.mass_factorizations(), 1);
  EXPECT_LE((a_reuse - a_direct).cwiseAbs().maxCoeff(), 1e-12 * a_direct.cwiseAbs().maxCoeff());

  // A turn of every director changes M(q) slightly (its director block, ~1e-6 here): the reused factorization of M(q0)
  // must not be used as if it were M(q1) -- the refinement solves M(q1) to round-off.
  const State s1 = turned(*model, s0, 0.05);
  SparseMatrix M0{model->pattern(), std::vector<double>(static_cast<size_t>(model->pattern()->nnz()))}, M1 = M0;
  model->mass(s0.u, s0.charts, M0);
  model->mass(s1.u, s1.charts, M1);
  double dM = 0.0, Mmax = 0.0;
  for (size_t k = 0; k < M0.values.size(); ++k) {
    dM = std::max(dM, std::abs(M1.values[k] - M0.values[k]));
    Mmax = std::max(Mmax, std::abs(M0.values[k]));
  }
  ASSERT_GT(dM, 1e-7 * Mmax) << "the test needs a configuration-dependent mass matrix";
  reuse.acceleration(0.0, s1, a_reuse);
  direct.acceleration(0.0, s1, a_direct);
  const double scale = a_direct.cwiseAbs().maxCoeff();
  EXPECT_LE((a_reuse - a_direct).cwiseAbs().maxCoeff(), 1e-10 * scale);
  EXPECT_EQ(reuse.mass_factorizations(), 1) << "a small change of M should not refactorize";
  EXPECT_GT(reuse.mass_refinements(), 0) << "M(q1) != M(q0): at least one correction is needed";
  EXPECT_EQ(direct.mass_factorizations(), 2);

  // A larger turn: still the exact answer (by refinement or by a refactorization).
  const State s2 = turned(*model, s0, 0.6);
  reuse.acceleration(0.0, s2, a_reuse);
  direct.acceleration(0.0, s2, a_direct);
  EXPECT_LE((a_reuse - a_direct).cwiseAbs().maxCoeff(), 1e-10 * a_direct.cwiseAbs().maxCoeff());
}

TEST(BaselineTuning, AbsoluteTolerancesScaleByVariableKind) {
  auto model = flight_plate();  // 2 x 1 plate: bounding-box diagonal √5
  const State s0 = flight_state(*model);
  FirstOrderSystem fos(*model, "eigen-ldlt");
  const auto sc = fos.tolerance_scales(s0, 0.0, 0.5);
  EXPECT_TRUE(sc.shell);
  EXPECT_NEAR(sc.length, std::sqrt(5.0), 1e-12);
  EXPECT_NEAR(sc.velocity, std::sqrt(5.0) / 0.5, 1e-12);
  // energy scale: max(1, K0 + |V0|)
  const Invariants inv = model->invariants(s0);
  EXPECT_NEAR(sc.energy, std::max(1.0, inv.kinetic + std::abs(inv.strain)), 1e-12);
  std::vector<double> atol(static_cast<size_t>(fos.size()));
  fos.absolute_tolerances(sc, 1e-8, atol.data());
  const Index n = fos.n();
  EXPECT_DOUBLE_EQ(atol[DofMap::dof(3, 1)], 1e-8 * std::sqrt(5.0));           // translation
  EXPECT_DOUBLE_EQ(atol[DofMap::dof(3, 4)], 1e-8);                            // director unknown
  EXPECT_DOUBLE_EQ(atol[n + DofMap::dof(3, 0)], 1e-8 * std::sqrt(5.0) / 0.5);  // velocity
  EXPECT_DOUBLE_EQ(atol[n + DofMap::dof(3, 3)], 1e-8 / 0.5);                  // director rate
  EXPECT_DOUBLE_EQ(atol[2 * n], 1e-8 * sc.energy);                            // external work
}

TEST(BaselineTuning, ResolvedTolerancesAndProgressLines) {
  omp_set_num_threads(1);
  for (const char* name : {"ida-bdf", "arkode-erk"}) {
    auto model = flight_plate();
    State s = flight_state(*model);
    IntegratorSettings settings(name, {{"rtol", "1e-6"}, {"time_scale", "2"}, {"progress_every", "1e-9"}});
    auto integ = make_integrator(settings, 0.01);
    std::ostringstream log;
    integ->set_progress_log(&log, "test");
    integ->initialize(*model, s);
    const auto resolved = integ->settings();
    std::map<std::string, std::string> kv(resolved.begin(), resolved.end());
    ASSERT_TRUE(kv.count("atol_translation")) << name;
    // atol = rtol/1000 by default, times L = √5 for translations, L/τ for velocities
    EXPECT_NEAR(std::stod(kv["atol_translation"]), 1e-9 * std::sqrt(5.0), 1e-14) << name;
    EXPECT_NEAR(std::stod(kv["atol_velocity"]), 1e-9 * std::sqrt(5.0) / 2.0, 1e-14) << name;
    EXPECT_NEAR(std::stod(kv["atol_director"]), 1e-9, 1e-16) << name;
    const StepReport r = integ->advance(*model, s, 0.002);
    EXPECT_GT(r.steps, 1) << name;
    EXPECT_NE(log.str().find("test | (inside the output interval) t = "), std::string::npos) << name << ": " << log.str();
    EXPECT_NEAR(s.t, 0.002, 1e-15);
  }
}

}  // namespace
}  // namespace shelldyn
