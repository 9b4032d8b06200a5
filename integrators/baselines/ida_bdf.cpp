#include "integrators/baselines/ida_bdf.hpp"

#include "integrators/baselines/sundials_baseline.hpp"
#include "integrators/sundials/sun_linear_solver.hpp"
#include "integrators/sundials/sundials_support.hpp"
#include "lib/assembler.hpp"

#include <ida/ida.h>
#include <ida/ida_ls.h>

#include <chrono>
#include <cmath>
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
    linear_solver_ = s.get("linear_solver", "klu");
    jacobian_ = s.get("jacobian", "approximate");
    dcj_lsetup_ = s.get("delta_cj_lsetup", 0.25);
    if (max_order_ < 1 || max_order_ > 5)
      throw std::invalid_argument("ida-bdf: max_order must be 1..5, got " + std::to_string(max_order_));
    if (linear_solver_ != "klu")
      throw std::invalid_argument("ida-bdf: linear_solver '" + linear_solver_ +
                                  "' is not supported: the IDA iteration matrix [[c_j I, -I], [K, c_j M]] is "
                                  "not symmetric, and only klu factors non-symmetric matrices");
    if (jacobian_ != "approximate" && jacobian_ != "fd-inertia")
      throw std::invalid_argument("ida-bdf: jacobian must be 'approximate' or 'fd-inertia', got '" + jacobian_ +
                                  "'");
    if (!(dcj_lsetup_ > 0.0 && dcj_lsetup_ < 1.0))
      throw std::invalid_argument("ida-bdf: delta_cj_lsetup must be in (0, 1), got " + std::to_string(dcj_lsetup_));
    resolved_ = s.resolved();
  }

  ~IdaBdf() override { free_ida(); }

 private:
  // --- SundialsBaseline hooks ---
  void create_solver(SemiDiscreteSystem& system, const State& state) override {
    free_ida();
    const Index N = fos_->size();
    build_block_pattern(*system.pattern());
    K_.pattern = M_.pattern = G_v_.pattern = system.pattern();
    K_.values.assign(static_cast<size_t>(system.pattern()->nnz()), 0.0);
    M_.values = G_v_.values = K_.values;
    fext_.resize(n_);
    cv_.resize(n_);
    y_ = make_serial_vector(N, *ctx_);
    yp_ = make_serial_vector(N, *ctx_);
    id_ = make_serial_vector(N, *ctx_);
    write_y(state);
    N_VConst(1.0, id_.get());
    J_ = make_csc_matrix(*big_.pattern, *ctx_);
    LS_.reset(make_sun_linear_solver(*ctx_, make_linear_solver(linear_solver_)));

    mem_ = IDACreate(*ctx_);
    check_ptr(mem_, "IDACreate");
    check(IDASetErrHandlerFn(mem_, record_sundials_error, &sundials_message_), "IDASetErrHandlerFn");
    check(IDAInit(mem_, residual, t_, y_.get(), yp_.get()), "IDAInit");
    check(IDASVtolerances(mem_, rtol_, atol_v_.get()), "IDASVtolerances");
    check(IDASetUserData(mem_, this), "IDASetUserData");
    check(IDASetLinearSolver(mem_, LS_.get(), J_.get()), "IDASetLinearSolver");
    check(IDASetJacFn(mem_, jacobian), "IDASetJacFn");
    check(IDASetId(mem_, id_.get()), "IDASetId");
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
  }
  void set_stop_time(double t_out) override { check(IDASetStopTime(mem_, t_out), "IDASetStopTime"); }
  int one_step(double t_out, double& tret) override {
    return IDASolve(mem_, t_out, &tret, y_.get(), yp_.get(), IDA_ONE_STEP);
  }
  StepOutcome outcome(int flag) const override {
    return flag == IDA_ROOT_RETURN ? StepOutcome::root : flag == IDA_TSTOP_RETURN ? StepOutcome::reached : StepOutcome::step;
  }
  void pack(const State& s) override { write_y(s, data(yp_.get())[fos_->work_index()]); }
  void reinit() override { check(IDAReInit(mem_, t_, y_.get(), yp_.get()), "IDAReInit"); }
  void unpack(State& s) override { read_y(s); }
  bool acceleration_in_y() const override { return true; }
  void rebase_counters() override { base_ = IdaCounters{}; }
  long factorizations() const override { return sun_linear_solver_backend(LS_.get()).stats().factorizations; }
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
    const std::string& ls = sun_linear_solver_last_error(LS_.get());
    if (!ls.empty()) os << "; " << ls;
    throw StepFailure(os.str());
  }

  void check(int flag, const char* call) const { check_flag(flag, call, IDAGetReturnFlagName); }

  void free_ida() {
    if (mem_) IDAFree(&mem_);
    mem_ = nullptr;
  }

  // --- Jacobian pattern: columns [q (n) | v (n) | w (1) | d (1)], rows likewise ---
  void build_block_pattern(const SparsePattern& P) {
    auto big = std::make_shared<SparsePattern>();
    const Index n = P.n, N = 2 * n + 2;
    big->n = N;
    big->colptr.reserve(static_cast<size_t>(N) + 1);
    big->colptr.push_back(0);
    auto& rows = big->rowind;
    for (Index j = 0; j < n; ++j) {  // q columns: (j, j) then the K rows
      rows.push_back(j);
      for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k) rows.push_back(n + P.rowind[k]);
      big->colptr.push_back(static_cast<Index>(rows.size()));
    }
    for (Index j = 0; j < n; ++j) {  // v columns: (j, n+j) = −1, the M rows, then the w and d rows
      rows.push_back(j);
      for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k) rows.push_back(n + P.rowind[k]);
      rows.push_back(2 * n);
      rows.push_back(2 * n + 1);
      big->colptr.push_back(static_cast<Index>(rows.size()));
    }
    rows.push_back(2 * n);  // w column
    big->colptr.push_back(static_cast<Index>(rows.size()));
    rows.push_back(2 * n + 1);  // d column
    big->colptr.push_back(static_cast<Index>(rows.size()));
    big_.pattern = big;
    big_.values.assign(rows.size(), 0.0);
  }

  // Forward differences of h(q, v) = M(q) v̇ + F_m(q, v): G_q += ∂h/∂q into K_, G_v = ∂F_m/∂v.
  void add_fd_inertia(const State& s, const Eigen::VectorXd& a) {
    const SparsePattern& P = *K_.pattern;
    SparseMatrix Mp{K_.pattern, std::vector<double>(K_.values.size())};
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
      for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k) K_.values[k] += (hp[P.rowind[k]] - h0[P.rowind[k]]) / eq;
      const double ev = 1e-7 * std::max(1.0, std::abs(v[j]));
      v[j] += ev;
      h(s.u, v, hp);
      v[j] = s.v[j];
      for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k) G_v_.values[k] = (hp[P.rowind[k]] - h0[P.rowind[k]]) / ev;
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

  static int jacobian(sunrealtype t, sunrealtype cj, N_Vector y, N_Vector yp, N_Vector, SUNMatrix J, void* ud,
                      N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<IdaBdf*>(ud);
    try {
      const Index n = self->n_;
      const double* yv = N_VGetArrayPointer(y);
      State& s = self->work_;
      self->fos_->unpack(yv, s);
      self->a_ = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(yp) + n, n);
      const SemiDiscreteSystem& sys = *self->sys_;
      sys.internal(s.u, s.charts, nullptr, &self->K_);
      sys.add_load_stiffness(t, s.u, s.charts, self->K_);
      sys.mass(s.u, s.charts, self->M_);
      sys.external(t, s.u, s.charts, self->fext_.data());
      self->G_v_.set_zero();
      // ∂F_m/∂v: the damping matrix C (docs/theory.md §8.5) in the approximate Jacobian; fd-inertia
      // differentiates F_m, which contains C v, so it has C already.
      if (self->jacobian_ == "fd-inertia")
        self->add_fd_inertia(s, self->a_);
      else
        sys.add_damping_matrix(1.0, self->G_v_);
      if (sys.has_damping())
        sys.damping_force(s.v, self->cv_.data());
      else
        self->cv_.setZero();

      const SparsePattern& P = *self->K_.pattern;
      const DofMap& dofs = sys.dofs();
      const Index* bcol = self->big_.pattern->colptr.data();
      double* val = self->big_.values.data();
      for (Index j = 0; j < n; ++j) {
        Index pq = bcol[j], pv = bcol[n + j];
        val[pq++] = cj;
        val[pv++] = -1.0;
        for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k, ++pq, ++pv) {
          const Index row = P.rowind[k];
          if (dofs.is_constrained(row)) {  // momentum row replaced by v̇_c = 0
            val[pq] = 0.0;
            val[pv] = row == j ? cj : 0.0;
          } else {
            val[pq] = self->K_.values[k];
            val[pv] = cj * self->M_.values[k] + self->G_v_.values[k];
          }
        }
        val[pv++] = -self->fext_[j];         // ∂(ẇ − F_ext·v)/∂v_j
        val[pv] = -2.0 * self->cv_[j];       // ∂(ḋ − vᵀ C v)/∂v_j (C symmetric)
      }
      val[bcol[2 * n]] = cj;
      val[bcol[2 * n + 1]] = cj;
      copy_to_sun_matrix(self->big_, J);  // IDA zeroed J, structure included (docs/dependencies.md §3.2)
      return 0;
    } catch (const std::domain_error&) {
      return 1;
    } catch (...) {
      self->errors_.capture("ida-bdf Jacobian");
      return -1;
    }
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
  int max_order_;
  double dcj_lsetup_;
  std::string linear_solver_, jacobian_;

  // run objects
  NVectorPtr y_, yp_, id_;
  SunMatrixPtr J_;
  SunLinearSolverPtr LS_;
  void* mem_ = nullptr;

  Eigen::VectorXd a_, r_, fext_, cv_;
  SparseMatrix K_, M_, G_v_, big_;
  IdaCounters base_;
};

}  // namespace

std::unique_ptr<Integrator> make_ida_bdf(IntegratorSettings& settings, double dt) {
  return std::make_unique<IdaBdf>(settings, dt);
}

}  // namespace shelldyn
