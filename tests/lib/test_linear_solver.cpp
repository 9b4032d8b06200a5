// Sparse direct solver back-ends (lib/linalg/linear_solver.hpp) on a 9-node-shell-like pattern:
// ne x ne quadratic quads, (2ne+1)^2 nodes, 5 DOF per node, every element couples its 45 DOFs
// (docs/dependencies.md §5.1). Values: per element a random SPD block B Bᵀ/45 + 0.01 I, so the assembled
// matrix is SPD; an indefinite variant shifts the diagonal.
#include "lib/linalg/linear_solver.hpp"

#include "tests/support/shell_matrices.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <dirent.h>
#include <dlfcn.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

namespace shelldyn {
namespace {

using test::relative_residual;
using test::shell_like_matrix;

std::vector<double> random_vector(Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> v(n);
  for (auto& x : v) x = u(rng);
  return v;
}

TEST(LinearSolver, FactoryListsNamesAndRejectsUnknown) {
  const auto names = linear_solver_names();
  ASSERT_EQ(names.size(), 4u);
  for (const auto& n : names) EXPECT_EQ(make_linear_solver(n)->name(), n);
  try {
    make_linear_solver("umfpack");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("umfpack"), std::string::npos) << msg;
    for (const auto& n : names) EXPECT_NE(msg.find(n), std::string::npos) << msg;
  }
}

TEST(LinearSolver, AllBackEndsSolveSpdShellPatternAndAgree) {
  const SparseMatrix A = shell_like_matrix(4, 1);  // 9x9 nodes, 405 DOFs
  const auto b = random_vector(A.pattern->n, 2);
  std::vector<std::vector<double>> solutions;
  for (const auto& name : linear_solver_names()) {
    auto s = make_linear_solver(name);
    s->analyze(A.view());
    s->factorize(A.view());
    std::vector<double> x(b.size());
    s->solve(b.data(), x.data());
    const double res = relative_residual(A.view(), x, b);
    EXPECT_LT(res, 1e-12) << name;
    RecordProperty(name + "_relres", std::to_string(res));
    solutions.push_back(x);
  }
  for (size_t k = 1; k < solutions.size(); ++k) {
    double diff = 0, ref = 0;
    for (size_t i = 0; i < b.size(); ++i) {
      diff = std::max(diff, std::abs(solutions[k][i] - solutions[0][i]));
      ref = std::max(ref, std::abs(solutions[0][i]));
    }
    EXPECT_LT(diff / ref, 1e-10) << linear_solver_names()[k] << " vs " << linear_solver_names()[0];
  }
}

TEST(LinearSolver, InPlaceSolveWhenXAliasesB) {
  const SparseMatrix A = shell_like_matrix(2, 3);
  const auto b = random_vector(A.pattern->n, 4);
  for (const auto& name : linear_solver_names()) {
    auto s = make_linear_solver(name);
    s->factorize(A.view());
    std::vector<double> x = b;
    s->solve(x.data(), x.data());
    EXPECT_LT(relative_residual(A.view(), x, b), 1e-12) << name;
  }
}

TEST(LinearSolver, AnalysisOnceAcrossSeveralFactorizations) {
  SparseMatrix A = shell_like_matrix(3, 5);
  const std::vector<double> base = A.values;
  const auto b = random_vector(A.pattern->n, 6);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  for (const auto& name : linear_solver_names()) {
    auto s = make_linear_solver(name);
    for (int k = 0; k < 4; ++k) {
      // New values on the same pattern (symmetric perturbation of the off-diagonals keeps SPD).
      A.values = base;
      const auto& P = *A.pattern;
      for (Index j = 0; j < P.n; ++j)
        for (Index p = P.colptr[j]; p < P.colptr[j + 1]; ++p)
          if (P.rowind[p] == j) A.values[p] *= 1.0 + u(rng);
      s->factorize(A.view());  // first call analyses implicitly
      std::vector<double> x(b.size());
      s->solve(b.data(), x.data());
      s->solve(b.data(), x.data());
      EXPECT_LT(relative_residual(A.view(), x, b), 1e-12) << name << " factorization " << k;
    }
    EXPECT_EQ(s->stats().analyses, 1) << name;
    EXPECT_EQ(s->stats().factorizations, 4) << name;
    EXPECT_EQ(s->stats().solves, 8) << name;
    EXPECT_GT(s->stats().factorize_s, 0.0) << name;
  }
}

// Documented behaviour: supernodal LLᵀ hits CHOLMOD_NOT_POSDEF, the solver switches to simplicial
// LDLᵀ for good (one extra analysis) and solves; later factorizations stay on LDLᵀ (no new analysis).
TEST(LinearSolver, CholmodFallsBackToLdltOnIndefiniteMatrix) {
  const SparseMatrix A = shell_like_matrix(3, 8, -0.5);
  const auto b = random_vector(A.pattern->n, 9);
  auto s = make_linear_solver("cholmod");
  s->analyze(A.view());
  s->factorize(A.view());
  EXPECT_EQ(s->stats().analyses, 2);
  std::vector<double> x(b.size());
  s->solve(b.data(), x.data());
  EXPECT_LT(relative_residual(A.view(), x, b), 1e-9);
  s->factorize(A.view());
  EXPECT_EQ(s->stats().analyses, 2);
  EXPECT_EQ(s->stats().factorizations, 2);
  // The matrix really is indefinite: Eigen's LDLᵀ must agree, KLU too.
  for (const char* other : {"eigen-ldlt", "klu"}) {
    auto o = make_linear_solver(other);
    o->factorize(A.view());
    std::vector<double> y(b.size());
    o->solve(b.data(), y.data());
    EXPECT_LT(relative_residual(A.view(), y, b), 1e-9) << other;
  }
}

// Indefinite matrix with a known spectrum: every back-end solves it, and the inertia reported by the
// LDLᵀ back-ends (negative_pivots(), Sylvester's law) equals the number of negative eigenvalues computed
// densely. The shift -0.5 puts a sizeable fraction of the 125 eigenvalues below zero, none near it.
TEST(LinearSolver, IndefiniteMatrixSolvedAndInertiaMatchesSpectrum) {
  const SparseMatrix A = shell_like_matrix(2, 14, -0.5);
  const Index n = A.pattern->n;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
  for (Index j = 0; j < n; ++j)
    for (Index p = A.pattern->colptr[j]; p < A.pattern->colptr[j + 1]; ++p) dense(A.pattern->rowind[p], j) = A.values[p];
  const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues();
  const long negative = static_cast<long>((lambda.array() < 0.0).count());
  ASSERT_GT(negative, 0);
  ASSERT_LT(negative, n);
  ASSERT_GT(lambda.cwiseAbs().minCoeff(), 1e-6);  // no eigenvalue near zero: the count is well defined
  const auto b = random_vector(n, 15);
  for (const auto& name : linear_solver_names()) {
    auto s = make_linear_solver(name);
    s->factorize(A.view());
    std::vector<double> x(b.size());
    s->solve(b.data(), x.data());
    EXPECT_LT(relative_residual(A.view(), x, b), 1e-9) << name;
    if (name == "klu")
      EXPECT_EQ(s->negative_pivots(), -1) << name;  // LU pivots are no inertia
    else
      EXPECT_EQ(s->negative_pivots(), negative) << name;
  }
}

// Refactorization with new values on the kept analysis: the second solution must be that of the new
// matrix (not of the first one), for every back-end.
TEST(LinearSolver, RefactorizeWithNewValuesSolvesTheNewMatrix) {
  SparseMatrix A = shell_like_matrix(3, 16);
  const auto b = random_vector(A.pattern->n, 17);
  for (const auto& name : linear_solver_names()) {
    SparseMatrix B = A;
    auto s = make_linear_solver(name);
    s->factorize(B.view());
    std::vector<double> x1(b.size()), x2(b.size());
    s->solve(b.data(), x1.data());
    for (auto& v : B.values) v *= 2.0;  // A2 = 2 A1: x2 = x1 / 2
    s->factorize(B.view());
    s->solve(b.data(), x2.data());
    EXPECT_LT(relative_residual(B.view(), x2, b), 1e-12) << name;
    double diff = 0, ref = 0;
    for (size_t i = 0; i < b.size(); ++i) diff = std::max(diff, std::abs(x2[i] - 0.5 * x1[i])), ref = std::max(ref, std::abs(x1[i]));
    EXPECT_LT(diff / ref, 1e-12) << name;
    EXPECT_EQ(s->stats().analyses, 1) << name;
  }
}

TEST(LinearSolver, SolveBeforeFactorizeThrows) {
  const SparseMatrix A = shell_like_matrix(1, 18);
  for (const auto& name : linear_solver_names()) {
    auto s = make_linear_solver(name);
    std::vector<double> x(A.pattern->n, 1.0);
    EXPECT_FALSE(s->factorized()) << name;
    EXPECT_THROW(s->solve(x.data(), x.data()), std::logic_error) << name;
    s->analyze(A.view());
    EXPECT_FALSE(s->factorized()) << name;
    EXPECT_THROW(s->solve(x.data(), x.data()), std::logic_error) << name;
    s->factorize(A.view());
    EXPECT_TRUE(s->factorized()) << name;
    s->analyze(A.view());  // a new analysis discards the factorization
    EXPECT_FALSE(s->factorized()) << name;
    EXPECT_THROW(s->solve(x.data(), x.data()), std::logic_error) << name;
  }
}

TEST(LinearSolver, SpdMatrixKeepsCholmodSupernodal) {
  const SparseMatrix A = shell_like_matrix(3, 10);
  auto s = make_linear_solver("cholmod");
  s->factorize(A.view());
  EXPECT_EQ(s->stats().analyses, 1);  // no fallback re-analysis
}

// Single-precision solves (docs/dependencies.md §5.5): CHOLMOD's supernodal factor copied to float. A solve is then
// exact for a matrix within ~6e-8 (float rounding) of A, so its residual lies far above a double solve's (~1e-16)
// and below 1e-5 on this well-conditioned matrix; the refinement x += solve(b − A x) that modified Newton does
// contracts the residual by about that factor per pass and reaches double precision. On the 16 x 16 pattern
// (5445 unknowns) the factor has supernodes of every size, so all code paths of the kernel run.
TEST(LinearSolver, CholmodSinglePrecisionSolvesRefineToDouble) {
  const SparseMatrix A = shell_like_matrix(16, 30);
  const auto b = random_vector(A.pattern->n, 31);
  auto s = make_linear_solver("cholmod");
  ASSERT_TRUE(s->set_single_precision_solves(true));
  s->factorize(A.view());
  std::vector<double> x(b.size());
  s->solve(b.data(), x.data());
  const double res1 = relative_residual(A.view(), x, b);
  EXPECT_EQ(s->stats().single_solves, 1);
  EXPECT_LT(res1, 1e-5);
  EXPECT_GT(res1, 1e-11);  // really the float factor: a double solve gives ~1e-16
  // In place: the same numbers bit for bit.
  std::vector<double> y = b;
  s->solve(y.data(), y.data());
  EXPECT_EQ(y, x);
  // Refinement with the double residual.
  std::vector<double> r(b.size()), d(b.size());
  double res = res1;
  int passes = 0;
  while (res > 1e-14 && passes < 6) {
    for (Index j = 0; j < A.pattern->n; ++j) r[j] = b[j];
    for (Index j = 0; j < A.pattern->n; ++j)
      for (Index p = A.pattern->colptr[j]; p < A.pattern->colptr[j + 1]; ++p) r[A.pattern->rowind[p]] -= A.values[p] * x[j];
    s->solve(r.data(), d.data());
    for (size_t i = 0; i < x.size(); ++i) x[i] += d[i];
    res = relative_residual(A.view(), x, b);
    ++passes;
  }
  std::printf("[ info ] single-precision solve: residual %.2e; after %d refinement passes %.2e\n", res1, passes, res);
  EXPECT_LT(res, 1e-14);
  EXPECT_LE(passes, 3);
  // Switched off: double solves again.
  ASSERT_TRUE(s->set_single_precision_solves(false));
  const long singles = s->stats().single_solves;
  s->solve(b.data(), x.data());
  EXPECT_LT(relative_residual(A.view(), x, b), 1e-12);
  EXPECT_EQ(s->stats().single_solves, singles);
}

// solve_precision = double with a supernodal LLᵀ factor runs the solves of lib/linalg/single_precision_factor on an exact
// copy of CHOLMOD's factor (columns paired in the forward sweep). They must solve to double round-off, agree with
// another back-end's solve, and give the same bits in place.
TEST(LinearSolver, CholmodDoubleSolvesOnTheCopiedFactorAreExactToRoundOff) {
  for (int ne : {3, 16}) {
    const SparseMatrix A = shell_like_matrix(ne, 40 + ne);
    const auto b = random_vector(A.pattern->n, 41 + ne);
    auto s = make_linear_solver("cholmod"), e = make_linear_solver("eigen-ldlt");
    s->factorize(A.view());
    e->factorize(A.view());
    std::vector<double> x(b.size()), xe(b.size());
    s->solve(b.data(), x.data());
    e->solve(b.data(), xe.data());
    double dmax = 0.0, xmax = 0.0;
    for (size_t i = 0; i < x.size(); ++i) dmax = std::max(dmax, std::abs(x[i] - xe[i])), xmax = std::max(xmax, std::abs(xe[i]));
    const double res = relative_residual(A.view(), x, b);
    std::printf("[ info ] n = %ld: residual %.2e, max|x - x_eigen|/max|x| %.2e\n", static_cast<long>(A.pattern->n), res,
                dmax / xmax);
    EXPECT_LT(res, 1e-14);
    EXPECT_LT(dmax, 1e-12 * xmax);
    EXPECT_EQ(s->stats().single_solves, 0);
    std::vector<double> y = b;
    s->solve(y.data(), y.data());
    EXPECT_EQ(y, x);
  }
}

// The other back-ends decline (and keep double solves); an indefinite matrix makes CHOLMOD fall back to simplicial
// LDLᵀ, whose solves stay double; the integrators' setting names the back-end it needs.
TEST(LinearSolver, SinglePrecisionSolvesOnlyWithCholmodSupernodal) {
  const SparseMatrix A = shell_like_matrix(3, 32);
  const auto b = random_vector(A.pattern->n, 33);
  for (const auto& name : linear_solver_names()) {
    auto s = make_linear_solver(name);
    EXPECT_TRUE(s->set_single_precision_solves(false)) << name;
    if (name == "cholmod") continue;
    EXPECT_FALSE(s->set_single_precision_solves(true)) << name;
    s->factorize(A.view());
    std::vector<double> x(b.size());
    s->solve(b.data(), x.data());
    EXPECT_LT(relative_residual(A.view(), x, b), 1e-12) << name;
    EXPECT_EQ(s->stats().single_solves, 0) << name;
  }
  const SparseMatrix B = shell_like_matrix(2, 14, -0.5);  // indefinite (test above)
  auto s = make_linear_solver("cholmod");
  ASSERT_TRUE(s->set_single_precision_solves(true));
  s->factorize(B.view());
  std::vector<double> x(B.pattern->n);
  const auto c = random_vector(B.pattern->n, 15);
  s->solve(c.data(), x.data());
  EXPECT_LT(relative_residual(B.view(), x, c), 1e-9);
  EXPECT_EQ(s->stats().single_solves, 0);
  EXPECT_EQ(s->stats().analyses, 2);  // the LDLᵀ fallback re-analysed
  // A factor beyond float's range (entries ~1e45) keeps double solves instead of producing inf.
  SparseMatrix C = shell_like_matrix(3, 34);
  for (double& v : C.values) v *= 1e90;
  auto big = make_linear_solver("cholmod");
  ASSERT_TRUE(big->set_single_precision_solves(true));
  big->factorize(C.view());
  const auto d = random_vector(C.pattern->n, 35);
  std::vector<double> xd(d.size());
  big->solve(d.data(), xd.data());
  EXPECT_LT(relative_residual(C.view(), xd, d), 1e-12);
  EXPECT_EQ(big->stats().single_solves, 0);
  EXPECT_FALSE(single_precision_setting("double", "klu", "em-galpha"));
  EXPECT_TRUE(single_precision_setting("single", "cholmod", "em-galpha"));
  for (const auto& [value, solver, expect] :
       std::vector<std::tuple<std::string, std::string, std::string>>{{"half", "cholmod", "'half' (use double or single)"},
                                                                       {"single", "klu", "needs linear_solver=cholmod"}}) {
    try {
      single_precision_setting(value, solver, "em-galpha");
      ADD_FAILURE() << value << " with " << solver << " accepted";
    } catch (const std::invalid_argument& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("em-galpha.solve_precision: ", 0), 0u) << msg;
      EXPECT_NE(msg.find(expect), std::string::npos) << msg;
    }
  }
}

// No hidden threads: CHOLMOD's supernodal kernels open OpenMP regions with a fixed num_threads(4) and
// OpenBLAS (used by CHOLMOD and MUMPS) starts its own pool (lib/linalg/linear_solver.cpp). With one OpenMP thread requested, factorizing and
// solving must not add a single thread to the process (counted in /proc/self/task). The matrix is large
// enough (16 x 16 elements, 5445 unknowns) for supernodes wider than CHOLMOD's 32-column threshold.
int process_threads() {
  int n = 0;
  if (DIR* d = opendir("/proc/self/task")) {
    while (const dirent* e = readdir(d))
      if (e->d_name[0] != '.') ++n;
    closedir(d);
  }
  return n;
}

TEST(LinearSolver, NoBackEndStartsHiddenThreads) {
  if (process_threads() == 0) GTEST_SKIP() << "no /proc/self/task on this system";
  omp_set_num_threads(1);
  const SparseMatrix A = shell_like_matrix(16, 11);
  const std::vector<double> b = random_vector(A.pattern->n, 12);
  for (const auto& name : linear_solver_names()) {
    const int before = process_threads();
    auto s = make_linear_solver(name);
    s->factorize(A.view());
    s->factorize(A.view());
    std::vector<double> x(b.size());
    s->solve(b.data(), x.data());
    EXPECT_LT(relative_residual(A.view(), x, b), 1e-12) << name;
    EXPECT_EQ(process_threads(), before) << name << " or its BLAS started threads beyond --threads";
  }
}

// OpenBLAS creates its pool when it is loaded, before any solver exists, so the thread count above cannot
// see whether the BLAS kernels of CHOLMOD and MUMPS run on one thread. Check the setting itself: raise the
// OpenBLAS thread count, make the back-end, and expect it to be 1 again.
TEST(LinearSolver, BlasBackEndsLimitOpenBlasToOneThread) {
  using GetThreads = int (*)();
  using SetThreads = void (*)(int);
  const auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  const auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  if (get == nullptr || set == nullptr) GTEST_SKIP() << "the BLAS in this process is not OpenBLAS";
  set(2);
  if (get() != 2) GTEST_SKIP() << "OpenBLAS was built or started for a single thread";
  for (const char* name : {"cholmod", "mumps"}) {
    set(2);
    auto s = make_linear_solver(name);
    EXPECT_EQ(get(), 1) << name << " leaves OpenBLAS on more than one thread";
  }
}

// A singular matrix (a zero row/column) must throw naming the back-end and the column.
TEST(LinearSolver, SingularMatrixThrowsNamingBackEndAndColumn) {
  SparseMatrix A = shell_like_matrix(2, 11);
  const auto& P = *A.pattern;
  const Index dead = 17;
  for (Index j = 0; j < P.n; ++j)
    for (Index p = P.colptr[j]; p < P.colptr[j + 1]; ++p)
      if (j == dead || P.rowind[p] == dead) A.values[p] = 0.0;
  for (const auto& name : linear_solver_names()) {
    auto s = make_linear_solver(name);
    try {
      s->factorize(A.view());
      FAIL() << name << ": expected std::runtime_error";
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(name, 0), 0u) << msg;
      EXPECT_NE(msg.find("column"), std::string::npos) << msg;
      if (name != "klu") {  // KLU reports the column in its own (BTF/AMD-permuted) numbering
        EXPECT_NE(msg.find("column 17"), std::string::npos) << msg;
      }
    }
    EXPECT_FALSE(s->factorized());
    std::vector<double> x(P.n, 1.0);
    EXPECT_THROW(s->solve(x.data(), x.data()), std::logic_error) << name;
  }
}

TEST(LinearSolver, BadInputIsRejectedWithAClearMessage) {
  SparseMatrix A = shell_like_matrix(1, 12);
  for (const auto& name : linear_solver_names()) {
    auto s = make_linear_solver(name);
    // Non-finite value.
    SparseMatrix B = A;
    B.values[5] = std::nan("");
    EXPECT_THROW(s->factorize(B.view()), std::invalid_argument) << name;
    // Unsorted rows.
    auto bad = std::make_shared<SparsePattern>(*A.pattern);
    std::swap(bad->rowind[0], bad->rowind[1]);
    SparseMatrix C{bad, A.values};
    try {
      s->analyze(C.view());
      FAIL() << name;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("column 0"), std::string::npos) << e.what();
    }
    // Pattern of another size after analysis.
    s->analyze(A.view());
    const SparseMatrix D = shell_like_matrix(2, 13);
    EXPECT_THROW(s->factorize(D.view()), std::invalid_argument) << name;
  }
}

}  // namespace
}  // namespace shelldyn
