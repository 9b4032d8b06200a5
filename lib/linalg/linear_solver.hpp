// Sparse direct solvers for the systems of the project (tangents K̄, mass matrices, the Schur complements of
// the IDA and ARKODE Newton matrices, integrators/baselines/second_order_newton.hpp), behind one small interface: analyse once per pattern, factorize per
// Newton setup, solve per iteration (architecture.md §4.4, docs/dependencies.md §5).
//
// Input contract (lib/linalg/sparse_matrix.hpp): square CSC with 64-bit indices, FULL storage (both
// triangles), row indices sorted within each column, no duplicates. Each back-end reads what it
// needs directly from that storage ("mumps" keeps its own 1-based copy of one triangle's indices).
// "cholmod", "eigen-ldlt" and "mumps" read one triangle and therefore assume symmetric values;
// "klu" factors the full storage and also works for non-symmetric matrices (e.g. ida-bdf's Schur complement
// with jacobian=fd-inertia, or unsymmetric load tangents in statics).
//   - "cholmod":    CHOLMOD (cholmod_l_*), upper triangle (stype = +1), AMD ordering, supernodal LLᵀ.
//                   The triangular solves of a supernodal factor run shelldyn's own kernels on a copy of it
//                   (lib/linalg/single_precision_factor.hpp): an exact one, or a float one with
//                   set_single_precision_solves below (docs/dependencies.md §5.5).
//                   If the matrix is not positive definite (CHOLMOD_NOT_POSDEF), the solver switches
//                   PERMANENTLY to simplicial LDLᵀ (re-analysis once; visible as an extra count in
//                   stats().analyses) and retries. Rationale: a tangent that was indefinite once
//                   (buckling, snap-through) tends to stay near-indefinite, and flip-flopping would
//                   re-analyse every time. LDLᵀ has no pivoting (docs/dependencies.md §5.3): a zero pivot or a
//                   non-finite factor throws. Supernodal speed depends on BLAS; with OpenBLAS set
//                   OPENBLAS_NUM_THREADS=1 on small shared machines (docs/dependencies.md §1.1).
//   - "eigen-ldlt": Eigen::SimplicialLDLT on an Eigen::Map of the arrays, lower triangle, AMD.
//                   LDLᵀ without pivoting: works on mildly indefinite matrices, throws on breakdown.
//   - "klu":        KLU (klu_l_*), LU with partial pivoting, AMD ordering (ordering = 0, never the
//                   COLAMD default, docs/dependencies.md §5.4). First factorization klu_l_factor, then
//                   klu_l_refactor (reuses the pivot order); when the reciprocal pivot growth
//                   estimate klu_l_rcond drops below eps^(2/3) a fresh klu_l_factor re-pivots
//                   (same threshold as SUNDIALS' own KLU module, docs/dependencies.md §3.2). Handles indefinite
//                   matrices; slower than the other two on shell patterns.
//   - "mumps":      sequential MUMPS 5.5 (dmumps_c, loaded with dlopen: docs/dependencies.md §2.4), SYM = 2:
//                   multifrontal LDLᵀ with threshold pivoting (1×1 and 2×2), so indefinite matrices are
//                   factorized stably; upper triangle in 1-based coordinates built once per pattern, AMD
//                   ordering, pattern-only analysis. Inertia from INFOG(12); null-pivot detection
//                   (ICNTL(24)) names the column of a singular matrix. No output (ICNTL(1..4)), BLAS on one
//                   thread. Slower than "cholmod" on the project's K̄ (docs/dependencies.md §5.2).
//
// Errors: bad input (wrong size, unsorted pattern, non-finite values, pattern different from the
// analysed one) -> std::invalid_argument; singular / not positive definite / breakdown ->
// std::runtime_error naming the back-end, the reason and the column where the library reports one.
// After a failed factorize() the solver has no valid factorization: solve() throws until the next
// successful factorize().
//
// Not thread-safe: solve() is const but uses internal work buffers and updates stats().
#pragma once

#include "lib/linalg/sparse_matrix.hpp"

#include <memory>
#include <string>
#include <vector>

namespace shelldyn {

class LinearSolver {
 public:
  virtual ~LinearSolver() = default;

  // Registered name ("cholmod", "eigen-ldlt", "klu", "mumps").
  virtual std::string name() const = 0;

  // Fill-reducing ordering + symbolic analysis. Call once per pattern; calling it again with a
  // new pattern is allowed (e.g. after remeshing) and discards the previous factorization.
  virtual void analyze(const CscView& A) = 0;

  // Numeric factorization of A on the analysed pattern (same n and nnz; the caller guarantees the
  // same colptr/rowind, the SUNDIALS adapter checks it). Analyses first if analyze() was never
  // called.
  virtual void factorize(const CscView& A) = 0;

  // x = A⁻¹ b with the last factorization; b and x have length n. x may alias b (x == b gives an
  // in-place solve); partial overlap is not allowed.
  virtual void solve(const double* b, double* x) const = 0;

  // True after a successful factorize() (and until the next analyze() or failed factorize()).
  virtual bool factorized() const = 0;

  // Inertia of the last factorization: the number of negative pivots of A = P L D Lᵀ Pᵀ, which by
  // Sylvester's law equals the number of negative eigenvalues of A (used for Sturm-sequence counts in
  // modal analysis and for limit/bifurcation detection in path following). -1 when the back-end
  // cannot tell (KLU's LU pivots are not an inertia). Requires factorized().
  virtual long negative_pivots() const { return -1; }

  // Mixed precision (docs/dependencies.md §5.5): on = do the triangular solves with a single-precision copy of
  // the factor (made at each factorize()), which halves the memory traffic of a solve; the factorization and
  // all arithmetic stay double, but a solve is then accurate to ~1e-7·cond(A) only: meant for modified Newton,
  // whose kept matrix is an approximation anyway. Returns false (and keeps double solves) where the back-end
  // cannot: only "cholmod" can, and only while its factor is supernodal LLᵀ and fits in float (after a fallback to
  // simplicial LDLᵀ, or with entries beyond ~3.4e38, its solves are double; stats().single_solves counts the
  // solves really done in single).
  virtual bool set_single_precision_solves(bool on) { return !on; }

  // Counters and process-independent wall times (std::chrono::steady_clock) in seconds.
  struct Stats {
    long analyses = 0, factorizations = 0, solves = 0;
    long single_solves = 0;  // of solves, those done with a single-precision factor
    double analyze_s = 0, factorize_s = 0, solve_s = 0;
  };
  const Stats& stats() const { return stats_; }

 protected:
  mutable Stats stats_;
};

// "cholmod" | "eigen-ldlt" | "klu" | "mumps"; anything else throws std::invalid_argument listing valid names.
std::unique_ptr<LinearSolver> make_linear_solver(const std::string& name);
std::vector<std::string> linear_solver_names();
// True if make_linear_solver(name) knows the name (lets callers validate settings before building a solver).
bool is_linear_solver_name(const std::string& name);

// An integrator's `solve_precision` setting: "double" -> false, "single" -> true (LinearSolver::
// set_single_precision_solves). Throws std::invalid_argument naming `who` for any other value, and for "single"
// with a back-end that cannot do it (only "cholmod" can).
bool single_precision_setting(const std::string& value, const std::string& linear_solver, const std::string& who);

// The BLAS the sparse factorizations run on, for run.json: with OpenBLAS its build configuration and the kernel
// set it chose for this CPU at load time, e.g. "OpenBLAS 0.3.21 NO_LAPACKE DYNAMIC_ARCH NO_AFFINITY Prescott
// MAX_THREADS=64". The kernels set the summation order inside CHOLMOD's supernodal factorization,
// so two machines whose cores differ give results that differ at round-off (docs/dependencies.md §5.6).
// "unknown (not OpenBLAS)" when the loaded BLAS is another one.
std::string blas_description();

// Structural checks shared by the back-ends (and useful to callers): n > 0, colptr[0] == 0,
// non-decreasing colptr, row indices in [0, n) and strictly increasing within each column.
// Throws std::invalid_argument naming `who`, the column and the problem.
void check_csc_pattern(const CscView& A, const std::string& who);

}  // namespace shelldyn
