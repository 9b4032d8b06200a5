// The integrator study behind `shelldyn study BENCHMARK|FILE` (docs/results.md, "Integrator study"): for one
// case, a work–precision sweep of every method of a study file (docs/reference/study-files.md; the paper's
// three benchmarks are the shipped apps/studies/*.yaml) on a window every method can afford, plus
// full-duration conservation runs. Built on the comparison machinery of compare.hpp: the groups' runs are
// one run_comparisons() batch (same specs, labels, settings inheritance and run execution as `shelldyn
// compare`, so the study runs wherever and however compare runs). Runs start longest expected first across
// both groups, so the full group's long baseline run overlaps the window's runs instead of ending the study alone.
//
// Groups (sub-folders of the study folder):
//   window/   the work–precision sweep on [0, window_t_end] (short enough for the explicit baseline, whose
//             stability limit does not depend on its tolerance): the fixed-step methods over their Δt lists,
//             the adaptive methods over their rtol lists, and one tight reference run (`reference`, a
//             fixed-step scheme at a Δt well below the sweep's) for displacement errors;
//   full/     the case's full duration: every fixed-step method at full_dt and the full.runs (baselines).
// The case's own integrator block is checked as `shelldyn run` checks it (make_case_integrator), although the
// study's runs replace the integrator: a case that `run` refuses is refused here too.
// Resumable: a run whose <group>/<label>/run.json says "status": "complete" is not run again (delete its
// folder, or pass rerun, to repeat it); only the missing runs go to run_comparisons().
// Per-run budget (max_wall_per_run / max_steps_per_run, the run driver's --max-wall / --max-steps): a run
// that hits it stops at its next output time and is a row "stopped at budget" with the time it reached —
// never a complete row, never a point of the work–precision diagram or the headline. It is kept on resume
// while the budget is not raised (a larger budget, no budget or rerun run it again from t = 0).
//
// Measures per run (study.csv / study.md, from the run folders, so resumed runs count too):
//   energy error  = energy balance max_t |H(t) − H(0)| / max_t (K + V)(t), H = K + V − W_ext (the exact flow keeps
//                   H constant with the loads on too; every integrator accumulates W_ext consistently with its
//                   own discretization); energy_error_after_loads = mechanical_energy_drift(history, loads_end)
//                   where the run goes past the loads' end;
//   displ. error  = max over the output times of ‖monitors(t) − monitors_ref(t)‖₂ against the window's
//                   reference run (the reference's own error is estimated from the finest sweep run of the
//                   same scheme, Richardson with order 2, and printed in study.md);
//   cost          = cpu_s (CPU seconds of the run, run.json) and rhs_evaluations (residual / right-hand-side
//                   evaluations; one per Newton iteration for the implicit schemes, one per stage for ARKODE).
//   ΔL, ΔJ        = max ‖L − L_ref‖, ‖J − J_ref‖ after the loads (run.json).
// Then scripts/plot_study.py draws work_precision.png, full_energy.png, full_momentum.png.
#pragma once

#include "integrators/runs/compare.hpp"

#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

// A method of a study (one entry of the study file's `methods:` list, docs/reference/study-files.md): an
// integrator with its settings, swept on the window over Δt (fixed-step) or rtol (adaptive = the integrator
// has an `rtol` setting, probed through the registry by name, so a registered plug-in method works the same).
struct StudyMethod {
  std::string spec;                       // compare spec NAME[:KEY=VALUE...] without dt / rtol
  std::string integrator;                 // NAME
  bool adaptive = false;                  // swept over rtol (else over dt)
  std::vector<double> sweep;              // its Δt (fixed-step) or rtol (adaptive) values on the window
  bool window = true;                     // in the window's work–precision sweep
  bool full = true;                       // fixed-step only: also a full-duration run (at full_dt)
  std::string where;                      // "FILE:LINE" of its entry, for messages
};

// One study: which runs, on which window (a study file, load_study_file; the shipped ones are
// apps/studies/<benchmark>.yaml, chosen so that the three benchmarks together fit in 30 minutes on 2 cores,
// docs/results.md lists the measured times).
struct StudyPreset {
  std::string name;                       // study name: folder default results/<name>/study, log prefixes
  std::string source;                     // the study file ("" for a preset built in code)
  std::string case_file;                  // as written in the study file (`case:`)
  std::string case_path;                  // case_file resolved against the study file's folder ("" if no such file)
  std::string case_where;                 // "FILE:LINE" of `case:`
  std::string note;                       // printed in study.md (why this window / Δt)
  bool has_window = true;                 // the window group exists
  double window_t_end = 0.0;              // work–precision window [0, window_t_end]
  double window_output = 0.0;             // output interval on the window (0: the case's)
  std::vector<double> dts, rtols;         // the window's default sweeps (methods without their own dt / rtol list)
  std::string reference_spec;             // tight reference on the window (a compare spec with dt; "" none)
  bool has_full = true;                   // the full group exists
  double full_t_end = -1.0;               // end of the full-duration runs (< 0: the case's)
  double full_dt = 0.0;                   // Δt of the full-duration runs (0: the case's)
  double full_output = 0.0;               // output interval of the full-duration runs (0: the case's)
  std::vector<std::string> full_baselines;  // complete specs run over the full duration (kind "baseline")
  std::vector<StudyMethod> methods;       // in file order
  std::vector<std::string> headline = {"em-galpha", "em-exact"};  // integrators of the study.md headline
};

// Reads and validates a study file (YAML, schema in docs/reference/study-files.md). Every method is made
// once through the registry (make_integrator, by name), so unknown integrators, unknown settings and bad
// values fail here, before any run. Errors: std::invalid_argument "FILE:LINE: key.path: reason (how to fix)".
// A method with `optional: true` whose integrator is not registered in this build is left out.
StudyPreset load_study_file(const std::string& path);
StudyPreset load_study_from_string(const std::string& text, const std::string& source, const std::string& base_dir);

// Adds a method given as a spec NAME[:KEY=VALUE...] (e.g. `shelldyn study --add-method`) to the study: swept
// over the window's default Δt or rtol list, and (fixed-step) run over the full duration. `where` prefixes
// error messages (e.g. "--add-method 'x'").
void add_study_method(StudyPreset& preset, const std::string& spec, const std::string& where);

struct StudyOptions {
  StudyPreset preset;
  std::string case_path;                  // resolved case file
  std::string out_dir;                    // required
  std::vector<std::string> groups = {"window", "full"};
  bool rerun = false;                     // true: run completed runs again
  bool dry_run = false;                   // true: list the runs (and which are done), run nothing
  bool report_only = false;               // true: run nothing, write study.csv/study.md from the run folders as
                                          // they are (runs not made: "not run"; stopped mid-run: "not run (...)")
  double max_wall_per_run = 0.0;          // per-run budget in wall seconds (0: none; see above)
  long long max_steps_per_run = 0;        // per-run budget in steps, checked at output times (0: none)
  CompareOptions execution;               // jobs / threads / executor handed to run_comparisons() (MPI: every rank
                                          // calls run_study; only the one with report = true writes the tables)
  bool report = true;
  std::ostream* log = nullptr;
  std::string command;
};

struct StudyRow {
  std::string group, label, integrator, kind;  // kind: fixed | adaptive | reference | baseline
  double dt = 0.0, rtol = 0.0;            // the swept parameter (0 where not applicable)
  std::string status;                     // "complete", "stopped at budget", "failed: ...", "not run[ (...)]"
  std::string stop_note;                  // stopped at budget: the run driver's message (run.json "status")
  double t_reached = 0.0;                 // last output time in history.csv (= t_end when complete)
  long steps = 0, rhs_evaluations = 0, factorizations = 0, nonlinear_iterations = 0;
  double cpu_s = 0.0, wall_s = 0.0;
  double energy_error = 0.0, energy_error_after_loads = 0.0, displacement_error = 0.0, max_dL = 0.0, max_dJ = 0.0, ref_L = 0.0, ref_J = 0.0;
  double t_end = 0.0;
};

struct StudyResult {
  std::vector<StudyRow> rows;
  int ran = 0, skipped = 0, failed = 0, stopped = 0;  // stopped: at the per-run budget (not failed)
  std::string study_csv, study_md;
};

StudyResult run_study(const StudyOptions& options);

// Several studies (e.g. all three benchmarks: `shelldyn study all`) in one batch of the executor of the first
// (execution settings of the first apply to all): runs start longest expected first across every study and
// group. Every case and spec is checked before anything runs. Results in the order given.
std::vector<StudyResult> run_studies(const std::vector<StudyOptions>& studies);

// The value of "key" in the "summary" object of a run.json (NaN if absent), and its "status".
double run_json_number(const std::string& run_json_text, const std::string& key);
std::string run_json_status(const std::string& run_json_text);
// The budget a run.json status "stopped: --max-wall S s reached ..." / "stopped: --max-steps N reached ..."
// names: {"max-wall", S} or {"max-steps", N}; {"", 0} for any other status.
std::pair<std::string, double> stopped_budget(const std::string& status);

}  // namespace shelldyn
