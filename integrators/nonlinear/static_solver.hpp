// Nonlinear statics: load control, arc-length path following and displacement control
// (docs/statics.md).
//
// The load parameter λ plays the role of time: F_ext(λ, u) = model.external(λ, u, ...), so a case file's
// load time functions define the load path (a `ramp` with t1 = 1 gives F_ext ∝ λ; with other functions
// λ is a pseudo-time and messages say so, see `parameter_name`). Every solve is a full Newton iteration on
//     R(u, λ) = F_int(u) − F_ext(λ, u) = 0     (constrained DOFs: identity rows, zero residual)
// with the tangent K(u) − sym ∂F_ext/∂u, factorized by the project's LinearSolver (an LDLᵀ back-end by
// default, whose negative pivots give the inertia of the tangent), and the scale-aware ConvergenceTest of
// integrators/nonlinear/path_following.hpp. Director charts are re-selected between steps
// (docs/theory.md §2.3), never inside a Newton solve.
//
// Controls:
//   load:          λ stepped to the multiples of `increment` (reported levels); a failed increment
//                  (no convergence, or the director overshoot guard |q| ≥ 1 of docs/theory.md §2.1) is
//                  halved and retried, and grows again after easy increments. Cannot pass a limit point:
//                  a step that passes one is REPORTED (critical_points), never silent: the inertia of the
//                  converged tangent changes, or the Newton iterates of the step crossed an indefinite
//                  tangent, or the converged increment is longer than `jump_ratio` × its tangent prediction
//                  K_n⁻¹ΔF (the solution jumped to a remote branch: snap-through).
//   arc_length:    Crisfield's cylindrical constraint ‖Δd‖₂ = Δl on the translations (path_following.hpp),
//                  with the usual root choice; predictor along K⁻¹F̂ (F̂ = ∂F_ext/∂λ) with the sign of
//                  its projection on the previous increment; Δl adapted to `target_iterations` and halved
//                  on failure. Δl of the first step makes its predictor Δλ = `increment`.
//   displacement:  the DOF `control_dof` is prescribed in steps of `increment` (length units), λ follows.
// Step control (arc length, displacement; docs/guide/statics-limit-points.md): besides the iteration count,
// a converged step is accepted only when
//   - the path tangent t = K⁻¹F̂ (translations) turns by at most 2·max_turn between its ends (else it is
//     retried shorter: a sharp snap is resolved, not jumped over), and the next step is sized so that the
//     tangent turns by about max_turn;
//   - the inertia of the tangent (its negative pivots) is the same at both ends and no Newton iterate met
//     more negative pivots than the ends. Otherwise a critical point lies inside the step: the step is cut
//     back by bisection until the step that crosses it is shorter than locate_tol × the first step, and
//     the critical point is reported there (a loop of two limit points inside one step is split the same
//     way). Its kind follows from the sign of dλ/ds at the two ends (the sign of the determinant of the
//     bordered arc-length system is sign(dλ/ds)·(−1)^pivots): a limit point when dλ/ds changes sign, a
//     bifurcation point when it does not (no branch switching: the solver stays on the primary path). The
//     λ of a limit point is the extremum of the cubic Hermite interpolant of λ(s) over the crossing step.
// A step whose tangent still turns by more than 2·max_turn at the smallest step is accepted and reported
// as a "path jump" (a warning: the path is not resolved there). With a back-end that cannot report the
// inertia (klu) a reversal of λ marks a limit point. The last arc-length step is solved under load control
// at exactly lambda_end.
//
// Loads: when every load is a ramp (λ is a load factor), F_ext is extended to λ < 0 as an odd function
// (F_ext(−λ) = −F_ext(λ), a reversed load) so that a path through negative loads stays traceable.
#pragma once

#include "integrators/nonlinear/path_following.hpp"
#include "lib/model/model.hpp"
#include "lib/model/state.hpp"

#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace shelldyn {

enum class PathControl { load, arc_length, displacement };
PathControl parse_path_control(const std::string& name);  // "load" | "arc_length" | "displacement"
const char* path_control_name(PathControl c);

struct StaticOptions {
  PathControl control = PathControl::load;
  double increment = 0.05;        // load: Δλ per level; arc_length: first predictor Δλ; displacement: Δ per step
  double min_increment = 1e-6;    // load: give up below this Δλ; others: below this fraction of the first Δl / Δ
  double growth = 1.5;            // load: increment growth after an easy increment; arc: max Δl growth per step
  int easy_iterations = 6;        // load: an increment converged in at most this many iterations is easy
  int target_iterations = 5;      // arc length: Δl ← Δl·sqrt(target/iterations), within [1/2, growth]
  double max_arc_factor = 4.0;    // arc length / displacement: Δl ≤ this × the first Δl
  int max_steps = 1000;           // arc length / displacement: give up after this many steps
  int max_iters = 30;             // Newton iterations per step
  double jump_ratio = 5.0;        // load: a converged increment longer than this × the tangent prediction is a jump
  double max_turn = 10.0;         // arc length / displacement: target turn of the path tangent per step, degrees
  double locate_tol = 0.01;       // arc length / displacement: a critical point is located to this × the first step
  bool odd_load_extension = false;  // F_ext(−λ) = −F_ext(λ) for λ < 0 (every load a ramp: λ is a load factor)
  // Progress of long steps: called with a one-line message at most every progress_seconds while a step's
  // Newton iterations run (the observer's lines count as progress). Null: silent.
  std::function<void(const std::string&)> progress;
  double progress_seconds = 5.0;
  ConvergenceTest convergence;
  std::string linear_solver = "eigen-ldlt";
  double rechart_hysteresis = 1.0;
  Index control_dof = -1;         // displacement control: the prescribed DOF
  double displacement_end = std::numeric_limits<double>::quiet_NaN();  // displacement: stop there
  std::string parameter_name = "load factor";  // "pseudo-time t" when the loads are not proportional to λ
};

// One reported point of the path (load control: a load level; other controls: every step).
struct StaticIncrement {
  int step = 0;
  double load_factor = 0.0;
  int newton_iterations = 0;     // since the previous reported point
  int chart_switches = 0;
  int cuts = 0;                  // failed attempts since the previous reported point
  double residual_norm = 0.0;    // ‖R_free‖₂ at the converged point
  double arc_length = 0.0;       // cumulative ‖Δd‖₂ along the path
  long negative_pivots = 0;      // inertia of the converged tangent (-1: back-end cannot tell)
  std::string event;             // "", "limit point", "bifurcation point", "critical point", "snap-through",
                                 // "path jump"; several in one step are joined by "; "
  std::string event_note;        // the critical point's one-line note (with its λ) when event is set
};

struct CriticalPoint {
  int step = 0;                  // reported point at which it was detected (just past it)
  double load_factor = 0.0;      // λ at that point
  double estimate = 0.0;         // λ of the located point (limit point: the extremum of λ; else the midpoint
                                 // of the crossing step)
  std::string kind;              // as StaticIncrement::event
  long pivots_before = 0, pivots_after = 0;
  std::string note;              // one line for logs and run.json
};

struct StaticReport {
  int levels = 0;                // reported points
  int increments = 0;            // converged (sub-)increments
  int failed_attempts = 0;
  int newton_iterations = 0;
  int jacobian_evaluations = 0;  // factorizations
  int chart_switches = 0;
  double wall_seconds = 0.0;
  double max_load_factor = 0.0;
  std::vector<CriticalPoint> critical_points;  // limit / bifurcation / critical points, snaps and path jumps
  int located_cuts = 0;          // steps cut back to locate critical points or to follow a sharp turn
};

class StaticSolver {
 public:
  StaticSolver(Model& model, StaticOptions options);

  using Observer = std::function<void(const State&, const StaticIncrement&)>;
  // Advances `state` (whose t is the current λ). Load control: to λ = lambda_end exactly. Arc length and
  // displacement control: until λ ≥ lambda_end, the controlled DOF reaches displacement_end, or max_steps
  // (the last is an error). Calls `observer` at every reported point. Throws std::runtime_error naming
  // the step, λ, the increment and the failed convergence test with its values when the step size falls
  // below its minimum.
  StaticReport solve(State& state, double lambda_end, const Observer& observer = {});

 private:
  Model& model_;
  StaticOptions options_;
};

}  // namespace shelldyn
