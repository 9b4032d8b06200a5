// Runs a static case end to end: options from the case's integrator block, load stepping or path
// following, outputs (static.csv: step, load_factor, monitors, newton_iters, arc_length,
// negative_pivots, event ("-" or the critical point passed); fields/ VTU series + fields.pvd; run.json
// with the critical points in its summary) and a one-line progress report per reported point.
#pragma once

#include "integrators/nonlinear/static_solver.hpp"
#include "lib/model/problem.hpp"

#include <ostream>
#include <string>
#include <vector>

namespace shelldyn {

// Reads the `integrator: {name: static, ...}` settings (docs/statics.md): control (load | arc_length |
// displacement), increment (default time.dt), min_increment, growth, easy_iterations, target_iterations,
// max_arc_factor, max_steps, max_iters, tol (residual relative to F_ref, default 1e-8), step_tol (increment
// relative to the displacement scale, default 1e-10), linear_solver, hysteresis, max_turn (degrees,
// default 10), locate_tol (default 0.01), progress_seconds (default 5), and for displacement
// control control_set (one node), control_dof (ux|uy|uz), displacement_end. `disc` resolves control_set
// (may be null when control is not displacement).
StaticOptions static_options(const CaseSpec& spec, const Discretization* disc = nullptr);

struct StaticRow {
  int step = 0;
  double load_factor = 0.0;
  std::vector<double> monitors;  // in the order of problem.disc.monitors
  int newton_iterations = 0;
  double arc_length = 0.0;       // cumulative ‖Δd‖₂ of the translations along the path
  long negative_pivots = 0;      // inertia of the converged tangent
  std::string event;             // "", "limit point", "bifurcation point", "critical point", "snap-through", "path jump" (several: joined by "; ")
};

// out_dir empty: no files. log may be null. Returns the converged increments (the initial state is
// row 0). Throws on failure after writing run.json with status "incomplete: <reason>".
// start: begin from this state instead of the reference state (`shelldyn static --state`): its u and
// director charts, at load factor λ₀ = start->t, velocities ignored; it must fit the model (the caller
// checks) and λ₀ < time.t_end.
std::vector<StaticRow> run_static(Problem& problem, const std::string& out_dir, std::ostream* log,
                                  StaticReport* report = nullptr, const State* start = nullptr);

}  // namespace shelldyn
