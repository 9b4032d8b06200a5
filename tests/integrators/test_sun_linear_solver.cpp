// The custom SUNLinearSolver (integrators/sundials/sun_linear_solver.hpp): ops called directly, then inside
// IDA (the KINSOL use is covered by test_newton_solver.cpp).
#include "integrators/sundials/sun_linear_solver.hpp"

#include <gtest/gtest.h>

#include <ida/ida.h>
#include <ida/ida_ls.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace shelldyn {
namespace {

// Tridiagonal SPD matrix a on the diagonal, -1 off it (full symmetric CSC).
SparseMatrix tridiagonal(Index n, double a) {
  auto P = std::make_shared<SparsePattern>();
  P->n = n;
  P->colptr.push_back(0);
  SparseMatrix M;
  for (Index j = 0; j < n; ++j) {
    for (Index i = std::max<Index>(0, j - 1); i <= std::min<Index>(n - 1, j + 1); ++i) {
      P->rowind.push_back(i);
      M.values.push_back(i == j ? a : -1.0);
    }
    P->colptr.push_back(static_cast<Index>(P->rowind.size()));
  }
  M.pattern = P;
  return M;
}

TEST(SunLinearSolver, ReportsTypeAndIdAndRejectsForeignObjects) {
  SunContext ctx;
  SunLinearSolverPtr S(make_sun_linear_solver(ctx, make_linear_solver("klu")));
  EXPECT_EQ(SUNLinSolGetType(S.get()), SUNLINEARSOLVER_DIRECT);
  EXPECT_EQ(SUNLinSolGetID(S.get()), SUNLINEARSOLVER_CUSTOM);
  EXPECT_EQ(sun_linear_solver_backend(S.get()).name(), "klu");
  EXPECT_THROW(make_sun_linear_solver(ctx, nullptr), std::invalid_argument);
  SUNLinearSolver empty = SUNLinSolNewEmpty(ctx);
  EXPECT_THROW(sun_linear_solver_backend(empty), std::invalid_argument);
  SUNLinSolFreeEmpty(empty);
}

TEST(SunLinearSolver, AnalysesOncePerPatternAndSolves) {
  SunContext ctx;
  for (const auto& name : linear_solver_names()) {
    SunLinearSolverPtr S(make_sun_linear_solver(ctx, make_linear_solver(name)));
    SparseMatrix M = tridiagonal(50, 4.0);
    SunMatrixPtr A = make_csc_matrix(*M.pattern, ctx);
    NVectorPtr b = make_serial_vector(50, ctx), x = make_serial_vector(50, ctx);
    N_VConst(1.0, b.get());
    ASSERT_EQ(SUNLinSolInitialize(S.get()), SUNLS_SUCCESS);
    for (int k = 0; k < 3; ++k) {
      M.values[0] = 4.0 + k;  // new values, same pattern
      copy_to_sun_matrix(M, A.get());
      ASSERT_EQ(SUNLinSolInitialize(S.get()), SUNLS_SUCCESS);  // no-op: must not force re-analysis
      ASSERT_EQ(SUNLinSolSetup(S.get(), A.get()), SUNLS_SUCCESS) << name;
      ASSERT_EQ(SUNLinSolSolve(S.get(), A.get(), x.get(), b.get(), 0.0), SUNLS_SUCCESS) << name;
      // residual of the first row: (4+k) x0 - x1 = 1
      const double* xp = N_VGetArrayPointer(x.get());
      EXPECT_NEAR((4.0 + k) * xp[0] - xp[1], 1.0, 1e-13) << name;
      EXPECT_NEAR(-xp[24] + 4.0 * xp[25] - xp[26], 1.0, 1e-13) << name;
    }
    EXPECT_EQ(sun_linear_solver_backend(S.get()).stats().analyses, 1) << name;
    EXPECT_EQ(sun_linear_solver_backend(S.get()).stats().factorizations, 3) << name;
    // A different pattern (same size, a dropped off-diagonal pair) triggers exactly one re-analysis.
    SparseMatrix D = tridiagonal(50, 4.0);
    auto P2 = std::make_shared<SparsePattern>();
    P2->n = 50;
    P2->colptr = {0};
    std::vector<double> v2;
    for (Index j = 0; j < 50; ++j) {
      for (Index p = D.pattern->colptr[j]; p < D.pattern->colptr[j + 1]; ++p) {
        const Index i = D.pattern->rowind[p];
        if ((i == 10 && j == 11) || (i == 11 && j == 10)) continue;
        P2->rowind.push_back(i);
        v2.push_back(D.values[p]);
      }
      P2->colptr.push_back(static_cast<Index>(P2->rowind.size()));
    }
    SparseMatrix M2{P2, v2};
    copy_to_sun_matrix(M2, A.get());  // fits: capacity is larger
    ASSERT_EQ(SUNLinSolSetup(S.get(), A.get()), SUNLS_SUCCESS) << name;
    EXPECT_EQ(sun_linear_solver_backend(S.get()).stats().analyses, 2) << name;
  }
}

TEST(SunLinearSolver, FailuresBecomeRecoverableFlagsWithMessages) {
  SunContext ctx;
  SunLinearSolverPtr S(make_sun_linear_solver(ctx, make_linear_solver("eigen-ldlt")));
  SparseMatrix M = tridiagonal(10, 4.0);
  SunMatrixPtr A = make_csc_matrix(*M.pattern, ctx);
  NVectorPtr b = make_serial_vector(10, ctx), x = make_serial_vector(10, ctx);
  N_VConst(1.0, b.get());
  // Solve before any setup.
  EXPECT_EQ(SUNLinSolSolve(S.get(), A.get(), x.get(), b.get(), 0.0), SUNLS_PACKAGE_FAIL_REC);
  EXPECT_NE(sun_linear_solver_last_error(S.get()).find("no valid factorization"), std::string::npos);
  // Singular matrix (all zeros).
  std::fill(M.values.begin(), M.values.end(), 0.0);
  copy_to_sun_matrix(M, A.get());
  EXPECT_EQ(SUNLinSolSetup(S.get(), A.get()), SUNLS_PACKAGE_FAIL_REC);
  EXPECT_EQ(SUNLinSolLastFlag(S.get()), SUNLS_PACKAGE_FAIL_REC);
  EXPECT_NE(sun_linear_solver_last_error(S.get()).find("eigen-ldlt: zero pivot"), std::string::npos)
      << sun_linear_solver_last_error(S.get());
  EXPECT_EQ(SUNLinSolSolve(S.get(), A.get(), x.get(), b.get(), 0.0), SUNLS_PACKAGE_FAIL_REC);
  // NaN in the matrix.
  M = tridiagonal(10, 4.0);
  M.values[3] = std::nan("");
  copy_to_sun_matrix(M, A.get());
  EXPECT_EQ(SUNLinSolSetup(S.get(), A.get()), SUNLS_PACKAGE_FAIL_REC);
  EXPECT_NE(sun_linear_solver_last_error(S.get()).find("non-finite"), std::string::npos);
  // Recovery: a good matrix clears the error.
  M = tridiagonal(10, 4.0);
  copy_to_sun_matrix(M, A.get());
  EXPECT_EQ(SUNLinSolSetup(S.get(), A.get()), SUNLS_SUCCESS);
  EXPECT_TRUE(sun_linear_solver_last_error(S.get()).empty());
  EXPECT_EQ(SUNLinSolSolve(S.get(), A.get(), x.get(), b.get(), 0.0), SUNLS_SUCCESS);
}

// IDA on M y' + K y = 0 (1-D heat equation, consistent mass): the iteration matrix K + cj M is
// symmetric, so every back-end applies. Checks the adapter works inside IDA with one analysis per
// run, and against the exact decay of the first mode.
struct Heat {
  SparseMatrix K, M;
};

int heat_res(sunrealtype, N_Vector y, N_Vector yp, N_Vector r, void* ud) {
  const auto& h = *static_cast<Heat*>(ud);
  const auto& P = *h.K.pattern;
  const double *Y = N_VGetArrayPointer(y), *Yp = N_VGetArrayPointer(yp);
  double* R = N_VGetArrayPointer(r);
  std::fill(R, R + P.n, 0.0);
  for (Index j = 0; j < P.n; ++j)
    for (Index p = P.colptr[j]; p < P.colptr[j + 1]; ++p)
      R[P.rowind[p]] += h.K.values[p] * Y[j] + h.M.values[p] * Yp[j];
  return 0;
}

int heat_jac(sunrealtype, sunrealtype cj, N_Vector, N_Vector, N_Vector, SUNMatrix J, void* ud,
             N_Vector, N_Vector, N_Vector) {
  const auto& h = *static_cast<Heat*>(ud);
  SparseMatrix A = h.K;
  for (size_t p = 0; p < A.values.size(); ++p) A.values[p] += cj * h.M.values[p];
  copy_to_sun_matrix(A, J);  // IDA zeroed J, structure included
  return 0;
}

TEST(SunLinearSolver, WorksInsideIdaWithOneAnalysis) {
  const Index n = 99;  // interior nodes of (0, 1), h = 1/100
  const double hx = 1.0 / (n + 1);
  Heat heat{tridiagonal(n, 2.0), tridiagonal(n, 4.0)};
  for (auto& v : heat.K.values) v /= hx;  // stiffness: (1/h) tridiag(-1, 2, -1)
  const auto& P = *heat.M.pattern;         // mass: (h/6) tridiag(1, 4, 1)
  for (Index j = 0; j < n; ++j)
    for (Index p = P.colptr[j]; p < P.colptr[j + 1]; ++p)
      heat.M.values[p] = (P.rowind[p] == j ? 4.0 : 1.0) * hx / 6.0;
  const double pi = std::acos(-1.0);
  for (const auto& name : linear_solver_names()) {
    SunContext ctx;
    NVectorPtr y = make_serial_vector(n, ctx), yp = make_serial_vector(n, ctx);
    for (Index i = 0; i < n; ++i) N_VGetArrayPointer(y.get())[i] = std::sin(pi * (i + 1) * hx);
    SunMatrixPtr J = make_csc_matrix(*heat.K.pattern, ctx);
    SunLinearSolverPtr LS(make_sun_linear_solver(ctx, make_linear_solver(name)));
    void* ida = IDACreate(ctx);
    ASSERT_NE(ida, nullptr);
    ASSERT_EQ(IDAInit(ida, heat_res, 0.0, y.get(), yp.get()), IDA_SUCCESS);
    ASSERT_EQ(IDASStolerances(ida, 1e-8, 1e-10), IDA_SUCCESS);
    ASSERT_EQ(IDASetUserData(ida, &heat), IDA_SUCCESS);
    ASSERT_EQ(IDASetLinearSolver(ida, LS.get(), J.get()), IDA_SUCCESS);
    ASSERT_EQ(IDASetJacFn(ida, heat_jac), IDA_SUCCESS);
    NVectorPtr id = make_serial_vector(n, ctx);
    N_VConst(1.0, id.get());  // all components differential: IDACalcIC solves M y'0 = -K y0
    ASSERT_EQ(IDASetId(ida, id.get()), IDA_SUCCESS);
    ASSERT_EQ(IDACalcIC(ida, IDA_YA_YDP_INIT, 1e-3), IDA_SUCCESS) << name;
    sunrealtype t = 0;
    ASSERT_EQ(IDASolve(ida, 0.1, &t, y.get(), yp.get(), IDA_NORMAL), IDA_SUCCESS) << name;
    long nsetups = 0;
    IDAGetNumLinSolvSetups(ida, &nsetups);
    IDAFree(&ida);
    // Exact semi-discrete decay rate of the first mode: λ = k/m with the FE stiffness/mass symbols.
    const double c = std::cos(pi * hx);
    const double lambda = (2.0 - 2.0 * c) / hx / (hx / 6.0 * (4.0 + 2.0 * c));
    const double expected = std::exp(-lambda * 0.1) * std::sin(pi * 50 * hx);
    EXPECT_NEAR(N_VGetArrayPointer(y.get())[49], expected, 1e-6 * std::abs(expected) + 1e-9) << name;
    const auto& st = sun_linear_solver_backend(LS.get()).stats();
    EXPECT_EQ(st.analyses, 1) << name;
    EXPECT_GT(st.factorizations, 1) << name;
    EXPECT_GE(nsetups, st.factorizations - 1) << name;  // IDACalcIC setups are not in nsetups
  }
}

}  // namespace
}  // namespace shelldyn
