// SUNDIALS baselines (ida-bdf, arkode-erk, arkode-dirk) on the shell semi-discretization: cost and
// accuracy per integrator and tolerance. A plain program that prints Markdown tables (not Google
// Benchmark: one run per row is already long enough to time).
//
//   bench_sundials_baselines                 # all tables (several minutes on 2 cores)
//   bench_sundials_baselines flight [t_end]  # free flight of docs/theory.md §7 item 12 only
//   bench_sundials_baselines spin [t_end]    # rigid spin R2 of docs/benchmarks.md §6 only
//   bench_sundials_baselines jacobian        # ida-bdf Newton iterations: approximate vs fd-inertia Jacobian
//   bench_sundials_baselines plate [case]    # free-flight phase of the flying plate, t = 5 .. 6
//   bench_sundials_baselines one CASE INTEGRATOR T_END key=value ...   # a single row
//
// Columns: steps (accepted), rejected attempts, RHS/residual evaluations, Newton iterations, linear
// setups, numeric factorizations, chart events / reinitializations, wall time, and the final errors
// |ΔH|/H₀ (H = K + V − W_ext), |Δ|J||/|J₀|, and for R2 the errors of K and |J| against the exact values.
#include "integrators/baselines/arkode_integrators.hpp"
#include "integrators/baselines/ida_bdf.hpp"
#include "lib/model/problem.hpp"
#include "tests/integrators/baseline_cases.hpp"

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace shelldyn;
using namespace shelldyn::baseline_cases;

namespace {

using KeyValues = std::vector<std::pair<std::string, std::string>>;

std::unique_ptr<Integrator> make(const std::string& name, const KeyValues& kv, double dt) {
  IntegratorSettings s(name, kv);
  std::unique_ptr<Integrator> integ;
  if (name == "ida-bdf") integ = make_ida_bdf(s, dt);
  else if (name == "arkode-erk") integ = make_arkode_erk(s, dt);
  else if (name == "arkode-dirk") integ = make_arkode_dirk(s, dt);
  else throw std::invalid_argument("unknown baseline " + name);
  s.finish();
  return integ;
}

std::string describe(const KeyValues& kv) {
  std::string out;
  for (const auto& p : kv) out += (out.empty() ? "" : " ") + p.first + "=" + p.second;
  return out;
}

void header() {
  std::printf("| integrator | settings | t | steps | rejected | f evals | Newton | setups | factor. | events/reinit | wall s | |dH|/H0 | |dJ|/J0 | extra |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
}

// Runs system from state s to t_end with output every `every`; prints one row.
void run_row(SemiDiscreteSystem& sys, State s, const std::string& name, const KeyValues& kv, double t_end,
             double every, bool r2 = false) {
  auto integ = make(name, kv, every);
  const double t0 = s.t;
  integ->initialize(sys, s);
  const Invariants inv0 = sys.invariants(s);
  const double H0 = inv0.kinetic + inv0.strain;
  StepReport tot;
  std::string status = "";
  try {
    for (int k = 1; t0 + k * every <= t_end + 1e-12; ++k) tot.accumulate(integ->advance(sys, s, t0 + k * every));
  } catch (const StepFailure& e) {
    status = std::string("FAILED: ") + e.what();
  }
  const Invariants inv = sys.invariants(s);
  const double H = inv.kinetic + inv.strain - integ->external_work();
  char extra[200] = "";
  if (r2)
    std::snprintf(extra, sizeof extra, "K err %.2e, |J| err %.2e", std::abs(inv.kinetic - kR2Kinetic) / kR2Kinetic,
                  std::abs(inv.J.norm() - kR2AngularMomentum) / kR2AngularMomentum);
  std::printf("| %s | %s | %.3g | %ld | %ld | %ld | %ld | %ld | %ld | %ld/%ld | %.2f | %.2e | %.2e | %s%s |\n", name.c_str(),
              describe(kv).c_str(), s.t, tot.steps, tot.rejected_steps, tot.rhs_evaluations, tot.nonlinear_iterations,
              tot.linear_setups, tot.factorizations, tot.root_events, tot.reinitializations, tot.wall_seconds,
              std::abs(H - H0) / H0, std::abs(inv.J.norm() - inv0.J.norm()) / inv0.J.norm(), extra, status.c_str());
  std::fflush(stdout);
}

void flight_table(double t_end) {
  std::printf("\n### Free flight (docs/theory.md §7 item 12), t = 0 .. %g\n\n", t_end);
  header();
  auto model = flight_plate();
  const State s0 = flight_state(*model);
  for (const char* rtol : {"1e-4", "1e-6", "1e-8"}) {
    run_row(*model, s0, "ida-bdf", {{"rtol", rtol}}, t_end, t_end / 10);
    run_row(*model, s0, "arkode-dirk", {{"rtol", rtol}}, t_end, t_end / 10);
  }
  for (const char* rtol : {"1e-4", "1e-6"}) run_row(*model, s0, "arkode-erk", {{"rtol", rtol}}, t_end, t_end / 10);
}

void spin_table(double t_end) {
  std::printf("\n### Rigid spin R2 (docs/benchmarks.md §6), t = 0 .. %g\n\n", t_end);
  header();
  auto model = spin_plate();
  const State s0 = spin_state(*model, Vec3(1, 0, 0));
  for (const char* rtol : {"1e-6", "1e-8"}) {
    run_row(*model, s0, "ida-bdf", {{"rtol", rtol}}, t_end, 1.0, true);
    run_row(*model, s0, "arkode-dirk", {{"rtol", rtol}}, t_end, 1.0, true);
  }
}

void jacobian_table() {
  std::printf("\n### ida-bdf: approximate vs finite-difference inertia Jacobian\n\n");
  header();
  auto flight = flight_plate();
  const State f0 = flight_state(*flight);
  auto spin = spin_plate();
  const State r0 = spin_state(*spin, Vec3(1, 0, 0));
  for (const char* jac : {"approximate", "fd-inertia"}) {
    run_row(*flight, f0, "ida-bdf", {{"rtol", "1e-6"}, {"jacobian", jac}}, 0.2, 0.02);
    run_row(*spin, r0, "ida-bdf", {{"rtol", "1e-6"}, {"jacobian", jac}}, 2.0, 0.1, true);
  }
}

void plate_table(const std::string& path) {
  std::printf("\n### Flying plate (%s), free-flight phase after the loads: t = 5 .. 6\n\n", path.c_str());
  Problem p = load_problem(path);
  State s = p.initial_state();
  // Bring the plate to t = 5 (end of the hat load) with ida-bdf at a tight tolerance.
  auto pre = make("ida-bdf", {{"rtol", "1e-8"}}, 0.1);
  pre->initialize(*p.model, s);
  for (int k = 1; k <= 50; ++k) pre->advance(*p.model, s, 0.1 * k);
  std::printf("(state at t = 5 from ida-bdf rtol 1e-8; W_ext(5) = %.6g)\n\n", pre->external_work());
  header();
  for (const char* rtol : {"1e-4", "1e-6", "1e-8"}) {
    run_row(*p.model, s, "ida-bdf", {{"rtol", rtol}}, 6.0, 0.1);
    run_row(*p.model, s, "arkode-dirk", {{"rtol", rtol}}, 6.0, 0.1);
  }
  run_row(*p.model, s, "arkode-erk", {{"rtol", "1e-6"}}, 6.0, 0.1);
}

// apps/cases/flying-plate.yaml next to this source file (__FILE__ is absolute in CMake builds).
std::string default_plate_case() {
  std::string f = __FILE__;
  return f.substr(0, f.rfind('/')) + "/../apps/cases/flying-plate.yaml";
}

}  // namespace

int main(int argc, char** argv) {
  // Meshes of 2-8 elements on 2 shared cores: OpenMP threads only spin at barriers (measured: 50 % of
  // the time in libgomp), so the element loops run on one thread.
  omp_set_num_threads(1);
  try {
    const std::string what = argc > 1 ? argv[1] : "all";
    if (what == "one" && argc >= 5) {
      const std::string c = argv[2], name = argv[3];
      const double t_end = std::atof(argv[4]);
      KeyValues kv;
      for (int i = 5; i < argc; ++i) {
        const char* eq = std::strchr(argv[i], '=');
        if (!eq) throw std::invalid_argument(std::string("expected key=value, got ") + argv[i]);
        kv.emplace_back(std::string(argv[i], static_cast<size_t>(eq - argv[i])), std::string(eq + 1));
      }
      header();
      if (c == "spin") {
        auto m = spin_plate();
        run_row(*m, spin_state(*m, Vec3(1, 0, 0)), name, kv, t_end, t_end / 10, true);
      } else {
        auto m = flight_plate();
        run_row(*m, flight_state(*m), name, kv, t_end, t_end / 10);
      }
      return 0;
    }
    if (what == "all" || what == "flight") flight_table(argc > 2 && what == "flight" ? std::atof(argv[2]) : 1.0);
    if (what == "all" || what == "spin") spin_table(argc > 2 && what == "spin" ? std::atof(argv[2]) : 20.0);
    if (what == "all" || what == "jacobian") jacobian_table();
    if (what == "all" || what == "plate")
      plate_table(argc > 2 && what == "plate" ? std::string(argv[2]) : default_plate_case());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_sundials_baselines: %s\n", e.what());
    return 1;
  }
}
