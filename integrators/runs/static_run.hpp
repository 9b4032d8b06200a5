// Runs a static case end to end: options from the case's integrator block, load stepping, outputs
// (static.csv, fields/ VTU series + fields.pvd, run.json) and a one-line progress report per increment.
#pragma once

#include "integrators/nonlinear/static_solver.hpp"
#include "lib/problem.hpp"

#include <ostream>
#include <string>
#include <vector>

namespace shelldyn {

// Reads the `integrator: {name: static, ...}` settings: increment (default time.dt), min_increment,
// growth, easy_iterations, max_iters, tol (relative residual, default 1e-9), linear_solver,
// line_search, hysteresis.
StaticOptions static_options(const CaseSpec& spec);

struct StaticRow {
  int step = 0;
  double load_factor = 0.0;
  std::vector<double> monitors;  // in the order of problem.disc.monitors
  int newton_iterations = 0;
};

// out_dir empty: no files. log may be null. Returns the converged increments (the initial state is
// row 0). Throws on failure after writing run.json with status "incomplete: <reason>".
std::vector<StaticRow> run_static(Problem& problem, const std::string& out_dir, std::ostream* log,
                                  StaticReport* report = nullptr);

}  // namespace shelldyn
