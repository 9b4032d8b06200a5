// The triangular solves of lib/linalg/single_precision_factor.hpp split along the elimination tree (several threads)
// against the sequential sweeps: on CHOLMOD's supernodal factors of random SPD matrices on 9-node shell patterns, the
// split must really happen (estimated time below the sequential one), agree with the sequential solve to round-off,
// give the same bits on one thread and on two (results independent of --threads), and solve A x = b.
#include "lib/io/case_file.hpp"
#include "lib/linalg/linear_solver.hpp"
#include "lib/linalg/single_precision_factor.hpp"
#include "lib/model/problem.hpp"

#include "tests/support/shell_matrices.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace shelldyn {
namespace {

using test::relative_residual;
using test::shell_like_matrix;

double max_relative_difference(const std::vector<double>& x, const std::vector<double>& y) {
  double d = 0, m = 0;
  for (size_t i = 0; i < x.size(); ++i) d = std::max(d, std::abs(x[i] - y[i])), m = std::max(m, std::abs(y[i]));
  return d / m;
}

template <typename Real>
void check_split(int ne, double residual_bound) {
  const SparseMatrix A = shell_like_matrix(ne, 70 + ne);
  SupernodalFactorCopy<Real> f;
  ASSERT_TRUE(copy_cholmod_factor(A.view(), f));
  const double estimate = f.split_estimate();
  std::printf("[ info ] n = %ld: estimated split time %.2f of the sequential one\n", static_cast<long>(A.pattern->n),
              estimate);
  EXPECT_LT(estimate, 0.9);  // the split must happen on these patterns
  std::mt19937 rng(ne);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> b(static_cast<size_t>(A.pattern->n));
  for (auto& v : b) v = u(rng);
  std::vector<double> xseq(b.size()), x1(b.size()), x2(b.size());
  const int saved = omp_get_max_threads();
  f.solve(b.data(), xseq.data(), false);  // the plain sequential sweeps
  omp_set_num_threads(1);
  f.solve(b.data(), x1.data());  // both groups on one thread
  omp_set_num_threads(2);
  f.solve(b.data(), x2.data());
  std::vector<double> y = b;
  f.solve(y.data(), y.data());  // in place
  omp_set_num_threads(saved);
  const double d = max_relative_difference(x2, xseq);
  std::printf("[ info ] max|x_split - x_sequential| / max|x| = %.2e\n", d);
  EXPECT_LE(d, 1e-12);
  EXPECT_GT(d, 0.0) << "the split sums the top part's updates in another order: some bits should differ";
  EXPECT_EQ(x2, x1);
  EXPECT_EQ(x2, y);
  EXPECT_LT(relative_residual(A.view(), x2, b), residual_bound);
}

TEST(ParallelSolve, SplitSolveAgreesWithSequentialDouble) {
  check_split<double>(16, 1e-13);
  check_split<double>(40, 1e-13);
}

TEST(ParallelSolve, SplitSolveAgreesWithSequentialFloat) { check_split<float>(24, 1e-5); }

// Through the "cholmod" back-end (solve_precision = double): two threads give the bits of one thread.
TEST(ParallelSolve, CholmodBackEndTwoThreadsAgreeWithOne) {
  const SparseMatrix A = shell_like_matrix(30, 5);
  auto s = make_linear_solver("cholmod");
  s->factorize(A.view());
  std::vector<double> b(static_cast<size_t>(A.pattern->n));
  for (size_t i = 0; i < b.size(); ++i) b[i] = std::sin(0.37 * static_cast<double>(i));
  std::vector<double> x1(b.size()), x2(b.size());
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  s->solve(b.data(), x1.data());
  omp_set_num_threads(2);
  s->solve(b.data(), x2.data());
  omp_set_num_threads(saved);
  EXPECT_EQ(x2, x1);
  EXPECT_LT(relative_residual(A.view(), x2, b), 1e-13);
}

// A real model's K̄ = M/(β Δt²) + K (β = 1/4, the case's Δt): the pinched hemisphere's initial iteration matrix, double
// and float copies of its factor.
TEST(ParallelSolve, HemisphereIterationMatrixSplitAgreesWithSequential) {
  Problem p = make_problem(load_case(std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/pinched-hemisphere.yaml"));
  const Model& m = *p.model;
  const State s0 = p.initial_state();
  SparseMatrix K = m.make_matrix(), M = m.make_matrix();
  std::vector<double> F(static_cast<size_t>(m.num_dofs()));
  m.internal(s0.u, s0.charts, F.data(), &K);
  m.mass(s0.u, s0.charts, M);
  const double dt = p.spec.time.dt;
  for (size_t k = 0; k < K.values.size(); ++k) K.values[k] = M.values[k] / (0.25 * dt * dt) + K.values[k];
  std::vector<double> b(static_cast<size_t>(m.num_dofs()));
  for (size_t i = 0; i < b.size(); ++i) b[i] = std::cos(0.11 * static_cast<double>(i)) * (1.0 + static_cast<double>(i % 7));
  const int saved = omp_get_max_threads();
  auto check = [&](const auto& f, double residual_bound, const char* what) {
    EXPECT_LT(f.split_estimate(), 0.9) << what;
    std::vector<double> x1(b.size()), x2(b.size()), xone(b.size());
    f.solve(b.data(), x1.data(), false);
    omp_set_num_threads(2);
    f.solve(b.data(), x2.data());
    omp_set_num_threads(1);
    f.solve(b.data(), xone.data());
    omp_set_num_threads(saved);
    EXPECT_EQ(x2, xone) << what;
    const double d = max_relative_difference(x2, x1);
    std::printf("[ info ] %s: split estimate %.3f, max|x_split - x_sequential| / max|x| = %.2e\n", what,
                f.split_estimate(), d);
    EXPECT_LE(d, 1e-12) << what;
    EXPECT_NE(x2, x1) << what;
    EXPECT_LT(relative_residual(K.view(), x2, b), residual_bound) << what;
  };
  DoublePrecisionFactor fd;
  ASSERT_TRUE(copy_cholmod_factor(K.view(), fd));
  check(fd, 1e-12, "double");
  SinglePrecisionFactor fs;
  ASSERT_TRUE(copy_cholmod_factor(K.view(), fs));
  check(fs, 1e-4, "float");
}

}  // namespace
}  // namespace shelldyn
