#include "integrators/nonlinear/static_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

StaticSolver::StaticSolver(Model& model, StaticOptions options)
    : model_(model), options_(options), newton_(model.pattern(), options.newton) {
  if (!(options_.increment > 0.0) || !(options_.min_increment > 0.0) || options_.min_increment > options_.increment)
    throw std::invalid_argument("static solver: need 0 < min_increment <= increment");
  if (!(options_.growth >= 1.0)) throw std::invalid_argument("static solver: growth must be >= 1");
}

StaticReport StaticSolver::solve(State& state, double lambda_end, const Observer& observer) {
  const auto start = std::chrono::steady_clock::now();
  StaticReport report;
  const Index n = model_.num_dofs();
  Eigen::VectorXd fint(n), fext(n), fscale(n);
  double dlambda = options_.increment;
  int cuts = 0, level_iterations = 0, level_switches = 0;
  const double eps = 1e-12 * std::max(1.0, std::abs(lambda_end));

  while (state.t < lambda_end - eps) {
    // Charts change only between increments (docs/theory.md §2.3).
    const int switches = model_.rechart(state, options_.rechart_hysteresis);
    report.chart_switches += switches;
    level_switches += switches;
    // Reported load levels are the multiples of `increment`; cut sub-increments end on them exactly.
    const double level =
        std::min(lambda_end, (std::floor(state.t / options_.increment + 1e-9) + 1.0) * options_.increment);
    const double lambda = (state.t + dlambda >= level - eps) ? level : state.t + dlambda;
    const auto& charts = state.charts;

    // Residual scale: the applied load at this level (max norm, as KINSOL's test), so fnorm_tol is relative.
    model_.external(lambda, state.u, charts, fext.data());
    zero_constrained(model_.dofs(), fext.data());
    const double fref = std::max(fext.lpNorm<Eigen::Infinity>(), 1e-300);
    fscale.setConstant(1.0 / fref);

    auto residual = [&](const double* u, double* f) {
      const Eigen::Map<const Eigen::VectorXd> uu(u, n);
      model_.internal(uu, charts, f, nullptr);
      model_.external(lambda, uu, charts, fext.data());
      for (Index i = 0; i < n; ++i) f[i] -= fext[i];
      zero_constrained(model_.dofs(), f);
    };
    auto jacobian = [&](const double* u, SparseMatrix& J) {
      const Eigen::Map<const Eigen::VectorXd> uu(u, n);
      model_.internal(uu, charts, nullptr, &J);
      model_.add_load_stiffness(lambda, uu, charts, J);
      apply_dirichlet(model_.dofs(), J, nullptr);
    };

    Eigen::VectorXd u = state.u;
    const NewtonSolver::Result r = newton_.solve(u.data(), residual, jacobian, fscale.data());
    report.newton_iterations += r.iterations;
    report.jacobian_evaluations += r.jacobian_evals;
    if (!r.converged) {
      ++report.failed_attempts;
      ++cuts;
      dlambda *= 0.5;
      if (dlambda < options_.min_increment) {
        std::ostringstream msg;
        msg << "static solver gave up at load factor " << state.t << ": increment " << dlambda * 2
            << " failed and the next (" << dlambda << ") is below min_increment " << options_.min_increment
            << "; last Newton failure: " << r.message;
        throw std::runtime_error(msg.str());
      }
      continue;
    }
    state.u = u;
    state.t = lambda;
    ++report.increments;
    level_iterations += r.iterations;
    if (lambda == level) {
      ++report.levels;
      if (observer) {
        StaticIncrement inc;
        inc.step = report.levels;
        inc.load_factor = lambda;
        inc.newton_iterations = level_iterations;
        inc.chart_switches = level_switches;
        inc.cuts = cuts;
        inc.residual_norm = r.fnorm;
        observer(state, inc);
      }
      cuts = level_iterations = level_switches = 0;
    }
    if (r.iterations <= options_.easy_iterations) dlambda = std::min(options_.increment, dlambda * options_.growth);
  }
  report.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace shelldyn
