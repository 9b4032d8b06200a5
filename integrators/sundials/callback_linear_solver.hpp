// A SUNLinearSolver (type DIRECT, id CUSTOM) whose Newton matrix lives in the caller, and the placeholder
// SUNMatrix that IDA and ARKODE need beside a direct solver (docs/dependencies.md §3.5, docs/theory/baseline-newton.md).
//
// Why: the baselines' Newton matrices of the first-order system y = (q, v) have twice the unknowns of the
// mechanical problem. They solve them by eliminating the velocity block (a Schur complement of the size
// of q, integrators/baselines/second_order_newton.hpp), so there is no (2n+2)² matrix for SUNDIALS to hold.
// The package still calls the Jacobian / linear-system function (which assembles the caller's blocks), then
// setup(), then solve(b) per Newton iteration; the placeholder matrix only satisfies its "direct solver
// needs a matrix" checks. Its ops are getid (CUSTOM), zero (no-op: IDA zeroes J before its Jacobian
// callback), clone and destroy; it owns no storage.
//
// The callbacks return SUNDIALS linear-solver flags (SUNLS_SUCCESS, SUNLS_PACKAGE_FAIL_REC: the package
// cuts the step, SUNLS_PACKAGE_FAIL_UNREC: it stops) and must not throw; the last flag is kept for
// SUNLinSolLastFlag. Exceptions that escape anyway are turned into SUNLS_PACKAGE_FAIL_UNREC.
#pragma once

#include "integrators/sundials/sundials_support.hpp"

#include <functional>

namespace shelldyn {

struct CallbackSolverOps {
  std::function<int()> setup;                                  // factorize the caller's Newton matrix
  std::function<int(const double* b, double* x)> solve;        // x = A⁻¹ b, vectors of the package's length
};

SunLinearSolverPtr make_callback_linear_solver(SUNContext ctx, CallbackSolverOps ops);
SunMatrixPtr make_placeholder_matrix(SUNContext ctx);

}  // namespace shelldyn
