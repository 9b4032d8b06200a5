// Where a time step's CPU time goes, for any case file and integrator (issue: "step breakdown").
//
//   build/bin/bench_step_breakdown apps/cases/pinched-hemisphere.yaml --steps 200 --threads 1
//   build/bin/bench_step_breakdown apps/cases/flying-plate.yaml --from 2.0 --steps 1000 --set newton=full
//
// Integrates the case with its integrator (settings from the case, overridden by --set/--integrator/--dt),
// first without measuring up to --from, then --steps steps with lib/analysis/profile.hpp switched on, and prints
// one row per instrumented section: process CPU ms per call (all threads), calls per step, CPU ms per
// step and share of the step's CPU time, then wall ms per step and share of the step's wall time. The row
// "Newton overhead (rest)" is the step's time not covered by any section: KINSOL, vector copies, the
// predictor, chart checks. CPU time is meaningful on a loaded machine; the wall columns show, with several
// threads, which pieces run on one (their wall time equals their CPU time) and what they cost in elapsed time.
// --residual-trace FILE also writes the scaled residual of every Newton iterate of every step (the integrators
// that report them: the Newmark family, em-galpha, em-exact; Integrator::set_residual_trace) and prints the
// median and 90th percentile of the accepted iterate's residual over the measured steps: the accuracy at which
// the scheme stops, for comparisons of iteration counts at equal accuracy (docs/theory/exact-energy-momentum.md §5.9).
#include "integrators/integrator.hpp"
#include "integrators/runs/registry.hpp"
#include "lib/analysis/profile.hpp"
#include "lib/model/problem.hpp"

#include "lib/linalg/openmp_wait_policy.hpp"
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

using namespace shelldyn;

namespace {

void usage() {
  std::puts(
      "usage: bench_step_breakdown CASE.yaml [--steps N] [--from T] [--threads K] [--dt DT]\n"
      "                            [--integrator NAME] [--set key=value]... [--residual-trace FILE]\n"
      "  --steps N        measured steps (default 200)\n"
      "  --from T         integrate to time T first, unmeasured (default 0)\n"
      "  --threads K      OpenMP threads (default 1)\n"
      "  --dt DT          time step (default: the case's)\n"
      "  --integrator     another integrator than the case's (keeps the case settings it understands)\n"
      "  --set key=value  integrator setting (repeatable), e.g. --set newton=full\n"
      "  --residual-trace FILE  CSV of every step's scaled Newton residuals (all steps, from t = 0), and the\n"
      "                   accepted iterate's residual over the measured steps (median, 90th percentile)");
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::string case_path, integrator_name, trace_path;
    long steps = 200;
    double from = 0.0, dt = 0.0;
    int threads = 1;
    std::vector<std::pair<std::string, std::string>> sets;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value (see --help)");
        return argv[++i];
      };
      if (a == "--help" || a == "-h") {
        usage();
        return 0;
      } else if (a == "--steps") {
        steps = std::stol(value());
      } else if (a == "--from") {
        from = std::stod(value());
      } else if (a == "--threads") {
        threads = std::stoi(value());
      } else if (a == "--dt") {
        dt = std::stod(value());
      } else if (a == "--residual-trace") {
        trace_path = value();
      } else if (a == "--integrator") {
        integrator_name = value();
      } else if (a == "--set") {
        const std::string kv = value();
        const auto eq = kv.find('=');
        if (eq == std::string::npos || eq == 0) throw std::invalid_argument("--set expects key=value, got '" + kv + "'");
        sets.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
      } else if (!a.empty() && a[0] == '-') {
        throw std::invalid_argument("unknown option '" + a + "' (see --help)");
      } else if (case_path.empty()) {
        case_path = a;
      } else {
        throw std::invalid_argument("more than one case file given ('" + case_path + "', '" + a + "')");
      }
    }
    if (case_path.empty()) throw std::invalid_argument("no case file given (see --help)");
    if (steps < 1 || threads < 1 || from < 0) throw std::invalid_argument("need --steps >= 1, --threads >= 1, --from >= 0");
    omp_set_num_threads(threads);

    Problem p = load_problem(case_path);
    if (dt <= 0) dt = p.spec.time.dt;
    IntegratorSettings settings =
        integrator_name.empty() || integrator_name == p.spec.integrator.name
            ? IntegratorSettings(p.spec.integrator)
            : IntegratorSettings(integrator_name, settings_understood_by(integrator_name, p.spec.integrator.settings));
    for (const auto& [k, v] : sets) settings.set(k, v);
    auto integ = make_integrator(settings, dt);
    // --residual-trace: one CSV row per accepted step. The accepted iterate's residual is the last evaluated one,
    // or, when the last correction was accepted unevaluated (as many residuals as iterations), the estimate
    // ρ_{k−1}²/ρ_{k−2} from the last contraction.
    std::ofstream trace_out;
    std::vector<double> accepted;  // measured steps
    bool measuring = false;
    long traced = 0;
    if (!trace_path.empty()) {
      trace_out.open(trace_path);
      if (!trace_out) throw std::runtime_error("cannot write the residual trace '" + trace_path + "' (check the directory)");
      trace_out << "step,measured,iterations,residuals,rho_first,rho_last,rho_accepted,rhos\n";
      trace_out.precision(3);
      const bool reported = integ->set_residual_trace([&](const std::vector<double>& rho, int iterations) {
        double acc = rho.empty() ? 0.0 : rho.back();
        const size_t m = rho.size();
        if (m >= 2 && static_cast<size_t>(iterations) >= m && rho[m - 2] > 0.0) acc = rho[m - 1] * rho[m - 1] / rho[m - 2];
        if (measuring) accepted.push_back(acc);
        trace_out << ++traced << ',' << (measuring ? 1 : 0) << ',' << iterations << ',' << m << ','
                  << std::scientific << (m ? rho.front() : 0.0) << ',' << (m ? rho.back() : 0.0) << ',' << acc << ',';
        for (size_t j = 0; j < m; ++j) trace_out << (j ? " " : "") << rho[j];
        trace_out << std::defaultfloat << '\n';
      });
      if (!reported)
        throw std::invalid_argument("--residual-trace: integrator " + integ->name() +
                                    " does not report its Newton residuals (the Newmark family, em-galpha and em-exact do)");
    }
    State s = p.initial_state();
    integ->initialize(*p.model, s);
    if (from > 0) integ->advance(*p.model, s, from);
    measuring = true;

    profile::reset();
    profile::enable(true);
    StepReport rep;
    const double cpu0 = profile::process_cpu_seconds(), wall0 = profile::wall_seconds();
    const double t0 = s.t;
    for (long k = 1; k <= steps; ++k) rep.accumulate(integ->advance(*p.model, s, t0 + static_cast<double>(k) * dt));
    const double cpu = profile::process_cpu_seconds() - cpu0, wall = profile::wall_seconds() - wall0;
    profile::enable(false);

    std::printf("case %s, integrator %s, dt %g, %ld steps from t = %g to %g, %d thread(s)\n", case_path.c_str(),
                integ->name().c_str(), dt, rep.steps, t0, s.t, threads);
    std::printf("settings:");
    for (const auto& [k, v] : integ->settings()) std::printf(" %s=%s", k.c_str(), v.c_str());
    const double ns = static_cast<double>(rep.steps > 0 ? rep.steps : 1);
    std::printf("\nper step: %.3f Newton iterations, %.3f factorizations, %.3f residual evaluations, %.3f linear setups"
                ", %ld rejected attempts, %ld chart switches\n",
                double(rep.nonlinear_iterations) / ns, double(rep.factorizations) / ns, double(rep.rhs_evaluations) / ns,
                double(rep.linear_setups) / ns, rep.rejected_steps, rep.chart_switches);
    std::printf("\n| piece | CPU ms per call | calls per step | CPU ms per step | share | wall ms per step | wall share |\n"
                "|---|---|---|---|---|---|---|\n");
    double covered = 0, covered_wall = 0;
    for (int i = 0; i < profile::kSections; ++i) {
      const auto sec = static_cast<profile::Section>(i);
      const profile::Totals t = profile::totals(sec);
      if (t.calls == 0) continue;
      covered += t.cpu_s;
      covered_wall += t.wall_s;
      std::printf("| %s | %.3f | %.2f | %.3f | %.1f %% | %.3f | %.1f %% |\n", profile::name(sec),
                  1e3 * t.cpu_s / double(t.calls), double(t.calls) / ns, 1e3 * t.cpu_s / ns, 100.0 * t.cpu_s / cpu,
                  1e3 * t.wall_s / ns, 100.0 * t.wall_s / wall);
    }
    std::printf("| Newton overhead (rest) | | | %.3f | %.1f %% | %.3f | %.1f %% |\n", 1e3 * (cpu - covered) / ns,
                100.0 * (cpu - covered) / cpu, 1e3 * (wall - covered_wall) / ns, 100.0 * (wall - covered_wall) / wall);
    std::printf("| **step** | | | **%.3f** | 100 %% | **%.3f** | 100 %% |\n", 1e3 * cpu / ns, 1e3 * wall / ns);
    if (!accepted.empty()) {
      std::sort(accepted.begin(), accepted.end());
      std::printf("\naccepted iterate's scaled residual over the %zu measured steps: median %.2e, 90th percentile %.2e "
                  "(trace: %s)\n",
                  accepted.size(), accepted[accepted.size() / 2], accepted[(accepted.size() * 9) / 10], trace_path.c_str());
    }
    std::printf("\nwindow: %.3f s CPU, %.3f s wall (CPU/wall %.2f); extrapolated to %.0f steps: %.1f s CPU, %.1f s wall\n",
                cpu, wall, cpu / wall, p.spec.time.t_end / dt, cpu / ns * (p.spec.time.t_end / dt),
                wall / ns * (p.spec.time.t_end / dt));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_step_breakdown: %s\n", e.what());
    return 2;
  }
}
