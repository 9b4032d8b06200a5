// Newton solver for F(u) = 0 with a sparse symmetric Jacobian on a fixed pattern: KINSOL (SUNDIALS
// 6.4.1) does the Newton iterations, the linear systems go through a shelldyn::LinearSolver wrapped
// as a custom SUNLinearSolver (integrators/sundials/sun_linear_solver.hpp). Used by every implicit scheme of
// the project, in particular the energy-momentum generalized-α scheme (docs/theory.md §6).
//
// HOW THE ITERATION IS DRIVEN (design decision)
// ---------------------------------------------
// KINSOL has no user stopping test, but the integrators need one: a minimum iteration count and the
// paper's energy criterion (docs/theory.md §6.5, paper eq. 39)
//     E_k = |Δu^(k+1) · F(u_k)|,  cc = E_k / E_0,  converged when cc ≤ energy_tol.
// So solve() runs KINSol with KINSetNumMaxIters(1) in a loop it controls: every KINSol call performs
// exactly one Newton iteration (Jacobian setup, linear solve, optional line search, update, F at the
// new iterate, KINSOL's own tests); between calls this wrapper reads the correction du, evaluates
// the energy criterion, calls the user hook and decides whether to stop. Consequences:
//   - KINSOL remains the Newton solver (same steps, same tests, same line search).
//   - A per-call KIN_MAXITER_REACHED means "iteration done, KINSOL's tests not met" and is not an
//     error; only the overall max_iters produces a failure (reported as KIN_MAXITER_REACHED).
//   - Each KINSol call starts by evaluating F at its initial iterate. A one-entry cache (bitwise
//     compare of u) returns the value computed at the end of the previous call, so residual_evals
//     counts only real evaluations: one per iteration plus one at the start (plus line-search trials).
//   - Jacobian refresh is controlled per call with KINSetNoInitSetup: full Newton refreshes at every
//     iteration; modified Newton refreshes every max_setup_calls iterations, counted ACROSS solve()
//     calls, so a factorization is reused over several steps. KINSOL may still refresh by itself
//     when a line search fails with a stale Jacobian (its own retry logic).
//   - The symbolic analysis happens once per NewtonSolver lifetime: the pattern is refilled
//     identically before each setup (KINSOL zeroes the SUNSparseMatrix, docs/dependencies.md §3.2 pitfall 2)
//     and the custom SUNLinearSolver only re-analyses when the pattern changes.
//
// STOPPING TESTS (StopTest) and how they relate
// ---------------------------------------------
//   fnorm:            KINSOL's tests: ‖fscale·F(u_k)‖∞ ≤ fnorm_tol (KIN_SUCCESS), or scaled step
//                     ‖uscale·Δu‖∞ ≤ step_tol (KIN_STEP_LT_STPTOL), or the initial iterate already
//                     has ‖fscale·F‖∞ ≤ 0.01·fnorm_tol (KIN_INITIAL_GUESS_OK).
//   energy:           cc ≤ energy_tol only; KINSOL's tolerance is set to the smallest positive
//                     double so that KINSOL never stops on its own.
//   fnorm_or_energy:  whichever holds first.
//   fnorm_and_energy: both must hold at the same iterate.
// With the energy test, E_0 = |Δu^(1)·F(u_0)|; if E_0 ≤ energy_floor (e.g. a coasting body with zero
// load, §6.5) cc is taken as 0, i.e. the state after the first min_iters iterations is accepted.
// Additionally the hook may return true ("accept now"), which stops with success as well.
// No test is honoured before min_iters iterations have been done (KINSOL is forced to iterate then).
// Since cc is a work-like quantity it converges like |du|²: with full Newton cc ≈ 1e-6 usually needs
// one iteration less than fnorm ≈ 1e-10.
//
// ERRORS. solve() never throws for a failing Newton solve. Result.converged = false with a message
// when: KINSOL returns a negative flag (its name from KINGetReturnFlagName and the last ‖F‖ are in
// the message), the residual / Jacobian / hook callback throws (e.g. the director overshoot guard
// of docs/theory.md §2.1; the exception's message is in Result.message), the residual returns a
// non-finite value, or the linear solver fails (its message is included). On failure u holds the
// last iterate KINSOL accepted. Bad arguments (options out of range, null pattern) throw
// std::invalid_argument from the constructor.
#pragma once

#include "lib/linalg/linear_solver.hpp"
#include "lib/linalg/sparse_matrix.hpp"

#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace shelldyn {

enum class StopTest { fnorm, energy, fnorm_or_energy, fnorm_and_energy };

struct NewtonOptions {
  int max_iters = 25;      // Newton iterations per solve() (>= 1)
  int min_iters = 1;       // no stopping test is honoured before this many iterations (>= 0)
  bool modified = false;   // modified Newton: keep the factorization across iterations and calls
  int max_setup_calls = 10;  // modified Newton: refresh the Jacobian every this many iterations
  double fnorm_tol = 1e-10;  // KINSetFuncNormTol: ‖fscale·F‖∞ (max norm!), scale F physically
  double step_tol = 1e-14;   // KINSetScaledStepTol: ‖uscale·Δu‖∞
  bool line_search = false;  // KIN_LINESEARCH instead of KIN_NONE
  std::string linear_solver = "eigen-ldlt";  // make_linear_solver() name
  // Triangular solves with a single-precision copy of the factor (LinearSolver::set_single_precision_solves,
  // docs/dependencies.md §5.5): "cholmod" only (the constructor throws for the others). Meant for modified
  // Newton: the converged iterate is still set by the double-precision residual.
  bool single_precision_solves = false;
  double max_newton_step = 1e30;  // KINSetMaxNewtonStep; large: the default is 1 when u0 = 0
  StopTest stop = StopTest::fnorm;
  double energy_tol = 1e-6;    // cc threshold of the energy test (paper: 1e-6)
  double energy_floor = 0.0;   // E_0 at or below this -> cc = 0 (absolute floor, §6.5)
  // Modified Newton only: refresh by observed contraction (0 = off, refresh by max_setup_calls only).
  // After an iteration whose scaled correction ‖uscale·Δu_k‖₂ did not shrink below refresh_contraction
  // times the previous one (θ_k = ‖Δu_k‖/‖Δu_{k−1}‖ > refresh_contraction, measured within one solve()),
  // the next iteration refreshes the Jacobian. With a factorization that is still good θ stays small
  // (e.g. 1e-3 on a mass-dominated K̄) and the factorization is kept over many steps; it grows as the
  // tangent drifts away, and is observed rather than guessed by a fixed count. Corrections at round-off
  // (‖uscale·Δu‖₂ ≤ 1e3 ε max(1, ‖uscale·u‖₂)) never trigger a refresh: their ratio is noise.
  double refresh_contraction = 0.0;
  // Skip the residual at an iterate that the energy test or the hook accepts (no line search only). Both
  // tests read Δu_k and F(u_{k−1}), which are known before F(u_k); KINSOL evaluates F(u_k) inside the
  // iteration for its own tests, so the wrapper runs the energy test and the hook from the residual
  // callback at the new iterate first and, if they accept, hands KINSOL F = 0 instead of evaluating it
  // (KINSOL's state is discarded; the next solve() starts afresh). The iterates are the same as without
  // it; one residual per solve() fewer. Result.fnorm is then that of F(u_{k−1}) (fnorm_at_u = false).
  bool skip_final_residual = false;
};

class NewtonSolver {
 public:
  using Residual = std::function<void(const double* u, double* f)>;         // may throw
  using Jacobian = std::function<void(const double* u, SparseMatrix& J)>;  // fill J.values (fixed pattern)

  // Called once per Newton iteration k = 1, 2, ... (cumulative KINSOL iteration count) with
  //   u  = the new iterate u_k,   du = u_k − u_{k−1} (the applied correction, λ·p with line search),
  //   f  = F(u_{k−1}), the residual the correction was computed from.
  // So |du·f| is E_{k−1} of the energy criterion. Accepts callables returning void (observer) or
  // bool (true = accept u_k now, a user stopping test; honoured only once k >= min_iters).
  // May throw: solve() then fails with the exception's message.
  class IterationHook {
   public:
    IterationHook() = default;
    template <class F, class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, IterationHook>>,
              class R = std::invoke_result_t<F&, int, const double*, const double*, const double*>>
    IterationHook(F f) {  // NOLINT: implicit on purpose, lambdas convert directly
      if constexpr (std::is_pointer_v<F> || is_std_function<F>::value) {
        if (!f) return;  // empty std::function / null pointer = no hook
      }
      if constexpr (std::is_void_v<R>) {
        fn_ = [f = std::move(f)](int k, const double* u, const double* du, const double* r) mutable {
          f(k, u, du, r);
          return false;
        };
      } else {
        static_assert(std::is_convertible_v<R, bool>, "iteration hook must return void or bool");
        fn_ = [f = std::move(f)](int k, const double* u, const double* du, const double* r) mutable {
          return static_cast<bool>(f(k, u, du, r));
        };
      }
    }
    explicit operator bool() const { return static_cast<bool>(fn_); }
    bool operator()(int k, const double* u, const double* du, const double* f) const { return fn_(k, u, du, f); }

   private:
    template <class T>
    struct is_std_function : std::false_type {};
    template <class Sig>
    struct is_std_function<std::function<Sig>> : std::true_type {};
    std::function<bool(int, const double*, const double*, const double*)> fn_;
  };

  enum class StopReason { none, fnorm, step, initial_guess, energy, hook, failure, max_iters };

  // Modified Newton across a change of unknowns (docs/theory.md §6.9): the kept Jacobian J₀ was formed in
  // unknowns u₀, and the current unknowns u relate to them by δu₀ = T δu with T block diagonal. The solves
  // then apply T⁻¹ J₀⁻¹ T⁻ᵀ, i.e. the kept matrix seen in the current unknowns, Tᵀ J₀ T, without a new
  // factorization. Each block gives T⁻¹ on the `size` (1..3) consecutive unknowns from `first`; blocks must
  // not overlap; unknowns in no block keep T = I. set_kept_basis_change() replaces the blocks; every Jacobian
  // setup clears them (a new matrix is formed in the current unknowns; the Jacobian callback may set them
  // again), and so does an empty vector.
  struct BasisBlock {
    Index first = 0;
    int size = 0;
    double inverse[9] = {};  // T⁻¹, row-major size × size in the top-left
  };
  void set_kept_basis_change(std::vector<BasisBlock> blocks);
  const std::vector<BasisBlock>& kept_basis_change() const;  // in use
  // Optional argument of solve(): called with the iterate u_k before every iteration that reuses the kept
  // Jacobian, it fills the blocks for that iteration (empty: none), or throws std::domain_error when the change
  // cannot be represented, which makes that iteration form a new Jacobian instead.
  using BasisProvider = std::function<void(const double* u, std::vector<BasisBlock>& blocks)>;

  struct Result {
    bool converged = false;
    int iterations = 0;      // KINSOL nonlinear iterations in this solve()
    int residual_evals = 0;  // real calls of the Residual (cache hits not counted)
    int jacobian_evals = 0;  // calls of the Jacobian = linear-solver setups
    int factorizations = 0;  // numeric factorizations done by the linear solver in this solve()
    double contraction = 0;  // last observed θ_k = ‖uscale·Δu_k‖₂/‖uscale·Δu_{k−1}‖₂ (0 before k = 2)
    double fnorm = 0;        // ‖fscale·F(u)‖∞ at the returned u (NaN if F failed there)
    bool fnorm_at_u = true;  // false: skip_final_residual accepted u unevaluated; fnorm is F(u_{k−1})'s
    double energy_ratio = 1;  // last cc = E_{k-1}/E_0 (1 before the second iteration)
    int kinsol_flag = 0;     // flag of the last KINSol call (see header comment)
    StopReason stop_reason = StopReason::none;
    std::string message;     // empty on success unless informative
  };

  // `pattern`: the fixed Jacobian pattern (full symmetric CSC). Creates the SUNContext, KINSOL and
  // the linear solver (named in options.linear_solver). Throws std::invalid_argument on bad options.
  NewtonSolver(std::shared_ptr<const SparsePattern> pattern, NewtonOptions options = {});
  ~NewtonSolver();
  NewtonSolver(NewtonSolver&&) noexcept;
  NewtonSolver& operator=(NewtonSolver&&) noexcept;

  // Solves F(u) = 0 starting from u (length n, overwritten with the result). fscale/uscale:
  // optional positive scaling vectors (length n), default all ones.
  Result solve(double* u, const Residual& residual, const Jacobian& jacobian,
               const double* fscale = nullptr, const double* uscale = nullptr,
               const IterationHook& hook = {}, const BasisProvider& basis = {});

  // Forces a Jacobian refresh at the next iteration (modified Newton: call it when the iteration
  // matrix changes for reasons the solver cannot see, e.g. a new time step size in K̄).
  void invalidate_jacobian();

  // Checkpoint/restart of modified Newton (integrators/checkpoint/): iterations done with the current
  // Jacobian, or -1 when the next iteration refreshes it anyway. resume_after_setup(k): after the next
  // Jacobian setup continue counting from k instead of 0, so that a restored solver (whose first setup
  // replays the saved matrix) refreshes at the same iterations as the solver that was saved.
  int iterations_since_setup() const;
  void resume_after_setup(int k);

  const NewtonOptions& options() const;
  const LinearSolver& linear_solver() const;  // stats(): analyses stay at 1 for a fixed pattern

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

std::string to_string(NewtonSolver::StopReason reason);

}  // namespace shelldyn
