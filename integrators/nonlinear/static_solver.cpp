#include "integrators/nonlinear/static_solver.hpp"

#include "lib/model/assembler.hpp"
#include "lib/linalg/linear_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <iomanip>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

PathControl parse_path_control(const std::string& name) {
  if (name == "load") return PathControl::load;
  if (name == "arc_length") return PathControl::arc_length;
  if (name == "displacement") return PathControl::displacement;
  throw std::invalid_argument("control: '" + name + "' is not one of load, arc_length, displacement");
}

const char* path_control_name(PathControl c) {
  switch (c) {
    case PathControl::load: return "load";
    case PathControl::arc_length: return "arc_length";
    case PathControl::displacement: return "displacement";
  }
  return "?";
}

StaticSolver::StaticSolver(Model& model, StaticOptions options) : model_(model), options_(std::move(options)) {
  if (!(options_.increment != 0.0) || !std::isfinite(options_.increment))
    throw std::invalid_argument("static solver: increment must be a non-zero number");
  if (options_.control != PathControl::displacement && !(options_.increment > 0.0))
    throw std::invalid_argument("static solver: increment must be > 0");
  if (!(options_.min_increment > 0.0) ||
      (options_.control == PathControl::load && options_.min_increment > options_.increment))
    throw std::invalid_argument("static solver: need 0 < min_increment <= increment");
  if (!(options_.growth >= 1.0)) throw std::invalid_argument("static solver: growth must be >= 1");
  if (options_.max_iters < 1 || options_.max_steps < 1 || options_.target_iterations < 1)
    throw std::invalid_argument("static solver: max_iters, max_steps and target_iterations must be >= 1");
  if (!(options_.convergence.residual_tol > 0.0) || !(options_.convergence.increment_tol > 0.0))
    throw std::invalid_argument("static solver: tol and step_tol must be > 0");
  if (options_.control == PathControl::displacement &&
      (options_.control_dof < 0 || options_.control_dof >= model_.num_dofs()))
    throw std::invalid_argument("static solver: displacement control needs a valid control DOF");
}

namespace {

using Clock = std::chrono::steady_clock;

// Newton solve of one step. Load control: λ fixed. Arc length: λ is an unknown with the cylindrical
// constraint about (u_n, Δl). Displacement: λ is an unknown with u[c] = target.
struct StepResult {
  bool converged = false;
  int iterations = 0, factorizations = 0;
  long max_pivots = 0;  // largest negative-pivot count of the tangents met during the iterations
  bool no_load_pattern = false;  // failed because F̂ = ∂F_ext/∂λ vanished (not a critical point)
  ConvergenceTest::Values values;
  std::string message;
};

}  // namespace

StaticReport StaticSolver::solve(State& state, double lambda_end, const Observer& observer) {
  const auto start = Clock::now();
  const StaticOptions& o = options_;
  StaticReport report;
  const Index n = model_.num_dofs();
  const DofMap& dofs = model_.dofs();
  std::vector<char> trans(static_cast<size_t>(n), 0);
  for (Index i = 0; i < n; ++i) trans[static_cast<size_t>(i)] = (i % kDofsPerNode) < 3 ? 1 : 0;

  SparseMatrix K = model_.make_matrix();
  auto solver = make_linear_solver(o.linear_solver);
  Eigen::VectorXd fint(n), fext(n), fext2(n), R(n), du_r(n), du_f(n), fhat(n);

  // F_ext(λ, u), extended to λ < 0 as an odd function when every load is a ramp (a reversed load; a ramp
  // itself is zero there, which would leave a path that dips below λ = 0 with no load to follow).
  SparseMatrix K_load;
  auto external = [&](double lam, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, double* F) {
    if (o.odd_load_extension && lam < 0.0) {
      model_.external(-lam, u, charts, F);
      Eigen::Map<Eigen::VectorXd>(F, n) *= -1.0;
    } else {
      model_.external(lam, u, charts, F);
    }
  };
  auto add_load_stiffness = [&](double lam, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts) {
    if (o.odd_load_extension && lam < 0.0) {  // −sym ∂F_ext(λ)/∂q = +sym ∂F_ext(−λ)/∂q
      if (K_load.values.empty()) K_load = model_.make_matrix();
      K_load.set_zero();
      model_.add_load_stiffness(-lam, u, charts, K_load);
      for (size_t i = 0; i < K.values.size(); ++i) K.values[i] -= K_load.values[i];
    } else {
      model_.add_load_stiffness(lam, u, charts, K);
    }
  };
  // F_ext(λ, u) and, on request, F̂ = ∂F_ext/∂λ by a forward difference (exact for ramps).
  auto load_vectors = [&](double lam, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, bool want_fhat) {
    external(lam, u, charts, fext.data());
    if (want_fhat) {
      // Forward difference (exact for ramps from λ = 0); backward at and beyond lambda_end, where a ramp ends.
      const double h0 = 1e-7 * std::max(1.0, std::abs(lam));
      const double h = lam + h0 > lambda_end ? -h0 : h0;
      external(lam + h, u, charts, fext2.data());
      fhat = (fext2 - fext) / h;
      zero_constrained(dofs, fhat.data());
    }
  };
  // R and the convergence values at (u, λ); δu is the last correction (null at the first evaluation).
  auto evaluate = [&](const Eigen::VectorXd& u, double lam, const std::vector<DirectorChart>& charts,
                      const Eigen::VectorXd& u_n, const Eigen::VectorXd* du, ConvergenceTest::Values& v) {
    model_.internal(u, charts, fint.data(), nullptr);
    external(lam, u, charts, fext.data());
    R = fint - fext;
    v.force_ref = std::max(fext.norm(), fint.norm());
    zero_constrained(dofs, R.data());
    v.residual = R.norm();
    if (!std::isfinite(v.residual)) throw std::runtime_error("non-finite residual");
    v.residual_ok = v.residual <= o.convergence.residual_tol * v.force_ref;
    v.increment_ok = false;
    if (du) {
      double dmax = 0, Dmax = 0, qmax = 0, stepmax = 0;
      for (Index i = 0; i < n; ++i) {
        if (trans[static_cast<size_t>(i)]) {
          dmax = std::max(dmax, std::abs((*du)[i]));
          Dmax = std::max(Dmax, std::abs(u[i]));
          stepmax = std::max(stepmax, std::abs(u[i] - u_n[i]));
        } else {
          qmax = std::max(qmax, std::abs((*du)[i]));
        }
      }
      v.dd = dmax;
      v.dq = qmax;
      v.disp_ref = std::max(Dmax, stepmax);
      v.increment_ok = dmax <= o.convergence.increment_tol * v.disp_ref && qmax <= o.convergence.increment_tol;
    }
  };
  auto factorize_tangent = [&](const Eigen::VectorXd& u, double lam, const std::vector<DirectorChart>& charts) {
    model_.internal(u, charts, nullptr, &K);
    add_load_stiffness(lam, u, charts);
    apply_dirichlet(dofs, K, nullptr);
    solver->factorize(K.view());
    ++report.jacobian_evaluations;
    return solver->negative_pivots();
  };

  // A progress line while a long step iterates (the pinched cylinder 48 × 48 needs minutes per step).
  auto last_line = Clock::now();
  auto maybe_progress = [&](int iteration, double residual, double lam) {
    if (!o.progress) return;
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last_line).count() < o.progress_seconds) return;
    last_line = now;
    char buf[200];
    std::snprintf(buf, sizeof buf, "  ... step %d: Newton iteration %d, |R| = %.3g, %s %.6g, %.0f s", report.levels + 1,
                  iteration, residual, o.parameter_name.c_str(), lam, std::chrono::duration<double>(now - start).count());
    o.progress(buf);
  };

  // One Newton solve from the predictor (u, lam) about the converged (u_n, lam_n).
  auto newton = [&](Eigen::VectorXd& u, double& lam, const Eigen::VectorXd& u_n, const std::vector<DirectorChart>& charts,
                    double dl, double target, PathControl mode) {
    StepResult s;
    Eigen::VectorXd du(n);
    bool have_du = false;
    try {
      for (int k = 0;; ++k) {
        evaluate(u, lam, charts, u_n, have_du ? &du : nullptr, s.values);
        if (s.values.converged()) {
          s.converged = true;
          return s;
        }
        if (k == o.max_iters) {
          s.message = "no convergence in " + std::to_string(o.max_iters) + " Newton iterations (" + s.values.describe(o.convergence) + ")";
          return s;
        }
        const long neg = factorize_tangent(u, lam, charts);
        ++s.factorizations;
        s.max_pivots = std::max(s.max_pivots, neg);
        solver->solve(R.data(), du_r.data());
        du_r = -du_r;
        double dlam = 0.0;
        if (mode != PathControl::load) {
          load_vectors(lam, u, charts, true);
          solver->solve(fhat.data(), du_f.data());
          if (!(translational_norm(du_f, trans) > 0.0)) {
            s.no_load_pattern = true;
            s.message = "the load pattern dF_ext/d" + std::string(o.parameter_name == "load factor" ? "lambda" : "t") + " is zero at " +
                        o.parameter_name + " " + std::to_string(lam) + " (the loads' time functions are constant there: no load to follow)";
            return s;
          }
          if (mode == PathControl::arc_length) {
            if (!arc_length_root(u - u_n, du_r, du_f, trans, dl, &dlam)) {
              s.message = "the arc-length constraint has no real root (cut the arc length)";
              return s;
            }
          } else {
            const Index c = o.control_dof;
            if (!(std::abs(du_f[c]) > 0.0)) {
              s.message = "the controlled DOF does not respond to the load (K^-1 F_hat = 0 there)";
              return s;
            }
            dlam = (target - u[c] - du_r[c]) / du_f[c];
          }
        }
        du = du_r;
        if (dlam != 0.0) du += dlam * du_f;
        u += du;
        lam += dlam;
        have_du = true;
        ++s.iterations;
        maybe_progress(s.iterations, s.values.residual, lam);
      }
    } catch (const std::exception& e) {
      s.converged = false;
      s.message = e.what();
    }
    return s;
  };

  const double eps = 1e-12 * std::max(1.0, std::abs(lambda_end));
  int cuts = 0, level_iterations = 0, level_switches = 0;
  double arc = 0.0;
  long pivots = -2;  // unknown until the first factorization at a converged state
  ConvergenceTest::Values last_values;
  std::vector<std::pair<double, double>> path;  // (arc, λ) of the converged points
  path.emplace_back(0.0, state.t);

  auto inertia_here = [&]() { return factorize_tangent(state.u, state.t, state.charts); };
  pivots = inertia_here();

  auto report_point = [&](const StepResult& r, const std::string& event) {
    ++report.levels;
    report.max_load_factor = std::max(report.max_load_factor, state.t);
    last_line = Clock::now();
    if (observer) {
      StaticIncrement inc;
      inc.step = report.levels;
      inc.load_factor = state.t;
      inc.newton_iterations = level_iterations;
      inc.chart_switches = level_switches;
      inc.cuts = cuts;
      inc.residual_norm = r.values.residual;
      inc.arc_length = arc;
      inc.negative_pivots = pivots;
      inc.event = event;
      if (!event.empty())
        for (const auto& cp : report.critical_points)
          if (cp.step == report.levels) inc.event_note += (inc.event_note.empty() ? "" : "; ") + cp.note;
      observer(state, inc);
    }
    cuts = level_iterations = level_switches = 0;
  };
  auto give_up = [&](const std::string& what, double size, double min_size, const StepResult& r) {
    std::ostringstream msg;
    msg << "static solver gave up at " << o.parameter_name << " " << state.t << " (step " << report.levels + 1 << "): "
        << what << " " << size << " failed and the next is below min_increment " << min_size << "; last failure: " << r.message;
    if ((pivots > 0 || r.max_pivots > 0) && !r.no_load_pattern)
      msg << "; the tangent has " << pivots << " negative pivots at the last converged state and up to " << r.max_pivots
          << " during the failed iterations: a limit or bifurcation point is near"
          << (o.control == PathControl::load ? " (trace it with control: arc_length)" : "");
    throw std::runtime_error(msg.str());
  };

  if (o.control == PathControl::load) {
    double dlambda = o.increment;
    std::string pending_event;  // a critical point inside a cut level is reported at the level
    while (state.t < lambda_end - eps) {
      const int switches = model_.rechart(state, o.rechart_hysteresis);
      report.chart_switches += switches;
      level_switches += switches;
      const double level = std::min(lambda_end, (std::floor(state.t / o.increment + 1e-9) + 1.0) * o.increment);
      double lambda = (state.t + dlambda >= level - eps) ? level : state.t + dlambda;
      // Tangent prediction of this increment with K at the converged state (factorized by inertia_here()):
      // the converged increment is compared with it to detect a jump (snap-through) to a remote branch.
      if (switches) pivots = inertia_here();
      external(lambda, state.u, state.charts, fext2.data());
      external(state.t, state.u, state.charts, fext.data());
      fhat = fext2 - fext;
      zero_constrained(dofs, fhat.data());
      solver->solve(fhat.data(), du_f.data());
      const double predicted = translational_norm(du_f, trans);
      Eigen::VectorXd u = state.u;
      const StepResult r = newton(u, lambda, state.u, state.charts, 0.0, 0.0, PathControl::load);
      report.newton_iterations += r.iterations;
      if (!r.converged) {
        ++report.failed_attempts;
        ++cuts;
        dlambda *= 0.5;
        if (dlambda < o.min_increment) give_up("increment", dlambda * 2, o.min_increment, r);
        pivots = inertia_here();  // restore K at the converged state for the next prediction
        continue;
      }
      const double lambda_prev = state.t;
      const double step_arc = translational_norm(u - state.u, trans);
      state.u = u;
      state.t = lambda;
      arc += step_arc;
      ++report.increments;
      level_iterations += r.iterations;
      // Inertia at the converged state: a change, or an indefinite tangent met inside the step while both
      // ends are stable, means a critical point was passed under load control (docs/statics.md).
      const long before = pivots;
      pivots = inertia_here();
      std::string event;
      const double jump = predicted > 0.0 ? step_arc / predicted : 0.0;
      const bool jumped = jump > o.jump_ratio;
      if ((before >= 0 && pivots >= 0 && (pivots != before || r.max_pivots > std::max(before, pivots))) || jumped) {
        CriticalPoint cp;
        cp.step = report.levels + 1;
        cp.load_factor = cp.estimate = state.t;
        cp.pivots_before = before;
        cp.pivots_after = pivots;
        std::ostringstream note;
        if (pivots != before && before >= 0 && pivots >= 0) {
          cp.kind = event = "critical point";
          note << "under load control the tangent's negative pivots changed from " << before << " to " << pivots << " between "
               << o.parameter_name << " " << lambda_prev << " and " << state.t
               << ": a limit or bifurcation point was passed; use control: arc_length to trace it";
        } else {
          cp.kind = event = "snap-through";
          note << "under load control the solution jumped between " << o.parameter_name << " " << lambda_prev << " and "
               << state.t << " (";
          if (jumped) note << "displacement increment " << jump << " x the tangent prediction";
          else note << "the Newton iterations crossed an indefinite tangent, " << r.max_pivots << " negative pivots";
          note << ", both ends stable): a limit point was passed and the solution snapped to another branch; use control: "
                  "arc_length to trace it";
        }
        cp.note = note.str();
        report.critical_points.push_back(cp);
      }
      last_values = r.values;
      if (!event.empty()) pending_event = event;
      if (lambda == level) {
        report_point(r, pending_event);
        pending_event.clear();
      }
      if (r.iterations <= o.easy_iterations) dlambda = std::min(o.increment, dlambda * o.growth);
    }
    report.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return report;
  }

  // --- arc length and displacement control (docs/guide/statics-limit-points.md) ---
  load_vectors(state.t, state.u, state.charts, true);
  // With a back-end that cannot report inertia (klu: pivots = -1) the path is still traced, but critical
  // points are found only from reversals of λ.
  solver->solve(fhat.data(), du_f.data());
  const double df_norm = translational_norm(du_f, trans);
  if (!(df_norm > 0.0)) throw std::runtime_error("static solver: the load pattern dF_ext/dlambda is zero at " + o.parameter_name + " " + std::to_string(state.t) + " (no loads to follow)");
  const double dl0 = o.control == PathControl::arc_length ? o.increment * df_norm : std::abs(o.increment);
  const double dl_locate = o.locate_tol * dl0;  // a crossing step this short locates its critical point
  const double dsign = o.increment > 0 ? 1.0 : -1.0;
  const double kDeg = 180.0 / 3.14159265358979323846;
  double dl = dl0;
  Eigen::VectorXd du_prev = du_f;  // direction of the first step: increasing λ
  Eigen::VectorXd t_n(n), t_end(n), u(n);
  double dlam_prev = 1.0, dlam_prevprev = 1.0;
  double crossing_within = 0.0;  // a critical point lies within this step length of the state (0: none known)
  double dl_resume = 0.0;        // the step size when the crossing was found: resumed once it is located
  double target = 0.0;
  // dλ/ds at a state with tangent t = K⁻¹F̂ along the path direction `dir`: arc length s = ‖Δd‖ (the sign
  // that the predictor takes), displacement control s = the controlled displacement in the step direction.
  auto slope = [&](const Eigen::VectorXd& t, const Eigen::VectorXd& dir) {
    if (o.control == PathControl::arc_length)
      return (translational_dot(t, dir, trans) >= 0.0 ? 1.0 : -1.0) / translational_norm(t, trans);
    return dsign / t[o.control_dof];
  };
  // Angle between the path tangents t_a and t_b (translations; their sign flips at a limit point).
  auto turn_angle = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    const double c = std::abs(translational_dot(a, b, trans)) / (translational_norm(a, trans) * translational_norm(b, trans));
    return std::isfinite(c) ? std::acos(std::min(1.0, c)) * kDeg : 0.0;
  };
  for (int step = 0;; ++step) {
    if (state.t >= lambda_end - eps) break;
    if (o.control == PathControl::displacement && std::isfinite(o.displacement_end) &&
        dsign * (state.u[o.control_dof] - o.displacement_end) >= -1e-12 * std::abs(o.displacement_end))
      break;
    if (step >= o.max_steps) {
      std::ostringstream msg;
      msg << "static solver: " << o.max_steps << " steps (max_steps) done at " << o.parameter_name << " " << state.t
          << " before reaching " << lambda_end << "; raise max_steps or the increment";
      throw std::runtime_error(msg.str());
    }
    const int switches = model_.rechart(state, o.rechart_hysteresis);
    report.chart_switches += switches;
    level_switches += switches;
    // Predictor along t_n = K⁻¹F̂ at the converged state (factorized by inertia_here()).
    load_vectors(state.t, state.u, state.charts, true);
    if (switches) pivots = inertia_here();
    solver->solve(fhat.data(), t_n.data());
    if (!(translational_norm(t_n, trans) > 0.0)) {
      std::ostringstream msg;
      msg << "static solver: the load pattern dF_ext/d" << (o.parameter_name == "load factor" ? "lambda" : "t") << " is zero at "
          << o.parameter_name << " " << state.t << " (step " << report.levels + 1
          << "): the loads' time functions are constant there, so there is no load to follow (use ramps, or end "
             "time.t_end where the loads stop changing)";
      throw std::runtime_error(msg.str());
    }
    StepResult r;
    double lam = 0.0, dl_try = dl;
    // Bisection towards a known crossing: half of what is left of the bracket, never below the locating size.
    if (crossing_within > 0.0) dl_try = std::min(dl, std::max(dl_locate, 0.5 * crossing_within));
    long p_end = pivots;
    double turn = 0.0;
    bool jump = false;
    for (;;) {
      du_f = t_n;
      u = state.u;
      lam = state.t;
      double dlam;
      if (o.control == PathControl::arc_length) {
        const double sign = translational_dot(du_f, du_prev, trans) >= 0.0 ? 1.0 : -1.0;
        dlam = sign * dl_try / translational_norm(du_f, trans);
      } else {
        double step_d = dsign * dl_try;
        if (std::isfinite(o.displacement_end)) step_d = dsign * std::min(dl_try, dsign * (o.displacement_end - state.u[o.control_dof]));
        target = state.u[o.control_dof] + step_d;
        if (!(std::abs(du_f[o.control_dof]) > 0.0))
          throw std::runtime_error("static solver: the controlled DOF does not respond to the load at " + o.parameter_name + " " +
                                   std::to_string(state.t) + " (choose a DOF the load moves)");
        dlam = step_d / du_f[o.control_dof];
      }
      PathControl mode = o.control;
      if (dlam > 0.0 && state.t + dlam > lambda_end) {
        // The last step ends exactly at lambda_end: a load-controlled solve from the scaled predictor.
        dlam = lambda_end - state.t;
        mode = PathControl::load;
      }
      u += dlam * du_f;
      lam += dlam;
      r = newton(u, lam, state.u, state.charts, dl_try, target, mode);
      report.newton_iterations += r.iterations;
      if (!r.converged) {
        ++report.failed_attempts;
        ++cuts;
        dl_try *= 0.5;
        if (dl_try < o.min_increment * dl0)
          give_up(o.control == PathControl::arc_length ? "arc length" : "displacement increment", dl_try * 2, o.min_increment * dl0, r);
        pivots = inertia_here();  // restore the factorization at the converged state
        continue;
      }
      // The end of the step: its inertia and path tangent (the factorization is kept for the next predictor).
      p_end = factorize_tangent(u, lam, state.charts);
      load_vectors(lam, u, state.charts, true);
      solver->solve(fhat.data(), t_end.data());
      turn = turn_angle(t_n, t_end);
      const bool crossed = pivots >= 0 && p_end >= 0 && (p_end != pivots || r.max_pivots > std::max(pivots, p_end));
      const bool sharp = turn > 2.0 * o.max_turn;
      if ((crossed || sharp) && dl_try > dl_locate) {
        // A critical point inside the step (bisection), or a turn too sharp to trust: retry shorter.
        ++report.located_cuts;
        ++cuts;
        if (crossed) {
          if (crossing_within == 0.0) dl_resume = dl_try;
          crossing_within = dl_try;
        }
        dl_try = std::max(dl_locate, dl_try * (crossed ? 0.5 : std::clamp(o.max_turn / turn, 0.1, 0.5)));
        pivots = inertia_here();
        continue;
      }
      jump = sharp;
      break;
    }
    const double lam_n = state.t, dlam_step = lam - state.t;
    const Eigen::VectorXd du_step = u - state.u;
    const double h = o.control == PathControl::arc_length ? translational_norm(du_step, trans) : std::abs(du_step[o.control_dof]);
    const double g0 = slope(t_n, du_prev), g1 = slope(t_end, du_step);
    du_prev = du_step;
    arc += translational_norm(du_step, trans);
    state.u = u;
    state.t = lam;
    ++report.increments;
    level_iterations += r.iterations;
    path.emplace_back(arc, lam);
    if (crossing_within > 0.0) crossing_within = std::max(0.0, crossing_within - h);
    const long before = pivots;
    pivots = p_end;
    dlam_prevprev = dlam_prev;
    dlam_prev = dlam_step;
    std::string event;
    auto add_point = [&](const std::string& kind, double estimate, const std::string& text) {
      CriticalPoint cp;
      cp.step = report.levels + 1;
      cp.kind = kind;
      event += (event.empty() ? "" : "; ") + kind;
      cp.load_factor = lam;
      cp.estimate = estimate;
      cp.pivots_before = before;
      cp.pivots_after = pivots;
      cp.note = text;
      report.critical_points.push_back(cp);
    };
    const bool located = before >= 0 && pivots >= 0 && pivots != before;
    if (located) {
      // A located change of inertia: a limit point when dλ/ds changes sign over the step, else a bifurcation.
      crossing_within = 0.0;
      std::ostringstream note;
      if ((g0 > 0.0) != (g1 > 0.0)) {
        // Extremum of λ(s): λ' varies about linearly over the short step, zero at s* = h g0/(g0 − g1).
        const double s_star = std::isfinite(g0 / (g0 - g1)) ? h * g0 / (g0 - g1) : 0.5 * h;
        double est = lam_n + 0.5 * g0 * s_star;
        est = g0 > 0.0 ? std::max({est, lam_n, lam}) : std::min({est, lam_n, lam});
        note << "limit point: " << o.parameter_name << " " << (g0 > 0.0 ? "maximum" : "minimum") << " " << est << " (located to "
             << std::setprecision(2) << std::max(std::abs(lam - lam_n), std::abs(est - lam)) << std::setprecision(6) << " in step "
             << report.levels + 1 << "; negative pivots " << before << " -> " << pivots << ")";
        add_point("limit point", est, note.str());
      } else {
        const double est = 0.5 * (lam_n + lam);
        note << "bifurcation point at " << o.parameter_name << " " << est << " (located to " << std::setprecision(2)
             << 0.5 * std::abs(lam - lam_n) << std::setprecision(6) << " in step " << report.levels + 1 << "; negative pivots " << before << " -> " << pivots << ", " << o.parameter_name
             << " still " << (g0 > 0.0 ? "rising" : "falling") << "); the solver stays on the primary path (no branch switching)";
        add_point("bifurcation point", est, note.str());
      }
    } else if (before < 0 || pivots < 0) {
      // No inertia (klu): a reversal of λ is a limit point, estimated by a parabola λ(s) through the three
      // points around the extremum.
      const bool reversed = step > 0 && (dlam_prev > 0) != (dlam_prevprev > 0) && dlam_prev != 0.0;
      if (reversed) {
        const auto& p0 = path[path.size() >= 3 ? path.size() - 3 : 0];
        const auto& p1 = path[path.size() - 2];
        const auto& p2 = path[path.size() - 1];
        double est = p1.second;
        if (path.size() >= 3) {
          const double d1 = (p1.second - p0.second) / (p1.first - p0.first), d2 = (p2.second - p1.second) / (p2.first - p1.first);
          const double a = (d2 - d1) / (p2.first - p0.first);
          const double b = d1 - a * (p0.first + p1.first);
          const double c = p0.second - a * p0.first * p0.first - b * p0.first;
          const double sm = a != 0.0 ? -b / (2 * a) : p1.first;
          if (a != 0.0 && sm >= p0.first && sm <= p2.first) est = a * sm * sm + b * sm + c;
        }
        std::ostringstream note;
        note << "limit point: " << o.parameter_name << " " << (dlam_prevprev > 0 ? "maximum" : "minimum") << " ~ " << est
             << " between steps " << report.levels << " and " << report.levels + 1
             << " (this linear solver reports no inertia: limit points are found from reversals only, bifurcation points not at all)";
        add_point("limit point", est, note.str());
      }
    }
    if (jump) {
      std::ostringstream note;
      note << "path jump: the path tangent turned by " << turn << " degrees within one step (between " << o.parameter_name << " " << lam_n
           << " and " << lam << ", step " << report.levels + 1 << ", at the smallest step locate_tol x the first)"
           << ": the path is not resolved there (a kink, or a jump to another branch); check the results past it";
      add_point("path jump", lam, note.str());
    }
    last_values = r.values;
    report_point(r, event);
    // The next step: sized to the iteration count and to the turn of the tangent (about max_turn per step).
    double factor = std::sqrt(static_cast<double>(o.target_iterations) / std::max(1, r.iterations));
    if (turn > 0.0) factor = std::min(factor, o.max_turn / turn);
    dl = std::min(std::clamp(factor, 0.5, o.growth) * dl_try, o.max_arc_factor * dl0);
    // Past a located critical point, resume the step size it was found with (not regrow from the tiny
    // locating step); the turn control shortens it again where the path is still sharply curved.
    if (located && dl_resume > dl) dl = std::min(dl_resume, o.max_arc_factor * dl0);
    if (located || crossing_within == 0.0) dl_resume = 0.0;
  }
  report.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

}  // namespace shelldyn
