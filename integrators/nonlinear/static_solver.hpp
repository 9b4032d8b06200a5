// Nonlinear statics by load-factor stepping with KINSOL Newton (issue: CR9 element + static solver).
//
// The load factor λ plays the role of time: F_ext(λ) = model.external(λ, ...), so a case file's load
// time functions define the load path (a `ramp` with t1 = 1 gives F_ext ∝ λ). Each increment solves
//     R(u) = F_int(u) − F_ext(λ, u) = 0     (constrained DOFs: identity rows, zero residual)
// with K(u) − ∂F_ext/∂u (symmetric part) as the Jacobian. Director charts are re-selected between
// increments (docs/theory.md §2.3), never inside a Newton solve. A failed increment (no convergence,
// or a director overshoot |q| ≥ 1 caught by the element, §2.1 guard) is cut in half and retried from
// the last converged state; after easy increments the increment grows again, up to the initial size.
#pragma once

#include "integrators/nonlinear/newton_solver.hpp"
#include "lib/model.hpp"
#include "lib/state.hpp"

#include <functional>
#include <string>

namespace shelldyn {

struct StaticOptions {
  double increment = 0.05;       // initial (and largest) load-factor increment
  double min_increment = 1e-6;   // give up below this
  double growth = 1.5;           // increment growth after an easy increment
  int easy_iterations = 6;       // an increment converged in at most this many iterations is easy
  double rechart_hysteresis = 1.0;
  NewtonOptions newton;          // KINSOL settings (full Newton by default)
};

// One reported load level (a multiple of `increment`, or the final load factor). When increments had
// to be cut, several converged sub-increments lead to one level; the counts cover all of them.
struct StaticIncrement {
  int step = 0;                  // levels reached so far
  double load_factor = 0.0;
  int newton_iterations = 0;     // over the sub-increments since the previous level
  int chart_switches = 0;        // director charts switched since the previous level
  int cuts = 0;                  // failed attempts since the previous level
  double residual_norm = 0.0;    // KINSOL's final scaled residual norm
};

struct StaticReport {
  int levels = 0;                // reported load levels
  int increments = 0;            // converged (sub-)increments
  int failed_attempts = 0;
  int newton_iterations = 0;
  int jacobian_evaluations = 0;
  int chart_switches = 0;
  double wall_seconds = 0.0;
};

class StaticSolver {
 public:
  StaticSolver(Model& model, StaticOptions options);

  using Observer = std::function<void(const State&, const StaticIncrement&)>;
  // Advances `state` (whose t is the current load factor) to load factor lambda_end. Calls `observer`
  // at every load level (the multiples of `increment` and lambda_end). Throws std::runtime_error naming the load factor, the increment
  // and KINSOL's message when the increment falls below min_increment.
  StaticReport solve(State& state, double lambda_end, const Observer& observer = {});

 private:
  Model& model_;
  StaticOptions options_;
  NewtonSolver newton_;
};

}  // namespace shelldyn
