#include "integrators/nonlinear/static_solver.hpp"

#include "lib/assembler.hpp"
#include "lib/linear_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
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

  // F_ext(λ, u) and, on request, F̂ = ∂F_ext/∂λ by a forward difference (exact for ramps).
  auto load_vectors = [&](double lam, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, bool want_fhat) {
    model_.external(lam, u, charts, fext.data());
    if (want_fhat) {
      // Forward difference (exact for ramps from λ = 0); backward at and beyond lambda_end, where a ramp ends.
      const double h0 = 1e-7 * std::max(1.0, std::abs(lam));
      const double h = lam + h0 > lambda_end ? -h0 : h0;
      model_.external(lam + h, u, charts, fext2.data());
      fhat = (fext2 - fext) / h;
      zero_constrained(dofs, fhat.data());
    }
  };
  // R and the convergence values at (u, λ); δu is the last correction (null at the first evaluation).
  auto evaluate = [&](const Eigen::VectorXd& u, double lam, const std::vector<DirectorChart>& charts,
                      const Eigen::VectorXd& u_n, const Eigen::VectorXd* du, ConvergenceTest::Values& v) {
    model_.internal(u, charts, fint.data(), nullptr);
    model_.external(lam, u, charts, fext.data());
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
    model_.add_load_stiffness(lam, u, charts, K);
    apply_dirichlet(dofs, K, nullptr);
    solver->factorize(K.view());
    ++report.jacobian_evaluations;
    return solver->negative_pivots();
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
      observer(state, inc);
    }
    cuts = level_iterations = level_switches = 0;
  };
  auto give_up = [&](const std::string& what, double size, double min_size, const StepResult& r) {
    std::ostringstream msg;
    msg << "static solver gave up at " << o.parameter_name << " " << state.t << " (step " << report.levels + 1 << "): "
        << what << " " << size << " failed and the next is below min_increment " << min_size << "; last failure: " << r.message;
    if (pivots > 0 || r.max_pivots > 0)
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
      model_.external(lambda, state.u, state.charts, fext2.data());
      model_.external(state.t, state.u, state.charts, fext.data());
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

  // --- arc length and displacement control ---
  load_vectors(state.t, state.u, state.charts, true);
  // With a back-end that cannot report inertia (klu: pivots = -1) the path is still traced, but critical
  // points are not detected.
  solver->solve(fhat.data(), du_f.data());
  const double df_norm = translational_norm(du_f, trans);
  if (!(df_norm > 0.0)) throw std::runtime_error("static solver: the load pattern dF_ext/dlambda is zero at " + o.parameter_name + " " + std::to_string(state.t) + " (no loads to follow)");
  const double dl0 = o.control == PathControl::arc_length ? o.increment * df_norm : std::abs(o.increment);
  double dl = dl0;
  Eigen::VectorXd du_prev = du_f;  // direction of the first step: increasing λ
  double dlam_prev = 1.0, dlam_prevprev = 1.0;
  bool pending_change = false;
  int change_step = 0;
  long change_before = 0;
  double change_lambda = 0.0;
  double target = 0.0;
  const double dsign = o.increment > 0 ? 1.0 : -1.0;
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
    // Predictor along K⁻¹F̂ at the converged state (factorized by inertia_here()).
    load_vectors(state.t, state.u, state.charts, true);
    if (switches) pivots = inertia_here();
    solver->solve(fhat.data(), du_f.data());
    StepResult r;
    Eigen::VectorXd u;
    double lam = 0.0;
    for (;;) {
      u = state.u;
      lam = state.t;
      double dlam;
      if (o.control == PathControl::arc_length) {
        const double sign = translational_dot(du_f, du_prev, trans) >= 0.0 ? 1.0 : -1.0;
        dlam = sign * dl / translational_norm(du_f, trans);
      } else {
        double step_d = dsign * dl;
        if (std::isfinite(o.displacement_end)) step_d = dsign * std::min(dl, dsign * (o.displacement_end - state.u[o.control_dof]));
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
      r = newton(u, lam, state.u, state.charts, dl, target, mode);
      report.newton_iterations += r.iterations;
      if (r.converged) break;
      ++report.failed_attempts;
      ++cuts;
      dl *= 0.5;
      if (dl < o.min_increment * dl0) give_up(o.control == PathControl::arc_length ? "arc length" : "displacement increment", dl * 2, o.min_increment * dl0, r);
      pivots = inertia_here();  // restore the factorization at the converged state for the next predictor
      load_vectors(state.t, state.u, state.charts, true);
      solver->solve(fhat.data(), du_f.data());
    }
    const double dlam_step = lam - state.t;
    du_prev = u - state.u;
    arc += translational_norm(du_prev, trans);
    state.u = u;
    state.t = lam;
    ++report.increments;
    level_iterations += r.iterations;
    path.emplace_back(arc, lam);
    const long before = pivots;
    pivots = inertia_here();
    dlam_prevprev = dlam_prev;
    dlam_prev = dlam_step;
    std::string event;
    // Critical points: a reversal of λ is a limit point (at the previous point, the extremum); a change of
    // the negative pivots not followed by a reversal within two steps is a bifurcation point.
    if (before >= 0 && pivots >= 0 && pivots != before) {
      pending_change = true;
      change_step = report.levels + 1;
      change_before = before;
      change_lambda = lam;
    }
    const bool reversed = step > 0 && (dlam_prev > 0) != (dlam_prevprev > 0) && dlam_prev != 0.0;
    if (reversed) {
      CriticalPoint cp;
      cp.step = report.levels + 1;
      cp.kind = event = "limit point";
      const auto& p0 = path[path.size() - 3 < path.size() ? path.size() - 3 : 0];
      const auto& p1 = path[path.size() - 2];
      const auto& p2 = path[path.size() - 1];
      cp.load_factor = cp.estimate = p1.second;
      if (path.size() >= 3) {
        // Parabola λ(s) through the three points around the extremum.
        const double d1 = (p1.second - p0.second) / (p1.first - p0.first), d2 = (p2.second - p1.second) / (p2.first - p1.first);
        const double a = (d2 - d1) / (p2.first - p0.first);
        const double b = d1 - a * (p0.first + p1.first);
        const double c = p0.second - a * p0.first * p0.first - b * p0.first;
        const double sm = a != 0.0 ? -b / (2 * a) : p1.first;
        if (a != 0.0 && sm >= p0.first && sm <= p2.first) cp.estimate = a * sm * sm + b * sm + c;
      }
      cp.pivots_before = pending_change ? change_before : pivots;
      cp.pivots_after = pivots;
      std::ostringstream note;
      note << "limit point: " << o.parameter_name << " reached a " << (dlam_prevprev > 0 ? "maximum" : "minimum") << " ~ "
           << cp.estimate << " between steps " << report.levels << " and " << report.levels + 1 << " (negative pivots "
           << cp.pivots_before << " -> " << pivots << (pending_change || pivots < 0 ? ")" : "; no inertia change seen: check the step size)");
      cp.note = note.str();
      report.critical_points.push_back(cp);
      pending_change = false;
    } else if (pending_change && report.levels + 1 - change_step >= 2) {
      CriticalPoint cp;
      cp.step = change_step;
      cp.load_factor = cp.estimate = change_lambda;
      cp.kind = event = "bifurcation point";
      cp.pivots_before = change_before;
      cp.pivots_after = pivots;
      std::ostringstream note;
      note << "bifurcation point near " << o.parameter_name << " " << change_lambda << " (negative pivots " << change_before
           << " changed at step " << change_step << " without a reversal of " << o.parameter_name
           << "); the solver stays on the primary path (no branch switching)";
      cp.note = note.str();
      report.critical_points.push_back(cp);
      pending_change = false;
    }
    last_values = r.values;
    report_point(r, event);
    // Adapt the step size to the iteration count.
    const double factor = std::clamp(std::sqrt(static_cast<double>(o.target_iterations) / std::max(1, r.iterations)), 0.5, o.growth);
    dl = std::min(dl * factor, o.max_arc_factor * dl0);
  }
  report.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

}  // namespace shelldyn
