// Factorize and solve times of the LinearSolver back-ends on 9-node-shell patterns
// (docs/dependencies.md §5.1): ne x ne quadratic quads, (2ne+1)^2 nodes, 5 DOF per node, random SPD
// element blocks B Bᵀ/45 + 0.01 I. ne = 16 is the size of the 256-element hemisphere benchmark
// (33 x 33 nodes, 5445 DOFs); ne = 8 is given for scale.
//
// Sample runs (one BLAS thread: OpenBLAS threads slow CHOLMOD down on shared 2-core machines):
//   OPENBLAS_NUM_THREADS=1 ./bench_linear_solvers
//   OPENBLAS_NUM_THREADS=1 ./bench_linear_solvers --benchmark_filter=Factorize/.*/16
// The "factorize" benchmark times the numeric factorization on a kept analysis (what a Newton setup
// costs); the analysis is timed separately; values are perturbed between iterations so KLU's
// refactor path is exercised as in a Newton loop.
//
// The effective tangent of a case instead of the synthetic pattern (docs/dependencies.md §5.2):
//   OPENBLAS_NUM_THREADS=1 ./bench_linear_solvers --case apps/cases/pinched-hemisphere.yaml [--case ...]
// builds K̄ = M/(β Δt²) + (1 − α_f) K at the case's initial state and time step Δt, with β = 1/4 and
// α_f = 1/2 (the trapezoidal member of the Newmark family; em-galpha's coefficients differ with ρ∞, which
// changes the values, not the pattern or the fill), and benchmarks every back-end on it. All other
// arguments go to Google Benchmark (--benchmark_filter=..., --benchmark_repetitions=..., see --help). The CPU
// column of these benchmarks is the whole process's CPU time, so a back-end's helper threads would show.
#include "lib/linalg/linear_solver.hpp"
#include "lib/model/problem.hpp"

#include <benchmark/benchmark.h>

#include <Eigen/Sparse>

#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using shelldyn::Index;

shelldyn::SparseMatrix shell_like_matrix(int ne) {
  const int nn = 2 * ne + 1;
  const Index n = Index(nn) * nn * 5;
  std::mt19937 rng(42);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Triplet<double, Index>> trip;
  trip.reserve(size_t(ne) * ne * 45 * 45);
  for (int ey = 0; ey < ne; ++ey)
    for (int ex = 0; ex < ne; ++ex) {
      std::vector<Index> dofs;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          for (int c = 0; c < 5; ++c) dofs.push_back((Index(2 * ey + a) * nn + (2 * ex + b)) * 5 + c);
      Eigen::MatrixXd B(45, 45);
      for (int i = 0; i < 45; ++i)
        for (int j = 0; j < 45; ++j) B(i, j) = normal(rng);
      const Eigen::MatrixXd Ke = B * B.transpose() / 45.0 + 0.01 * Eigen::MatrixXd::Identity(45, 45);
      for (int i = 0; i < 45; ++i)
        for (int j = 0; j < 45; ++j) trip.emplace_back(dofs[i], dofs[j], Ke(i, j));
    }
  Eigen::SparseMatrix<double, Eigen::ColMajor, Index> A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  A.makeCompressed();
  auto pattern = std::make_shared<shelldyn::SparsePattern>();
  pattern->n = n;
  pattern->colptr.assign(A.outerIndexPtr(), A.outerIndexPtr() + n + 1);
  pattern->rowind.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
  shelldyn::SparseMatrix M;
  M.pattern = pattern;
  M.values.assign(A.valuePtr(), A.valuePtr() + A.nonZeros());
  return M;
}

const std::vector<std::string>& names() {
  static const std::vector<std::string> n = shelldyn::linear_solver_names();
  return n;
}

void Analyze(benchmark::State& state) {
  const auto& name = names()[state.range(0)];
  const auto A = shell_like_matrix(static_cast<int>(state.range(1)));
  for (auto _ : state) {
    auto s = shelldyn::make_linear_solver(name);
    s->analyze(A.view());
    benchmark::DoNotOptimize(s.get());
  }
  state.SetLabel(name + ", n = " + std::to_string(A.pattern->n) + ", nnz = " + std::to_string(A.pattern->nnz()));
}

void Factorize(benchmark::State& state) {
  const auto& name = names()[state.range(0)];
  auto A = shell_like_matrix(static_cast<int>(state.range(1)));
  const std::vector<double> base = A.values;
  auto s = shelldyn::make_linear_solver(name);
  s->analyze(A.view());
  s->factorize(A.view());  // KLU: first klu_l_factor outside the timing, then refactor
  int k = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const double f = 1.0 + 1e-3 * ((++k % 7) - 3);  // new values, same pattern, still SPD
    for (size_t p = 0; p < base.size(); ++p) A.values[p] = base[p] * f;
    state.ResumeTiming();
    s->factorize(A.view());
  }
  state.SetLabel(name + ", n = " + std::to_string(A.pattern->n));
  state.counters["analyses"] = static_cast<double>(s->stats().analyses);
}

void Solve(benchmark::State& state) {
  const auto& name = names()[state.range(0)];
  const auto A = shell_like_matrix(static_cast<int>(state.range(1)));
  auto s = shelldyn::make_linear_solver(name);
  s->factorize(A.view());
  std::vector<double> b(A.pattern->n, 1.0), x(A.pattern->n);
  for (auto _ : state) {
    s->solve(b.data(), x.data());
    benchmark::DoNotOptimize(x.data());
  }
  state.SetLabel(name + ", n = " + std::to_string(A.pattern->n));
}

void Args(benchmark::internal::Benchmark* b) {
  for (int ne : {8, 16})
    for (int i = 0; i < static_cast<int>(names().size()); ++i) b->Args({i, ne});
  b->ArgNames({"solver", "ne"})->Unit(benchmark::kMillisecond);
}

// ---- K̄ of a case file (--case) ------------------------------------------------------------------
shelldyn::SparseMatrix case_kbar(const std::string& path) {
  shelldyn::Problem p = shelldyn::load_problem(path);
  const shelldyn::Model& m = *p.model;
  const shelldyn::State s = p.initial_state();
  shelldyn::SparseMatrix K = m.make_matrix(), M = m.make_matrix();
  m.internal(s.u, s.charts, nullptr, &K);
  m.mass(s.u, s.charts, M);
  const double dt = p.spec.time.dt, beta = 0.25, alpha_f = 0.5;
  for (size_t k = 0; k < K.values.size(); ++k) K.values[k] = M.values[k] / (beta * dt * dt) + (1 - alpha_f) * K.values[k];
  return K;
}

void register_case(const std::string& path) {
  auto A = std::make_shared<shelldyn::SparseMatrix>(case_kbar(path));
  std::string stem = path.substr(path.find_last_of('/') + 1);
  stem = stem.substr(0, stem.find('.'));
  const std::string label = ", n = " + std::to_string(A->pattern->n) + ", nnz = " + std::to_string(A->pattern->nnz());
  for (const auto& name : names()) {
    benchmark::RegisterBenchmark(("CaseAnalyze/" + stem + "/" + name).c_str(), [=](benchmark::State& st) {
      for (auto _ : st) {
        auto s = shelldyn::make_linear_solver(name);
        s->analyze(A->view());
        benchmark::DoNotOptimize(s.get());
      }
      st.SetLabel(name + label);
    })->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
    benchmark::RegisterBenchmark(("CaseFactorize/" + stem + "/" + name).c_str(), [=](benchmark::State& st) {
      shelldyn::SparseMatrix B = *A;
      auto s = shelldyn::make_linear_solver(name);
      s->analyze(B.view());
      s->factorize(B.view());
      int k = 0;
      for (auto _ : st) {
        st.PauseTiming();
        const double f = 1.0 + 1e-3 * ((++k % 7) - 3);  // new values, same pattern
        for (size_t p = 0; p < B.values.size(); ++p) B.values[p] = A->values[p] * f;
        st.ResumeTiming();
        s->factorize(B.view());
      }
      st.SetLabel(name + label);
      st.counters["negative_pivots"] = static_cast<double>(s->negative_pivots());
    })->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
    benchmark::RegisterBenchmark(("CaseSolve/" + stem + "/" + name).c_str(), [=](benchmark::State& st) {
      auto s = shelldyn::make_linear_solver(name);
      s->factorize(A->view());
      std::vector<double> b(A->pattern->n, 1.0), x(A->pattern->n);
      for (auto _ : st) {
        s->solve(b.data(), x.data());
        benchmark::DoNotOptimize(x.data());
      }
      st.SetLabel(name + label);
    })->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
  }
  // CHOLMOD's factor solved with its float copy (solve_precision = single, docs/dependencies.md §5.5). Warm caches
  // here; inside a run, where the element loops evict the factor between solves, the gap is larger.
  benchmark::RegisterBenchmark(("CaseSolve/" + stem + "/cholmod-single").c_str(), [=](benchmark::State& st) {
    auto s = shelldyn::make_linear_solver("cholmod");
    s->set_single_precision_solves(true);
    s->factorize(A->view());
    std::vector<double> b(A->pattern->n, 1.0), x(A->pattern->n);
    for (auto _ : st) {
      s->solve(b.data(), x.data());
      benchmark::DoNotOptimize(x.data());
    }
    st.SetLabel("cholmod, single-precision solves" + label);
  })->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest{argv[0]};
  std::vector<std::string> cases;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--case") == 0) {
      if (i + 1 >= argc) {
        std::cerr << "bench_linear_solvers: --case needs a case file (e.g. apps/cases/flying-plate.yaml)\n";
        return 2;
      }
      cases.emplace_back(argv[++i]);
    } else {
      if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0)
        std::puts("bench_linear_solvers [--case CASE.yaml]... [Google Benchmark options]\n"
                  "  without --case: synthetic 9-node-shell patterns, ne = 8 and 16 (5445 unknowns)\n"
                  "  --case FILE     K̄ = M/(Δt²/4) + K/2 of the case at its initial state and time step;\n"
                  "                  repeatable; the synthetic benchmarks are then left out\n"
                  "  Google Benchmark's own options follow.\n");
      rest.push_back(argv[i]);
    }
  }
  try {
    for (const auto& c : cases) register_case(c);
  } catch (const std::exception& e) {
    std::cerr << "bench_linear_solvers: " << e.what() << "\n";
    return 1;
  }
  if (cases.empty()) {
    benchmark::RegisterBenchmark("Analyze", Analyze)->Apply(Args);
    benchmark::RegisterBenchmark("Factorize", Factorize)->Apply(Args);
    benchmark::RegisterBenchmark("Solve", Solve)->Apply(Args);
  }
  int rargc = static_cast<int>(rest.size());
  benchmark::Initialize(&rargc, rest.data());
  if (benchmark::ReportUnrecognizedArguments(rargc, rest.data())) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
