// How shelldyn's cost grows with the mesh (docs/scaling.md): one configuration per process, so that the
// peak memory (VmHWM) is that configuration's. scripts/scaling_study.py runs the series, fits the
// exponents and plots.
//
//   build/bin/bench_scaling hemisphere 16 --threads 2      # full pinched hemisphere, 4n x n elements
//   build/bin/bench_scaling plate 64 --threads 1           # clamped square plate, n x n elements
//   build/bin/bench_scaling --header                       # the CSV header
//
// Prints ONE CSV row (see --header):
//   unknowns             number of DOFs (5 per node)
//   nnz_K                non-zeros of the (full symmetric) tangent pattern
//   rss_model_mb         resident memory after the model, its matrices and one assembly are built
//   peak_rss_mb          peak resident memory of the process (after factorizations and time steps)
//   assembly_s           F_int + K (exact tangent, all elements), min over repetitions, wall
//   assembly_cpu_s       the same, process CPU time (user + sys) per assembly
//   cholmod_nnz_L, cholmod_flops   CHOLMOD's symbolic analysis of K̄ (its default ordering: AMD, or METIS
//                        when AMD fills badly): non-zeros of the factor L and flops of one factorization
//   factor_<solver>_s    one numeric factorization of K̄ = M/(β Δt²) + K (the em-galpha iteration matrix
//                        shape), min over 2 repetitions, wall; analyse excluded
//   factor_<solver>_cpu_s  the same, process CPU time (all threads: OpenBLAS's in CHOLMOD)
//   step_s, step_cpu_s   one em-galpha step during the load pulse (full Newton, the integrator's default
//                        linear solver), mean over the measured steps, wall and CPU
//   newton_per_step, factorizations_per_step
// Wall times are minima / means over few repetitions on a shared machine: compare within one series and
// read the CPU columns for what the code costs.
#include "integrators/integrator.hpp"
#include "integrators/integrator_settings.hpp"
#include "integrators/runs/registry.hpp"
#include "lib/io/case_file.hpp"
#include "lib/linalg/linear_solver.hpp"
#include "lib/model/problem.hpp"

#include "lib/linalg/openmp_wait_policy.hpp"  // OpenMP threads wait as in the apps (bounded spin)

#include <cholmod.h>
#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using namespace shelldyn;

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

double cpu() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double status_mb(const char* key) {  // VmRSS / VmHWM of /proc/self/status, in MB
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key, 0) == 0) return std::stod(line.substr(std::string(key).size())) / 1024.0;
  return std::nan("");
}

// The hemisphere case of apps/cases with n elements per quarter in each direction (4n x n in all).
CaseSpec hemisphere_case(int n) {
  CaseSpec c = load_case(std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/pinched-hemisphere.yaml");
  std::get<HemisphereMeshSpec>(c.mesh).n = n;
  return c;
}

// A 1 m square steel plate, 10 mm thick, clamped on two opposite edges, a centre force pulse.
CaseSpec plate_case(int n) {
  std::ostringstream y;
  y << "name: scaling-plate\n"
       "description: clamped square plate for the scaling study\n"
       "mesh: {generator: rectangle, a: 1.0, b: 1.0, nx: "
    << n << ", ny: " << n
    << "}\n"
       "material: {E: 2.1e11, nu: 0.3, rho: 7850.0, thickness: 0.01}\n"
       "sets:\n  centre: {point: [0.5, 0.5, 0.0]}\n"
       "boundary_conditions:\n  - {set: left, fix: [ux, uy, uz, director]}\n"
       "  - {set: right, fix: [ux, uy, uz, director]}\n"
       "loads:\n  - {set: centre, type: force, direction: [0, 0, 1], amplitude: 1.0e4,\n"
       "     function: {type: triangle, t_peak: 1.0e-3, t_end: 2.0e-3}}\n"
       "integrator: {name: em-galpha}\n"
       "time: {dt: 1.0e-4, t_end: 4.0e-3}\n"
       "output: {vtu: false, history: false}\n";
  return load_case_from_string(y.str(), "scaling-plate.yaml");
}

// ordering < 0: CHOLMOD's default strategy; else only that method (CHOLMOD_AMD, CHOLMOD_METIS, ...).
long cholmod_analysis(const CscView& A, double* flops, int ordering = -1) {
  cholmod_common c;
  cholmod_l_start(&c);
  if (ordering >= 0) {
    c.nmethods = 1;
    c.method[0].ordering = ordering;
    c.postorder = 1;
  }
  cholmod_sparse S{};
  S.nrow = S.ncol = static_cast<size_t>(A.n);
  S.nzmax = static_cast<size_t>(A.nnz());
  S.p = const_cast<Index*>(A.colptr);
  S.i = const_cast<Index*>(A.rowind);
  S.x = const_cast<double*>(A.values);
  S.stype = 1;
  S.itype = CHOLMOD_LONG;
  S.xtype = CHOLMOD_REAL;
  S.dtype = CHOLMOD_DOUBLE;
  S.sorted = 1;
  S.packed = 1;
  cholmod_factor* L = cholmod_l_analyze(&S, &c);
  if (!L) throw std::runtime_error("cholmod_l_analyze failed");
  const long lnz = static_cast<long>(c.lnz);
  *flops = c.fl;
  cholmod_l_free_factor(&L, &c);
  cholmod_l_finish(&c);
  return lnz;
}

}  // namespace

int main(int argc, char** argv) {
  const char* header =
      "mesh,n,threads,elements,unknowns,nnz_K,rss_model_mb,peak_rss_mb,assembly_s,assembly_cpu_s,cholmod_nnz_L,"
      "cholmod_flops,factor_eigen-ldlt_s,factor_cholmod_s,factor_eigen-ldlt_cpu_s,factor_cholmod_cpu_s,step_s,step_cpu_s,newton_per_step,factorizations_per_step";
  if (argc >= 2 && std::string(argv[1]) == "--header") {
    std::cout << header << "\n";
    return 0;
  }
  if (argc < 3) {
    std::cerr << "usage: bench_scaling hemisphere|plate N [--threads T] [--steps S] [--skip SOLVER] [--fill-only] | --header\n";
    return 2;
  }
  try {
    const std::string mesh = argv[1];
    const int n = std::stoi(argv[2]);
    int threads = 1, steps = 3;
    std::vector<std::string> skip;
    bool fill_only = false;
    for (int k = 3; k < argc; k += 2) {
      const std::string a = argv[k];
      if (a == "--fill-only") {
        fill_only = true;
        --k;
        continue;
      }
      if (k + 1 >= argc) throw std::invalid_argument("option " + a + " needs a value");
      if (a == "--threads") threads = std::stoi(argv[k + 1]);
      else if (a == "--steps") steps = std::stoi(argv[k + 1]);
      else if (a == "--skip") skip.push_back(argv[k + 1]);
      else throw std::invalid_argument("unknown option " + a);
    }
    if (mesh != "hemisphere" && mesh != "plate") throw std::invalid_argument("mesh must be hemisphere or plate");
    if (n < 1 || threads < 1 || steps < 1) throw std::invalid_argument("N, --threads and --steps must be >= 1");
    omp_set_num_threads(threads);

    Problem p = make_problem(mesh == "hemisphere" ? hemisphere_case(n) : plate_case(n));
    const Model& m = *p.model;
    const State s0 = p.initial_state();
    SparseMatrix K = m.make_matrix(), M = m.make_matrix();
    Eigen::VectorXd F(m.num_dofs());
    m.internal(s0.u, s0.charts, F.data(), &K);
    const double rss_model = status_mb("VmRSS:");

    // Assembly of F_int + K: repetitions until ~1 s of wall time (at least 2).
    double best = 1e300, cpu_sum = 0.0;
    int reps = 0;
    for (const double start = now(); reps < 2 || (now() - start < 1.0 && reps < 50); ++reps) {
      const double t0 = now(), c0 = cpu();
      m.internal(s0.u, s0.charts, F.data(), &K);
      best = std::min(best, now() - t0);
      cpu_sum += cpu() - c0;
    }
    const double assembly = best, assembly_cpu = cpu_sum / reps;

    // K̄ = M/(β Δt²) + K at the case's Δt (β = 1/4).
    m.mass(s0.u, s0.charts, M);
    const double dt = p.spec.time.dt;
    for (size_t k = 0; k < K.values.size(); ++k) K.values[k] = M.values[k] / (0.25 * dt * dt) + K.values[k];
    double flops = 0.0;
    const long lnz = cholmod_analysis(K.view(), &flops);
    if (fill_only) {  // --fill-only: mesh,n,unknowns,nnz_K, then nnz(L) and flops for default / AMD / METIS orderings
      double f_amd = 0.0, f_metis = 0.0;
      const long l_amd = cholmod_analysis(K.view(), &f_amd, CHOLMOD_AMD);
      const long l_metis = cholmod_analysis(K.view(), &f_metis, CHOLMOD_METIS);
      std::printf("%s,%d,%lld,%lld,%ld,%.6g,%ld,%.6g,%ld,%.6g\n", mesh.c_str(), n, static_cast<long long>(m.num_dofs()),
                  static_cast<long long>(K.pattern->nnz()), lnz, flops, l_amd, f_amd, l_metis, f_metis);
      return 0;
    }
    double factor[2] = {std::nan(""), std::nan("")}, factor_cpu[2] = {std::nan(""), std::nan("")};
    const char* solvers[2] = {"eigen-ldlt", "cholmod"};
    for (int j = 0; j < 2; ++j) {
      if (std::find(skip.begin(), skip.end(), solvers[j]) != skip.end()) continue;
      auto solver = make_linear_solver(solvers[j]);
      solver->analyze(K.view());
      double b = 1e300, bc = 1e300;
      for (int r = 0; r < 2; ++r) {
        const double t0 = now(), c0 = cpu();
        solver->factorize(K.view());
        b = std::min(b, now() - t0);
        bc = std::min(bc, cpu() - c0);
      }
      factor[j] = b;
      factor_cpu[j] = bc;
    }

    // em-galpha steps into the load pulse (full Newton, default linear solver).
    IntegratorSettings settings("em-galpha", {{"newton", "full"}});
    auto integ = make_integrator(settings, dt);
    State s = p.initial_state();
    integ->initialize(*p.model, s);
    for (int k = 1; k <= 2; ++k) integ->advance(*p.model, s, s.t + dt);  // warm-up, into the pulse
    long iters = 0, facts = 0;
    const double t0 = now(), c0 = cpu();
    for (int k = 0; k < steps; ++k) {
      const StepReport r = integ->advance(*p.model, s, s.t + dt);
      iters += r.nonlinear_iterations;
      facts += r.factorizations;
    }
    const double step = (now() - t0) / steps, step_cpu = (cpu() - c0) / steps;

    std::printf("%s,%d,%d,%d,%lld,%lld,%.1f,%.1f,%.6g,%.6g,%ld,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.3g,%.3g\n", mesh.c_str(), n, threads,
                m.mesh().num_elements(), static_cast<long long>(m.num_dofs()), static_cast<long long>(K.pattern->nnz()),
                rss_model, status_mb("VmHWM:"), assembly, assembly_cpu, lnz, flops, factor[0], factor[1], factor_cpu[0], factor_cpu[1], step, step_cpu,
                double(iters) / steps, double(facts) / steps);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench_scaling: error: " << e.what() << "\n";
    return 1;
  }
}
