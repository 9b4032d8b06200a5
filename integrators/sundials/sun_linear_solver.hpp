// A custom SUNLinearSolver (type DIRECT, id CUSTOM) wrapping any shelldyn::LinearSolver, so that
// KINSOL, IDA and ARKODE use CHOLMOD / Eigen LDLᵀ / KLU with one symbolic analysis per run
// (docs/dependencies.md §3.4, architecture.md §4.4).
//
// Behaviour of the ops:
//   initialize: no-op. KINSOL calls it at every KINSol() call (docs/dependencies.md §3.2 pitfall 1); doing the
//               analysis there would re-analyse once per time step.
//   setup(A):   A must be a CSC SUNSparseMatrix. (Re)analyses only when A's colptr/rowind differ
//               from the copy stored at the last analysis (O(nnz) compare, no allocation), then
//               factorizes. Any failure (singular, not positive definite, bad input) returns
//               SUNLS_PACKAGE_FAIL_REC: a recoverable flag, so IDA/ARKODE cut the step and KINSOL
//               reports KIN_LSETUP_FAIL; the message is kept for sun_linear_solver_last_error().
//   solve:      x = A⁻¹ b with the last factorization (tol ignored: direct solver). Returns
//               SUNLS_PACKAGE_FAIL_REC if there is no valid factorization or the solution is not
//               finite; SUNLS_PACKAGE_FAIL_UNREC on an unexpected exception.
//   lastflag, free: as usual; free deletes the wrapped solver.
// No exception ever crosses the C boundary.
//
// Matrix symmetry: "cholmod" and "eigen-ldlt" read one triangle and need symmetric matrices
// (KINSOL with a symmetric tangent); "klu" also factors non-symmetric ones. (The ida-bdf and arkode-dirk
// baselines do not use this adapter: they solve their Newton matrices by a Schur complement,
// integrators/sundials/callback_linear_solver.hpp.)
#pragma once

#include "integrators/sundials/sundials_support.hpp"
#include "lib/linalg/linear_solver.hpp"

#include <functional>
#include <memory>
#include <string>

namespace shelldyn {

// Takes ownership of `solver`. The returned object is freed with SUNLinSolFree (or
// SunLinearSolverPtr). Throws std::invalid_argument if solver is null.
SUNLinearSolver make_sun_linear_solver(SUNContext ctx, std::unique_ptr<LinearSolver> solver);

// Accessors; S must come from make_sun_linear_solver (std::invalid_argument otherwise).
LinearSolver& sun_linear_solver_backend(SUNLinearSolver S);
// Message of the last failed setup/solve; empty after a successful setup.
const std::string& sun_linear_solver_last_error(SUNLinearSolver S);
// Optional observer of every successful solve: (b, x, n) after x = A⁻¹ b. Lets a caller see the
// Newton correction without touching the nonlinear solver (pass an empty function to remove).
using SolveObserver = std::function<void(const double* b, const double* x, Index n)>;
void sun_linear_solver_set_observer(SUNLinearSolver S, SolveObserver observer);

}  // namespace shelldyn
