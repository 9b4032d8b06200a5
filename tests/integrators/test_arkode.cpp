// arkode-erk / arkode-dirk (integrators/baselines/arkode_integrators.hpp): ARKStep on ẏ = [v; M(q)⁻¹(...); F_ext·v].
#include "integrators/baselines/arkode_integrators.hpp"

#include "tests/integrators/baseline_cases.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

namespace shelldyn {
namespace {

using namespace baseline_cases;
using KV = std::vector<std::pair<std::string, std::string>>;

std::unique_ptr<Integrator> ark(const std::string& name, KV kv, double dt = 0.01) {
  IntegratorSettings s(name, std::move(kv));
  auto integ = name == "arkode-erk" ? make_arkode_erk(s, dt) : make_arkode_dirk(s, dt);
  s.finish();
  return integ;
}

std::string error_of(const std::string& name, KV kv) {
  try {
    ark(name, std::move(kv));
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

TEST(Arkode, DirkFreeFlightKeepsMomentumAndEnergyToTheTolerance) {
  omp_set_num_threads(1);  // 2-element mesh: threads would only spin at barriers
  auto model = flight_plate();
  State s = flight_state(*model);
  const Invariants inv0 = model->invariants(s);
  const double H0 = total_energy(*model, s, 0.0);
  auto integ = ark("arkode-dirk", {{"rtol", "1e-8"}});
  integ->initialize(*model, s);
  StepReport r;
  for (int k = 1; k <= 4; ++k) r.accumulate(integ->advance(*model, s, 0.0025 * k));
  EXPECT_EQ(s.t, 0.01);
  const Invariants inv = model->invariants(s);
  EXPECT_LT((inv.L - inv0.L).norm(), 1e-9 * inv0.L.norm());
  EXPECT_LT(std::abs(total_energy(*model, s, integ->external_work()) - H0) / H0, 1e-8);
  EXPECT_GT(r.nonlinear_iterations, 0);
  EXPECT_GT(r.linear_setups, 0);
  std::printf("[ measured ] dirk rtol 1e-8, 0.01 s: %ld steps, %ld rejected, %ld f, %ld Newton, %ld setups\n", r.steps,
              r.rejected_steps, r.rhs_evaluations, r.nonlinear_iterations, r.linear_setups);
}

TEST(Arkode, ErkFreeFlightAdaptive) {
  omp_set_num_threads(1);
  auto model = flight_plate();
  State s = flight_state(*model);
  const double H0 = total_energy(*model, s, 0.0);
  // mass_reuse (default): M(q) is refactorized only when the refinement with the last factorization stalls,
  // which on this free flight is never needed; without it, one factorization per RHS (+1 for state.a).
  // Same accuracy either way: the refinement solves the current M(q) to a 1e-12 residual.
  for (const char* reuse : {"true", "false"}) {
    State s1 = s;
    auto integ = ark("arkode-erk", {{"rtol", "1e-8"}, {"mass_reuse", reuse}});
    integ->initialize(*model, s1);
    const StepReport r = integ->advance(*model, s1, 0.005);
    EXPECT_EQ(s1.t, 0.005);
    EXPECT_EQ(r.nonlinear_iterations, 0);
    if (std::string(reuse) == "true")
      EXPECT_LT(r.factorizations * 10, r.rhs_evaluations);
    else
      EXPECT_GE(r.factorizations, r.rhs_evaluations);
    EXPECT_LT(std::abs(total_energy(*model, s1, integ->external_work()) - H0) / H0, 1e-8) << reuse;
  }
}

// docs/dependencies.md §7 item 11: past the stability limit a fixed-step ERK silently produces NaN; here it must
// stop with a StepFailure that says why. dt = 1e-3 is ~50x the measured adaptive ERK step (2e-5).
TEST(Arkode, FixedStepErkPastItsStabilityLimitThrows) {
  omp_set_num_threads(1);
  auto model = flight_plate();
  State s = flight_state(*model);
  auto integ = ark("arkode-erk", {{"fixed_step", "true"}}, 1e-3);
  integ->initialize(*model, s);
  const State before = s;
  try {
    for (int k = 1; k <= 200; ++k) integ->advance(*model, s, 1e-3 * k);
    FAIL() << "no StepFailure";
  } catch (const StepFailure& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("arkode-erk"), std::string::npos) << m;
    EXPECT_NE(m.find("stability limit"), std::string::npos) << m;
  }
  // The state handed back is the last good one: finite.
  EXPECT_TRUE(s.u.allFinite() && s.v.allFinite());
  (void)before;
}

TEST(Arkode, FixedStepErkBelowTheLimitRuns) {
  omp_set_num_threads(1);
  auto model = flight_plate();
  State s = flight_state(*model);
  auto integ = ark("arkode-erk", {{"fixed_step", "true"}}, 1e-5);
  integ->initialize(*model, s);
  const StepReport r = integ->advance(*model, s, 1e-3);
  EXPECT_NEAR(double(r.steps), 100.0, 1.0);  // stop time may add one round-off step (docs/dependencies.md §4.2)
  EXPECT_TRUE(s.u.allFinite());
}

TEST(Arkode, SettingsErrorsAreClear) {
  EXPECT_NE(error_of("arkode-erk", {{"table", "ARKODE_NOPE_4_5"}}).find("unknown ERK table 'ARKODE_NOPE_4_5'"),
            std::string::npos);
  EXPECT_NE(error_of("arkode-dirk", {{"table", "ARKODE_DORMAND_PRINCE_7_4_5"}}).find("unknown DIRK table"),
            std::string::npos);
  EXPECT_NE(error_of("arkode-erk", {{"table", "ARKODE_KNOTH_WOLKE_3_3"}}).find("no embedding"), std::string::npos);
  EXPECT_EQ(error_of("arkode-erk", {{"table", "ARKODE_KNOTH_WOLKE_3_3"}, {"fixed_step", "true"}}), "no error");
  EXPECT_NE(error_of("arkode-dirk", {{"rtol", "0"}}).find("arkode-dirk: rtol must be in (0, 1), got 0"),
            std::string::npos);
  EXPECT_NE(error_of("arkode-dirk", {{"linear_solver", "lu"}}).find("unknown linear_solver"), std::string::npos);
  EXPECT_NE(error_of("arkode-erk", {{"mass_solver", "klu"}}).find("SPD"), std::string::npos);
  EXPECT_NE(error_of("arkode-erk", {{"linear_solver", "klu"}}), "no error");  // dirk-only key
}

}  // namespace
}  // namespace shelldyn
