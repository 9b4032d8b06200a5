// em-exact: exactly energy–momentum conserving step (docs/theory/exact-energy-momentum.md; header for the
// equations and settings).
#include "integrators/newmark/em_exact.hpp"

#include "elements/exact_energy.hpp"
#include "integrators/newmark/bordered_newton.hpp"
#include "integrators/newmark/consistent_acceleration.hpp"
#include "integrators/newmark/kept_iteration_matrix.hpp"
#include "integrators/nonlinear/energy_floor_test.hpp"
#include "integrators/nonlinear/newton_solver.hpp"
#include "lib/model/assembler.hpp"
#include "lib/linalg/linear_solver.hpp"
#include "lib/model/exact_energy_system.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <utility>

namespace shelldyn {
namespace {

std::string fmt(double x) {  // %.6g
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", x);
  return b;
}

// max_i Σ_j |J_ij| of a matrix with a full (symmetric) pattern: the column sums are the row sums.
double max_row_abs_sum(const SparseMatrix& J) {
  const SparsePattern& p = *J.pattern;
  double m = 0.0;
  for (Index c = 0; c < p.n; ++c) {
    double sum = 0.0;
    for (Index k = p.colptr[static_cast<size_t>(c)]; k < p.colptr[static_cast<size_t>(c) + 1]; ++k) sum += std::abs(J.values[static_cast<size_t>(k)]);
    m = std::max(m, sum);
  }
  return m;
}

class EmExact final : public Integrator, public EmExactDiagnostics {
 public:
  EmExact(IntegratorSettings& s, double dt) : dt_(dt) {
    if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("em-exact: time step dt must be > 0");
    const double rho_inf = s.get("rho_inf", 1.0);
    const double xi = s.get("xi", 0.0);
    if (!(rho_inf > 0.0 && rho_inf <= 1.0)) throw std::invalid_argument("em-exact: rho_inf must be in (0, 1]");
    if (!(xi >= 0.0 && xi < 0.5)) throw std::invalid_argument("em-exact: xi must be in [0, 0.5)");
    // Theory §6: on a linear oscillator the step is k[(½+ξ)u_{n+1} + (½−ξ)u_n], whose root tends to
    // (½−ξ)/(½+ξ) as ωΔt → ∞; ρ∞ < 1 asks for that limit, i.e. ξ = (1−ρ∞)/(2(1+ρ∞)).
    xi_ = xi + (1.0 - rho_inf) / (2.0 * (1.0 + rho_inf));
    // Modified Newton by default, as em-galpha (docs/theory/newton-iteration.md §1): K̄ kept and corotated, the
    // trapezoidal predictor, certify = predicted; a failed step is retried with full Newton from u_n.
    const std::string newton = s.get("newton", "modified");
    if (newton != "full" && newton != "modified")
      throw std::invalid_argument("em-exact.newton: '" + newton + "' (use full or modified)");
    nopt_.modified = (newton == "modified");
    // Modified Newton keeps K̄ while the iteration contracts (as em-galpha: refresh when the observed
    // contraction ‖Δu_k‖/‖Δu_{k−1}‖ exceeds `refresh`; refresh = 0 restores the fixed count setup_every).
    // Opt-in (theory §5.5): refresh_cost > 0 also refreshes K̄ when a step's iterations exceed the average cost
    // per step since the last refresh, the refresh counted as refresh_cost iterations (the renewal rule). It
    // adds refreshes where K̄ ages slowly; the contraction test stays, because the stall rule of §5 relies on the
    // contraction it enforces (a laxer guard let slow convergence pass for the floor).
    refresh_cost_ = s.get("refresh_cost", 0.0);
    if (!(refresh_cost_ >= 0.0) || !std::isfinite(refresh_cost_))
      throw std::invalid_argument("em-exact.refresh_cost must be >= 0 (a refresh's cost in iterations; 0 = off)");
    nopt_.refresh_contraction = s.get("refresh", nopt_.modified ? 0.03 : 0.0);
    nopt_.max_setup_calls = s.get("setup_every", nopt_.refresh_contraction > 0 ? 1000000 : 20);
    // How a kept K̄ is carried to later configurations (docs/theory.md §6.9; kept_iteration_matrix.hpp).
    kept_.set_basis(KeptIterationMatrix::parse_basis(s.get("kbar_basis", std::string("corotated")), std::string("em-exact")));
    // CHOLMOD's supernodal Cholesky as em-galpha (faster solves than Eigen's simplicial LDLᵀ, no hidden threads).
    nopt_.linear_solver = s.get("linear_solver", "cholmod");
    // Predictor (theory §5, §5.7): u_n, or with modified Newton the trapezoidal extrapolation d_n + Δt v_n + Δt²/2 a_n,
    // p_n + Δt w_n + Δt²/2 ẇ_n with the last step's accelerations a_n = Δv/Δt, ẇ_n = Δw/Δt ("trapezoidal"), or
    // without the director term ("trapezoidal-v", the predictor before the fourteenth session), or with the end-point
    // accelerations of Newmark's trapezoidal recursion a_{n+1} = 2Δv/Δt − a_n, started from the consistent initial
    // acceleration ("newmark": em-galpha's predictor, theory §5.9). A failed step is retried from u_n with full Newton.
    const std::string predictor = s.get("predictor", nopt_.modified ? "trapezoidal" : "none");
    if (predictor != "none" && predictor != "trapezoidal" && predictor != "trapezoidal-v" && predictor != "newmark")
      throw std::invalid_argument("em-exact.predictor: '" + predictor + "' (use none, trapezoidal, trapezoidal-v or newmark)");
    predictor_ = (predictor != "none");
    director_acceleration_ = (predictor == "trapezoidal" || predictor == "newmark");
    newmark_predictor_ = (predictor == "newmark");
    make_linear_solver(nopt_.linear_solver);
    nopt_.single_precision_solves =  // float copy of the kept factor (docs/dependencies.md §5.5)
        single_precision_setting(s.get("solve_precision", "double"), nopt_.linear_solver, "em-exact");
    // KINSOL never stops on its own (tolerances at the bottom of the double range): the iteration hook
    // applies the residual / stagnation rule of theory §5.
    nopt_.stop = StopTest::fnorm;
    nopt_.fnorm_tol = 1e-300;
    nopt_.step_tol = 0.0;
    nopt_.min_iters = 1;
    max_iters_ = s.get("max_iters", 25);
    // The solver may run to 2 max_iters; the iteration hook stops at max_iters unless the residual is still
    // contracting (docs/theory/newton-iteration.md §3.1).
    nopt_.max_iters = 2 * max_iters_;
    nopt_.line_search = false;
    res_tol_ = s.get("res_tol", 1e-12);
    stall_tol_ = s.get("stall_tol", 1e-6);
    stall_ratio_ = s.get("stall_ratio", 0.5);
    stall_step_ = s.get("stall_step", 1e-6);
    max_cuts_ = s.get("max_cuts", 0);
    hysteresis_ = s.get("hysteresis", 1.0);
    correction_ = s.get("correction", true);
    // How the round-off floor is seen (theory §5.3): "residual" evaluates the residual of the accepted
    // iterate and sees the stall there; "floor" accepts u_k = u_{k−1} + Δu_k without its residual once
    // u_{k−1}'s residual is within floor_margin of the floor of the recent steps; "predicted" (theory §5.4)
    // also accepts u_k unevaluated once the residual it is predicted to have, ρ_{k−1}²/ρ_{k−2}, is within
    // floor_margin/predict_factor of that floor (one correction earlier, not exact to the floor: a trade of
    // conservation for iterations, measured in §5.4 and §5.8). "auto", the default, is resolved by
    // initialize(): residual with full Newton; with modified Newton predicted, or floor when the system
    // prescribes displacements (their reaction work is taken from the last evaluated force, theory §5.8).
    // "energy" (theory §5.10) stops by em-galpha's modified-Newton rule instead of at the floor, with its setting names
    // and defaults: u_k unevaluated once the energy of its correction E_k = |Δu_k·r(u_{k−1})| is below cc_tol·E_1 (eq. 39)
    // or below e_floor times the energy the body holds, or the estimated energy of the next correction is
    // (docs/theory.md §6.5), or the correction is at round-off (step_tol). The balances then hold to that tolerance,
    // not to round-off.
    certify_ = s.get("certify", std::string("auto"));
    if (certify_ != "auto" && certify_ != "residual" && certify_ != "floor" && certify_ != "predicted" && certify_ != "energy")
      throw std::invalid_argument("em-exact.certify: '" + certify_ + "' (use auto, residual, floor, predicted or energy)");
    e_floor_ = s.get("e_floor", 1e-20);
    if (!(e_floor_ >= 0.0) || !std::isfinite(e_floor_))
      throw std::invalid_argument("em-exact.e_floor must be >= 0 (certify = energy: the energy floor relative to K + V, 0 = off, "
                                  "theory §5.10)");
    cc_tol_ = s.get("cc_tol", 1e-14);  // certify = energy: paper eq. 39's relative test E_k/E_1 (em-galpha's modified default)
    step_tol_ = s.get("step_tol", 1e-14);  // certify = energy: em-galpha's round-off fallback on the scaled correction
    if (!(cc_tol_ > 0.0) || !(step_tol_ >= 0.0))
      throw std::invalid_argument("em-exact: need cc_tol > 0 and step_tol >= 0 (certify = energy, theory §5.10)");
    floor_margin_ = s.get("floor_margin", 1.5);
    predict_factor_ = s.get("predict_factor", 1.0);
    if (!(predict_factor_ > 0.0) || !std::isfinite(predict_factor_))
      throw std::invalid_argument("em-exact.predict_factor must be > 0 (a safety factor on the predicted residual, theory §5.4)");
    if (!(res_tol_ > 0.0) || !(stall_tol_ >= 0.0) || !(stall_step_ >= 0.0) || !(stall_ratio_ > 0.0 && stall_ratio_ <= 1.0) ||
        max_iters_ < 1 || max_cuts_ < 0 || hysteresis_ < 1.0 || !(floor_margin_ >= 1.0))
      throw std::invalid_argument(
          "em-exact: need res_tol > 0, stall_tol >= 0, stall_step >= 0, 0 < stall_ratio <= 1, max_iters >= 1, max_cuts >= 0, "
          "hysteresis >= 1, floor_margin >= 1");
    resolved_ = s.resolved();
    char b[64];
    std::snprintf(b, sizeof b, "%.10g", dt_);
    resolved_.insert(resolved_.begin(), {"dt", b});
    std::snprintf(b, sizeof b, "%.10g", xi_);
    resolved_.emplace_back("xi_effective", b);
  }

  std::string name() const override { return "em-exact"; }
  // Joints and rigid bodies (docs/theory/multibody.md §9.4; step_constrained()).
  bool supports_constraints() const override { return true; }
  std::vector<std::pair<std::string, std::string>> settings() const override { return resolved_; }
  double external_work() const override { return work_; }
  double prescribed_work() const override { return prescribed_work_; }
  bool supports_prescribed_motion() const override { return true; }
  const Data& diagnostics() const override { return diag_; }
  bool set_residual_trace(ResidualTrace trace) override {
    residual_trace_ = std::move(trace);
    return true;
  }

  // Checkpoint (docs/architecture.md "Checkpoints and resume"): the State carries d, v and, in
  // State::pdot, the embedded director velocities w (theory §2), which the step needs exactly; the
  // directors p follow from q and the charts, also in the State. Beyond it a step depends on W_ext,
  // the step counter (messages), the last step size (a new h refreshes the iteration matrix) and, with
  // modified Newton, the K̄ in use and the iterations done with it: restore() makes the next setup
  // replay that K̄ and resume the refresh count, so the continued run is bitwise the uninterrupted
  // one. The diagnostics (EmExactDiagnostics) are saved too, so they cover the whole run.
  void save(IntegratorCheckpoint& c) const override {
    if (!newton_) throw std::logic_error("em-exact: save() before initialize()");
    c.exact = true;
    c.scalars["W_ext"] = work_;
    c.scalars["W_presc"] = prescribed_work_;
    c.scalars["steps"] = static_cast<double>(steps_);
    if (lambda_.size() > 0) c.vectors["lambda"] = lambda_;  // constrained steps: the next step's guess
    c.scalars["diag_dissipation"] = diag_.dissipation;
    c.scalars["diag_min_step_dissipation"] = diag_.min_step_dissipation;
    c.scalars["diag_max_residual"] = diag_.max_residual;
    c.scalars["diag_max_beta_z"] = diag_.max_beta_z;
    c.scalars["diag_rigid_guards"] = static_cast<double>(diag_.rigid_guards);
    c.scalars["diag_residual_work"] = diag_.residual_work;
    c.scalars["diag_unevaluated_steps"] = static_cast<double>(diag_.unevaluated_steps);
    c.scalars["diag_metric_switches"] = static_cast<double>(diag_.metric_switches);
    c.scalars["director_weight"] = director_weight_;  // the correction's metric in use (step_with_cuts)
    c.scalars["renew_steps"] = static_cast<double>(renew_steps_);  // the renewal rule's count (theory §5.5)
    c.scalars["renew_iterations"] = static_cast<double>(renew_iterations_);
    // certify = floor: the floors of the recent steps (the next step's acceptance depends on them).
    for (long j = 0; j < kFloorSteps; ++j) c.scalars["floor_" + std::to_string(j)] = recent_floor_[static_cast<size_t>(j)];
    c.vectors["director_acceleration"] = wdot_;  // the predictor's ẇ_n (theory §5.7)
    if (newmark_predictor_) {  // predictor = newmark: the recursion's end-point accelerations (theory §5.9)
      c.vectors["newmark_acceleration"] = an_;
      c.vectors["newmark_director_acceleration"] = wan_;
    }
    // 0 residual, 1 floor, 2 predicted, 3 energy
    c.scalars["certify_rule"] = energy_rule_ ? 3.0 : predicted_ ? 2.0 : certify_floor_ ? 1.0 : 0.0;
    c.scalars["energy0"] = energy0_;  // certify = energy: scale of the floor (initialize() would take the restored state's)
    kept_.save(c, *newton_, nopt_.modified);
  }

  void restore(SemiDiscreteSystem& sys, State& s, const IntegratorCheckpoint& c) override {
    if (!newton_ || model_ != &sys) throw std::logic_error("em-exact: restore() before initialize() (or on another system)");
    const Index n = sys.num_dofs();
    if (s.u.size() != n || s.v.size() != n || s.a.size() != n)
      throw std::runtime_error("em-exact: checkpoint state has the wrong size for this model");
    if (s.pdot.size() != 3 * nn_)
      throw std::runtime_error("em-exact: the checkpoint has no director velocities (State::pdot) for " +
                               std::to_string(nn_) + " nodes; it was not written by em-exact");
    work_ = c.scalar("W_ext");
    prescribed_work_ = c.scalars.count("W_presc") ? c.scalar("W_presc") : 0.0;
    steps_ = static_cast<long>(c.scalar("steps"));
    diag_.dissipation = c.scalar("diag_dissipation");
    diag_.min_step_dissipation = c.scalar("diag_min_step_dissipation");
    diag_.max_residual = c.scalar("diag_max_residual");
    diag_.max_beta_z = c.scalar("diag_max_beta_z");
    diag_.rigid_guards = static_cast<long>(c.scalar("diag_rigid_guards"));
    diag_.residual_work = c.scalars.count("diag_residual_work") ? c.scalar("diag_residual_work") : 0.0;
    diag_.unevaluated_steps = c.scalars.count("diag_unevaluated_steps") ? static_cast<long>(c.scalar("diag_unevaluated_steps")) : 0;
    diag_.metric_switches = c.scalars.count("diag_metric_switches") ? static_cast<long>(c.scalar("diag_metric_switches")) : 0;
    director_weight_ = c.scalars.count("director_weight") ? c.scalar("director_weight") : 0.0;
    renew_steps_ = c.scalars.count("renew_steps") ? static_cast<long>(c.scalar("renew_steps")) : 0;
    renew_iterations_ = c.scalars.count("renew_iterations") ? static_cast<long>(c.scalar("renew_iterations")) : 0;
    if (c.scalars.count("energy0")) energy0_ = c.scalar("energy0");
    for (long j = 0; j < kFloorSteps; ++j) {
      const std::string key = "floor_" + std::to_string(j);
      recent_floor_[static_cast<size_t>(j)] = c.scalars.count(key) ? c.scalar(key) : 0.0;
    }
    // The predictor's ẇ_n; absent from checkpoints written before it existed, whose runs then continue with ẇ_n = 0
    // for one step (not bitwise: their first step's predictor differs).
    if (c.vectors.count("director_acceleration"))
      wdot_ = c.vector("director_acceleration", 3 * nn_);
    else
      wdot_.setZero(3 * nn_);
    // predictor = newmark: the recursion's accelerations; a checkpoint without them (written with another predictor)
    // restarts the recursion from the consistent acceleration of the restored state (not bitwise, theory §5.9).
    if (newmark_predictor_ && c.vectors.count("newmark_acceleration") && c.vectors.count("newmark_director_acceleration")) {
      an_ = c.vector("newmark_acceleration", 3 * nn_);
      wan_ = c.vector("newmark_director_acceleration", 3 * nn_);
    } else if (newmark_predictor_) {
      start_newmark_recursion(s);
    }
    kept_.restore(c, *newton_, nopt_.modified, sys, "em-exact");
    if (c.vectors.count("lambda")) lambda_ = c.vector("lambda", sys.num_constraints());
    // certify = auto with modified Newton: a resumed run keeps the rule it started with (theory §5.8). A
    // checkpoint without the record was written when auto meant floor (before the fifteenth session). A run begun
    // with certify = energy (theory §5.10) continues with it too. These rules all skip the accepted iterate's
    // residual, so the solver initialize() built serves each.
    if (certify_ == "auto" && certify_floor_) {
      const double rule = c.scalars.count("certify_rule") ? c.scalar("certify_rule") : 1.0;
      if (rule == 1.0 || rule == 2.0 || rule == 3.0) use_certify(rule == 3.0 ? "energy" : rule == 2.0 ? "predicted" : "floor");
    }
  }

  void initialize(SemiDiscreteSystem& sys, State& s) override {
    model_ = dynamic_cast<ExactEnergySystem*>(&sys);
    if (!model_)
      throw std::invalid_argument("em-exact: needs a system with the ExactEnergySystem extension (lib/model/exact_energy_system.hpp: embedded director velocities, element energies), such as the CR9 shell Model; got another system");
    // Its embedded formulation takes nodal dead loads only (docs/manual.md §2.7–2.8): refuse what it would ignore.
    if (model_->has_damping() || model_->has_follower_loads())
      throw std::invalid_argument("em-exact: Rayleigh damping and follower pressures are not supported by this "
                                  "integrator (use em-galpha, or remove 'damping' / the follower_pressure loads)");
    const Index n = sys.num_dofs();
    nn_ = model_->num_nodes();
    // certify = auto (constructor): resolved here, where the system is known; run.json records the result.
    use_certify(certify_ != "auto"        ? certify_
                : !nopt_.modified             ? "residual"
                : sys.has_prescribed_motion() ? "floor"
                                              : "predicted");
    newton_ = std::make_unique<NewtonSolver>(sys.pattern(), nopt_);
    full_newton_.reset();
    director_weight_ = 0.0;  // the system's metric (step_with_cuts may switch it)
    M_ = SparseMatrix{sys.pattern(), std::vector<double>(static_cast<size_t>(sys.pattern()->nnz()), 0.0)};
    K_ = M_;
    for (Eigen::VectorXd* v : {&un_, &umid_, &fint_, &r_, &last_u_}) v->setZero(n);
    for (Eigen::VectorXd* v : {&wdot_, &an_, &wan_, &vn_, &wn_, &pn_, &p1_, &pmid_, &v1_, &w1_, &dv_, &dw_, &mv_, &mw_, &fd_, &g_}) v->setZero(3 * nn_);
    work_ = prescribed_work_ = 0.0;
    recent_floor_.fill(0.0);
    renew_steps_ = renew_iterations_ = 0;
    diag_ = Data{};
    diag_.min_step_dissipation = std::numeric_limits<double>::infinity();
    sys.rechart(s, hysteresis_);
    if (s.pdot.size() != 3 * nn_) {  // embedded director velocities from q̇: w_i = A1_i q̇_i (theory §2)
      s.pdot.setZero(3 * nn_);
      for (int i = 0; i < nn_; ++i) {
        const Index k = DofMap::dof(i, 3);
        s.pdot.segment<3>(3 * i) = director_A1(s.u.segment<2>(k), s.charts[static_cast<size_t>(i)]) * s.v.segment<2>(k);
      }
    }
    if (s.a.size() != n) s.a.setZero(n);
    if (sys.num_constraints() > 0 && sys.has_prescribed_motion())
      throw std::invalid_argument("em-exact: joints together with prescribed displacement histories are not supported "
                                  "(drive the motion through a prescribed_rotation joint instead)");
    lambda_.setZero(sys.num_constraints());
    bordered_.reset();
    bordered_full_.reset();
    {  // K + V at the start, with the embedded w just set: the scale of certify = energy's floor (theory §5.10)
      const Invariants inv = sys.invariants(s);
      energy0_ = std::abs(inv.kinetic) + std::abs(inv.strain);
    }
    if (newmark_predictor_) start_newmark_recursion(s);
    k0_.clear();
    if (xi_ > 0.0) {
      k0_.resize(static_cast<size_t>(model_->num_elements()));
      for (int e = 0; e < model_->num_elements(); ++e) k0_[static_cast<size_t>(e)] = model_->reference_local_stiffness(e);
    }
  }

  StepReport advance(SemiDiscreteSystem& sys, State& s, double t_out) override {
    if (!newton_ || model_ != &sys) throw std::logic_error("em-exact: advance() before initialize() (or on another system)");
    const auto start = std::chrono::steady_clock::now();
    StepReport rep;
    while (s.t < t_out - 1e-12 * dt_) {
      double h = std::min(dt_, t_out - s.t);
      if (t_out - (s.t + h) < 1e-9 * dt_) h = t_out - s.t;
      step_with_cuts(s, h, 0, rep);
      if (stop_requested()) break;  // at a step boundary: the driver checkpoints and stops
    }
    rep.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return rep;
  }

 private:
  // The floor rule in use (theory §5.3–5.4, §5.8): its flags, the solver option (read when initialize() builds the
  // solver; floor and predicted both skip the accepted iterate's residual) and the value settings() reports, a
  // valid setting, so that run.json's integrator block reruns as is.
  void use_certify(const std::string& rule) {
    certify_floor_ = (rule != "residual");
    predicted_ = (rule == "predicted");
    energy_rule_ = (rule == "energy");
    nopt_.skip_final_residual = certify_floor_;
    for (auto& kv : resolved_)
      if (kv.first == "certify") kv.second = rule;
  }

  void step_with_cuts(State& s, double h, int depth, StepReport& rep) {
    std::string why;
    if (step(s, h, rep, &why)) return;
    ++rep.rejected_steps;
    if (nopt_.modified) {
      if (step(s, h, rep, &why, true)) return;
      ++rep.rejected_steps;
    }
    // Then in the other metric of the correction (docs/theory/newton-iteration.md §4): the weighted one w = h ℓ_e
    // has a higher round-off floor on stiff bodies, the unweighted w = 1 stalls on thin plates (theory §3). A
    // step that succeeds only in the other metric makes it the one in use for the following steps. Unconstrained
    // steps only; each failed attempt counts as a rejected step.
    if (correction_ && model_->num_constraints() == 0 && model_->num_rigid_bodies() == 0) {
      director_weight_ = director_weight_ == 0.0 ? 1.0 : 0.0;
      if (step(s, h, rep, &why)) {
        ++diag_.metric_switches;
        return;
      }
      ++rep.rejected_steps;
      director_weight_ = director_weight_ == 0.0 ? 1.0 : 0.0;
    }
    if (depth >= max_cuts_) {
      // One line: where, why (the last attempt's), and the setting that would help (step()).
      std::string hint = hint_;
      if (max_cuts_ > 0 && hint.find("max_cuts=4") != std::string::npos)
        hint.replace(hint.find("max_cuts=4"), 10, "max_cuts=" + std::to_string(max_cuts_ + 2));
      throw StepFailure("em-exact: step " + std::to_string(steps_ + 1) + " at t = " + fmt(s.t) + " (dt = " + fmt(h) + ") failed" +
                        (max_cuts_ > 0 ? " after " + std::to_string(depth) + " cuts" : std::string()) + ": " + why + "; " + hint);
    }
    step_with_cuts(s, 0.5 * h, depth + 1, rep);
    step_with_cuts(s, 0.5 * h, depth + 1, rep);
  }

  // The round-off floor of the recent steps (certify = floor): the median of the smallest scaled residuals of
  // the last kFloorSteps steps, which follows slow drift (e.g. as the body moves away from the origin) and
  // ignores a single step far off; 0 until kFloorSteps steps have been taken. With certify = predicted the steps
  // stop short of the floor, so only every kFloorSteps-th step iterates to it and is recorded (measures_floor()):
  // the ring then spans kFloorSteps² steps.
  double floor_estimate() const {
    if (steps_ < kFloorSteps) return 0.0;
    std::array<double, kFloorSteps> f = recent_floor_;
    std::nth_element(f.begin(), f.begin() + kFloorSteps / 2, f.end());
    return f[kFloorSteps / 2];
  }

  // Whether the step about to be taken measures the floor (always but with certify = predicted, theory §5.4; never
  // with certify = energy, whose steps stop short of the floor and do not use it, theory §5.10).
  bool measures_floor() const { return !energy_rule_ && (!predicted_ || steps_ < kFloorSteps || steps_ % kFloorSteps == 0); }
  // The ring slot of the step about to be taken.
  size_t floor_slot() const {
    return static_cast<size_t>((predicted_ && steps_ >= kFloorSteps ? steps_ / kFloorSteps : steps_) % kFloorSteps);
  }

  // predictor = newmark (theory §5.9): the recursion starts from the acceleration that satisfies the equations
  // of motion at s (em-galpha's start-up, docs/theory.md §6.4): a = the translational entries, ẇ = A1 q̈ + A2(q, q̇).
  void start_newmark_recursion(const State& s) {
    Eigen::VectorXd a;
    consistent_acceleration(*model_, s, nopt_.linear_solver, a);
    for (int i = 0; i < nn_; ++i) {
      const Index k = DofMap::dof(i, 0);
      const DirectorChart& ch = s.charts[static_cast<size_t>(i)];
      const Eigen::Vector2d q = s.u.segment<2>(k + 3), qd = s.v.segment<2>(k + 3);
      an_.segment<3>(3 * i) = a.segment<3>(k);
      wan_.segment<3>(3 * i) = director_A1(q, ch) * a.segment<2>(k + 3) + director_A2(q, qd, ch);
    }
  }

  // Directors p(q) of all nodes (3 per node) in the step's charts.
  void directors(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, Eigen::VectorXd& p) const {
    for (int i = 0; i < nn_; ++i)
      p.segment<3>(3 * i) = director(u.segment<2>(DofMap::dof(i, 3)), charts[static_cast<size_t>(i)]);
  }

  // Midpoint quantities of the trial u_{n+1}: p_{n+1}, p_mid, v_{n+1}, w_{n+1}, M_d Δv/h, M_p Δw/h, loads.
  void kinematics(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, double h, double tmid) {
    directors(u, charts, p1_);
    pmid_ = 0.5 * (pn_ + p1_);
    for (int i = 0; i < nn_; ++i) {
      const Index k = DofMap::dof(i, 0);
      v1_.segment<3>(3 * i) = (2.0 / h) * (u.segment<3>(k) - un_.segment<3>(k)) - vn_.segment<3>(3 * i);
    }
    w1_ = (2.0 / h) * (p1_ - pn_) - wn_;
    const double rh = model_->translational_density(), rh3 = model_->director_density();  // ρh, ρh³/12
    dv_ = v1_ - vn_;
    dw_ = w1_ - wn_;
    model_->scalar_mass_times(dv_, dw_, mv_, mw_);
    mv_ *= rh / h;
    mw_ *= rh3 / h;
    model_->embedded_external(tmid, pmid_, fd_, g_);
  }

  bool step(State& s, double h, StepReport& rep, std::string* why, bool full_newton = false) {
    if (model_->num_constraints() > 0 || model_->num_rigid_bodies() > 0) return step_constrained(s, h, rep, why, full_newton);
    ExactEnergySystem& sys = *model_;
    rep.chart_switches += sys.rechart(s, hysteresis_);  // between steps only; d, p, v, w unchanged
    kept_.start_step(h, *newton_);  // K̄ depends on h
    if (full_newton && !full_newton_) {
      NewtonOptions full = nopt_;
      full.modified = false;
      full_newton_ = std::make_unique<NewtonSolver>(sys.pattern(), full);
    }
    NewtonSolver& newton = full_newton ? *full_newton_ : *newton_;
    const auto& charts = s.charts;
    const Index n = sys.num_dofs();
    const double t1 = s.t + h, tmid = s.t + 0.5 * h;
    un_ = s.u;
    for (int i = 0; i < nn_; ++i) vn_.segment<3>(3 * i) = s.v.segment<3>(DofMap::dof(i, 0));
    wn_ = s.pdot;
    directors(un_, charts, pn_);
    sys.step_energies(un_, charts, Un_);  // U(u_n) from the step's element state (no extra element pass)

    std::vector<double> history;  // scaled residual of every evaluated iterate
    double last_scale = 0.0;      // force scale of the last evaluated residual (the denominator of ρ)
    double best = std::numeric_limits<double>::infinity();
    ExactEnergySystem::ExactForceInfo finfo;
    int last_jacobian_iter = 0;

    auto residual = [&](const double* up, double* rp) {
      const Eigen::Map<const Eigen::VectorXd> u(up, n);
      Eigen::Map<Eigen::VectorXd> r(rp, n);
      const double scale = shell_residual(sys, u, charts, h, tmid, finfo, r);
      zero_constrained(sys.dofs(), rp);
      if (!r.allFinite()) throw std::runtime_error("non-finite residual");
      const double rn = r.cwiseAbs().maxCoeff();
      const double rel = rn == 0.0 ? 0.0 : rn / scale;
      last_scale = scale;
      history.push_back(rel);
      best = std::min(best, rel);
      // The accepted iterate is the last one evaluated, not the one with the smallest residual: at the
      // floor the smallest-residual iterate is usually an earlier one, still short of the solution on the
      // predictor's side, and its residual's work Δuᵀr is one-signed (theory §5.1).
      last_u_ = u;
      last_r_ = r;
    };
    bool replayed = false;
    // The kept K̄ seen from each iterate's midpoint configuration (docs/theory.md §6.9; modified Newton only).
    const NewtonSolver::BasisProvider basis =
        full_newton ? NewtonSolver::BasisProvider{}
                    : kept_.provider(sys, charts, [this, n](const double* u, Eigen::VectorXd& x) {
                        x = 0.5 * (Eigen::Map<const Eigen::VectorXd>(u, n) + un_);
                      });
    auto jacobian = [&](const double* up, SparseMatrix& J) {
      if (!full_newton && kept_.replay(J, newton, basis, up)) {  // first setup after restore(): the saved K̄, not a new one
        // The uninterrupted run reuses this K̄ from an earlier step here: last_jacobian_iter stays 0.
        replayed = true;
        kbar_row_sum_[0] = max_row_abs_sum(J);  // the saved K̄'s, as the uninterrupted run computed it
        return;
      }
      last_jacobian_iter = static_cast<int>(history.size());  // used for the iteration that follows
      const Eigen::Map<const Eigen::VectorXd> u(up, n);
      umid_ = 0.5 * (u + un_);
      // Theory §5: em-galpha's symmetric K̄ = (2/Δt²) M(u_mid) + ½ K_mid (+ ξ G), an approximate Jacobian.
      sys.mass(umid_, charts, M_);
      sys.exact_internal(un_, u, charts, Un_, false, xi_, xi_ > 0.0 ? &k0_ : nullptr, nullptr, &K_, nullptr, nullptr);
      sys.add_load_stiffness(tmid, umid_, charts, K_);
      const double cm = 2.0 / (h * h);
      for (size_t k = 0; k < J.values.size(); ++k) J.values[k] = cm * M_.values[k] + 0.5 * K_.values[k];
      apply_dirichlet(sys.dofs(), J, nullptr);
      kbar_row_sum_[full_newton ? 1 : 0] = max_row_abs_sum(J);
      if (nopt_.modified && !full_newton) kept_.keep(J, umid_, charts);  // for save()
    };
    double first_step = 0.0;  // scaled size of the first correction
    double prev_step = 0.0;   // scaled size of the previous correction (certify = predicted)
    const double recent_floor = floor_estimate();  // certify = floor, predicted
    const bool predict = predicted_ && !measures_floor();
    // The hook sees u_k, Δu_k and the residual history. With certify = residual it runs after r(u_k) was
    // evaluated (history ends with ρ_k). With certify = floor it runs before (the solver's
    // skip_final_residual: history ends with ρ_{k−1}); the residual and stall tests then accept the last
    // evaluated iterate u_{k−1} (the one the same tests accept with certify = residual; Δu_k is discarded)
    // and the floor test accepts u_k unevaluated (theory §5, §5.3).
    bool accept_last_evaluated = false;
    int gave_up = 0;  // the iterations done when the hook stopped the iteration (beyond max_iters, not contracting)
    // certify = energy (theory §5.10): em-galpha's floor on E_k = |Δu_k·r(u_{k−1})|, relative to the energy held.
    // Also as em-galpha: the paper's relative test E_k ≤ cc_tol·E_1 from the second correction on (eq. 39), and the
    // scaled correction max_i |Δu_k,i| / max(1, |u_n,i|) ≤ step_tol (round-off reached).
    EnergyFloorTest energy_floor(energy_rule_ ? e_floor_ * (energy0_ + std::abs(work_)) : 0.0, true);
    double energy_first = 0.0;  // E_1
    // The residual's round-off level (docs/theory/newton-iteration.md §3): one unit in the last place of every unknown,
    // max(1, ‖u_n‖∞)·ε, moves a row of the residual by up to Σ_j |K̄_ij| times it (K̄ is ∂r/∂u), so no iteration
    // gets ρ below ~ε·max_i Σ_j |K̄_ij|·max(1, ‖u_n‖∞) / scale. It grows with E (the membrane stiffness) and with the
    // mesh (stiffer elements), and a stall at or below it is the floor whatever stall_tol says.
    const double u_max = std::max(1.0, un_.cwiseAbs().maxCoeff());
    auto roundoff_level = [&] {  // ρ_ε of the last evaluated residual
      const double level = std::numeric_limits<double>::epsilon() * kbar_row_sum_[full_newton ? 1 : 0] * u_max;
      return last_scale > 0.0 ? level / last_scale : 0.0;
    };
    auto stall_ceiling = [&] { return std::max(stall_tol_, roundoff_level()); };
    auto hook = [&](int k, const double*, const double* du, const double* f) -> bool {
      const double rk = history.back();
      const double ceiling = stall_ceiling();
      const Eigen::Map<const Eigen::VectorXd> d(du, n);
      const double step = (d.cwiseAbs().array() * uscale_.array()).maxCoeff();
      if (k == 1) first_step = step;
      const double step_before = prev_step;
      prev_step = step;
      if (energy_rule_) {
        const double Ek = std::abs(d.dot(Eigen::Map<const Eigen::VectorXd>(f, n)));
        if (k == 1) energy_first = Ek;
        if ((k > 1 && Ek <= cc_tol_ * energy_first) || energy_floor.accept(Ek) || step <= step_tol_) {
          accept_last_evaluated = false;  // u_k, unevaluated (as em-galpha accepts it)
          return true;
        }
      }
      accept_last_evaluated = certify_floor_;
      if (rk <= res_tol_) return true;
      // Beyond max_iters only while the residual still contracts: at most half of what it was 4 evaluations earlier
      // (stiff bodies, where K̄ leaves out enough of the corrected force's tangent that the iteration contracts
      // only linearly, ~0.6 per iteration on the tumbling plate at E = 1e11).
      if (k > max_iters_ && (history.size() < 5 || rk > 0.5 * history[history.size() - 5])) {
        gave_up = k - 1;
        throw std::runtime_error("gave up");
      }
      double prev_best = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j + 1 < history.size(); ++j) prev_best = std::min(prev_best, history[j]);
      const bool converged_step = step <= stall_step_ * first_step;
      if (rk <= ceiling && rk > stall_ratio_ * prev_best) {
        // Stagnation at the round-off floor if the iteration matrix was fresh, or if the corrections have
        // already shrunk by stall_step relative to the first (the iteration converged; what stalls is the
        // residual's round-off, theory §5), or if the residual is at the floor of the recent steps; otherwise
        // refresh the matrix first.
        // (With certify = floor, "converged_step" reads Δu_k, one correction later than the stalled u_{k−1}.)
        // A stall within floor_margin of the recent steps' floor is that floor too (theory §5.7): the corrections
        // at the floor are round-off, and measured against the first correction they are larger the better the
        // predictor was, so without it a good predictor turned stalls at the floor into refreshes of K̄.
        if (last_jacobian_iter >= k - 1 || converged_step || (recent_floor > 0.0 && rk <= floor_margin_ * recent_floor))
          return true;
        newton.invalidate_jacobian();
        return false;
      }
      // certify = floor (theory §5.3): u_{k−1} is at the round-off floor when its residual is within
      // floor_margin of the floor of the recent steps; u_k = u_{k−1} + Δu_k is then the iterate that the
      // stall rule accepts after evaluating r(u_k), and it is accepted without that residual.
      accept_last_evaluated = false;
      if (certify_floor_ && recent_floor > 0.0 && converged_step && rk <= ceiling && rk <= floor_margin_ * recent_floor)
        return true;
      // certify = predicted (theory §5.4): u_k unevaluated when the iteration contracts (residual and correction)
      // and the residual it predicts for u_k, ρ_{k−1}·(ρ_{k−1}/ρ_{k−2}), is within the floor's margin. Not from
      // ρ_1/ρ_0: the first correction removes the predictor's error far better than the later ones contract
      // (hemisphere: 1e-7 against 1e-3), so that ratio would predict the floor two corrections too early.
      if (!predict || recent_floor <= 0.0 || history.size() < 3 || rk > ceiling) return false;
      const double rp = history[history.size() - 2];
      return rk < rp && step < 0.5 * step_before && predict_factor_ * rk * (rk / rp) <= floor_margin_ * recent_floor;
    };

    Eigen::VectorXd u = un_;  // predictor u_{n+1} = u_n (theory §5)
    if (predictor_ && !full_newton) {  // trapezoidal extrapolation (constructor); directors through their chart
      for (int i = 0; i < nn_; ++i) {
        const Index k = DofMap::dof(i, 0);
        const Vec3 a = newmark_predictor_ ? Vec3(an_.segment<3>(3 * i)) : Vec3(s.a.segment<3>(k));
        u.segment<3>(k) += h * vn_.segment<3>(3 * i) + (0.5 * h * h) * a;
        Vec3 p = pn_.segment<3>(3 * i) + h * wn_.segment<3>(3 * i);
        if (director_acceleration_)
          p += (0.5 * h * h) * (newmark_predictor_ ? Vec3(wan_.segment<3>(3 * i)) : Vec3(wdot_.segment<3>(3 * i)));
        u.segment<2>(k + 3) = chart_coordinates(p.normalized(), charts[static_cast<size_t>(i)]);
      }
      for (Index d : sys.dofs().constrained_dofs()) u[d] = un_[d];  // constrained entries stay bitwise u_n
    }
    sys.prescribed_displacement(t1, u.data());  // prescribed DOFs at g(t_{n+1}) (docs/theory.md §8.6)
    last_u_ = u;
    last_r_.setZero(n);
    // Scale of the unknowns 1/max(1, |u_n,i|): the solver's round-off guard of the contraction test is relative.
    uscale_ = (1.0 / un_.array().abs().max(1.0)).matrix();
    const NewtonSolver::Result r = newton.solve(u.data(), residual, jacobian, nullptr, uscale_.data(), hook, basis);
    if (full_newton) newton_->invalidate_jacobian();
    // The renewal rule (theory §5.5), modified Newton only: after a step that kept K̄, refresh it for the next
    // step when this step's iterations exceed the average since the last refresh, (refresh_cost + Σ it)/steps.
    // A replayed K̄ (restore()) is the uninterrupted run's, not a refresh.
    if (refresh_cost_ > 0.0 && nopt_.modified && !full_newton && r.converged) {
      if (r.jacobian_evals - (replayed ? 1 : 0) > 0) {
        renew_steps_ = 0;
        renew_iterations_ = 0;
      } else {
        ++renew_steps_;
        renew_iterations_ += r.iterations;
        if (static_cast<double>(r.iterations) * static_cast<double>(renew_steps_) >
            refresh_cost_ + static_cast<double>(renew_iterations_))
          newton.invalidate_jacobian();
      }
    }
    rep.nonlinear_iterations += r.iterations;
    // A replayed K̄ (restore()) is the uninterrupted run's matrix, not a new setup: not counted.
    rep.linear_setups += r.jacobian_evals - (replayed ? 1 : 0);
    rep.factorizations += r.factorizations - (replayed ? 1 : 0);
    rep.rhs_evaluations += r.residual_evals;
    rep.residual_norm = history.empty() ? 0.0 : history.back();
    if (!r.converged) {
      // One short, true line (docs/theory/newton-iteration.md §4): the last scaled residual, the lowest one only if
      // it is lower, and the setting that would help: a stall above the round-off ceiling asks for stall_tol, an
      // iteration that diverged or crawled for smaller steps (max_cuts).
      char b[200];
      const double last = history.empty() ? std::numeric_limits<double>::quiet_NaN() : history.back();
      double prev_best = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j + 1 < history.size(); ++j) prev_best = std::min(prev_best, history[j]);
      const bool stalled = history.size() >= 3 && last <= 1e-3 && last > stall_ratio_ * prev_best;
      if (r.stop_reason == NewtonSolver::StopReason::max_iters || gave_up > 0) {
        std::snprintf(b, sizeof b, "no convergence in %d iterations, scaled residual %.3g", gave_up > 0 ? gave_up : r.iterations, last);
        *why = b;
        if (best < last) {
          std::snprintf(b, sizeof b, " (lowest %.3g)", best);
          *why += b;
        }
      } else {
        *why = r.message.substr(0, r.message.find_first_of(";\n"));
        if (why->size() > 100) *why = why->substr(0, 97) + "...";
      }
      if (stalled && last > stall_ceiling()) {  // stalled above max(stall_tol, round-off level): accept it, or cut
        std::snprintf(b, sizeof b, "%.0e", 3.0 * last);
        *why += ", stalled above " + fmt(stall_ceiling());
        hint_ = "set max_cuts=4 (halve the step) or stall_tol=" + std::string(b);
      } else if (r.stop_reason == NewtonSolver::StopReason::max_iters) {  // still contracting at 2 max_iters
        hint_ = "set max_iters=" + std::to_string(2 * max_iters_) + " (still converging) or max_cuts=4 (halve the step)";
      } else {
        hint_ = "set max_cuts=4 (halve the step)";
      }
      return false;
    }
    if (residual_trace_) residual_trace_(history, r.iterations);  // ρ_k as the stopping rule sees it (theory §5)
    // The accepted iterate: the last evaluated one, or (certify = floor, floor test) the solver's u_k,
    // accepted before its residual was evaluated.
    const bool evaluated = !certify_floor_ || accept_last_evaluated;
    if (evaluated) u = last_u_;
    // The floor of this step for the next ones: its smallest scaled residual (an iterate at the floor).
    if (measures_floor()) recent_floor_[floor_slot()] = *std::min_element(history.begin(), history.end());
    // Final quantities at the accepted iterate.
    kinematics(u, charts, h, tmid);
    if (xi_ > 0.0) {
      ExactEnergySystem::ExactForceInfo fi;
      sys.exact_internal(un_, u, charts, Un_, correction_, xi_, &k0_, fint_.data(), nullptr, nullptr, &fi, &pmid_,
                         director_weight_);  // the metric the step converged in
      diag_.dissipation += fi.dissipation;
      diag_.min_step_dissipation = std::min(diag_.min_step_dissipation, fi.dissipation);
      diag_.max_beta_z = std::max(diag_.max_beta_z, fi.max_beta_z);
      diag_.rigid_guards += fi.rigid_guards;
    } else {
      diag_.max_beta_z = std::max(diag_.max_beta_z, finfo.max_beta_z);
      diag_.rigid_guards += finfo.rigid_guards;
      diag_.min_step_dissipation = std::min(diag_.min_step_dissipation, 0.0);
    }
    diag_.max_residual = std::max(diag_.max_residual, rep.residual_norm);
    if (evaluated)
      diag_.residual_work += (u - un_).dot(last_r_);  // constrained rows of r are zero
    else
      ++diag_.unevaluated_steps;
    // External work as the scheme evaluates it (theory §4): F_ext(t_mid)·Δd + Σ g_i·Δp_i.
    double dw = g_.dot(p1_ - pn_);
    for (int i = 0; i < nn_; ++i) {
      const Index k = DofMap::dof(i, 0);
      dw += fd_.segment<3>(3 * i).dot(u.segment<3>(k) - un_.segment<3>(k));
    }
    work_ += dw;
    // Reaction work of the prescribed translations (docs/theory.md §8.6): their rows of the translational
    // balance, Σ (M_d Δv/Δt + F*_int − F_ext(t_mid))_c Δd_c, at the accepted iterate. fint_ is its force, or
    // with certify = floor that of the iterate before, which differs from it by a correction at the round-off
    // floor (PrescribedMotion.EnergyBalanceClosesWithThePrescribedWork: 3.9e-14 either way).
    for (Index dof : sys.prescribed_dofs()) {
      const Index i = dof / kDofsPerNode, c = dof % kDofsPerNode;
      prescribed_work_ += (mv_[3 * i + c] + fint_[dof] - fd_[3 * i + c]) * (u[dof] - un_[dof]);
    }
    wdot_ = (w1_ - wn_) / h;  // Δw/Δt: the q̈ entries below, and ẇ_n of the next step's predictor (theory §5.7)
    if (newmark_predictor_) {  // theory §5.9: a_{n+1} = 2 Δv/Δt − a_n, ẇ_{n+1} = 2 Δw/Δt − ẇ_n (exact for any Δt)
      an_ = (2.0 / h) * dv_ - an_;  // dv_ = v_{n+1} − v_n of the accepted iterate (kinematics() above)
      wan_ = 2.0 * wdot_ - wan_;
    }
    accept_step(s, u, t1, h, charts, rep);
    return true;
  }

  // ---- Constrained step: joints and rigid bodies (docs/theory/multibody.md §9.4) -------------------------------
  // step()'s balance with the constraint force Ḡᵀλ, Ḡ = Ḡ(u_n, u_{n+1}) the system's discrete gradient (Ḡ Δu + τ =
  // Δg exactly), and g(u_{n+1}, t_{n+1}) = 0. The rigid bodies' blocks (ExactEnergySystem::rigid_block, constant
  // mass M_b) take the midpoint rule with embedded velocities like the shell translations:
  //     M_b (v_{n+1} − v_n)/Δt + F_b − F_ext,b(t_mid) = 0,      v_{n+1} = 2Δq_b/Δt − v_n,
  // so that their K is conserved exactly (constant M_b) and their momenta (3.4) too. The energy identity of step()
  // gains −λ·ḠΔu = −λ·(Δg − τ) = λ·τ (g_n = g_{n+1} = 0): ΔK + ΔV = W_ext + λ·τ, λ·τ (a driver's work) counted in
  // W_presc. The iteration is BorderedNewton's (bordered_newton.hpp; K̄ = (2/Δt²)M + ½K + ∂(Ḡᵀλ)/∂u_{n+1}), which
  // stops at ‖r + Ḡᵀλ‖∞/scale ≤ res_tol and ‖g‖∞ ≤ 1e-12, or at the residual's round-off floor; the stall, floor and
  // predicted rules of step() are not used here.
  bool step_constrained(State& s, double h, StepReport& rep, std::string* why, bool full_newton) {
    ExactEnergySystem& sys = *model_;
    rep.chart_switches += sys.rechart(s, hysteresis_);
    std::unique_ptr<BorderedNewton>& bn = full_newton ? bordered_full_ : bordered_;
    if (!bn) {
      BorderedNewtonOptions o;
      o.linear_solver = nopt_.linear_solver;
      o.max_iters = max_iters_;
      o.res_tol = res_tol_;
      o.stall_tol = stall_tol_;
      o.refresh = (nopt_.modified && !full_newton) ? 0.1 : 0.0;
      bn = std::make_unique<BorderedNewton>(sys.pattern(), o);
    }
    const auto& charts = s.charts;
    const Index n = sys.num_dofs(), m = sys.num_constraints();
    const double tn = s.t, t1 = s.t + h, tmid = s.t + 0.5 * h;
    un_ = s.u;
    for (int i = 0; i < nn_; ++i) vn_.segment<3>(3 * i) = s.v.segment<3>(DofMap::dof(i, 0));
    wn_ = s.pdot;
    directors(un_, charts, pn_);
    sys.step_energies(un_, charts, Un_);
    const Eigen::VectorXd vrb_n = s.v;  // rigid blocks' velocities (their entries)
    Eigen::VectorXd fext_rb(n), tau;
    ExactEnergySystem::ExactForceInfo finfo;
    const int nb = sys.num_rigid_bodies();
    BorderedNewton::Callbacks cb;
    cb.residual = [&](const Eigen::VectorXd& u, Eigen::VectorXd& r) {  // step()'s residual, plus the rigid blocks
      r.setZero(n);
      double scale = shell_residual(sys, u, charts, h, tmid, finfo, r);
      if (nb > 0) {
        umid_ = 0.5 * (u + un_);
        sys.external(tmid, umid_, charts, fext_rb.data());  // dead loads (gravity) on the bodies at t_mid
      }
      for (int b = 0; b < nb; ++b) {
        const ExactEnergySystem::RigidBlock blk = sys.rigid_block(b);
        const Index k = blk.first_dof;
        Eigen::Matrix<double, 12, 1> md;
        md << Eigen::Vector3d::Constant(blk.mass), Eigen::Vector3d::Constant(blk.E[0]), Eigen::Vector3d::Constant(blk.E[1]),
            Eigen::Vector3d::Constant(blk.E[2]);
        const Eigen::Matrix<double, 12, 1> dv = (2.0 / h) * (u.segment<12>(k) - un_.segment<12>(k)) - 2.0 * vrb_n.segment<12>(k);
        const Eigen::Matrix<double, 12, 1> inertia = md.cwiseProduct(dv) / h;
        r.segment<12>(k) = inertia + fint_.segment<12>(k) - fext_rb.segment<12>(k);
        scale = std::max({scale, inertia.cwiseAbs().maxCoeff(), fint_.segment<12>(k).cwiseAbs().maxCoeff(),
                          fext_rb.segment<12>(k).cwiseAbs().maxCoeff()});
      }
      zero_constrained(sys.dofs(), r.data());
      last_u_ = u;
      return std::max(scale, 1e-300);
    };
    cb.jacobian = [&](const Eigen::VectorXd& u, SparseMatrix& J) {  // step()'s K̄; the rigid blocks' is (2/Δt²) M_b
      umid_ = 0.5 * (u + un_);
      sys.mass(umid_, charts, M_);
      sys.exact_internal(un_, u, charts, Un_, false, xi_, xi_ > 0.0 ? &k0_ : nullptr, nullptr, &K_, nullptr, nullptr);
      sys.add_load_stiffness(tmid, umid_, charts, K_);
      const double cm = 2.0 / (h * h);
      for (size_t k = 0; k < J.values.size(); ++k) J.values[k] = cm * M_.values[k] + 0.5 * K_.values[k];
    };
    cb.force_matrix = [&](const Eigen::VectorXd& u, BorderedNewton::ConstraintMatrix& Gh) {
      sys.constraint_discrete_gradient(tn, un_, t1, u, charts, Gh, tau);
    };
    cb.force_tangent = [&](const Eigen::VectorXd& u, const Eigen::VectorXd& l, SparseMatrix& J) {
      sys.add_constraint_discrete_tangent(tn, un_, t1, u, charts, l, 1.0, J);
    };
    cb.constraints = [&](const Eigen::VectorXd& u, Eigen::VectorXd& g, BorderedNewton::ConstraintMatrix& G) {
      sys.constraint_values(t1, u, charts, g);
      sys.constraint_jacobian(t1, u, charts, G);
    };
    Eigen::VectorXd u = un_;  // predictor u_n (the trapezoidal one is step()'s)
    Eigen::VectorXd lambda = lambda_;
    const BorderedNewton::Result r = bn->solve(sys.dofs(), un_, u, lambda, m, cb);
    rep.nonlinear_iterations += r.iterations;
    rep.linear_setups += r.factorizations;
    rep.factorizations += r.factorizations;
    rep.rhs_evaluations += r.residual_evals;
    rep.residual_norm = r.residual;
    if (!r.converged) {
      *why = r.message;
      hint_ = "set max_cuts=4 (halve the step)";
      return false;
    }
    lambda_ = lambda;
    u = last_u_;  // the accepted iterate was the last evaluated one (kinematics() and fint_ are its)
    diag_.max_residual = std::max(diag_.max_residual, r.residual);
    diag_.max_beta_z = std::max(diag_.max_beta_z, finfo.max_beta_z);
    diag_.rigid_guards += finfo.rigid_guards;
    diag_.min_step_dissipation = std::min(diag_.min_step_dissipation, 0.0);
    {  // the drivers' discrete work λ·τ (multibody.md (2.3))
      BorderedNewton::ConstraintMatrix Gb;
      sys.constraint_discrete_gradient(tn, un_, t1, u, charts, Gb, tau);
      if (tau.size() == m) prescribed_work_ += lambda.dot(tau);
    }
    double dw = g_.dot(p1_ - pn_);  // external work as step() (theory §4), plus the bodies' loads
    for (int i = 0; i < nn_; ++i) {
      const Index k = DofMap::dof(i, 0);
      dw += fd_.segment<3>(3 * i).dot(u.segment<3>(k) - un_.segment<3>(k));
    }
    for (int b = 0; b < nb; ++b) {
      const Index k = sys.rigid_block(b).first_dof;
      dw += fext_rb.segment<12>(k).dot(u.segment<12>(k) - un_.segment<12>(k));
      s.v.segment<12>(k) = (2.0 / h) * (u.segment<12>(k) - un_.segment<12>(k)) - vrb_n.segment<12>(k);
      s.a.segment<12>(k) = (s.v.segment<12>(k) - vrb_n.segment<12>(k)) / h;
    }
    work_ += dw;
    wdot_ = (w1_ - wn_) / h;
    accept_step(s, u, t1, h, charts, rep);
    return true;
  }
  // The shell nodes' residual at the iterate u (step() and step_constrained()): kinematics(), the corrected element
  // forces in the metric in use, then per node the translational balance and the director balance projected by
  // A1(p_mid)ᵀ (theory §2 / §4), written into the nodes' entries of r. Returns the force scale (the denominator of ρ).
  double shell_residual(ExactEnergySystem& sys, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                        double h, double tmid, ExactEnergySystem::ExactForceInfo& finfo, Eigen::Ref<Eigen::VectorXd> r) {
    kinematics(u, charts, h, tmid);
    sys.exact_internal(un_, u, charts, Un_, correction_, xi_, xi_ > 0.0 ? &k0_ : nullptr, fint_.data(), nullptr, nullptr,
                       &finfo, &pmid_, director_weight_);  // p_mid from kinematics() just above
    double scale = 0.0;
    for (int i = 0; i < nn_; ++i) {
      const Index k = DofMap::dof(i, 0);
      const Vec3 Ad = mv_.segment<3>(3 * i), Ap = mw_.segment<3>(3 * i);
      const Vec3 fd = fd_.segment<3>(3 * i), g = g_.segment<3>(3 * i);
      r.segment<3>(k) = Ad + fint_.segment<3>(k) - fd;
      const DirectorChart& ch = charts[static_cast<size_t>(i)];
      r.segment<2>(k + 3) = embedded_A1(Vec3(pmid_.segment<3>(3 * i)), ch).transpose() * (Ap - g) + fint_.segment<2>(k + 3);
      scale = std::max({scale, Ad.cwiseAbs().maxCoeff(), Ap.cwiseAbs().maxCoeff(), fd.cwiseAbs().maxCoeff(),
                        g.cwiseAbs().maxCoeff(), fint_.segment<5>(k).cwiseAbs().maxCoeff()});
    }
    return scale;
  }

  // The accepted step's end state of the shell nodes (step() and step_constrained()): v, w from the trapezoidal
  // relations; q̇ and q̈ entries hold the chart's minor components of w and Δw/Δt (for output only: the scheme's state
  // is (d, p, v, w)); a_d = Δv/Δt.
  void accept_step(State& s, const Eigen::VectorXd& u, double t1, double h, const std::vector<DirectorChart>& charts,
                   StepReport& rep) {
    for (int i = 0; i < nn_; ++i) {
      const Index k = DofMap::dof(i, 0);
      const DirectorChart& ch = charts[static_cast<size_t>(i)];
      s.v.segment<3>(k) = v1_.segment<3>(3 * i);
      s.a.segment<3>(k) = (v1_.segment<3>(3 * i) - vn_.segment<3>(3 * i)) / h;
      s.v.segment<2>(k + 3) = chart_coordinates(Vec3(w1_.segment<3>(3 * i)), ch);
      s.a.segment<2>(k + 3) = chart_coordinates(Vec3(wdot_.segment<3>(3 * i)), ch);
    }
    s.pdot = w1_;
    s.u = u;
    s.t = t1;
    ++steps_;
    ++rep.steps;
    rep.last_dt = h;
  }

  std::unique_ptr<BorderedNewton> bordered_, bordered_full_;  // constrained steps (full: the retry)
  Eigen::VectorXd lambda_;                                    // the last step's multipliers (the next guess)

  double dt_;
  double xi_ = 0.0;
  NewtonOptions nopt_;
  double res_tol_ = 1e-12, stall_tol_ = 1e-6, stall_ratio_ = 0.5, stall_step_ = 1e-6;
  bool predictor_ = false;
  int max_cuts_ = 0;
  int max_iters_ = 25;    // the max_iters setting (the solvers get 2 max_iters: the hook's contraction rule)
  double hysteresis_ = 1.0;
  bool correction_ = true;
  std::string certify_;          // the setting: auto, residual, floor, predicted or energy (auto resolved by initialize())
  bool certify_floor_ = false;  // certify = floor or predicted (theory §5.3)
  bool predicted_ = false;      // certify = predicted (theory §5.4)
  bool energy_rule_ = false;    // certify = energy (theory §5.10)
  double e_floor_ = 1e-20;      // its floor relative to energy0_ + |W_ext|
  double cc_tol_ = 1e-14;       // relative test E_k/E_1
  double step_tol_ = 1e-14;     // scaled-correction test
  double energy0_ = 0.0;        // K + V at initialize()
  double floor_margin_ = 1.5;
  double predict_factor_ = 1.0;
  double refresh_cost_ = 0.0;   // renewal rule (theory §5.5); 0 = off
  double kbar_row_sum_[2] = {0.0, 0.0};  // max_i Σ_j |K̄_ij| of the last K̄ of the modified [0] and full [1] solver
  std::string hint_;  // the setting that would help the last failed step (step_with_cuts' message)
  double director_weight_ = 0.0;  // the correction's metric in use (exact_internal): 0 = the system's w, or 1
  long renew_steps_ = 0;        // steps since the last refresh of K̄
  long renew_iterations_ = 0;   // their iterations
  static constexpr long kFloorSteps = 16;
  std::array<double, kFloorSteps> recent_floor_{};
  std::vector<std::pair<std::string, std::string>> resolved_;

  ExactEnergySystem* model_ = nullptr;
  int nn_ = 0;
  std::unique_ptr<NewtonSolver> newton_, full_newton_;
  SparseMatrix M_, K_;
  std::vector<ExactEnergySystem::ElementStiffness> k0_;
  std::vector<double> Un_;
  // The last step's director accelerations (w_{n+1} − w_n)/Δt in ℝ³ (3 per node; 0 before the first step): the
  // predictor's ẇ_n. Chart-free, so a chart switch between steps does not touch it; saved in checkpoints.
  Eigen::VectorXd wdot_;
  bool director_acceleration_ = false;  // predictor = trapezoidal or newmark (theory §5.7)
  bool newmark_predictor_ = false;      // predictor = newmark (theory §5.9)
  Eigen::VectorXd an_, wan_;            // its end-point accelerations a_n, ẇ_n (3 per node, ℝ³)
  ResidualTrace residual_trace_;        // set_residual_trace()
  Eigen::VectorXd un_, umid_, fint_, r_, last_u_, last_r_, uscale_;
  Eigen::VectorXd vn_, wn_, pn_, p1_, pmid_, v1_, w1_, dv_, dw_, mv_, mw_, fd_, g_;
  double work_ = 0.0, prescribed_work_ = 0.0;
  long steps_ = 0;
  Data diag_;
  KeptIterationMatrix kept_;  // the modified solver's K̄ across steps and checkpoints
};

}  // namespace

std::unique_ptr<Integrator> make_em_exact(IntegratorSettings& s, double dt) { return std::make_unique<EmExact>(s, dt); }

}  // namespace shelldyn
