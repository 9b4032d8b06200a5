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
#include "lib/linear_solver.hpp"

#include <benchmark/benchmark.h>

#include <Eigen/Sparse>

#include <memory>
#include <random>
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

BENCHMARK(Analyze)->Apply(Args);
BENCHMARK(Factorize)->Apply(Args);
BENCHMARK(Solve)->Apply(Args);

}  // namespace

BENCHMARK_MAIN();
