// Performance of the assembled model and of one em-galpha time step on the pinched hemisphere
// (256 CR9 elements, 1088 nodes, 5440 DOFs; apps/cases/pinched-hemisphere.yaml).
//
//   build/bin/bench_model_step                       # all benchmarks
//   build/bin/bench_model_step --benchmark_filter=Step
//
// Reports: full assembly of F_int + K (and of the strain-averaged F*, K*) on 1 and 2 threads, the mass
// matrix, one factorization of K̄ per linear solver, and ms per time step with full and modified Newton
// for each linear solver on 1 and 2 threads. Run with OPENBLAS_NUM_THREADS=1. Timings are wall time;
// on a shared 2-core machine compare ratios within one run.
#include "integrators/newmark/em_generalized_alpha.hpp"
#include "integrators/runs/registry.hpp"
#include "lib/linalg/linear_solver.hpp"
#include "lib/model/problem.hpp"

#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <memory>

namespace {

using namespace shelldyn;

Problem& hemisphere() {
  static Problem p = load_problem(std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/pinched-hemisphere.yaml");
  return p;
}

// A deformed state: the pinch mode scaled to a visible amplitude, directors tilted accordingly.
State deformed_state(const Model& m) {
  State s = m.initial_state();
  for (int i = 0; i < m.mesh().num_nodes(); ++i) {
    const Eigen::Vector3d X = m.mesh().X[static_cast<size_t>(i)];
    const double phi = std::atan2(X.y(), X.x());
    s.u.segment<3>(DofMap::dof(i, 0)) = 0.3 * std::cos(2 * phi) * Eigen::Vector3d(X.x(), X.y(), 0.0) / 10.0;
    Eigen::Vector3d p = (X / X.norm() + Eigen::Vector3d(0.05 * std::sin(phi), 0.0, 0.02)).normalized();
    s.u.segment<2>(DofMap::dof(i, 3)) = chart_coordinates(p, s.charts[static_cast<size_t>(i)]);
  }
  return s;
}

void BM_InternalAssembly(benchmark::State& st) {
  omp_set_num_threads(static_cast<int>(st.range(0)));
  const Model& m = *hemisphere().model;
  const State s = deformed_state(m);
  SparseMatrix K = m.make_matrix();
  Eigen::VectorXd F(m.num_dofs());
  for (auto _ : st) benchmark::DoNotOptimize(m.internal(s.u, s.charts, F.data(), &K));
  st.counters["elements"] = m.mesh().num_elements();
}
BENCHMARK(BM_InternalAssembly)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_AlgorithmicAssembly(benchmark::State& st) {
  omp_set_num_threads(static_cast<int>(st.range(0)));
  const Model& m = *hemisphere().model;
  const State s0 = m.initial_state(), s1 = deformed_state(m);
  SparseMatrix K = m.make_matrix();
  Eigen::VectorXd F(m.num_dofs());
  for (auto _ : st) benchmark::DoNotOptimize(m.algorithmic_internal(s0.u, s1.u, s1.charts, 0.5, 0.0, F.data(), &K));
}
BENCHMARK(BM_AlgorithmicAssembly)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MassAssembly(benchmark::State& st) {
  omp_set_num_threads(static_cast<int>(st.range(0)));
  const Model& m = *hemisphere().model;
  const State s = deformed_state(m);
  SparseMatrix M = m.make_matrix();
  for (auto _ : st) {
    m.mass(s.u, s.charts, M);
    benchmark::DoNotOptimize(M.values.data());
  }
}
BENCHMARK(BM_MassAssembly)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

const char* kSolvers[] = {"eigen-ldlt", "cholmod", "klu"};

void BM_FactorizeKbar(benchmark::State& st) {
  const Model& m = *hemisphere().model;
  const State s = deformed_state(m);
  SparseMatrix K = m.make_matrix(), M = m.make_matrix();
  m.internal(s.u, s.charts, nullptr, &K);
  m.mass(s.u, s.charts, M);
  const double dt = 1.25e-4;
  for (size_t k = 0; k < K.values.size(); ++k) K.values[k] = M.values[k] / (0.25 * dt * dt) + 0.5 * K.values[k];
  auto solver = make_linear_solver(kSolvers[st.range(0)]);
  solver->analyze(K.view());
  for (auto _ : st) solver->factorize(K.view());
  st.SetLabel(kSolvers[st.range(0)]);
}
BENCHMARK(BM_FactorizeKbar)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();

// ms per em-galpha step during the load pulse (t from 0.005 s), dt = 1.25e-4 as in the paper.
void BM_Step(benchmark::State& st) {
  omp_set_num_threads(static_cast<int>(st.range(2)));
  Problem& p = hemisphere();
  const double dt = 1.25e-4;
  IntegratorSettings settings("em-galpha", {{"newton", st.range(0) ? "modified" : "full"},
                                            {"linear_solver", kSolvers[st.range(1)]}});
  auto integ = make_integrator(settings, dt);
  State s = p.initial_state();
  integ->initialize(*p.model, s);
  for (int k = 1; k <= 40; ++k) integ->advance(*p.model, s, k * dt);  // into the pulse
  long iters = 0, steps = 0, facts = 0;
  for (auto _ : st) {
    const StepReport r = integ->advance(*p.model, s, s.t + dt);
    iters += r.nonlinear_iterations;
    facts += r.factorizations;
    ++steps;
  }
  st.counters["iters_per_step"] = double(iters) / double(steps);
  st.counters["factorizations_per_step"] = double(facts) / double(steps);
  st.SetLabel(std::string(st.range(0) ? "modified" : "full") + " Newton, " + kSolvers[st.range(1)] + ", " +
              std::to_string(st.range(2)) + " thread(s)");
}
BENCHMARK(BM_Step)
    ->ArgsProduct({{0, 1}, {0, 1, 2}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
