// KINSOL-driven Newton solver; the design (one KINSol call per iteration, residual cache, setup
// control, stopping tests) is explained in the header.
#include "integrators/nonlinear/newton_solver.hpp"

#include "integrators/sundials/sun_linear_solver.hpp"
#include "integrators/sundials/sundials_support.hpp"

#include <kinsol/kinsol.h>
#include <kinsol/kinsol_ls.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace shelldyn {

std::string to_string(NewtonSolver::StopReason r) {
  switch (r) {
    case NewtonSolver::StopReason::none: return "none";
    case NewtonSolver::StopReason::fnorm: return "fnorm";
    case NewtonSolver::StopReason::step: return "step";
    case NewtonSolver::StopReason::initial_guess: return "initial_guess";
    case NewtonSolver::StopReason::energy: return "energy";
    case NewtonSolver::StopReason::hook: return "hook";
    case NewtonSolver::StopReason::failure: return "failure";
    case NewtonSolver::StopReason::max_iters: return "max_iters";
  }
  return "?";
}

namespace {

void check_kin(int flag, const char* call) { check_flag(flag, call, KINGetReturnFlagName); }

void validate(const NewtonOptions& o) {
  auto bad = [](const std::string& what) {
    throw std::invalid_argument("NewtonOptions: " + what);
  };
  if (o.max_iters < 1) bad("max_iters must be >= 1, got " + std::to_string(o.max_iters));
  if (o.min_iters < 0 || o.min_iters > o.max_iters)
    bad("min_iters must be in [0, max_iters = " + std::to_string(o.max_iters) + "], got " +
        std::to_string(o.min_iters));
  if (o.max_setup_calls < 1) bad("max_setup_calls must be >= 1, got " + std::to_string(o.max_setup_calls));
  if (!(o.fnorm_tol > 0)) bad("fnorm_tol must be > 0, got " + std::to_string(o.fnorm_tol));
  if (!(o.step_tol >= 0)) bad("step_tol must be >= 0, got " + std::to_string(o.step_tol));
  if (!(o.max_newton_step > 0)) bad("max_newton_step must be > 0");
  if (o.stop != StopTest::fnorm && !(o.energy_tol > 0))
    bad("energy_tol must be > 0 when the energy test is used, got " + std::to_string(o.energy_tol));
  if (!(o.energy_floor >= 0)) bad("energy_floor must be >= 0");
  if (!(o.refresh_contraction >= 0) || !std::isfinite(o.refresh_contraction))
    bad("refresh_contraction must be >= 0 (0 = off), got " + std::to_string(o.refresh_contraction));
  if (!is_linear_solver_name(o.linear_solver)) make_linear_solver(o.linear_solver);  // throws with the valid names
}

// The linear solver seen through a change of unknowns (NewtonSolver::set_kept_basis_change): x = T⁻¹ A⁻¹ T⁻ᵀ b
// with A the inner solver's factorized matrix. With no blocks the inner solve runs on b and x directly
// (bitwise the inner solver's).
class BasisChangeSolver final : public LinearSolver {
 public:
  BasisChangeSolver(std::unique_ptr<LinearSolver> inner, const std::vector<NewtonSolver::BasisBlock>* blocks, Index n)
      : inner_(std::move(inner)), blocks_(blocks), n_(n) {}
  std::string name() const override { return inner_->name(); }
  void analyze(const CscView& A) override {
    inner_->analyze(A);
    stats_ = inner_->stats();
  }
  void factorize(const CscView& A) override {
    inner_->factorize(A);
    stats_ = inner_->stats();
  }
  void solve(const double* b, double* x) const override {
    if (blocks_->empty()) {
      inner_->solve(b, x);
    } else {
      work_.assign(b, b + n_);
      for (const auto& bl : *blocks_) apply(bl, true, work_.data());  // T⁻ᵀ b
      inner_->solve(work_.data(), x);
      for (const auto& bl : *blocks_) apply(bl, false, x);  // T⁻¹ x
    }
    stats_ = inner_->stats();
  }
  bool factorized() const override { return inner_->factorized(); }
  long negative_pivots() const override { return inner_->negative_pivots(); }
  bool set_single_precision_solves(bool on) override { return inner_->set_single_precision_solves(on); }

 private:
  // v ← T⁻¹ v (transposed: T⁻ᵀ v) on the block's unknowns.
  static void apply(const NewtonSolver::BasisBlock& bl, bool transposed, double* v) {
    double y[3];
    for (int i = 0; i < bl.size; ++i) {
      y[i] = 0.0;
      for (int j = 0; j < bl.size; ++j) y[i] += (transposed ? bl.inverse[3 * j + i] : bl.inverse[3 * i + j]) * v[bl.first + j];
    }
    for (int i = 0; i < bl.size; ++i) v[bl.first + i] = y[i];
  }

  std::unique_ptr<LinearSolver> inner_;
  const std::vector<NewtonSolver::BasisBlock>* blocks_;
  Index n_;  // unknowns
  mutable std::vector<double> work_;
};

}  // namespace

struct NewtonSolver::Impl {
  // Declaration order = construction order; SUNDIALS objects are destroyed before the context.
  std::shared_ptr<const SparsePattern> pattern;
  NewtonOptions opt;
  SunContext ctx;
  Index n = 0;
  NVectorPtr u, uscale, fscale;
  SunMatrixPtr J;
  SunLinearSolverPtr LS;
  void* kin = nullptr;
  std::string kinsol_msg;  // last message of KINSOL's error handler
  SparseMatrix Jwork;      // what the user's Jacobian fills

  // Per-solve state, read by the C callbacks.
  const Residual* residual = nullptr;
  const Jacobian* jacobian = nullptr;
  CallbackError cb_error;
  std::vector<double> cache_u, cache_f, f_start, u_prev, du;
  bool cache_valid = false, first_eval_in_call = false;
  int residual_evals = 0, jacobian_evals = 0;
  // skip_final_residual: the stopping tests run at the new iterate before F is evaluated there.
  std::function<bool(const double* u_new)> early_test;
  bool early_accepted = false;

  // Modified Newton bookkeeping (across solve() calls).
  bool have_jacobian = false, force_setup = false;
  int since_setup = 0;
  int resume_since_setup = -1;  // checkpoint restart: since_setup after the next setup (-1: 0)
  std::vector<BasisBlock> basis;  // set_kept_basis_change(); cleared at every Jacobian setup
  std::vector<BasisBlock> basis_work;  // filled by solve()'s BasisProvider

  ~Impl() {
    if (kin) KINFree(&kin);
  }

  static int residual_cb(N_Vector uu, N_Vector ff, void* user_data) {
    auto* s = static_cast<Impl*>(user_data);
    try {
      const double* up = N_VGetArrayPointer(uu);
      double* fp = N_VGetArrayPointer(ff);
      const size_t bytes = sizeof(double) * static_cast<size_t>(s->n);
      if (s->early_test && !s->first_eval_in_call) {  // F at the call's new iterate (header: skip_final_residual)
        bool accept = false;
        try {
          accept = s->early_test(up);
        } catch (...) {
          s->cb_error.capture("iteration hook");
          return -1;
        }
        if (accept) {
          s->early_accepted = true;
          std::fill(fp, fp + s->n, 0.0);  // KINSOL stops on it; the wrapper returns u as accepted
          return 0;
        }
      }
      if (s->cache_valid && std::memcmp(up, s->cache_u.data(), bytes) == 0) {
        std::memcpy(fp, s->cache_f.data(), bytes);
      } else {
        ++s->residual_evals;
        (*s->residual)(up, fp);
        for (Index i = 0; i < s->n; ++i)
          if (!std::isfinite(fp[i]))
            throw std::runtime_error("residual component " + std::to_string(i) + " is " +
                                     std::to_string(fp[i]));
        std::memcpy(s->cache_u.data(), up, bytes);
        std::memcpy(s->cache_f.data(), fp, bytes);
        s->cache_valid = true;
      }
      if (s->first_eval_in_call) {  // KINSolInit's evaluation at the call's initial iterate
        std::memcpy(s->f_start.data(), fp, bytes);
        s->first_eval_in_call = false;
      }
      return 0;
    } catch (...) {
      s->cb_error.capture("residual callback");
      return -1;  // unrecoverable: KINSOL stops with KIN_SYSFUNC_FAIL / KIN_FIRST_SYSFUNC_ERR
    }
  }

  static int jacobian_cb(N_Vector uu, N_Vector, SUNMatrix Jm, void* user_data, N_Vector, N_Vector) {
    auto* s = static_cast<Impl*>(user_data);
    try {
      ++s->jacobian_evals;
      s->basis.clear();  // the new matrix is formed in the current unknowns (the callback may set a change again)
      (*s->jacobian)(N_VGetArrayPointer(uu), s->Jwork);
      if (s->Jwork.pattern != s->pattern || static_cast<Index>(s->Jwork.values.size()) != s->pattern->nnz())
        throw std::invalid_argument(
            "the Jacobian callback changed the matrix pattern or the size of its value array; fill "
            "J.values only");
      // KINSOL zeroed Jm including its structure: refill everything (docs/dependencies.md §3.2 pitfall 2).
      copy_to_sun_matrix(s->Jwork, Jm);
      return 0;
    } catch (...) {
      s->cb_error.capture("Jacobian callback");
      return -1;  // KINSOL reports KIN_LSETUP_FAIL
    }
  }

  double fnorm_inf(const double* f, const double* scale) const {
    double m = 0;
    for (Index i = 0; i < n; ++i) m = std::max(m, std::abs(scale[i] * f[i]));
    return m;
  }
};

NewtonSolver::NewtonSolver(std::shared_ptr<const SparsePattern> pattern, NewtonOptions options)
    : impl_(std::make_unique<Impl>()) {
  if (!pattern) throw std::invalid_argument("NewtonSolver: null sparsity pattern");
  validate(options);
  check_csc_pattern({pattern->n, pattern->colptr.data(), pattern->rowind.data(), nullptr},
                    "NewtonSolver pattern");
  Impl& s = *impl_;
  s.pattern = pattern;
  s.opt = std::move(options);
  s.n = pattern->n;
  s.u = make_serial_vector(s.n, s.ctx);
  s.uscale = make_serial_vector(s.n, s.ctx);
  s.fscale = make_serial_vector(s.n, s.ctx);
  // KINSOL's per-iteration norms and updates on vectorized loops (before KINInit clones its work vectors from u).
  for (N_Vector v : {s.u.get(), s.uscale.get(), s.fscale.get()}) use_vectorized_ops(v);
  s.J = make_csc_matrix(*pattern, s.ctx);
  {
    auto ls = make_linear_solver(s.opt.linear_solver);
    if (s.opt.single_precision_solves && !ls->set_single_precision_solves(true))
      throw std::invalid_argument("NewtonSolver: linear_solver '" + s.opt.linear_solver +
                                  "' has no single-precision solves (docs/dependencies.md §5.5); use cholmod, "
                                  "or double solves");
    s.LS.reset(make_sun_linear_solver(s.ctx, std::make_unique<BasisChangeSolver>(std::move(ls), &s.basis, s.n)));
  }
  s.Jwork.pattern = pattern;
  s.Jwork.values.assign(pattern->nnz(), 0.0);
  for (auto* v : {&s.cache_u, &s.cache_f, &s.f_start, &s.u_prev, &s.du}) v->assign(s.n, 0.0);

  s.kin = KINCreate(s.ctx);
  check_ptr(s.kin, "KINCreate");
  check_kin(KINSetErrHandlerFn(s.kin, record_sundials_error, &s.kinsol_msg), "KINSetErrHandlerFn");
  check_kin(KINInit(s.kin, Impl::residual_cb, s.u.get()), "KINInit");
  check_kin(KINSetUserData(s.kin, &s), "KINSetUserData");
  check_kin(KINSetLinearSolver(s.kin, s.LS.get(), s.J.get()), "KINSetLinearSolver");
  check_kin(KINSetJacFn(s.kin, Impl::jacobian_cb), "KINSetJacFn");
  // One Newton iteration per KINSol call (header). msbset >= 2 so that KINSOL itself never triggers
  // a setup inside the call; setups are requested per call through KINSetNoInitSetup.
  check_kin(KINSetNumMaxIters(s.kin, 1), "KINSetNumMaxIters");
  check_kin(KINSetMaxSetupCalls(s.kin, 10), "KINSetMaxSetupCalls");
  check_kin(KINSetNoResMon(s.kin, SUNTRUE), "KINSetNoResMon");
  check_kin(KINSetMaxNewtonStep(s.kin, s.opt.max_newton_step), "KINSetMaxNewtonStep");
  // KINSetScaledStepTol treats 0 as "default" (≈ 3.7e-11): use the smallest positive value instead.
  check_kin(KINSetScaledStepTol(s.kin, s.opt.step_tol > 0 ? s.opt.step_tol
                                                          : std::numeric_limits<double>::min()),
            "KINSetScaledStepTol");
}

NewtonSolver::~NewtonSolver() = default;
NewtonSolver::NewtonSolver(NewtonSolver&&) noexcept = default;
NewtonSolver& NewtonSolver::operator=(NewtonSolver&&) noexcept = default;

const NewtonOptions& NewtonSolver::options() const { return impl_->opt; }
const LinearSolver& NewtonSolver::linear_solver() const { return sun_linear_solver_backend(impl_->LS.get()); }
void NewtonSolver::invalidate_jacobian() { impl_->force_setup = true; }
int NewtonSolver::iterations_since_setup() const {
  const Impl& s = *impl_;
  // A Jacobian that has served max_setup_calls iterations is refreshed at the next one: nothing to resume.
  return s.have_jacobian && !s.force_setup && s.since_setup < s.opt.max_setup_calls ? s.since_setup : -1;
}
void NewtonSolver::resume_after_setup(int k) { impl_->resume_since_setup = k; }
void NewtonSolver::set_kept_basis_change(std::vector<BasisBlock> blocks) {
  if (blocks.empty()) {
    impl_->basis.clear();
    return;
  }
  std::vector<char> used(static_cast<size_t>(impl_->n), 0);
  for (const BasisBlock& b : blocks) {
    if (b.size < 1 || b.size > 3 || b.first < 0 || b.first + b.size > impl_->n)
      throw std::invalid_argument("NewtonSolver::set_kept_basis_change: block at " + std::to_string(b.first) +
                                  " of size " + std::to_string(b.size) + " is outside the " +
                                  std::to_string(impl_->n) + " unknowns");
    for (int i = 0; i < b.size; ++i) {
      if (used[static_cast<size_t>(b.first + i)]++)
        throw std::invalid_argument("NewtonSolver::set_kept_basis_change: blocks overlap at unknown " +
                                    std::to_string(b.first + i));
      for (int j = 0; j < b.size; ++j)
        if (!std::isfinite(b.inverse[3 * i + j]))
          throw std::invalid_argument("NewtonSolver::set_kept_basis_change: non-finite entry in the block at " +
                                      std::to_string(b.first));
    }
  }
  impl_->basis = std::move(blocks);
}
const std::vector<NewtonSolver::BasisBlock>& NewtonSolver::kept_basis_change() const { return impl_->basis; }

NewtonSolver::Result NewtonSolver::solve(double* u, const Residual& residual, const Jacobian& jacobian,
                                         const double* fscale, const double* uscale,
                                         const IterationHook& hook, const BasisProvider& basis) {
  Impl& s = *impl_;
  const NewtonOptions& o = s.opt;
  if (u == nullptr) throw std::invalid_argument("NewtonSolver::solve: u is null");
  if (!residual || !jacobian)
    throw std::invalid_argument("NewtonSolver::solve: residual and Jacobian callbacks are required");
  const Index n = s.n;
  double* uu = data(s.u.get());
  std::copy(u, u + n, uu);
  double* fs = data(s.fscale.get());
  double* us = data(s.uscale.get());
  for (Index i = 0; i < n; ++i) {
    fs[i] = fscale ? fscale[i] : 1.0;
    us[i] = uscale ? uscale[i] : 1.0;
    if (!(fs[i] > 0) || !(us[i] > 0) || !std::isfinite(fs[i]) || !std::isfinite(us[i]))
      throw std::invalid_argument("NewtonSolver::solve: scaling vectors must be positive and finite (index " +
                                  std::to_string(i) + ")");
  }

  s.residual = &residual;
  s.jacobian = &jacobian;
  s.cb_error.clear();
  s.kinsol_msg.clear();
  s.cache_valid = false;  // F may differ from the previous solve (new time step)
  s.residual_evals = s.jacobian_evals = 0;
  const long factorizations0 = linear_solver().stats().factorizations;

  const bool fnorm_test = o.stop != StopTest::energy;
  const bool energy_test = o.stop != StopTest::fnorm;
  const double tiny = std::numeric_limits<double>::min();
  const int strategy = o.line_search ? KIN_LINESEARCH : KIN_NONE;

  Result r;
  double E0 = 0;
  double du_norm_prev = 0;  // ‖uscale·Δu_{k−1}‖₂ (contraction-based refresh)
  bool energy_ok = false;  // energy test at the current iterate
  int k = 0;               // iterations done

  // skip_final_residual (header): the energy test and the hook at the new iterate u_{k+1}, from Δu and
  // F(u_k), with the arithmetic of the tests after the call (so they agree bitwise).
  bool early_hook_called = false, early_hook_value = false;
  s.early_accepted = false;
  s.early_test = nullptr;
  if (o.skip_final_residual && !o.line_search)
    s.early_test = [&](const double* unew) {
      if (k + 1 < o.min_iters) return false;
      double E = 0;
      for (Index i = 0; i < n; ++i) {
        s.du[i] = unew[i] - s.u_prev[i];
        E += s.du[i] * s.f_start[i];
      }
      E = std::abs(E);
      const bool first = (k == 0);
      const double e0 = first ? E : E0;
      const double ratio = (e0 <= o.energy_floor) ? 0.0 : E / e0;
      const bool eok = energy_test && ratio <= o.energy_tol && (!first || e0 <= o.energy_floor);
      if (eok && (o.stop == StopTest::energy || o.stop == StopTest::fnorm_or_energy)) return true;
      if (!hook) return false;
      early_hook_called = true;
      early_hook_value = hook(k + 1, unew, s.du.data(), s.f_start.data());
      return early_hook_value;
    };

  auto finish = [&](bool converged, StopReason why, int flag, std::string msg) {
    r.converged = converged;
    r.stop_reason = why;
    r.kinsol_flag = flag;
    r.iterations = k;
    r.residual_evals = s.residual_evals;
    r.jacobian_evals = s.jacobian_evals;
    r.factorizations = static_cast<int>(linear_solver().stats().factorizations - factorizations0);
    r.fnorm_at_u = true;
    if (s.cache_valid && std::memcmp(s.cache_u.data(), uu, sizeof(double) * n) == 0) {
      r.fnorm = s.fnorm_inf(s.cache_f.data(), fs);
    } else if (s.early_accepted && converged) {  // u accepted before F(u) was evaluated
      r.fnorm = s.fnorm_inf(s.f_start.data(), fs);
      r.fnorm_at_u = false;
    } else {
      r.fnorm = std::numeric_limits<double>::quiet_NaN();  // F never evaluated at u (early failure)
    }
    s.early_test = nullptr;
    s.early_accepted = false;
    r.message = std::move(msg);
    if (!converged) s.force_setup = true;  // do not reuse a Jacobian that just failed
    std::copy(uu, uu + n, u);
    s.residual = nullptr;
    s.jacobian = nullptr;
    return r;
  };
  auto failure_message = [&](int flag) {
    std::ostringstream os;
    if (s.cb_error.has_error()) os << s.cb_error.message() << "; ";
    const std::string& ls = sun_linear_solver_last_error(s.LS.get());
    if (!ls.empty()) os << ls << "; ";
    os << "KINSol returned " << flag_name(KINGetReturnFlagName, flag) << " (" << flag << ") after "
       << k << " iteration(s)";
    double fn = 0;
    if (KINGetFuncNorm(s.kin, &fn) == KIN_SUCCESS) os << ", last scaled ||F||_2 = " << fn;
    if (!s.kinsol_msg.empty()) os << "; " << s.kinsol_msg;
    return os.str();
  };

  while (k < o.max_iters) {
    bool need_setup = !o.modified || !s.have_jacobian || s.force_setup || s.since_setup >= o.max_setup_calls;
    if (basis && !need_setup) {  // the kept Jacobian seen from u_k (docs/theory.md §6.9)
      try {
        basis(uu, s.basis_work);
        set_kept_basis_change(s.basis_work);
      } catch (const std::domain_error&) {
        s.basis.clear();
        s.force_setup = need_setup = true;
      } catch (...) {
        s.cb_error.capture("basis provider");
        return finish(false, StopReason::failure, 0, s.cb_error.message());
      }
    }
    check_kin(KINSetNoInitSetup(s.kin, need_setup ? SUNFALSE : SUNTRUE), "KINSetNoInitSetup");
    std::copy(uu, uu + n, s.u_prev.begin());
    const int jac0 = s.jacobian_evals;
    early_hook_called = false;

    // Before min_iters (or with the energy test alone) KINSOL must not stop on its own.
    bool forced = !fnorm_test || k < o.min_iters;
    int flag = 0;
    for (;;) {
      check_kin(KINSetFuncNormTol(s.kin, forced ? tiny : o.fnorm_tol), "KINSetFuncNormTol");
      s.first_eval_in_call = true;
      flag = KINSol(s.kin, s.u.get(), strategy, s.uscale.get(), s.fscale.get());
      if (flag != KIN_INITIAL_GUESS_OK || forced) break;
      // u_k already satisfies ‖F‖ ≤ 0.01 fnorm_tol: accept unless the energy test must also hold.
      if (o.stop != StopTest::fnorm_and_energy || energy_ok || k == 0) break;
      forced = true;  // make KINSOL iterate once more
    }
    if (s.cb_error.has_error() || (flag < 0 && flag != KIN_MAXITER_REACHED))
      return finish(false, StopReason::failure, flag, failure_message(flag));
    if (flag == KIN_INITIAL_GUESS_OK)  // no iteration in this call; F(u_k) is (numerically) zero
      return finish(true, StopReason::initial_guess, flag, {});

    long nni = 0;
    check_kin(KINGetNumNonlinSolvIters(s.kin, &nni), "KINGetNumNonlinSolvIters");
    const bool first_call = (k == 0);
    k += static_cast<int>(nni);
    if (s.jacobian_evals > jac0) {
      s.have_jacobian = true;
      s.force_setup = false;
      s.since_setup = s.resume_since_setup > 0 ? s.resume_since_setup : 0;
      s.resume_since_setup = -1;
    }
    s.since_setup += static_cast<int>(nni);

    // Energy criterion (docs/theory.md §6.5): E = |du · F(u_prev)|.
    double E = 0;
    for (Index i = 0; i < n; ++i) {
      s.du[i] = uu[i] - s.u_prev[i];
      E += s.du[i] * s.f_start[i];
    }
    E = std::abs(E);
    if (first_call) E0 = E;
    // Observed contraction of the (modified) Newton iteration; a poor one asks for a fresh Jacobian.
    double du_norm = 0;
    for (Index i = 0; i < n; ++i) du_norm += (us[i] * s.du[i]) * (us[i] * s.du[i]);
    du_norm = std::sqrt(du_norm);
    // At round-off (corrections below ~1e3 ε of the scaled iterate) θ is noise, not a verdict on K̄.
    double u_norm = 0;
    for (Index i = 0; i < n; ++i) u_norm += (us[i] * uu[i]) * (us[i] * uu[i]);
    const bool roundoff = du_norm <= 1e3 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::sqrt(u_norm));
    if (!first_call && du_norm_prev > 0) {
      r.contraction = du_norm / du_norm_prev;
      if (o.modified && o.refresh_contraction > 0 && r.contraction > o.refresh_contraction && !roundoff &&
          s.jacobian_evals == jac0)  // this iteration used a stale Jacobian
        s.force_setup = true;
    }
    du_norm_prev = du_norm;
    r.energy_ratio = (E0 <= o.energy_floor) ? 0.0 : E / E0;
    // cc = 1 by definition after the first iteration; only the floor can accept there.
    energy_ok = energy_test && r.energy_ratio <= o.energy_tol && (!first_call || E0 <= o.energy_floor);

    bool hook_accept = false;
    if (early_hook_called) {
      hook_accept = early_hook_value;  // already asked at this iterate from the residual callback
    } else if (hook) {
      try {
        hook_accept = hook(k, uu, s.du.data(), s.f_start.data());
      } catch (...) {
        s.cb_error.capture("iteration hook");
        return finish(false, StopReason::failure, flag, s.cb_error.message());
      }
    }
    if (s.early_accepted)  // F(u_k) was not evaluated (KINSOL saw F = 0): only these two tests may stop
      return finish(true,
                    energy_ok && (o.stop == StopTest::energy || o.stop == StopTest::fnorm_or_energy) ? StopReason::energy
                                                                                                    : StopReason::hook,
                    flag, {});
    if (k < o.min_iters) continue;

    const bool kinsol_ok = fnorm_test && (flag == KIN_SUCCESS || flag == KIN_STEP_LT_STPTOL);
    const StopReason kinsol_reason = flag == KIN_SUCCESS ? StopReason::fnorm : StopReason::step;
    switch (o.stop) {
      case StopTest::fnorm:
        if (kinsol_ok) return finish(true, kinsol_reason, flag, {});
        break;
      case StopTest::energy:
        if (energy_ok) return finish(true, StopReason::energy, flag, {});
        break;
      case StopTest::fnorm_or_energy:
        if (kinsol_ok) return finish(true, kinsol_reason, flag, {});
        if (energy_ok) return finish(true, StopReason::energy, flag, {});
        break;
      case StopTest::fnorm_and_energy:
        if (kinsol_ok && energy_ok) return finish(true, kinsol_reason, flag, {});
        break;
    }
    if (hook_accept) return finish(true, StopReason::hook, flag, {});
  }
  std::ostringstream os;
  os << "no convergence: KIN_MAXITER_REACHED after " << k << " iteration(s)";
  if (s.cache_valid) os << ", ||fscale*F||_inf = " << s.fnorm_inf(s.cache_f.data(), fs);
  if (energy_test) os << ", energy ratio cc = " << r.energy_ratio;
  return finish(false, StopReason::max_iters, KIN_MAXITER_REACHED, os.str());
}

}  // namespace shelldyn
