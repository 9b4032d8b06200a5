#include "integrators/baselines/ida_bdf.hpp"

#include "integrators/baselines/second_order_newton.hpp"
#include "integrators/baselines/sundials_baseline.hpp"
#include "integrators/sundials/callback_linear_solver.hpp"
#include "integrators/sundials/sundials_support.hpp"
#include "lib/model/assembler.hpp"

#include <ida/ida.h>
#include <ida/ida_ls.h>

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace shelldyn {
namespace {

// Cumulative IDA counters since the last IDAInit/IDAReInit (IDAReInit resets them).
struct IdaCounters {
  long steps = 0, residuals = 0, newton = 0, conv_fails = 0, err_fails = 0, setups = 0;
};

class IdaBdf final : public SundialsBaseline {
 public:
  IdaBdf(IntegratorSettings& s, double /*dt: IDA chooses its own steps (init_step)*/) : SundialsBaseline("ida-bdf", s) {
    max_order_ = s.get("max_order", 2);
    jacobian_ = s.get("jacobian", "approximate");
    // The Newton matrix is solved through its n × n Schur complement S = c_j² M + c_j G + K
    // (docs/theory/baseline-newton.md): symmetric with the approximate Jacobian, so Cholesky by default;
    // fd-inertia's G and K are not symmetric and need an LU.
    linear_solver_ = s.get("linear_solver", jacobian_ == "fd-inertia" ? "klu" : "cholmod");
    dcj_lsetup_ = s.get("delta_cj_lsetup", 0.25);
    jacobian_reuse_ = s.get("jacobian_reuse", 20);
    if (max_order_ < 1 || max_order_ > 5)
      throw std::invalid_argument("ida-bdf: max_order must be 1..5, got " + std::to_string(max_order_));
    if (jacobian_ != "approximate" && jacobian_ != "fd-inertia")
      throw std::invalid_argument("ida-bdf: jacobian must be 'approximate' or 'fd-inertia', got '" + jacobian_ +
                                  "'");
    if (!is_linear_solver_name(linear_solver_))
      throw std::invalid_argument("ida-bdf: unknown linear_solver '" + linear_solver_ +
                                  "' (the Newton matrix's Schur complement is symmetric: cholmod, eigen-ldlt, mumps or "
                                  "klu)");
    if (jacobian_ == "fd-inertia" && linear_solver_ != "klu")
      throw std::invalid_argument("ida-bdf: jacobian=fd-inertia gives a non-symmetric Newton matrix; linear_solver '" +
                                  linear_solver_ + "' factors symmetric matrices only, use linear_solver=klu");
    if (jacobian_reuse_ < 0)
      throw std::invalid_argument("ida-bdf: jacobian_reuse must be >= 0 steps (0: assemble at every Newton-matrix "
                                  "setup), got " + std::to_string(jacobian_reuse_));
    if (!(dcj_lsetup_ > 0.0 && dcj_lsetup_ < 1.0))
      throw std::invalid_argument("ida-bdf: delta_cj_lsetup must be in (0, 1), got " + std::to_string(dcj_lsetup_));
    resolved_ = s.resolved();
  }

  ~IdaBdf() override { free_ida(); }
  // Holonomic constraints as an index-2 stabilized (GGL) DAE (ida_bdf.hpp, docs/theory/multibody.md §7).
  bool supports_constraints() const override { return true; }
  // W_presc = ∫ λᵀ ∂g/∂t dt, the work of the driven joints (prescribed_rotation; docs/manual.md §2.13): the power
  // of the constraint force −Gᵀλ is −λᵀ G v = λᵀ ∂g/∂t on the constraint manifold (G v + ∂g/∂t = 0). It is one
  // more differential unknown p of the GGL DAE, ṗ = λᵀ ∂g/∂t, after λ and μ (em-galpha's discrete counterpart
  // is Σ λᵀ τ).
  double prescribed_work() const override { return presc_; }
  void save(IntegratorCheckpoint& c) const override {
    SundialsBaseline::save(c);
    c.scalars["W_presc"] = presc_;
  }
  void restore(SemiDiscreteSystem& system, State& state, const IntegratorCheckpoint& c) override {
    presc_ = c.scalars.count("W_presc") ? c.scalar("W_presc") : 0.0;  // checkpoints before W_presc: no driver
    SundialsBaseline::restore(system, state, c);
  }

 private:
  // --- SundialsBaseline hooks ---
  void create_solver(SemiDiscreteSystem& system, const State& state) override {
    free_ida();
    m_ = system.num_constraints();
    presc_ = 0.0;  // (restore() sets the checkpoint's value after initialize())
    const Index N = fos_->size() + (m_ > 0 ? 2 * m_ + 1 : 0);  // GGL: λ, μ, p after [q; v; w; d]
    newton_ = std::make_unique<SecondOrderNewton>(system.pattern(), system.dofs(), linear_solver_);
    fext_.resize(n_);
    cv_.resize(n_);
    y_ = make_serial_vector(N, *ctx_);
    yp_ = make_serial_vector(N, *ctx_);
    id_ = make_serial_vector(N, *ctx_);
    write_y(state);
    N_VConst(1.0, id_.get());
    for (Index k = fos_->size(); k < fos_->size() + 2 * m_; ++k) data(id_.get())[k] = 0.0;  // λ, μ algebraic
    if (m_ > 0) {  // tolerances of λ, μ (out of the error test, IDASetSuppressAlg; used by Newton's norm)
      atol_all_ = make_serial_vector(N, *ctx_);
      std::copy(data(atol_v_.get()), data(atol_v_.get()) + fos_->size(), data(atol_all_.get()));
      // λ, μ: rtol · max(1, |λ₀|∞). Their Newton corrections scale like 1/h (index 2), so the energy-scaled atol of
      // w (1e-11 at rtol 1e-8) made Newton's convergence test fail at the first steps.
      Eigen::VectorXd a0, lambda0;
      ggl_initial(state, a0, lambda0);
      const double a_mult = rtol_ * std::max(1.0, lambda0.size() ? lambda0.cwiseAbs().maxCoeff() : 0.0);
      for (Index k = fos_->size(); k < N - 1; ++k) data(atol_all_.get())[k] = a_mult;
      data(atol_all_.get())[N - 1] = data(atol_v_.get())[fos_->work_index()];  // p: an energy, as w
    }
    J_ = make_placeholder_matrix(*ctx_);
    LS_ = make_callback_linear_solver(*ctx_, {[this] { return ls_setup(); },
                                              [this](const double* b, double* x) { return ls_solve(b, x); }});

    mem_ = IDACreate(*ctx_);
    check_ptr(mem_, "IDACreate");
    check(IDASetErrHandlerFn(mem_, record_sundials_error, &sundials_message_), "IDASetErrHandlerFn");
    check(IDAInit(mem_, residual, t_, y_.get(), yp_.get()), "IDAInit");
    check(IDASVtolerances(mem_, rtol_, m_ > 0 ? atol_all_.get() : atol_v_.get()), "IDASVtolerances");
    check(IDASetUserData(mem_, this), "IDASetUserData");
    check(IDASetLinearSolver(mem_, LS_.get(), J_.get()), "IDASetLinearSolver");
    check(IDASetJacFn(mem_, jacobian), "IDASetJacFn");
    check(IDASetId(mem_, id_.get()), "IDASetId");
    if (m_ > 0) check(IDASetSuppressAlg(mem_, SUNTRUE), "IDASetSuppressAlg");
    check(IDASetMaxOrd(mem_, max_order_), "IDASetMaxOrd");
    check(IDASetDeltaCjLSetup(mem_, dcj_lsetup_), "IDASetDeltaCjLSetup");
    if (max_step_ > 0) check(IDASetMaxStep(mem_, max_step_), "IDASetMaxStep");
    if (init_step_ > 0) check(IDASetInitStep(mem_, init_step_), "IDASetInitStep");
    check(IDASetMaxNumSteps(mem_, static_cast<long>(max_steps_)), "IDASetMaxNumSteps");
    check(IDARootInit(mem_, 1, root), "IDARootInit");
    int direction = -1;  // only a margin going negative is an event
    check(IDASetRootDirection(mem_, &direction), "IDASetRootDirection");
    check(IDASetNoInactiveRootWarn(mem_), "IDASetNoInactiveRootWarn");
    base_ = IdaCounters{};
    invalidate_blocks();
  }
  void set_stop_time(double t_out) override { check(IDASetStopTime(mem_, t_out), "IDASetStopTime"); }
  int one_step(double t_out, double& tret) override {
    return IDASolve(mem_, t_out, &tret, y_.get(), yp_.get(), IDA_ONE_STEP);
  }
  StepOutcome outcome(int flag) const override {
    return flag == IDA_ROOT_RETURN ? StepOutcome::root : flag == IDA_TSTOP_RETURN ? StepOutcome::reached : StepOutcome::step;
  }
  void pack(const State& s) override { write_y(s, data(yp_.get())[fos_->work_index()]); }
  void reinit() override {
    check(IDAReInit(mem_, t_, y_.get(), yp_.get()), "IDAReInit");
    invalidate_blocks();  // a chart switch changes what the unknowns mean; IDA's counters restart at 0
  }
  void unpack(State& s) override { read_y(s); }
  bool acceleration_in_y() const override { return true; }
  void rebase_counters() override { base_ = IdaCounters{}; }
  long factorizations() const override {
    return (newton_ ? newton_->backend().stats().factorizations : 0) + ggl_factorizations_;
  }
  double last_step() const override {
    double h = 0;
    IDAGetLastStep(mem_, &h);
    return h;
  }
  const double* y() const override { return N_VGetArrayPointer(y_.get()); }

  // --- state <-> (y, ẏ) ---
  void write_y(const State& s, double wdot = 0.0) {
    double* y = data(y_.get());
    double* yp = data(yp_.get());
    fos_->pack(s, w_, d_, y);
    std::copy(s.v.data(), s.v.data() + n_, yp);
    std::copy(s.a.data(), s.a.data() + n_, yp + n_);
    if (m_ > 0) {  // consistent (v̇, λ) from the acceleration-level condition, μ = 0 (ggl_initial)
      Eigen::VectorXd a, lambda;
      ggl_initial(s, a, lambda);
      std::copy(a.data(), a.data() + n_, yp + n_);
      const Index k0 = fos_->size();
      for (Index k = 0; k < m_; ++k) {
        y[k0 + k] = lambda[k];
        y[k0 + m_ + k] = 0.0;
        yp[k0 + k] = yp[k0 + m_ + k] = 0.0;
      }
      Eigen::VectorXd gt;  // p and ṗ = λᵀ ∂g/∂t
      sys_->constraint_time_derivative(s.t, s.u, s.charts, gt);
      y[k0 + 2 * m_] = presc_;
      yp[k0 + 2 * m_] = lambda.dot(gt);
    }
    yp[fos_->work_index()] = wdot;
    yp[fos_->damping_index()] = fos_->damping_power(s.v);  // ḋ = vᵀ C v: consistent from the start
  }
  void read_y(State& s) {
    const double* y = data(y_.get());
    fos_->unpack(y, s);
    s.a = Eigen::Map<const Eigen::VectorXd>(data(yp_.get()) + n_, n_);
    s.t = t_;
    w_ = y[fos_->work_index()];
    d_ = y[fos_->damping_index()];
    if (m_ > 0) presc_ = y[fos_->size() + 2 * m_];
  }

  // --- statistics ---
  IdaCounters counters() const {
    IdaCounters c;
    IDAGetNumSteps(mem_, &c.steps);
    IDAGetNumResEvals(mem_, &c.residuals);
    IDAGetNumNonlinSolvIters(mem_, &c.newton);
    IDAGetNumNonlinSolvConvFails(mem_, &c.conv_fails);
    IDAGetNumErrTestFails(mem_, &c.err_fails);
    IDAGetNumLinSolvSetups(mem_, &c.setups);
    return c;
  }
  void add_counters(StepReport& rep) override {
    const IdaCounters c = counters();
    rep.steps += c.steps - base_.steps;
    rep.rhs_evaluations += c.residuals - base_.residuals;
    rep.nonlinear_iterations += c.newton - base_.newton;
    rep.rejected_steps += (c.conv_fails - base_.conv_fails) + (c.err_fails - base_.err_fails);
    rep.linear_setups += c.setups - base_.setups;
    base_ = c;
  }

  [[noreturn]] void fail(int flag, double t, const std::string& what) override {
    double h = 0;
    IDAGetCurrentStep(mem_, &h);
    std::ostringstream os;
    os << "ida-bdf: IDASolve failed at t = " << t << " (step size " << h << ")";
    if (flag < 0) os << " with " << flag_name(IDAGetReturnFlagName, flag);
    if (!what.empty()) os << ": " << what;
    if (!sundials_message_.empty()) os << "; " << sundials_message_;
    if (errors_.has_error()) os << "; " << errors_.message();
    throw StepFailure(os.str());
  }

  void check(int flag, const char* call) const { check_flag(flag, call, IDAGetReturnFlagName); }

  void free_ida() {
    if (mem_) IDAFree(&mem_);
    mem_ = nullptr;
  }

  // Forward differences of h(q, v) = M(q) v̇ + F_m(q, v): ∂h/∂q added to K, G = ∂F_m/∂v.
  void add_fd_inertia(const State& s, const Eigen::VectorXd& a) {
    SparseMatrix& K = newton_->K;
    SparseMatrix& G = newton_->G;
    const SparsePattern& P = *K.pattern;
    SparseMatrix Mp{K.pattern, std::vector<double>(K.values.size())};
    Eigen::VectorXd h0(n_), hp(n_), fm(n_);
    auto h = [&](const Eigen::VectorXd& u, const Eigen::VectorXd& v, Eigen::VectorXd& out) {
      sys_->mass(u, s.charts, Mp);
      multiply(Mp.view(), a.data(), out.data());
      sys_->inertial(u, v, s.charts, fm.data());
      out += fm;
    };
    h(s.u, s.v, h0);
    Eigen::VectorXd u = s.u, v = s.v;
    for (Index j = 0; j < n_; ++j) {
      const double eq = 1e-7 * std::max(1.0, std::abs(u[j]));
      u[j] += eq;
      h(u, s.v, hp);
      u[j] = s.u[j];
      for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k) K.values[k] += (hp[P.rowind[k]] - h0[P.rowind[k]]) / eq;
      const double ev = 1e-7 * std::max(1.0, std::abs(v[j]));
      v[j] += ev;
      h(s.u, v, hp);
      v[j] = s.v[j];
      for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k) G.values[k] = (hp[P.rowind[k]] - h0[P.rowind[k]]) / ev;
    }
  }

  // --- C callbacks: no exception crosses them ---
  static int residual(sunrealtype t, N_Vector y, N_Vector yp, N_Vector r, void* ud) {
    auto* self = static_cast<IdaBdf*>(ud);
    try {
      const Index n = self->n_;
      const double* yv = N_VGetArrayPointer(y);
      const double* ypv = N_VGetArrayPointer(yp);
      double* rv = N_VGetArrayPointer(r);
      State& s = self->work_;
      self->fos_->unpack(yv, s);
      self->a_ = Eigen::Map<const Eigen::VectorXd>(ypv + n, n);
      if (!all_finite(yv, 2 * n + 2) || !all_finite(ypv, 2 * n + 2)) return 1;  // recoverable: cut the step
      const FirstOrderSystem::Powers power = self->fos_->momentum_residual(t, s, self->a_, self->r_);
      for (Index i = 0; i < n; ++i) rv[i] = ypv[i] - yv[n + i];
      std::copy(self->r_.data(), self->r_.data() + n, rv + n);
      if (self->m_ > 0) self->ggl_residual(t, s, yv, ypv, rv);
      rv[2 * n] = ypv[2 * n] - power.external;
      rv[2 * n + 1] = ypv[2 * n + 1] - power.damping;  // ḋ = vᵀ C v (first_order_system.hpp)
      return 0;
    } catch (const std::domain_error&) {
      return 1;  // director overshoot (docs/theory.md §2.1 guard) or non-finite: IDA cuts the step
    } catch (...) {
      self->errors_.capture("ida-bdf residual");
      return -1;
    }
  }

  // Assembles the blocks of the Newton matrix J = ∂F/∂y + c_j ∂F/∂ẏ (rows q, v, w, d):
  //   [[c_j I, −I], [K, c_j M + G]] on (q, v), and the w and d rows c_j x_w − F_ext·x_v, c_j x_d − 2 (C v)·x_v;
  // ls_setup() factorizes its Schur complement, ls_solve() eliminates (docs/theory/baseline-newton.md §3).
  // The placeholder J is not written.
  static int jacobian(sunrealtype t, sunrealtype cj, N_Vector y, N_Vector yp, N_Vector, SUNMatrix, void* ud,
                      N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<IdaBdf*>(ud);
    try {
      self->cj_ = cj;
      if (self->m_ == 0 && self->reuse_blocks()) return 0;  // only c_j changed enough: refactorize, keep K, M, G
      const Index n = self->n_;
      const double* yv = N_VGetArrayPointer(y);
      State& s = self->work_;
      self->fos_->unpack(yv, s);
      self->a_ = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(yp) + n, n);
      const SemiDiscreteSystem& sys = *self->sys_;
      SecondOrderNewton& nw = *self->newton_;
      sys.internal(s.u, s.charts, nullptr, &nw.K);
      sys.add_load_stiffness(t, s.u, s.charts, nw.K);
      sys.mass(s.u, s.charts, nw.M);
      sys.external(t, s.u, s.charts, self->fext_.data());
      nw.G.set_zero();
      // ∂F_m/∂v: the damping matrix C (docs/theory.md §8.5) in the approximate Jacobian; fd-inertia
      // differentiates F_m, which contains C v, so it has C already.
      if (self->jacobian_ == "fd-inertia")
        self->add_fd_inertia(s, self->a_);
      else
        sys.add_damping_matrix(1.0, nw.G);
      if (sys.has_damping())
        sys.damping_force(s.v, self->cv_.data());
      else
        self->cv_.setZero();
      self->blocks_valid_ = true;
      if (self->m_ > 0) self->ggl_jacobian(t, s, yv);
      return 0;
    } catch (const std::domain_error&) {
      return 1;
    } catch (...) {
      self->errors_.capture("ida-bdf Jacobian");
      return -1;
    }
  }

  // IDA asks for a new Newton matrix after a convergence failure and whenever c_j has changed by more than
  // delta_cj_lsetup, which with error-test rejections is nearly every step. The blocks K, M, G, F_ext and C v do
  // not depend on c_j, so they are re-assembled only when the Jacobian may be bad: a second request within the same
  // step attempt (IDA's Newton retrying after slow convergence with a stale matrix: neither the step count nor a
  // failure count has moved since the last request), a convergence failure since the last assembly, jacobian_reuse
  // steps since it, or a re-initialization (chart switch). Otherwise the setup only refactorizes S at the new c_j.
  // A stale block makes the Newton matrix approximate, never the residual: every accepted step satisfies the same
  // equations to the same tolerance; only the Newton contraction and, through round-off, the step sequence can
  // change (IDA's convergence test decides, as for its own stale Jacobians). docs/theory/baseline-newton.md §3.
  void invalidate_blocks() {
    blocks_valid_ = false;
    request_steps_ = request_conv_fails_ = request_err_fails_ = -1;
  }

  bool reuse_blocks() {
    long steps = 0, conv_fails = 0, err_fails = 0;
    IDAGetNumSteps(mem_, &steps);
    IDAGetNumNonlinSolvConvFails(mem_, &conv_fails);
    IDAGetNumErrTestFails(mem_, &err_fails);
    const bool retry = steps == request_steps_ && conv_fails == request_conv_fails_ && err_fails == request_err_fails_;
    request_steps_ = steps;
    request_conv_fails_ = conv_fails;
    request_err_fails_ = err_fails;
    const bool reuse = blocks_valid_ && jacobian_reuse_ > 0 && !retry && conv_fails == assembled_conv_fails_ &&
                       steps - assembled_steps_ < jacobian_reuse_;
    if (!reuse) {
      assembled_steps_ = steps;
      assembled_conv_fails_ = conv_fails;
    }
    return reuse;
  }

  int ls_setup() {
    try {
      if (m_ > 0) return ggl_factorize();
      newton_->factorize(1.0 / cj_);
      return SUNLS_SUCCESS;
    } catch (...) {
      errors_.capture("ida-bdf Newton-matrix factorization");
      return SUNLS_PACKAGE_FAIL_REC;  // IDA cuts the step and retries
    }
  }

  // J x = b with the c_j of the last factorization (IDA rescales x for a changed c_j itself). With γ = 1/c_j the
  // (q, v) rows are the block system of second_order_newton.hpp with r_q = γ b_q, p = γ b_v (constrained rows:
  // c_j x_v,c = b_v,c); then x_w = (b_w + F_ext·x_v)/c_j and x_d = (b_d + 2 (C v)·x_v)/c_j.
  int ls_solve(const double* b, double* x) {
    try {
      if (m_ > 0) return ggl_solve(b, x);
      const Index n = n_;
      const double g = newton_->gamma();
      rq_ = g * Eigen::Map<const Eigen::VectorXd>(b, n);
      p_ = g * Eigen::Map<const Eigen::VectorXd>(b + n, n);
      newton_->solve(rq_.data(), nullptr, p_.data(), x, x + n);
      const Eigen::Map<const Eigen::VectorXd> xv(x + n, n);
      x[2 * n] = g * (b[2 * n] + fext_.dot(xv));
      x[2 * n + 1] = g * (b[2 * n + 1] + 2.0 * cv_.dot(xv));
      return all_finite(x, 2 * n + 2) ? SUNLS_SUCCESS : SUNLS_PACKAGE_FAIL_REC;  // non-finite: cut the step
    } catch (...) {
      errors_.capture("ida-bdf Newton solve");
      return SUNLS_PACKAGE_FAIL_UNREC;
    }
  }

  // ---- GGL (index-2 stabilized) form of the constrained system (ida_bdf.hpp) -------------------------------
  using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, Index>;
  using Trip = Eigen::Triplet<double, Index>;

  // The constraint rows of F: q rows += Gᵀμ, v rows += Gᵀλ, then g, G v + ∂g/∂t and ṗ − λᵀ ∂g/∂t.
  void ggl_residual(double t, const State& s, const double* yv, const double* ypv, double* rv) {
    const Index n = n_, k0 = fos_->size();
    const Eigen::Map<const Eigen::VectorXd> lambda(yv + k0, m_), mu(yv + k0 + m_, m_);
    sys_->constraint_jacobian(t, s.u, s.charts, Gc_);
    const Eigen::VectorXd Gl = Gc_.transpose() * lambda, Gm = Gc_.transpose() * mu;
    for (Index i = 0; i < n; ++i) {
      rv[i] += Gm[i];
      rv[n + i] += Gl[i];
    }
    Eigen::VectorXd g, gt;
    sys_->constraint_values(t, s.u, s.charts, g);
    sys_->constraint_time_derivative(t, s.u, s.charts, gt);
    const Eigen::VectorXd gd = Gc_ * s.v + gt;
    for (Index k = 0; k < m_; ++k) {
      rv[k0 + k] = g[k];
      rv[k0 + m_ + k] = gd[k];
    }
    rv[k0 + 2 * m_] = ypv[k0 + 2 * m_] - lambda.dot(gt);
    gt_ = gt;  // for the p row of ggl_solve
  }

  // The constraint blocks of the Newton matrix at (t, y): G, the Hessian contractions ∂(Gᵀλ)/∂q, ∂(Gᵀμ)/∂q, and
  // D = ∂(G v + ∂g/∂t)/∂q by central differences over the columns G touches.
  void ggl_jacobian(double t, const State& s, const double* yv) {
    const Index k0 = fos_->size();
    const Eigen::Map<const Eigen::VectorXd> lambda(yv + k0, m_), mu(yv + k0 + m_, m_);
    sys_->constraint_jacobian(t, s.u, s.charts, Gj_);
    Hl_ = SparseMatrix{sys_->pattern(), std::vector<double>(static_cast<size_t>(sys_->pattern()->nnz()), 0.0)};
    Hm_ = Hl_;
    sys_->add_constraint_hessian(t, s.u, s.charts, lambda, 1.0, Hl_);
    sys_->add_constraint_hessian(t, s.u, s.charts, mu, 1.0, Hm_);
    std::vector<Index> cols;
    for (Index r = 0; r < Gj_.outerSize(); ++r)
      for (SemiDiscreteSystem::ConstraintMatrix::InnerIterator it(Gj_, r); it; ++it) cols.push_back(it.col());
    std::sort(cols.begin(), cols.end());
    cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
    D_.clear();
    Eigen::VectorXd u = s.u, gt_p, gt_m;
    SemiDiscreteSystem::ConstraintMatrix Gp, Gm;
    for (Index j : cols) {
      const double h = 1e-7 * std::max(1.0, std::abs(s.u[j]));
      u[j] = s.u[j] + h;
      sys_->constraint_jacobian(t, u, s.charts, Gp);
      sys_->constraint_time_derivative(t, u, s.charts, gt_p);
      u[j] = s.u[j] - h;
      sys_->constraint_jacobian(t, u, s.charts, Gm);
      sys_->constraint_time_derivative(t, u, s.charts, gt_m);
      u[j] = s.u[j];
      const Eigen::VectorXd col = (Eigen::VectorXd(Gp * s.v) + gt_p - Eigen::VectorXd(Gm * s.v) - gt_m) / (2.0 * h);
      for (Index k = 0; k < m_; ++k)
        if (col[k] != 0.0) D_.emplace_back(k, j, col[k]);
    }
  }

  // Assembles and factorizes (sparse LU) the Newton matrix on (q, v, λ, μ) at c_j (w and d eliminated as in the
  // unconstrained solve):
  //   [ c_j I + H_μ      −I            0    Gᵀ ]
  //   [ K + H_λ          c_j M + C     Gᵀ   0  ]   (constrained momentum rows: c_j e_cᵀ)
  //   [ G                0             0    0  ]
  //   [ D                G             0    0  ]
  int ggl_factorize() {
    const Index n = n_, N = 2 * n + 2 * m_;
    const DofMap& dofs = sys_->dofs();
    std::vector<Trip> t;
    const SparsePattern& P = *newton_->K.pattern;
    for (Index i = 0; i < n; ++i) {
      t.emplace_back(i, i, cj_);
      t.emplace_back(i, n + i, -1.0);
    }
    for (Index j = 0; j < P.n; ++j)
      for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k) {
        const Index i = P.rowind[k];
        if (Hm_.values[k] != 0.0) t.emplace_back(i, j, Hm_.values[k]);
        if (dofs.is_constrained(i)) continue;
        const double kq = newton_->K.values[k] + Hl_.values[k];
        const double kv = cj_ * newton_->M.values[k] + newton_->G.values[k];
        if (kq != 0.0) t.emplace_back(n + i, j, kq);
        if (kv != 0.0) t.emplace_back(n + i, n + j, kv);
      }
    for (Index c : dofs.constrained_dofs()) t.emplace_back(n + c, n + c, cj_);
    for (Index r = 0; r < Gj_.outerSize(); ++r)
      for (SemiDiscreteSystem::ConstraintMatrix::InnerIterator it(Gj_, r); it; ++it) {
        t.emplace_back(it.col(), 2 * n + m_ + r, it.value());  // Gᵀ μ in the q rows
        t.emplace_back(n + it.col(), 2 * n + r, it.value());   // Gᵀ λ in the v rows
        t.emplace_back(2 * n + r, it.col(), it.value());       // g
        t.emplace_back(2 * n + m_ + r, n + it.col(), it.value());  // G v
      }
    for (const Trip& d : D_) t.emplace_back(2 * n + m_ + d.row(), d.col(), d.value());
    SpMat A(N, N);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    lu_.compute(A);
    ++ggl_factorizations_;
    cj_fact_ = cj_;
    if (lu_.info() != Eigen::Success) {
      errors_.capture("ida-bdf GGL Newton-matrix factorization: singular (redundant joints?)");
      return SUNLS_PACKAGE_FAIL_REC;
    }
    return SUNLS_SUCCESS;
  }

  int ggl_solve(const double* b, double* x) {
    const Index n = n_, k0 = fos_->size();
    Eigen::VectorXd rhs(2 * n + 2 * m_);
    rhs.head(2 * n) = Eigen::Map<const Eigen::VectorXd>(b, 2 * n);
    rhs.tail(2 * m_) = Eigen::Map<const Eigen::VectorXd>(b + k0, 2 * m_);
    const Eigen::VectorXd z = lu_.solve(rhs);
    std::copy(z.data(), z.data() + 2 * n, x);
    std::copy(z.data() + 2 * n, z.data() + 2 * n + 2 * m_, x + k0);
    const Eigen::Map<const Eigen::VectorXd> xv(x + n, n);
    const double g = 1.0 / cj_fact_;
    x[2 * n] = g * (b[2 * n] + fext_.dot(xv));
    x[2 * n + 1] = g * (b[2 * n + 1] + 2.0 * cv_.dot(xv));
    // p row: c_j x_p − (∂g/∂t)ᵀ x_λ = b_p (its dependence on q through ∂g/∂t left out: p feeds nothing back).
    x[k0 + 2 * m_] = g * (b[k0 + 2 * m_] + (gt_.size() == m_ ? gt_.dot(Eigen::Map<const Eigen::VectorXd>(x + k0, m_)) : 0.0));
    return all_finite(x, k0 + 2 * m_ + 1) ? SUNLS_SUCCESS : SUNLS_PACKAGE_FAIL_REC;
  }

  // Consistent initial values (ida_bdf.hpp): μ = 0, and (v̇, λ) from
  //   M v̇ + Gᵀλ = F_ext − F_int − F_m,   G v̇ = −d/dt(G v + ∂g/∂t)|_{v̇ = 0}
  // (the time derivative along (q + εv, t + ε) by central differences), supported DOFs v̇_c = 0.
  void ggl_initial(const State& s, Eigen::VectorXd& a, Eigen::VectorXd& lambda) {
    const Index n = n_;
    const DofMap& dofs = sys_->dofs();
    Eigen::VectorXd r;
    fos_->momentum_residual(s.t, s, Eigen::VectorXd::Zero(n), r);  // F_m + F_int − F_ext (0 on supported rows)
    const SparseMatrix& M = fos_->last_mass();
    SemiDiscreteSystem::ConstraintMatrix G;
    sys_->constraint_jacobian(s.t, s.u, s.charts, G);
    double vmax = 1.0;
    for (Index i = 0; i < n; ++i) vmax = std::max(vmax, std::abs(s.v[i]));
    const double eps = 1e-5 / vmax;
    auto phi = [&](double e) {
      const Eigen::VectorXd u = s.u + e * s.v;
      SemiDiscreteSystem::ConstraintMatrix Ge;
      Eigen::VectorXd gt;
      sys_->constraint_jacobian(s.t + e, u, s.charts, Ge);
      sys_->constraint_time_derivative(s.t + e, u, s.charts, gt);
      return Eigen::VectorXd(Ge * s.v + gt);
    };
    const Eigen::VectorXd gamma = -(phi(eps) - phi(-eps)) / (2.0 * eps);
    std::vector<Trip> t;
    const SparsePattern& P = *M.pattern;
    for (Index j = 0; j < P.n; ++j)
      for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k) {
        const Index i = P.rowind[k];
        if (dofs.is_constrained(i) || dofs.is_constrained(j)) continue;
        if (M.values[k] != 0.0) t.emplace_back(i, j, M.values[k]);
      }
    for (Index c : dofs.constrained_dofs()) t.emplace_back(c, c, 1.0);
    for (Index row = 0; row < G.outerSize(); ++row)
      for (SemiDiscreteSystem::ConstraintMatrix::InnerIterator it(G, row); it; ++it) {
        t.emplace_back(it.col(), n + row, it.value());
        t.emplace_back(n + row, it.col(), it.value());
      }
    SpMat A(n + m_, n + m_);
    A.setFromTriplets(t.begin(), t.end());
    Eigen::SparseLU<SpMat> lu(A);
    if (lu.info() != Eigen::Success)
      throw std::invalid_argument("ida-bdf: the initial constraint Jacobian and mass matrix give a singular system "
                                  "(redundant joints, or a joint on massless unknowns)");
    Eigen::VectorXd rhs(n + m_);
    rhs.head(n) = -r;
    for (Index c : dofs.constrained_dofs()) rhs[c] = 0.0;
    rhs.tail(m_) = gamma;
    const Eigen::VectorXd z = lu.solve(rhs);
    a = z.head(n);
    lambda = z.tail(m_);
  }

  static int root(sunrealtype, N_Vector y, N_Vector, sunrealtype* g, void* ud) {
    auto* self = static_cast<IdaBdf*>(ud);
    try {
      g[0] = self->chart_root(N_VGetArrayPointer(y));
      return 0;
    } catch (...) {
      self->errors_.capture("ida-bdf chart-margin root function");
      return -1;
    }
  }

  // settings
  int max_order_, jacobian_reuse_;
  double dcj_lsetup_;
  std::string linear_solver_, jacobian_;

  // run objects
  NVectorPtr y_, yp_, id_;
  SunMatrixPtr J_;
  SunLinearSolverPtr LS_;
  void* mem_ = nullptr;

  std::unique_ptr<SecondOrderNewton> newton_;
  double cj_ = 1.0;
  bool blocks_valid_ = false;
  long assembled_steps_ = 0, assembled_conv_fails_ = 0;                     // at the last assembly
  long request_steps_ = -1, request_conv_fails_ = -1, request_err_fails_ = -1;  // at the last Jacobian request
  Eigen::VectorXd a_, r_, fext_, cv_, rq_, p_;
  IdaCounters base_;
  // GGL (m_ > 0)
  Index m_ = 0;
  NVectorPtr atol_all_;
  Eigen::VectorXd gt_;   // ∂g/∂t at the last residual evaluation (the p row of the Newton matrix)
  double presc_ = 0.0;   // W_presc = p at the time of y (read_y), or at the restart
  SemiDiscreteSystem::ConstraintMatrix Gc_, Gj_;
  SparseMatrix Hl_, Hm_;
  std::vector<Trip> D_;
  Eigen::SparseLU<SpMat> lu_;
  double cj_fact_ = 1.0;
  long ggl_factorizations_ = 0;
};

}  // namespace

std::unique_ptr<Integrator> make_ida_bdf(IntegratorSettings& settings, double dt) {
  return std::make_unique<IdaBdf>(settings, dt);
}

}  // namespace shelldyn
