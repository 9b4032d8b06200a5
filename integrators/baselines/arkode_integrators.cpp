#include "integrators/baselines/arkode_integrators.hpp"

#include "integrators/baselines/second_order_newton.hpp"
#include "integrators/baselines/sundials_baseline.hpp"
#include "integrators/sundials/callback_linear_solver.hpp"
#include "integrators/sundials/sundials_support.hpp"
#include "lib/model/assembler.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>  // arkode_butcher.h uses FILE without including it (docs/dependencies.md §2.2)
#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_butcher_dirk.h>
#include <arkode/arkode_butcher_erk.h>

#include <chrono>
#include <cmath>
#include <sstream>

namespace shelldyn {
namespace {

struct ArkCounters {
  long steps = 0, attempts = 0, fe = 0, fi = 0, newton = 0, setups = 0;
};

class ArkodeIntegrator final : public SundialsBaseline {
 public:
  ArkodeIntegrator(IntegratorSettings& s, double dt, bool implicit)
      : SundialsBaseline(implicit ? "arkode-dirk" : "arkode-erk", s), implicit_(implicit), dt_(dt) {
    table_ = s.get("table", implicit ? "ARKODE_ESDIRK547L2SA_7_4_5" : "ARKODE_DORMAND_PRINCE_7_4_5");
    fixed_ = s.get("fixed_step", false);
    if (implicit) {
      linear_solver_ = s.get("linear_solver", "eigen-ldlt");
      max_nonlin_ = s.get("max_nonlin_iters", 3);
      lsetup_frequency_ = s.get("lsetup_frequency", 0);
    }
    if (fixed_ && !(dt_ > 0.0 && std::isfinite(dt_)))
      throw std::invalid_argument(name_ + ": fixed_step needs a positive time step dt, got " + std::to_string(dt_));
    if (implicit) {
      if (!is_linear_solver_name(linear_solver_))
        throw std::invalid_argument(name_ + ": unknown linear_solver '" + linear_solver_ +
                                    "' (M + gamma^2 K is symmetric: eigen-ldlt, cholmod, mumps or klu)");
      if (lsetup_frequency_ < 0) throw std::invalid_argument(name_ + ": lsetup_frequency must be >= 0 (0 = ARKODE default 20)");
      if (max_nonlin_ < 1) throw std::invalid_argument(name_ + ": max_nonlin_iters must be >= 1");
    }
    // Validate the table now, so that a typo is a settings error, not a failure at initialize().
    ARKodeButcherTable B = nullptr;
    {  // SUNDIALS prints its own "[ARKODE ERROR] ... Unknown Butcher table" lines: keep stderr to one line
      std::fflush(stderr);
      const int saved = dup(2);
      const int null = open("/dev/null", O_WRONLY);
      if (saved >= 0 && null >= 0) dup2(null, 2);
      B = implicit ? ARKodeButcherTable_LoadDIRKByName(table_.c_str()) : ARKodeButcherTable_LoadERKByName(table_.c_str());
      std::fflush(stderr);
      if (saved >= 0 && null >= 0) dup2(saved, 2);
      if (null >= 0) close(null);
      if (saved >= 0) close(saved);
    }
    if (B == nullptr)
      throw std::invalid_argument(name_ + ": unknown " + (implicit ? "DIRK" : "ERK") + " table '" + table_ +
                                  "' (SUNDIALS 6.4.1 names)\ne.g. " +
                                  (implicit ? "ARKODE_ESDIRK547L2SA_7_4_5, ARKODE_SDIRK_5_3_4"
                                            : "ARKODE_DORMAND_PRINCE_7_4_5, ARKODE_VERNER_8_5_6") +
                                  "; full list: docs/dependencies.md §4.4");
    const bool embedded = B->d != nullptr;
    ARKodeButcherTable_Free(B);
    if (!embedded && !fixed_)
      throw std::invalid_argument(name_ + ": table '" + table_ +
                                  "' has no embedding and cannot adapt the step: set fixed_step: true");
    resolved_ = s.resolved();
  }

  ~ArkodeIntegrator() override { free_ark(); }

 private:
  // --- SundialsBaseline hooks ---
  void create_solver(SemiDiscreteSystem& system, const State& state) override {
    free_ark();
    const Index N = fos_->size();
    y_ = make_serial_vector(N, *ctx_);
    fos_->pack(state, w_, d_, data(y_.get()));
    mem_ = implicit_ ? ARKStepCreate(nullptr, rhs, t_, y_.get(), *ctx_) : ARKStepCreate(rhs, nullptr, t_, y_.get(), *ctx_);
    check_ptr(mem_, "ARKStepCreate");
    check(ARKStepSetErrHandlerFn(mem_, record_sundials_error, &sundials_message_), "ARKStepSetErrHandlerFn");
    check(ARKStepSetUserData(mem_, this), "ARKStepSetUserData");
    check(implicit_ ? ARKStepSetTableName(mem_, table_.c_str(), "ARKODE_ERK_NONE")
                    : ARKStepSetTableName(mem_, "ARKODE_DIRK_NONE", table_.c_str()),
          "ARKStepSetTableName");
    check(ARKStepSVtolerances(mem_, rtol_, atol_v_.get()), "ARKStepSVtolerances");
    if (fixed_) check(ARKStepSetFixedStep(mem_, dt_), "ARKStepSetFixedStep");
    if (max_step_ > 0) check(ARKStepSetMaxStep(mem_, max_step_), "ARKStepSetMaxStep");
    if (init_step_ > 0) check(ARKStepSetInitStep(mem_, init_step_), "ARKStepSetInitStep");
    check(ARKStepSetMaxNumSteps(mem_, static_cast<long>(max_steps_)), "ARKStepSetMaxNumSteps");
    check(ARKStepSetPostprocessStepFn(mem_, after_step), "ARKStepSetPostprocessStepFn");
    check(ARKStepRootInit(mem_, 1, root), "ARKStepRootInit");
    int direction = -1;  // only a margin going negative is an event
    check(ARKStepSetRootDirection(mem_, &direction), "ARKStepSetRootDirection");
    check(ARKStepSetNoInactiveRootWarn(mem_), "ARKStepSetNoInactiveRootWarn");
    if (implicit_) setup_newton_solver(system);
    base_ = ArkCounters{};
  }
  void set_stop_time(double t_out) override { check(ARKStepSetStopTime(mem_, t_out), "ARKStepSetStopTime"); }
  int one_step(double t_out, double& tret) override { return ARKStepEvolve(mem_, t_out, y_.get(), &tret, ARK_ONE_STEP); }
  StepOutcome outcome(int flag) const override {
    return flag == ARK_ROOT_RETURN ? StepOutcome::root : flag == ARK_TSTOP_RETURN ? StepOutcome::reached : StepOutcome::step;
  }
  void pack(const State& s) override { fos_->pack(s, w_, d_, data(y_.get())); }
  void reinit() override {
    check(ARKStepReInit(mem_, implicit_ ? nullptr : rhs, implicit_ ? rhs : nullptr, t_, y_.get()), "ARKStepReInit");
  }
  void unpack(State& s) override {
    const double* y = data(y_.get());
    fos_->unpack(y, s);
    s.t = t_;
    w_ = y[fos_->work_index()];
    d_ = y[fos_->damping_index()];
  }
  bool acceleration_in_y() const override { return false; }
  void rebase_counters() override { base_ = ArkCounters{}; }
  double last_step() const override {
    double h = 0;
    ARKStepGetLastStep(mem_, &h);
    return h;
  }
  const double* y() const override { return N_VGetArrayPointer(y_.get()); }

  long factorizations() const override {
    long f = fos_->mass_factorizations();
    if (newton_) f += newton_->backend().stats().factorizations;
    return f;
  }

  ArkCounters counters() const {
    ArkCounters c;
    ARKStepGetNumSteps(mem_, &c.steps);
    ARKStepGetNumStepAttempts(mem_, &c.attempts);
    ARKStepGetNumRhsEvals(mem_, &c.fe, &c.fi);
    if (implicit_) {
      ARKStepGetNumNonlinSolvIters(mem_, &c.newton);
      ARKStepGetNumLinSolvSetups(mem_, &c.setups);
    }
    return c;
  }
  void add_counters(StepReport& rep) override {
    const ArkCounters c = counters();
    rep.steps += c.steps - base_.steps;
    rep.rejected_steps += (c.attempts - base_.attempts) - (c.steps - base_.steps);
    rep.rhs_evaluations += (c.fe - base_.fe) + (c.fi - base_.fi);
    rep.nonlinear_iterations += c.newton - base_.newton;
    rep.linear_setups += c.setups - base_.setups;
    base_ = c;
  }

  [[noreturn]] void fail(int flag, double t, const std::string& what) override {
    double h = 0;
    ARKStepGetCurrentStep(mem_, &h);
    std::ostringstream os;
    os << name_ << ": ARKStepEvolve failed at t = " << t << " (step size " << h << ")";
    if (flag < 0) os << " with " << flag_name(ARKStepGetReturnFlagName, flag);
    if (!what.empty()) os << ": " << what;
    if (errors_.has_error()) os << "; " << errors_.message();
    if (!sundials_message_.empty()) os << "; " << sundials_message_;
    throw StepFailure(os.str());
  }

  void check(int flag, const char* call) const { check_flag(flag, call, ARKStepGetReturnFlagName); }

  void free_ark() {
    if (mem_) ARKStepFree(&mem_);
    mem_ = nullptr;
  }

  // --- the Newton solver of arkode-dirk (header): placeholder matrix + callback solver + linsys function ---
  void setup_newton_solver(SemiDiscreteSystem& system) {
    newton_ = std::make_unique<SecondOrderNewton>(system.pattern(), system.dofs(), linear_solver_);
    system.add_damping_matrix(1.0, newton_->G);  // C: constant (reference state), zero without damping
    A_ = make_placeholder_matrix(*ctx_);
    LS_ = make_callback_linear_solver(*ctx_, {[this] { return ls_setup(); },
                                              [this](const double* b, double* x) { return ls_solve(b, x); }});
    check(ARKStepSetLinearSolver(mem_, LS_.get(), A_.get()), "ARKStepSetLinearSolver");
    check(ARKStepSetLinSysFn(mem_, linsys), "ARKStepSetLinSysFn");
    check(ARKStepSetMaxNonlinIters(mem_, max_nonlin_), "ARKStepSetMaxNonlinIters");
    if (lsetup_frequency_ > 0) check(ARKStepSetLSetupFrequency(mem_, lsetup_frequency_), "ARKStepSetLSetupFrequency");
  }

  // A = I − γJ: re-assemble K and M only when ARKODE asks for a new Jacobian (jok = false).
  static int linsys(sunrealtype t, N_Vector y, N_Vector, SUNMatrix, SUNMatrix, sunbooleantype jok,
                    sunbooleantype* jcur, sunrealtype gamma, void* ud, N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<ArkodeIntegrator*>(ud);
    try {
      if (!jok) {
        State& s = self->work_;
        self->fos_->unpack(N_VGetArrayPointer(y), s);
        self->sys_->internal(s.u, s.charts, nullptr, &self->newton_->K);
        self->sys_->add_load_stiffness(t, s.u, s.charts, self->newton_->K);
        self->sys_->mass(s.u, s.charts, self->newton_->M);
        *jcur = SUNTRUE;
      } else {
        *jcur = SUNFALSE;
      }
      self->gamma_ = gamma;
      return 0;
    } catch (const std::domain_error&) {
      return 1;
    } catch (...) {
      self->errors_.capture("arkode-dirk linear system");
      return -1;
    }
  }

  // Factorize S = M + γC + γ²K with constrained rows/columns as identity (Schur complement, header;
  // docs/theory/baseline-newton.md).
  int ls_setup() {
    try {
      newton_->factorize(gamma_);
      return SUNLS_SUCCESS;
    } catch (...) {
      errors_.capture("arkode-dirk Newton-matrix factorization");
      return SUNLS_PACKAGE_FAIL_REC;
    }
  }

  // (I − γJ) x = b: the block system of second_order_newton.hpp with r_q = b_q, m = b_v (momentum rows
  // M x_v + γ K x_q + γ C x_v = M b_v). The w and d rows are the identity: their coupling to v is left out; they
  // do not feed back, so the Newton iteration still converges to them.
  int ls_solve(const double* b, double* x) {
    try {
      const Index n = n_;
      newton_->solve(b, b + n, nullptr, x, x + n);
      x[2 * n] = b[2 * n];
      x[2 * n + 1] = b[2 * n + 1];
      return all_finite(x, 2 * n + 2) ? SUNLS_SUCCESS : SUNLS_PACKAGE_FAIL_REC;
    } catch (...) {
      errors_.capture("arkode-dirk Newton solve");
      return SUNLS_PACKAGE_FAIL_UNREC;
    }
  }

  // --- RHS, root and post-step callbacks: no exception crosses them ---
  static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* ud) {
    auto* self = static_cast<ArkodeIntegrator*>(ud);
    try {
      const Index n = self->n_;
      const double* yv = N_VGetArrayPointer(y);
      double* f = N_VGetArrayPointer(ydot);
      State& s = self->work_;
      self->fos_->unpack(yv, s);
      const FirstOrderSystem::Powers power = self->fos_->acceleration(t, s, self->a_);
      std::copy(yv + n, yv + 2 * n, f);
      std::copy(self->a_.data(), self->a_.data() + n, f + n);
      f[2 * n] = power.external;
      f[2 * n + 1] = power.damping;  // ḋ = vᵀ C v (first_order_system.hpp)
      return 0;
    } catch (const std::domain_error& e) {
      // Non-finite stage or director overshoot (docs/theory.md §2.1 guard): adaptive steppers retry
      // with a smaller step; a fixed step cannot, so stop with the reason.
      if (!self->fixed_) return 1;
      try {
        std::ostringstream os;
        os << e.what() << " -- the fixed step dt = " << self->dt_
           << (self->implicit_ ? " is too large for the Newton iteration"
                               : " is probably past the explicit stability limit")
           << " (use a smaller dt or adaptive stepping)";
        throw std::runtime_error(os.str());
      } catch (...) {
        self->errors_.capture("right-hand side");
      }
      return -1;
    } catch (...) {
      self->errors_.capture("right-hand side");
      return -1;
    }
  }

  static int root(sunrealtype, N_Vector y, sunrealtype* g, void* ud) {
    auto* self = static_cast<ArkodeIntegrator*>(ud);
    try {
      g[0] = self->chart_root(N_VGetArrayPointer(y));
      return 0;
    } catch (...) {
      self->errors_.capture("chart-margin root function");
      return -1;
    }
  }

  // Every accepted step: a non-finite state means the step was unstable (docs/dependencies.md §7 item 11).
  static int after_step(sunrealtype t, N_Vector y, void* ud) {
    auto* self = static_cast<ArkodeIntegrator*>(ud);
    if (all_finite(N_VGetArrayPointer(y), self->fos_->size())) return 0;
    try {
      std::ostringstream os;
      os << "non-finite state after the step to t = " << t;
      if (self->fixed_)
        os << " (fixed step dt = " << self->dt_ << (self->implicit_ ? "" : " is past the explicit stability limit")
           << "; use a smaller dt or adaptive stepping)";
      throw std::runtime_error(os.str());
    } catch (...) {
      self->errors_.capture(self->name_.c_str());
    }
    return -1;
  }

  // settings
  bool implicit_;
  double dt_;
  std::string table_, linear_solver_;
  bool fixed_ = false;
  int max_nonlin_ = 3, lsetup_frequency_ = 0;

  // run objects
  NVectorPtr y_;
  SunMatrixPtr A_;
  SunLinearSolverPtr LS_;
  void* mem_ = nullptr;
  Eigen::VectorXd a_;

  // Newton solver of arkode-dirk
  std::unique_ptr<SecondOrderNewton> newton_;
  double gamma_ = 0.0;

  ArkCounters base_;
};

}  // namespace

std::unique_ptr<Integrator> make_arkode_erk(IntegratorSettings& settings, double dt) {
  return std::make_unique<ArkodeIntegrator>(settings, dt, false);
}

std::unique_ptr<Integrator> make_arkode_dirk(IntegratorSettings& settings, double dt) {
  return std::make_unique<ArkodeIntegrator>(settings, dt, true);
}

}  // namespace shelldyn
