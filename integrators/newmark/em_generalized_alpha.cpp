#include "integrators/newmark/em_generalized_alpha.hpp"

#include "integrators/newmark/bordered_newton.hpp"
#include "integrators/newmark/consistent_acceleration.hpp"
#include "integrators/newmark/kept_iteration_matrix.hpp"
#include "integrators/nonlinear/energy_floor_test.hpp"
#include "integrators/nonlinear/newton_solver.hpp"
#include "lib/model/assembler.hpp"
#include "lib/linalg/linear_solver.hpp"
#include "lib/analysis/profile.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace shelldyn {

GeneralizedAlphaParameters generalized_alpha_parameters(double rho_inf) {
  if (!(rho_inf >= 0.0 && rho_inf <= 1.0))
    throw std::invalid_argument((std::ostringstream() << "rho_inf = " << rho_inf << " is outside [0, 1]").str());
  // docs/theory.md §6.1 (Chung–Hulbert; Kuhl–Crisfield GEMM convention x_{n+1−α} = (1−α)x_{n+1} + α x_n).
  GeneralizedAlphaParameters p;
  p.alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
  p.alpha_f = rho_inf / (rho_inf + 1.0);
  p.gamma = 0.5 - p.alpha_m + p.alpha_f;
  p.beta = 0.25 * (1.0 - p.alpha_m + p.alpha_f) * (1.0 - p.alpha_m + p.alpha_f);
  return p;
}

namespace {

enum class Scheme { EmGalpha, Midpoint, Galpha, Newmark };

class NewmarkFamily final : public Integrator {
 public:
  NewmarkFamily(Scheme scheme, std::string name, IntegratorSettings& s, double dt)
      : scheme_(scheme), name_(std::move(name)), dt_(dt) {
    auto g = [](double x) {
      char b[32];
      std::snprintf(b, sizeof b, "%.10g", x);
      return std::string(b);
    };
    if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument(name_ + ": time step dt must be > 0");
    if (scheme_ == Scheme::Newmark) {
      p_.alpha_m = p_.alpha_f = 0.0;
      p_.beta = s.get("beta", 0.25);
      p_.gamma = s.get("gamma", 0.5);
      if (!(p_.beta > 0.0) || !(p_.gamma >= 0.5))
        throw std::invalid_argument(name_ + ": need beta > 0 and gamma >= 0.5 (got beta = " + g(p_.beta) + ", gamma = " +
                                    g(p_.gamma) + ")");
    } else {
      p_ = generalized_alpha_parameters(s.get("rho_inf", 1.0));
    }
    if (scheme_ == Scheme::EmGalpha) {
      xi_ = s.get("xi", 0.0);
      if (!(xi_ >= 0.0 && xi_ < 0.5)) throw std::invalid_argument(name_ + ": xi must be in [0, 0.5)");
    }
    // Modified Newton by default (docs/theory/newton-iteration.md §1): K̄ factorized once and kept over iterations
    // and steps, carried through the body's rotation (kbar_basis = corotated, docs/theory.md §6.9), the Newmark
    // predictor and the energy-floor stopping rule below: the settings the benchmark case files asked for, now for
    // every case (apps/cases/spinning-plate.yaml: 1 factorization instead of 840 in 200 steps). A stale K̄ can still
    // fail where stiff elements turn fast as rigid bodies (the rotated elastic stiffness leaks into the soft
    // rigid-body directions), so a step that fails under modified Newton is retried with full Newton before any
    // step cutting (test EmGeneralizedAlpha.KeptKbarFollowsTheBodysRotation). newton = full is the paper's §6.4.
    const std::string newton = s.get("newton", "modified");
    if (newton != "full" && newton != "modified")
      throw std::invalid_argument(name_ + ".newton: '" + newton + "' (use full or modified)");
    nopt_.modified = (newton == "modified");
    // Refresh of a kept K̄ by observed contraction θ = ‖Δu_k‖/‖Δu_{k−1}‖ (integrators/nonlinear/newton_solver.hpp):
    // refresh = 0 keeps the fixed count setup_every; refresh > 0 refreshes when θ exceeds it.
    nopt_.refresh_contraction = s.get("refresh", nopt_.modified ? 0.1 : 0.0);
    nopt_.max_setup_calls = s.get("setup_every", nopt_.refresh_contraction > 0 ? 1000000 : 20);
    // How a kept K̄ is carried to later configurations (docs/theory.md §6.9; kept_iteration_matrix.hpp).
    kept_.set_basis(KeptIterationMatrix::parse_basis(s.get("kbar_basis", std::string("corotated")), name_));
    // Predictor (§6.4 uses u_{n+1}^(0) = u_n): "newmark" starts from the constant-acceleration prediction
    // u_n + Δt v_n + Δt²/2 a_n, for which the Newmark relations give ü_{n+1}^(0) = a_n.
    const std::string predictor = s.get("predictor", nopt_.modified ? "newmark" : "none");
    if (predictor != "none" && predictor != "newmark")
      throw std::invalid_argument(name_ + ".predictor: '" + predictor + "' (use none or newmark)");
    newmark_predictor_ = (predictor == "newmark");
    // Absolute floor of the energy criterion, in the system's energy units (docs/theory.md §6.5): accept u_k
    // once E_k = |Δu_k·P̄(u_{k−1})| ≤ e_floor·E_sys, E_sys = K_0 + V_0 + |W_ext| (the energy the body holds).
    // E_k ≈ P̄ᵀK̄⁻¹P̄ is quadratic in the residual, and the energy of a whole step in the K̄ norm is
    // ΔuᵀK̄Δu ≈ 2(1−α_m)/β K ≤ 4 E_sys, so e_floor = 1e-20 asks for a residual ≈ 1e-10 of the force that drives
    // the step: the level at which cc ≤ 1e-20 stopped with the predictor u_n (whose E_0 is that step energy),
    // independent of how good the predictor is. The paper's cc = E_k/E_0 is relative to the predictor's E_0,
    // which the Newmark predictor makes small: its round-off floor (measured: cc stalls at ~1e-14 on the
    // flying plate at t ≈ 10 s, 70 m from the origin) then lies above any cc_tol that works with u_n.
    e_floor_ = s.get("e_floor", nopt_.modified ? 1e-20 : 0.0);
    if (!(e_floor_ >= 0.0)) throw std::invalid_argument(name_ + ": e_floor must be >= 0");
    // floor_test (docs/theory.md §6.5): "correction" accepts u_k once its own correction E_k is below the floor,
    // which bounds the error of u_{k−1}; "estimate" also accepts u_k once the estimated energy of the next
    // correction is (one iteration fewer where the iteration contracts steadily).
    const std::string floor_test = s.get("floor_test", std::string(nopt_.modified ? "estimate" : "correction"));
    if (floor_test != "correction" && floor_test != "estimate")
      throw std::invalid_argument(name_ + ".floor_test: '" + floor_test + "' (use correction or estimate)");
    floor_estimate_ = (floor_test == "estimate");
    // CHOLMOD's supernodal Cholesky by default (simplicial LDLᵀ if K̄ is ever indefinite, lib/linalg/linear_solver.hpp):
    // with its hidden threads switched off it factorizes the hemisphere's K̄ in ~0.8x and solves in ~0.6x the
    // CPU time of Eigen's simplicial LDLᵀ, and with a kept factorization the solves dominate
    // (benchmarks/bench_step_breakdown.cpp).
    nopt_.linear_solver = s.get("linear_solver", "cholmod");
    make_linear_solver(nopt_.linear_solver);  // validate the name now, not at the first step
    // Triangular solves with a float copy of the kept factor (docs/dependencies.md §5.5): half the memory traffic
    // of a solve; the iteration still converges to the double-precision residual's tolerance.
    nopt_.single_precision_solves = single_precision_setting(s.get("solve_precision", "double"), nopt_.linear_solver, name_);
    // Paper eq. 39 (docs/theory.md §6.5): stop when cc = |Δu^(k+1)·P̄^(k)| / |Δu^(1)·P̄^(0)| ≤ cc_tol.
    // Default 1e-12, far tighter than the paper's 1e-6: conservation studies need the algebraic error well
    // below the time-discretization error (with 1e-8 a tumbling plate drifts by 3e-7 in 2000 steps, with
    // 1e-12 it stays at 4e-9). Because cc ∝ |Δu|², quadratic convergence makes this cost about one extra
    // iteration. KINSOL's scaled-step test (|Δu_i| ≤ 1e-14 max(1, |u_i|)) stops the iteration at round-off
    // when cc cannot fall further; KINSOL's residual-norm test is off (the residual has no natural scale).
    nopt_.stop = StopTest::fnorm_or_energy;
    nopt_.fnorm_tol = 1e-300;
    nopt_.step_tol = s.get("step_tol", 1e-14);
    // Modified Newton applies the step test itself (in the iteration hook), once, as the round-off fallback:
    // KINSOL's own test, met with a stale Jacobian, insists on a refresh and one more iteration, which costs a
    // factorization per step exactly where the iteration has converged to round-off.
    // step_refresh = true restores KINSOL's behaviour (refresh and iterate once more with a current K̄).
    step_tol_ = nopt_.step_tol;
    step_refresh_ = s.get("step_refresh", false);
    if (nopt_.modified && !step_refresh_) nopt_.step_tol = 0.0;  // 0: the smallest positive double, i.e. never
    // Modified Newton: cc_tol 1e-14 (the paper's relative criterion, kept above its round-off floor, see
    // e_floor above); the energy floor is what usually ends the iteration (on the flying plate, the cylindrical
    // panel and the pinched hemisphere cc_tol 1e-14 and 1e-20 gave the same iterations to within 0.04 %).
    nopt_.energy_tol = s.get("cc_tol", nopt_.modified ? 1e-14 : 1e-12);
    nopt_.min_iters = s.get("min_iters", 1);
    nopt_.max_iters = s.get("max_iters", 25);
    nopt_.line_search = false;
    // The accepted iterate's residual is never used (the tests read Δu_k and F(u_{k−1})): not evaluated.
    nopt_.skip_final_residual = true;
    max_cuts_ = s.get("max_cuts", 0);
    hysteresis_ = s.get("hysteresis", 1.0);
    if (!(nopt_.energy_tol > 0.0) || nopt_.max_iters < 1 || nopt_.min_iters < 0 || max_cuts_ < 0 || hysteresis_ < 1.0)
      throw std::invalid_argument(name_ + ": out-of-range Newton settings (limits below)\nneed cc_tol > 0, max_iters >= 1, "
                                  "min_iters >= 0, max_cuts >= 0, hysteresis >= 1");
    resolved_ = s.resolved();
    resolved_.insert(resolved_.begin(), {{"dt", g(dt_)}, {"alpha_m", g(p_.alpha_m)}, {"alpha_f", g(p_.alpha_f)},
                                         {"beta", g(p_.beta)}, {"gamma", g(p_.gamma)}});
  }

  std::string name() const override { return name_; }
  std::vector<std::pair<std::string, std::string>> settings() const override { return resolved_; }
  double external_work() const override { return work_; }
  double damping_work() const override { return damping_work_; }
  double prescribed_work() const override { return prescribed_work_; }
  bool supports_prescribed_motion() const override { return true; }
  // Holonomic constraints with index-3 multipliers (docs/theory/multibody.md §9; step_constrained()).
  bool supports_constraints() const override { return true; }
  bool set_residual_trace(ResidualTrace trace) override {
    residual_trace_ = std::move(trace);
    return true;
  }

  // Checkpoint (docs/architecture.md "Checkpoints and resume"): besides the State (u, v, a, charts)
  // a step depends on W_ext, the step counter (messages), the last step size (modified Newton
  // refreshes K̄ when it changes) and, with modified Newton, the K̄ in use and the iterations done with
  // it. restore() makes the next setup replay that K̄ (same values, hence the same factorization)
  // and resume the refresh count, so the continued run is bitwise the uninterrupted one.
  void save(IntegratorCheckpoint& c) const override {
    if (!newton_) throw std::logic_error(name_ + ": save() before initialize()");
    c.exact = true;
    c.scalars["W_ext"] = work_;
    c.scalars["W_damp"] = damping_work_;
    c.scalars["W_presc"] = prescribed_work_;
    c.scalars["steps"] = static_cast<double>(steps_);
    c.scalars["energy0"] = energy0_;  // scale of the energy floor (initialize() would take the restored state's)
    if (lambda_.size() > 0) c.vectors["lambda"] = lambda_;  // constrained steps: the next step's guess
    kept_.save(c, *newton_, nopt_.modified);
  }

  void restore(SemiDiscreteSystem& sys, State& s, const IntegratorCheckpoint& c) override {
    if (!newton_) throw std::logic_error(name_ + ": restore() before initialize()");
    if (s.u.size() != sys.num_dofs() || s.v.size() != sys.num_dofs() || s.a.size() != sys.num_dofs())
      throw std::runtime_error(name_ + ": checkpoint state has the wrong size for this model");
    work_ = c.scalar("W_ext");
    damping_work_ = c.scalar("W_damp");
    prescribed_work_ = c.scalars.count("W_presc") ? c.scalar("W_presc") : 0.0;
    steps_ = static_cast<long>(c.scalar("steps"));
    energy0_ = c.scalar("energy0");
    if (c.vectors.count("lambda")) lambda_ = c.vector("lambda", sys.num_constraints());
    kept_.restore(c, *newton_, nopt_.modified, sys, name_);
  }

  void initialize(SemiDiscreteSystem& sys, State& s) override {
    const Index n = sys.num_dofs();
    newton_ = std::make_unique<NewtonSolver>(sys.pattern(), nopt_);
    M_ = SparseMatrix{sys.pattern(), std::vector<double>(static_cast<size_t>(sys.pattern()->nnz()), 0.0)};
    K_ = M_;
    for (Eigen::VectorXd* v : {&un_, &vn_, &an_, &umid_, &vmid_, &amid_, &fint_, &fm_, &fext_, &fint_n_, &fext_n_, &tmp_})
      v->setZero(n);
    work_ = damping_work_ = prescribed_work_ = 0.0;
    sys.rechart(s, hysteresis_);
    {
      const Invariants inv = sys.invariants(s);
      energy0_ = std::abs(inv.kinetic) + std::abs(inv.strain);
    }
    if (sys.num_constraints() > 0) {  // multibody.md §9.3: M a + Gᵀλ = f, G a = −(d/dt)(G) u̇
      if (sys.has_prescribed_motion())
        throw std::invalid_argument(name_ + ": joints together with prescribed displacement histories are not supported "
                                    "(drive the motion through a prescribed_rotation joint instead)");
      constrained_acceleration(sys, s, nopt_.linear_solver, s.a, &lambda_);
      bordered_.reset();
      return;
    }
    consistent_acceleration(sys, s, nopt_.linear_solver, s.a);  // docs/theory.md §6.4 start-up
  }

  StepReport advance(SemiDiscreteSystem& sys, State& s, double t_out) override {
    if (!newton_) throw std::logic_error(name_ + ": advance() before initialize()");
    const auto start = std::chrono::steady_clock::now();
    StepReport rep;
    while (s.t < t_out - 1e-12 * dt_) {
      double h = std::min(dt_, t_out - s.t);
      if (t_out - (s.t + h) < 1e-9 * dt_) h = t_out - s.t;  // land exactly on t_out
      step_with_cuts(sys, s, h, 0, rep);
      if (stop_requested()) break;  // at a step boundary: the driver checkpoints and stops
    }
    rep.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return rep;
  }

 private:
  void step_with_cuts(SemiDiscreteSystem& sys, State& s, double h, int depth, StepReport& rep) {
    std::string why;
    if (step(sys, s, h, rep, &why)) return;
    ++rep.rejected_steps;
    if (nopt_.modified) {  // retry once with full Newton
      if (step(sys, s, h, rep, &why, /*full_newton=*/true)) return;
      ++rep.rejected_steps;
    }
    if (depth >= max_cuts_) {  // one line: where, why (the last attempt's), and the setting that would help
      std::ostringstream msg;
      msg.precision(6);
      msg << name_ << ": step " << steps_ + 1 << " at t = " << s.t << " (dt = " << h << ") failed"
          << (max_cuts_ > 0 ? " after " + std::to_string(depth) + " cuts" : std::string()) << ": " << why << "; set max_cuts="
          << max_cuts_ + (max_cuts_ > 0 ? 2 : 4) << " (halve the step)";
      throw StepFailure(msg.str());
    }
    step_with_cuts(sys, s, 0.5 * h, depth + 1, rep);
    step_with_cuts(sys, s, 0.5 * h, depth + 1, rep);
  }

  // One step of size h from s (docs/theory.md §6.6). Returns false (s unchanged but for charts) on failure.
  bool step(SemiDiscreteSystem& sys, State& s, double h, StepReport& rep, std::string* why, bool full_newton = false) {
    if (sys.num_constraints() > 0) return step_constrained(sys, s, h, rep, why, full_newton);
    rep.chart_switches += sys.rechart(s, hysteresis_);  // §2.3: between steps only
    kept_.start_step(h, *newton_);  // K̄ depends on h (modified Newton)
    if (full_newton && !full_newton_) {
      NewtonOptions full = nopt_;
      full.modified = false;
      full.step_tol = step_tol_;  // KINSOL's step test is harmless with a current Jacobian
      full_newton_ = std::make_unique<NewtonSolver>(sys.pattern(), full);
    }
    NewtonSolver& newton = full_newton ? *full_newton_ : *newton_;
    const double am = p_.alpha_m, af = p_.alpha_f, be = p_.beta, ga = p_.gamma;
    const double tn = s.t, t1 = s.t + h, tmid = t1 - af * h;
    un_ = s.u;
    vn_ = s.v;
    an_ = s.a;
    const auto& charts = s.charts;
    const Index n = sys.num_dofs();
    // §6.2 generalized-midpoint velocity and acceleration as affine functions of u_{n+1}.
    const double cu = (1 - af) * ga / (be * h), cv = ((1 - af) * ga - be) / be, ca = (1 - af) * (ga - 2 * be) / (2 * be) * h;
    const double du = (1 - am) / (be * h * h), dv = (1 - am) / (be * h), da = (1 - am - 2 * be) / (2 * be);
    const bool endpoint = (scheme_ == Scheme::Galpha || scheme_ == Scheme::Newmark);
    if (endpoint) {  // t_n contributions of the α_f-weighted end-point forces
      sys.internal(un_, charts, fint_n_.data(), nullptr);
      sys.external(tn, un_, charts, fext_n_.data());
    }

    auto midpoint_state = [&](const double* u) {
      const Eigen::Map<const Eigen::VectorXd> uu(u, n);
      umid_ = (1 - af) * uu + af * un_;
      vmid_ = cu * (uu - un_) - cv * vn_ - ca * an_;
      amid_ = du * (uu - un_) - dv * vn_ - da * an_;
    };
    auto external_force = [&](const double* u) {  // F_ext as the scheme evaluates it (fills fext_)
      const Eigen::Map<const Eigen::VectorXd> uu(u, n);
      if (endpoint) {
        sys.external(t1, uu, charts, tmp_.data());
        fext_ = (1 - af) * tmp_ + af * fext_n_;
      } else {
        sys.external(tmid, umid_, charts, fext_.data());
      }
    };
    bool keep_constrained = false;  // true: the residual keeps its constrained rows (the reactions)
    std::vector<double> trace;      // scaled residuals of the step's iterates (set_residual_trace())
    auto residual = [&](const double* u, double* r) {
      const Eigen::Map<const Eigen::VectorXd> uu(u, n);
      midpoint_state(u);
      sys.inertia_force(umid_, vmid_, amid_, charts, fm_.data());  // M_mid ü_{n+1−α_m} + F_m,mid
      scheme_internal_force(sys, uu, charts, af);
      external_force(u);
      Eigen::Map<Eigen::VectorXd> rr(r, n);
      rr = fm_ + fint_ - fext_;  // = −P̄ (§6.4)
      if (!keep_constrained) zero_constrained(sys.dofs(), r);
      if (!rr.allFinite()) throw std::runtime_error("non-finite residual");
      if (residual_trace_) {  // set_residual_trace(): ‖r‖∞ over the largest force entry, as em-exact scales it
        const double scale = std::max({fm_.cwiseAbs().maxCoeff(), fint_.cwiseAbs().maxCoeff(), fext_.cwiseAbs().maxCoeff()});
        const double rn = rr.cwiseAbs().maxCoeff();
        trace.push_back(rn == 0.0 ? 0.0 : rn / scale);
      }
    };
    bool replayed = false;
    // The kept K̄ seen from each iterate's midpoint configuration (docs/theory.md §6.9; modified Newton only).
    const NewtonSolver::BasisProvider basis =
        full_newton ? NewtonSolver::BasisProvider{}
                    : kept_.provider(sys, charts, [this, n, af](const double* u, Eigen::VectorXd& x) {
                        x = (1 - af) * Eigen::Map<const Eigen::VectorXd>(u, n) + af * un_;
                      });
    auto jacobian = [&](const double* u, SparseMatrix& J) {
      if (!full_newton && kept_.replay(J, newton, basis, u)) {  // first setup after restore(): the saved K̄, not a new one
        replayed = true;
        return;
      }
      const Eigen::Map<const Eigen::VectorXd> uu(u, n);
      midpoint_state(u);
      sys.mass(umid_, charts, M_);
      scheme_stiffness(sys, uu, charts, af, tmid, t1);
      // §6.4: K̄ = (1−α_m)/(βΔt²) M_mid + (1−α_f) K_mid (symmetric; the (1−α_m) reading of §6.8 item 3).
      profile::Scope prof(profile::Section::combine);
      for (size_t k = 0; k < J.values.size(); ++k) J.values[k] = du * M_.values[k] + (1 - af) * K_.values[k];
      sys.add_damping_matrix(cu, J);  // ∂(C u̇_mid)/∂u_{n+1} (docs/theory.md §8.5)
      apply_dirichlet(sys.dofs(), J, nullptr);
      if (nopt_.modified && !full_newton) kept_.keep(J, umid_, charts);  // for save()
    };

    Eigen::VectorXd u = un_;  // predictor u_{n+1}^(0) = u_n (§6.4)
    if (newmark_predictor_ && !full_newton) u += h * vn_ + (0.5 * h * h) * an_;
    sys.prescribed_displacement(t1, u.data());  // prescribed DOFs at g(t_{n+1}); Newton leaves them there
    uscale_ = (1.0 / un_.array().abs().max(1.0)).matrix();
    // Stopping rule of modified Newton (constructor): cc ≤ cc_tol (in NewtonSolver), the energy floor
    // E_k ≤ e_floor·E_sys, or the scaled step test once (round-off reached).
    const double floor = e_floor_ * (energy0_ + std::abs(work_));
    // floor_test = estimate (docs/theory.md §6.5): E_k measures the error of u_{k−1}; that of u_k is about the next
    // correction's energy, estimated from the observed energy contraction (energy_floor_test.hpp).
    EnergyFloorTest energy_floor(floor, floor_estimate_);
    NewtonSolver::IterationHook hook;
    if (floor > 0.0 || nopt_.modified)
      hook = [this, n, &newton, &energy_floor](int, const double*, const double* du, const double* f) {
        const Eigen::Map<const Eigen::VectorXd> d(du, n), r(f, n);
        const double Ek = std::abs(d.dot(r));  // E_k = |Δu_k·P̄(u_{k−1})| (eq. 39)
        if (energy_floor.accept(Ek)) return true;
        // Scaled step test |Δu_i| ≤ step_tol max(1, |u_n,i|), met once (modified Newton, see the constructor).
        if (!newton.options().modified || step_refresh_) return false;
        return (d.array().abs() * uscale_.array()).maxCoeff() <= step_tol_;
      };
    const NewtonSolver::Result r = newton.solve(u.data(), residual, jacobian, nullptr, uscale_.data(), hook, basis);
    if (full_newton) newton_->invalidate_jacobian();  // the modified solver's K̄ is stale now
    rep.nonlinear_iterations += r.iterations;
    // A replayed K̄ (restore()) is the uninterrupted run's matrix, not a new setup: not counted.
    rep.linear_setups += r.jacobian_evals - (replayed ? 1 : 0);
    rep.factorizations += r.factorizations - (replayed ? 1 : 0);
    rep.rhs_evaluations += r.residual_evals;
    rep.residual_norm = r.fnorm;
    rep.energy_ratio = r.energy_ratio;
    if (!r.converged) {
      // One short line (docs/theory/newton-iteration.md §4): iterations, the last residual and energy ratio, each once.
      char b[200];
      if (r.stop_reason == NewtonSolver::StopReason::max_iters) {
        std::snprintf(b, sizeof b, "no convergence in %d iterations, |r|inf = %.3g, energy ratio cc = %.3g (cc_tol = %.3g)",
                      r.iterations, r.fnorm, r.energy_ratio, nopt_.energy_tol);
        *why = b;
      } else {  // a failed residual, Jacobian or solve: the solver's reason, first line
        *why = r.message.substr(0, r.message.find_first_of(";\n"));
        if (why->size() > 100) *why = why->substr(0, 97) + "...";
      }
      return false;
    }
    if (residual_trace_) residual_trace_(trace, r.iterations);
    if (sys.has_prescribed_motion()) {  // reaction work Σ r_c Δu_c of the prescribed DOFs (docs/theory.md §8.6)
      keep_constrained = true;
      rc_.resize(n);
      residual(u.data(), rc_.data());
      for (Index dof : sys.prescribed_dofs()) prescribed_work_ += rc_[dof] * (u[dof] - un_[dof]);
    }
    // Discrete external work with the scheme's own load evaluation (docs/benchmarks.md §0).
    midpoint_state(u.data());
    external_force(u.data());
    work_ += fext_.dot(u - un_);
    if (sys.has_damping()) {  // dissipated work Δuᵀ C u̇_mid (docs/theory.md §8.5)
      sys.damping_force(vmid_, tmp_.data());
      damping_work_ += tmp_.dot(u - un_);
    }
    // §6.2 Newmark updates.
    s.a = (u - un_) / (be * h * h) - vn_ / (be * h) - (0.5 / be - 1.0) * an_;
    s.v = vn_ + h * ((1 - ga) * an_ + ga * s.a);
    s.u = u;
    s.t = t1;
    ++steps_;
    ++rep.steps;
    rep.last_dt = h;
    return true;
  }

  // ---- Constrained step (docs/theory/multibody.md §9.1) ---------------------------------------------------------
  // The step of step() with the constraint force Ĝᵀλ in the residual and g(u_{n+1}, t_{n+1}) = 0 among the
  // equations, λ a new unknown of each step (index 3):
  //   em-galpha, midpoint:  Ĝ from the discrete gradient Ḡ(u_n, u_{n+1}) (multibody.md §2), so that at ρ∞ = 1, where
  //                         the unconstrained step conserves energy, the constraint forces do no discrete work;
  //   galpha, newmark:      Ĝ from the end-point Jacobians, as the classical index-3 schemes.
  // λ is the reaction of the α_f-weighted balance (multibody.md §9.1 argues it against Arnold & Brüls' form). The
  // iteration is BorderedNewton's (bordered_newton.hpp: K̄ kept, Schur complement on the constraint rows) instead of
  // KINSOL's; full_newton (the retry of step_with_cuts) refreshes K̄ every iteration.
  bool step_constrained(SemiDiscreteSystem& sys, State& s, double h, StepReport& rep, std::string* why, bool full_newton) {
    rep.chart_switches += sys.rechart(s, hysteresis_);  // §2.3: between steps only
    std::unique_ptr<BorderedNewton>& bn = full_newton ? bordered_full_ : bordered_;
    if (!bn) {
      BorderedNewtonOptions o;
      o.linear_solver = nopt_.linear_solver;
      o.max_iters = nopt_.max_iters;
      o.refresh = (nopt_.modified && !full_newton) ? 0.1 : 0.0;
      bn = std::make_unique<BorderedNewton>(sys.pattern(), o);
    }
    const double am = p_.alpha_m, af = p_.alpha_f, be = p_.beta, ga = p_.gamma;
    const double tn = s.t, t1 = s.t + h, tmid = t1 - af * h;
    un_ = s.u;
    vn_ = s.v;
    an_ = s.a;
    const auto& charts = s.charts;
    const Index m = sys.num_constraints();
    const double cu = (1 - af) * ga / (be * h), cv = ((1 - af) * ga - be) / be, ca = (1 - af) * (ga - 2 * be) / (2 * be) * h;
    const double du = (1 - am) / (be * h * h), dv = (1 - am) / (be * h), da = (1 - am - 2 * be) / (2 * be);
    const bool endpoint = (scheme_ == Scheme::Galpha || scheme_ == Scheme::Newmark);
    if (endpoint) {
      sys.internal(un_, charts, fint_n_.data(), nullptr);
      sys.external(tn, un_, charts, fext_n_.data());
    }
    auto midpoint_state = [&](const Eigen::VectorXd& uu) {
      umid_ = (1 - af) * uu + af * un_;
      vmid_ = cu * (uu - un_) - cv * vn_ - ca * an_;
      amid_ = du * (uu - un_) - dv * vn_ - da * an_;
    };
    auto external_force = [&](const Eigen::VectorXd& uu) {
      if (endpoint) {
        sys.external(t1, uu, charts, tmp_.data());
        fext_ = (1 - af) * tmp_ + af * fext_n_;
      } else {
        sys.external(tmid, umid_, charts, fext_.data());
      }
    };
    BorderedNewton::Callbacks cb;
    cb.residual = [&](const Eigen::VectorXd& uu, Eigen::VectorXd& r) {  // as step()'s residual
      midpoint_state(uu);
      sys.inertia_force(umid_, vmid_, amid_, charts, fm_.data());
      scheme_internal_force(sys, uu, charts, af);
      external_force(uu);
      r = fm_ + fint_ - fext_;
      zero_constrained(sys.dofs(), r.data());
      return std::max({fm_.cwiseAbs().maxCoeff(), fint_.cwiseAbs().maxCoeff(), fext_.cwiseAbs().maxCoeff(), 1e-300});
    };
    cb.jacobian = [&](const Eigen::VectorXd& uu, SparseMatrix& J) {  // as step()'s K̄ (§6.4)
      midpoint_state(uu);
      sys.mass(umid_, charts, M_);
      scheme_stiffness(sys, uu, charts, af, tmid, t1);
      for (size_t k = 0; k < J.values.size(); ++k) J.values[k] = du * M_.values[k] + (1 - af) * K_.values[k];
      sys.add_damping_matrix(cu, J);
    };
    // Ĝ (multibody.md §9.1): the constraint force is weighted like the scheme's other forces, at t_{n+1−α_f}:
    //   galpha, newmark:     Ĝ = (1−α_f) G(u_{n+1}) + α_f G(u_n)                       (index 3; newmark: G(u_{n+1}));
    //   em-galpha, midpoint: Ĝ = Ḡ(u_n, u_{n+1}) + (½ − α_f)(G(u_{n+1}) − G(u_n)),
    // which is the discrete gradient at ρ∞ = 1 (α_f = ½: no discrete work, conserving) and G(u_{n+1−α_f}) for every
    // quadratic constraint. Ĝ = G(u_{n+1}) alone, or Ḡ alone at α_f ≠ ½, puts the reaction O(Δt) off the time of
    // the balance and the scheme drops to first order (measured, multibody.md §9.5).
    Eigen::VectorXd tau;
    BorderedNewton::ConstraintMatrix G_n, G_1;
    sys.constraint_jacobian(tn, un_, charts, G_n);
    cb.force_matrix = [&](const Eigen::VectorXd& uu, BorderedNewton::ConstraintMatrix& Gh) {
      sys.constraint_jacobian(t1, uu, charts, G_1);
      if (endpoint) {
        Gh = (1 - af) * G_1 + af * G_n;
      } else {
        sys.constraint_discrete_gradient(tn, un_, t1, uu, charts, Gh, tau);
        if (af != 0.5) Gh += (0.5 - af) * (G_1 - G_n);
      }
    };
    cb.force_tangent = [&](const Eigen::VectorXd& uu, const Eigen::VectorXd& l, SparseMatrix& J) {
      if (endpoint) {
        sys.add_constraint_hessian(t1, uu, charts, l, 1 - af, J);
      } else {
        sys.add_constraint_discrete_tangent(tn, un_, t1, uu, charts, l, 1.0, J);
        if (af != 0.5) sys.add_constraint_hessian(t1, uu, charts, l, 0.5 - af, J);
      }
    };
    cb.constraints = [&](const Eigen::VectorXd& uu, Eigen::VectorXd& g, BorderedNewton::ConstraintMatrix& G) {
      sys.constraint_values(t1, uu, charts, g);
      sys.constraint_jacobian(t1, uu, charts, G);
    };
    Eigen::VectorXd u = un_;
    if (newmark_predictor_ && !full_newton) u += h * vn_ + (0.5 * h * h) * an_;
    Eigen::VectorXd lambda = lambda_;
    const BorderedNewton::Result r = bn->solve(sys.dofs(), un_, u, lambda, m, cb);
    rep.nonlinear_iterations += r.iterations;
    rep.linear_setups += r.factorizations;
    rep.factorizations += r.factorizations;
    rep.rhs_evaluations += r.residual_evals;
    rep.residual_norm = r.residual;
    if (!r.converged) {
      *why = r.message;
      return false;
    }
    lambda_ = lambda;
    // The drivers' discrete work λ·τ (multibody.md §2.1, (2.3)), counted with the prescribed work: H = K + V − W_ext −
    // W_presc. For galpha / newmark it is the same quadrature of the drivers' power, not an identity.
    {
      BorderedNewton::ConstraintMatrix Gb;
      sys.constraint_discrete_gradient(tn, un_, t1, u, charts, Gb, tau);
      if (tau.size() == m) prescribed_work_ += lambda.dot(tau);
    }
    midpoint_state(u);
    external_force(u);
    work_ += fext_.dot(u - un_);
    if (sys.has_damping()) {
      sys.damping_force(vmid_, tmp_.data());
      damping_work_ += tmp_.dot(u - un_);
    }
    s.a = (u - un_) / (be * h * h) - vn_ / (be * h) - (0.5 / be - 1.0) * an_;  // §6.2 Newmark updates
    s.v = vn_ + h * ((1 - ga) * an_ + ga * s.a);
    s.u = u;
    s.t = t1;
    ++steps_;
    ++rep.steps;
    rep.last_dt = h;
    return true;
  }
  std::unique_ptr<BorderedNewton> bordered_, bordered_full_;  // constrained steps (full: the retry)
  Eigen::VectorXd lambda_;                                    // the last step's multipliers (the next guess)

  Scheme scheme_;
  std::string name_;
  // fint_ = the scheme's internal force at the iterate u_{n+1} = uu, umid_ already set: strain-averaged (em-galpha,
  // §6.3), at the midpoint (midpoint), or (1−α_f) F(u_{n+1}) + α_f F(u_n) (galpha, newmark).
  template <class V>
  void scheme_internal_force(const SemiDiscreteSystem& sys, const V& uu, const std::vector<DirectorChart>& charts,
                             double af) {
    switch (scheme_) {
      case Scheme::EmGalpha:
        sys.algorithmic_internal(un_, uu, charts, af, xi_, fint_.data(), nullptr);
        break;
      case Scheme::Midpoint:
        sys.internal(umid_, charts, fint_.data(), nullptr);
        break;
      case Scheme::Galpha:
      case Scheme::Newmark:
        sys.internal(uu, charts, fint_.data(), nullptr);
        fint_ = (1 - af) * fint_ + af * fint_n_;
        break;
    }
  }

  // K_ = the scheme's stiffness at the iterate u_{n+1} = uu (§6.4), umid_ already set: the strain-averaged tangent
  // (em-galpha), the midpoint tangent (midpoint) or the end-point tangent (galpha, newmark), load stiffness added.
  // (V: the Eigen vector or map the caller holds the iterate in, passed on as it is.)
  template <class V>
  void scheme_stiffness(const SemiDiscreteSystem& sys, const V& uu, const std::vector<DirectorChart>& charts, double af,
                        double tmid, double t1) {
    switch (scheme_) {
      case Scheme::EmGalpha:
        sys.algorithmic_internal(un_, uu, charts, af, xi_, nullptr, &K_);
        sys.add_load_stiffness(tmid, umid_, charts, K_);
        break;
      case Scheme::Midpoint:
        sys.internal(umid_, charts, nullptr, &K_);
        sys.add_load_stiffness(tmid, umid_, charts, K_);
        break;
      case Scheme::Galpha:
      case Scheme::Newmark:
        sys.internal(uu, charts, nullptr, &K_);
        sys.add_load_stiffness(t1, uu, charts, K_);
        break;
    }
  }

  double dt_;
  GeneralizedAlphaParameters p_{};
  double xi_ = 0.0;
  NewtonOptions nopt_;
  int max_cuts_ = 0;
  double hysteresis_ = 1.0;
  std::vector<std::pair<std::string, std::string>> resolved_;

  std::unique_ptr<NewtonSolver> newton_, full_newton_;  // full_newton_: fallback of modified Newton
  SparseMatrix M_, K_;
  Eigen::VectorXd un_, vn_, an_, umid_, vmid_, amid_, fint_, fm_, fext_, fint_n_, fext_n_, tmp_, uscale_;
  double work_ = 0.0, damping_work_ = 0.0, prescribed_work_ = 0.0;
  Eigen::VectorXd rc_;  // residual with its constrained rows (prescribed-motion work)
  double energy0_ = 0.0;  // K + V at initialize() (scale of the energy floor)
  double e_floor_ = 0.0;
  double step_tol_ = 1e-14;
  bool step_refresh_ = false;
  bool newmark_predictor_ = false;
  ResidualTrace residual_trace_;  // set_residual_trace()
  long steps_ = 0;
  bool floor_estimate_ = false;
  KeptIterationMatrix kept_;  // the modified solver's K̄ across steps and checkpoints
};

}  // namespace

std::unique_ptr<Integrator> make_em_galpha(IntegratorSettings& s, double dt) {
  return std::make_unique<NewmarkFamily>(Scheme::EmGalpha, "em-galpha", s, dt);
}
std::unique_ptr<Integrator> make_galpha(IntegratorSettings& s, double dt) {
  return std::make_unique<NewmarkFamily>(Scheme::Galpha, "galpha", s, dt);
}
std::unique_ptr<Integrator> make_midpoint(IntegratorSettings& s, double dt) {
  return std::make_unique<NewmarkFamily>(Scheme::Midpoint, "midpoint", s, dt);
}
std::unique_ptr<Integrator> make_newmark(IntegratorSettings& s, double dt) {
  return std::make_unique<NewmarkFamily>(Scheme::Newmark, "newmark", s, dt);
}

}  // namespace shelldyn
