// The comparison study behind `shelldyn compare` (style.md habit 9): one case, several integrator
// settings, each an independent run_dynamic() into its own folder, and a summary table.
//
// Run settings ("specs"): NAME[:KEY=VALUE[:KEY=VALUE...]], e.g.
//   em-galpha                      the integrator with the case's settings (if it is the case's integrator)
//                                  or its defaults
//   galpha:rho_inf=0.8             an integrator-setting override (as `shelldyn run --set`)
//   em-galpha:dt=2e-3              `dt` is the run's time step, not an integrator setting
//   ida-bdf:rtol=1e-8:atol=1e-10   adaptive integrators take rtol/atol like any setting
// Sweeps: `dts` multiplies every FIXED-STEP spec that does not set dt itself (one run per dt);
// `rtols` multiplies every spec whose integrator has an `rtol` setting (adaptive; probed by making the
// integrator with its defaults) and does not set rtol itself. Labels (folder and row names) are
// run_label-style: NAME then _KEY=VALUE per override, e.g. "galpha_rho_inf=0.8_dt=0.002".
//
// Fairness: every run inherits those settings of the case's `integrator:` block that its integrator
// understands (e.g. newton, linear_solver, cc_tol, rho_inf; probed from the integrator's defaults), so
// runs differ only in their integrator and what their spec says; spec overrides win. They are recorded
// in run.json and summary.csv (`settings`), not in the labels.
//
// Execution (integrators/runs/executor.hpp): `executor` if given — e.g. the ranks of an MPI job,
// integrators/runs/mpi_executor.hpp — else `jobs` worker threads of this process (OpenMP threads = 1 per
// run when jobs > 1). Runs start longest expected first (t_end/dt steps; adaptive runs weighted, see
// expected_cost in compare.cpp). Each run has its own Problem (case loaded anew) and writes
// DIR/<label>/{history.csv,run.json,log.txt[,fields]} and, once finished, compare-outcome.txt (its
// summary figures and a fingerprint of its settings). A run that throws is a row with status
// "failed: <reason>", never dropped.
// Summaries are rewritten after every finished run, with the runs not finished yet as rows "failed: not
// finished (...)", so a sweep stopped at any point (killed, time limit) leaves a summary of every run.
// resume = true: a run whose folder holds a compare-outcome.txt with the same fingerprint (case file
// bytes, shelldyn version, integrator, settings, dt, t_end, output interval, vtu) is not run again; its
// recorded outcome is used.
// Under MPI only the collecting rank (rank 0) writes summaries; the others return rows without results.
//
// Results: DIR/summary.csv (one row per run, machine-readable) and DIR/summary.md (the same as a table
// with the command, the case and the reference run). The displacement error of a run is
// max_t ‖m(t) − m_ref(t)‖₂ over all monitor columns and the output times both runs share, against the
// reference run: `reference` if given, else the completed fixed-step run with the smallest dt (ties:
// the one listed first), else the completed run with the most steps. The energy error is the run's
// mechanical_energy_drift (below): max |H − H_ref|/(K_ref + V_ref) after the loads end; NaN (shown
// "n/a") if t_end is before the loads end.
//
// Errors: bad specs (unknown integrator or setting, malformed KEY=VALUE, dt <= 0), duplicate labels or an
// unreadable case throw std::invalid_argument / std::runtime_error before any run starts.
#pragma once

#include "integrators/runs/executor.hpp"
#include "integrators/runs/run_driver.hpp"

#include <limits>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

struct CompareOptions {
  std::string case_path;
  std::vector<std::string> specs;   // see above
  std::vector<double> dts;          // sweep for fixed-step specs (empty: the case's dt)
  std::vector<double> rtols;        // sweep for adaptive specs (empty: their default)
  double t_end = -1.0;              // < 0: the case's
  double output_interval = 0.0;     // 0: the case's
  int vtu_every = 0;                // VTU output per run: 0 none (default), < 0 the case's
  int jobs = 2;                     // runs at a time
  int threads = 0;                  // OpenMP threads per run when jobs == 1 (0: default)
  RunExecutor* executor = nullptr;  // where runs execute (null: a local pool of `jobs` threads)
  bool resume = false;              // reuse finished runs of an earlier sweep (see above)
  double max_wall = 0.0;            // per-run budget: RunOptions::max_wall / max_steps of every run (0: none); a
  long long max_steps = 0;          // run that hits it is a row "failed: stopped: --max-wall ..." (run.json says so)
  std::string out_dir;              // required
  std::string reference;            // label of the reference run (empty: automatic, see above)
  std::ostream* log = nullptr;      // one line per run start/finish
  // Progress of the runs on `log` (each run's own progress lines go to its log.txt): one line "LABEL | t = ..."
  // per run every progress_every seconds of wall time (and at its first and last output); < 0: none.
  double progress_every = 10.0;
  std::string command;              // recorded in run.json and summary.md
  std::string log_prefix;           // put before run labels in log lines (run_comparisons: e.g. "window/")
};

struct CompareRun {
  std::string label;                // folder and row name
  std::string integrator;
  std::vector<std::pair<std::string, std::string>> overrides;  // integrator-setting overrides (spec)
  std::vector<std::pair<std::string, std::string>> inherited;  // from the case's integrator block
  double dt = 0.0;                  // 0: the case's
  bool adaptive = false;            // integrator has an rtol setting
};

struct CompareRow {
  CompareRun run;
  bool ok = false;
  std::string status;               // "complete" or "failed: <reason>"
  RunSummary summary;               // valid when ok
  double energy_error = std::numeric_limits<double>::quiet_NaN();
  double displacement_error = std::numeric_limits<double>::quiet_NaN();
  std::string out_dir;
};

struct CompareResult {
  std::vector<CompareRow> rows;
  std::string reference;            // label of the reference run ("" if none completed)
  std::vector<std::string> monitors;
  std::string summary_csv, summary_md;
};

// Parses NAME[:KEY=VALUE...]; throws std::invalid_argument on malformed input.
CompareRun parse_compare_spec(const std::string& spec);

// The runs the options describe (sweeps expanded, labels made, every integrator and setting checked by
// constructing it); throws on bad input, before anything is run or written.
std::vector<CompareRun> expand_compare_runs(const CompareOptions& options);

// Runs the study and writes summary.csv / summary.md. Throws only for bad options or when the summary
// cannot be written; failed runs are rows. On a non-collecting MPI rank the summary paths are empty.
CompareResult run_comparison(const CompareOptions& options);

// Several sweeps (e.g. the window and full groups of a study) in ONE batch of the executor of the first
// (its jobs / threads / executor settings apply to all): runs start longest expected first across the sweeps,
// so a long run of one sweep overlaps the short runs of the others instead of running alone at the end. Each
// sweep keeps its own folder, summaries and result (returned in the order given); log lines number the runs
// in the batch and put each sweep's log_prefix before its labels.
std::vector<CompareResult> run_comparisons(const std::vector<CompareOptions>& sweeps);

// history.csv (or any numeric CSV with a header row) as columns; "nan" parses as NaN.
struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> data;  // data[column][row]
  const std::vector<double>* column(const std::string& name) const;
};
CsvTable read_csv_table(const std::string& path);

// Energy drift of a history after the loads end, normalised by the MECHANICAL energy K + V at the
// reference time (the first output time t_ref >= loads_end): max_{t >= t_ref} |H(t) − H(t_ref)| /
// (K(t_ref) + V(t_ref)). Unlike history.csv's rel_drift (normalised by |H_ref|, which is ~0 for a body
// set in motion by loads, since then H = K + V − W_ext ≈ 0), this is meaningful for loaded and unloaded
// cases alike. NaN if no output time is at or after loads_end or K + V = 0 there.
double mechanical_energy_drift(const CsvTable& history, double loads_end);

// max_t ‖m(t) − m_ref(t)‖₂ over the output times both histories share, m = the named monitor columns
// (the displacement error of compare and study); NaN if no time is shared or a column is missing.
double monitor_distance(const CsvTable& a, const CsvTable& b, const std::vector<std::string>& monitors);

}  // namespace shelldyn
