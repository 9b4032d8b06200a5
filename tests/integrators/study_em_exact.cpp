// Long conservation runs of em-exact beside em-galpha (the numbers of docs/theory/exact-energy-momentum.md
// and the README). DISABLED_ in the default suite; run them with the ctest label `benchmark`
// (tests/CMakeLists.txt: benchmark_em_exact_*), or directly:
//   build/bin/test_integrators --gtest_also_run_disabled_tests --gtest_filter='EmExactStudy.*FreePlate*'
#include "integrators/newmark/em_exact.hpp"
#include "integrators/runs/registry.hpp"

#include "dynamics_fixtures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <tuple>

namespace shelldyn {
namespace {

using testing::free_plate;
using testing::set_free_flight_velocity;
using testing::total_energy;

struct Long {
  double max_dH = 0, max_dL = 0, max_dJ = 0, max_strain = 0, final_dH = 0;
  long steps = 0, iterations = 0, switches = 0;
};

// Runs to t_end, printing ΔH/H and strain/H every t_end/20.
Long long_run(Model& model, State s, const std::string& name, double dt, double t_end, const char* label,
              std::vector<std::pair<std::string, std::string>> settings = {}) {
  IntegratorSettings set(name, std::move(settings));
  auto integ = make_integrator(set, dt);
  integ->initialize(model, s);
  const Invariants inv0 = model.invariants(s);
  const double H0 = total_energy(inv0);
  Long r;
  const long n = std::lround(t_end / dt);
  for (long k = 1; k <= n; ++k) {
    const StepReport rep = integ->advance(model, s, k * dt);
    const Invariants inv = model.invariants(s);
    const double H = total_energy(inv);
    r.max_dH = std::max(r.max_dH, std::abs(H - H0) / H0);
    r.max_dL = std::max(r.max_dL, (inv.L - inv0.L).norm() / std::max(inv0.L.norm(), 1e-300));
    r.max_dJ = std::max(r.max_dJ, (inv.J - inv0.J).norm() / inv0.J.norm());
    r.max_strain = std::max(r.max_strain, inv.strain / H);
    r.final_dH = (H - H0) / H0;
    r.steps += rep.steps;
    r.iterations += rep.nonlinear_iterations;
    r.switches += rep.chart_switches;
    if (k % (n / 20) == 0)
      std::printf("  %s %s dt %g  t = %6.1f  dH/H %+.2e  max|dH|/H %.2e  strain/H %.2e  max|dJ|/|J| %.2e\n", label,
                  name.c_str(), dt, k * dt, r.final_dH, r.max_dH, inv.strain / H, r.max_dJ);
    if (k % (n / 20) == 0) std::fflush(stdout);
  }
  std::printf("%s %-9s dt %-5g: max|dH|/H %.2e  max|dL|/|L| %.2e  max|dJ|/|J| %.2e  max strain/H %.2e  %.2f it/step  %ld switches\n",
              label, name.c_str(), dt, r.max_dH, r.max_dL, r.max_dJ, r.max_strain, double(r.iterations) / r.steps,
              r.switches);
  std::fflush(stdout);
  return r;
}

// The free plate of docs/theory.md §7 item 12, 20 s.
TEST(EmExactStudy, DISABLED_FreePlate20s) {
  for (double dt : {0.02, 0.01, 0.005})
    for (const char* name : {"em-exact", "em-galpha"}) {
      auto model = free_plate(2.0, 1.0, 2, 1, ShellMaterial{1e6, 0.3, 1.0, 0.1});
      State s = model->initial_state();
      set_free_flight_velocity(*model, s, Eigen::Vector3d(0.1, 0, 0.2), Eigen::Vector3d(0.3, 0.5, 1.0), 0.5);
      const Long r = long_run(*model, s, name, dt, 20.0, "free plate 20 s");
      if (std::string(name) == "em-exact") {
        EXPECT_LT(r.max_dH, 1e-10);
        EXPECT_LT(r.max_dJ, 1e-9);
      }
    }
}

// docs/benchmarks.md §6 plate (E 1e8, 4×2) with spin ω0; 200 s.
Long spin(const Eigen::Vector3d& w, double dt, const char* label, const char* name = "em-exact",
          std::vector<std::pair<std::string, std::string>> settings = {}) {
  auto model = free_plate(2.0, 1.0, 4, 2, ShellMaterial{1e8, 0.3, 1.0, 0.1});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, Eigen::Vector3d::Zero(), w, 0.0);
  return long_run(*model, s, name, dt, 200.0, label, std::move(settings));
}

// Issue bound: |ΔH|/H ≤ 1e-10, strain/H ≤ 1e-6 over 200 s (docs/theory/exact-energy-momentum.md §5.1).
TEST(EmExactStudy, DISABLED_TumblingPlate200sDt001) {
  const Long r = spin({0.01, 1.0, 0.01}, 0.01, "tumbling 200 s");
  EXPECT_LT(r.max_strain, 1e-6);
  EXPECT_LT(r.max_dH, 1e-10);
  EXPECT_LT(r.max_dJ, 1e-9);
}
TEST(EmExactStudy, DISABLED_TumblingPlate200sDt002) {
  const Long r = spin({0.01, 1.0, 0.01}, 0.02, "tumbling 200 s");
  EXPECT_LT(r.max_strain, 1e-6);
  EXPECT_LT(r.max_dH, 1e-10);
  EXPECT_LT(r.max_dJ, 1e-9);
}
TEST(EmExactStudy, DISABLED_SpinR1200s) {
  const Long r = spin({0, 0, 1}, 0.01, "R1 200 s");
  EXPECT_LT(r.max_strain, 1e-6);
  EXPECT_LT(r.max_dH, 1e-10);
  EXPECT_LT(r.max_dJ, 1e-9);
}
TEST(EmExactStudy, DISABLED_SpinR2200s) {
  const Long r = spin({1, 0, 0}, 0.01, "R2 200 s");
  EXPECT_LT(r.max_strain, 1e-6);
  EXPECT_LT(r.max_dH, 1e-10);
  EXPECT_LT(r.max_dJ, 1e-9);
}

// Modified Newton, as the benchmark apps' case files run em-exact. certify = predicted (§5.4), the default there
// since §5.8, stops a correction short of the floor when the contraction predicts the floor; certify = floor
// (§5.3) sees the floor from the floor of the recent steps and, beside it, certify = residual in the residual
// of the accepted iterate. The stiff tumbling plate has the highest round-off floor of the study and is where
// accepting an iterate short of the floor shows as a one-signed drift (§5.1): the same bounds must hold for
// every rule. The last run adds the renewal refresh (refresh_cost, §5.5) to certify = floor.
TEST(EmExactStudy, DISABLED_TumblingPlate200sModifiedNewton) {
  const std::vector<std::pair<const char*, std::vector<std::pair<std::string, std::string>>>> runs = {
      {"predicted (default)", {}},
      {"floor", {{"certify", "floor"}}},
      {"residual", {{"certify", "residual"}}},
      {"renewal", {{"certify", "floor"}, {"refresh_cost", "12"}}}};
  for (const auto& [label, extra] : runs) {
    std::vector<std::pair<std::string, std::string>> settings = {{"newton", "modified"}};
    settings.insert(settings.end(), extra.begin(), extra.end());
    const Long r = spin({0.01, 1.0, 0.01}, 0.01, label, "em-exact", settings);
    EXPECT_LT(r.max_strain, 1e-6);
    EXPECT_LT(r.max_dH, 1e-10);
    EXPECT_LT(r.max_dJ, 1e-9);
  }
}

// The free plate of docs/theory.md §7 item 12 for 20 s at Δt 0.02, 0.01 and 0.005, and the stiff free flight (E = 1e9,
// Δt 0.02, 4 s), under em-exact with `settings`; check(E, run) judges each run.
void free_flights(const std::vector<std::pair<std::string, std::string>>& settings, const std::string& label,
                  const std::function<void(double, const Long&)>& check) {
  for (const auto& [E, dt, t_end] : {std::tuple<double, double, double>{1e6, 0.02, 20.0}, {1e6, 0.01, 20.0},
                                     {1e6, 0.005, 20.0}, {1e9, 0.02, 4.0}}) {
    auto model = free_plate(2.0, 1.0, 2, 1, ShellMaterial{E, 0.3, 1.0, 0.1});
    State s = model->initial_state();
    set_free_flight_velocity(*model, s, Eigen::Vector3d(0.1, 0, 0.2), Eigen::Vector3d(0.3, 0.5, 1.0), 0.5);
    const std::string what = (E > 1e6 ? "stiff free flight, " : "free plate, ") + label;
    check(E, long_run(*model, s, "em-exact", dt, t_end, what.c_str(), settings));
  }
}

// The other cases under modified Newton with its default certify (predicted, §5.8), the way the
// benchmark apps run em-exact: the docs/theory.md §7.12 plate 20 s at three Δt, the stiff free flight (E = 1e9, Δt 0.02, 4 s),
// the tumbling plate at Δt 0.02 and the spins R1, R2 over 200 s. Same bounds as the full-Newton runs above.
TEST(EmExactStudy, DISABLED_ModifiedNewtonDefaultOtherCases) {
  const std::vector<std::pair<std::string, std::string>> modified = {{"newton", "modified"}};
  free_flights(modified, "modified", [](double, const Long& r) {
    EXPECT_LT(r.max_dH, 1e-10);
    EXPECT_LT(r.max_dJ, 1e-9);
  });
  for (const auto& [w, dt, label] : {std::tuple<Eigen::Vector3d, double, const char*>{{0.01, 1.0, 0.01}, 0.02, "tumbling, modified"},
                                     {{0, 0, 1}, 0.01, "R1, modified"}, {{1, 0, 0}, 0.01, "R2, modified"}}) {
    const Long r = spin(w, dt, label, "em-exact", modified);
    EXPECT_LT(r.max_strain, 1e-6);
    EXPECT_LT(r.max_dH, 1e-10);
    EXPECT_LT(r.max_dJ, 1e-9);
  }
}

// certify = energy (docs/theory/exact-energy-momentum.md §5.10): em-galpha's modified-Newton stopping rule on em-exact's
// step, on every case of the issue. The balances then hold to that rule's tolerance, not to round-off, and the
// issue's 1e-10 is not met: measured max |ΔH|/H 3.4e-9 / 1.8e-9 / 7.1e-10 (free plate, Δt 0.02 / 0.01 / 0.005),
// 7.1e-8 (stiff free flight), 6.1e-10 / 9.9e-9 (tumbling, Δt 0.01 / 0.02), 5.5e-10 / 5.3e-10 (R1 / R2); max ‖ΔJ‖/‖J‖
// up to 2.1e-7 (stiff free flight). The bounds below are those measurements rounded up: a regression check of
// the quantified behaviour, not the bounds (which certify = residual, floor and predicted meet above).
TEST(EmExactStudy, DISABLED_CertifyEnergyCases) {
  const std::vector<std::pair<std::string, std::string>> energy = {{"newton", "modified"}, {"certify", "energy"}};
  free_flights(energy, "energy", [](double E, const Long& r) {
    EXPECT_LT(r.max_dH, E > 1e6 ? 1e-7 : 5e-9);
    EXPECT_LT(r.max_dJ, E > 1e6 ? 5e-7 : 5e-9);
  });
  for (const auto& [w, dt, label] : {std::tuple<Eigen::Vector3d, double, const char*>{{0.01, 1.0, 0.01}, 0.01, "tumbling, energy"},
                                     {{0.01, 1.0, 0.01}, 0.02, "tumbling, energy"},
                                     {{0, 0, 1}, 0.01, "R1, energy"}, {{1, 0, 0}, 0.01, "R2, energy"}}) {
    const Long r = spin(w, dt, label, "em-exact", energy);
    EXPECT_LT(r.max_strain, 1e-6);
    EXPECT_LT(r.max_dH, 2e-8);
    EXPECT_LT(r.max_dJ, 1e-8);
  }
}

}  // namespace
}  // namespace shelldyn
