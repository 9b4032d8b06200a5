// The dynamic run driver behind `shelldyn run` and the benchmark apps (issue: time integration, item 4).
//
// Time loop over the output times k·output_interval (and t_end): the integrator advances to each output
// time (fixed-step schemes re-select director charts before every step, adaptive ones at chart events);
// after each output time the driver evaluates the invariants and writes
//   history.csv   one row per output time: step,t,dt,kinetic,strain,external_work,total,rel_drift,
//                 Lx..Jz,nonlinear_iters,linear_setups,wall_s, then the case's monitors
//   fields/       a VTU every `vtu_every` output times, listed with their times in fields.pvd
//   run.json      resolved settings, versions, status and the final summary (rewritten at the end)
// and prints one progress line (at most ~5 per second of wall time; the last one always).
//
// Energy bookkeeping: total H = K + V − W_ext (+ W_damp, the energy dissipated by Rayleigh damping, for damped
// models; docs/theory.md §8.5), with W_ext accumulated by the integrator consistently with
// its own time discretization. rel_drift = (H − H_ref)/(K + V)_ref, where H_ref and (K + V)_ref are taken at
// the first output time at or after the loads end (t = 0 for unloaded cases); it is NaN before that. (K + V,
// not H, is the scale: a body started at rest holds exactly the work done on it, so H_ref ≈ 0.) Momentum changes ΔL, ΔJ are
// measured from the same reference time.
//
// Failure (StepFailure, bad settings, I/O): run.json gets status "incomplete: <reason>", the history and
// fields written so far stay, and the exception propagates (the CLI exits non-zero). If run.json itself
// cannot be written (e.g. the disk is full), the original cause is still what propagates.
//
// Checkpoints, limits and signals (docs/architecture.md "Checkpoints and resume"):
//   - RunOptions::checkpoint says when DIR/checkpoint.cbor is (re)written (integrators/checkpoint/):
//     every N steps, every T of simulated time or every W seconds of wall time, at the first output time
//     after the threshold; written atomically; removed when the run completes.
//   - handle_signals: the first SIGINT/SIGTERM asks the integrator to stop after the current step
//     (Newmark family) or abandons the current output interval (SUNDIALS: back to the last output
//     time); the driver writes a checkpoint and run.json "interrupted: ..." and throws RunStopped with
//     exit code 130 / 143. A second signal exits at once (_exit(128 + signal)).
//   - max_wall (checked like a signal) and max_steps (checked at output times) stop the run the same
//     way with status "stopped: ..." and exit code 4.
//   - resume: continue from a checkpoint (shelldyn resume DIR): history.csv is cut at the checkpoint's
//     row and continued, fields.pvd keeps its entries, counters and reference quantities continue. For
//     the Newmark family the continued run is bitwise the uninterrupted one (history.csv identical but
//     for the wall_s column); SUNDIALS baselines restart from the saved state (see their save()).
#pragma once

#include "integrators/checkpoint/checkpoint.hpp"
#include "integrators/integrator.hpp"
#include "lib/model/problem.hpp"

#include <functional>
#include <stdexcept>

#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

// When to write checkpoints. At most one of the thresholds is normally set; 0 = not by this measure.
struct CheckpointPolicy {
  long long steps = 0;     // every this many steps
  double sim_time = 0.0;   // every this much simulated time
  double wall = 0.0;       // every this many seconds of wall time
  bool requested = false;  // given explicitly: an integrator without checkpoints is then an error
  bool enabled() const { return steps > 0 || sim_time > 0.0 || wall > 0.0; }
  std::string text() const;  // e.g. "500", "0.5s", "60w", "off"
};
// Parses --checkpoint-every: "N" (steps), "Ts" (simulated time), "Ww" (wall seconds), "off" or "0".
// Throws std::invalid_argument with an example on anything else (nan, negative, huge, junk).
CheckpointPolicy parse_checkpoint_policy(const std::string& text);
// Default of `shelldyn run` and the apps: every 60 s of wall time (short runs never write one).
CheckpointPolicy default_checkpoint_policy();

// Thrown after an orderly stop (signal, --max-wall, --max-steps): everything is written, run.json says
// "interrupted: ..." or "stopped: ...", a checkpoint exists if the integrator supports them.
class RunStopped : public std::runtime_error {
 public:
  RunStopped(const std::string& what, int exit_code) : std::runtime_error(what), exit_code_(exit_code) {}
  int exit_code() const { return exit_code_; }

 private:
  int exit_code_;
};

struct RunOptions {
  std::string out_dir;             // empty: no files at all
  std::string integrator;          // empty: the case's integrator.name
  std::vector<std::pair<std::string, std::string>> settings;  // overrides of integrator settings
  double dt = 0.0;                 // 0: the case's time.dt
  double t_end = -1.0;             // < 0: the case's time.t_end
  double output_interval = 0.0;    // 0: the case's time.output_interval
  int vtu_every = -1;              // < 0: the case's output.vtu_every; 0: no VTU
  int threads = 0;                 // 0: OpenMP default
  std::ostream* log = nullptr;     // progress lines and the final summary
  std::string command;             // recorded in run.json
  std::string label;               // optional label printed in progress lines (e.g. "FLP-prov")
  // Besides `log`: one plain progress line (as in `log`, label first) every `progress_every` seconds of wall time
  // (0: at every output time) handed to `progress`, e.g. the console of `shelldyn compare` whose runs log to files.
  std::function<void(const std::string& line)> progress;
  double progress_every = 10.0;
  CheckpointPolicy checkpoint;     // default: none (the CLI and the apps use default_checkpoint_policy())
  long long max_steps = 0;         // stop at the first output time with at least this many steps; 0: none
  double max_wall = 0.0;           // stop after this many seconds of wall time; 0: none
  bool handle_signals = false;     // SIGINT/SIGTERM stop the run in order (see above)
  const Checkpoint* resume = nullptr;  // continue from this checkpoint (the folder is out_dir)
  // Command-line flags that changed the case (recorded in run.json "command_line_overrides").
  std::vector<std::pair<std::string, std::string>> overrides;
};

// Name of the checkpoint file in a result folder.
inline const char* checkpoint_file_name() { return "checkpoint.cbor"; }

// `shelldyn resume`: the Problem and RunOptions stored in a checkpoint (case text, resolved material,
// command-line options). Throws std::runtime_error if a mesh file changed since the checkpoint.
Problem problem_from_checkpoint(const Checkpoint& c);
RunOptions run_options_from_checkpoint(const Checkpoint& c);

struct RunSummary {
  std::string integrator;
  std::vector<std::pair<std::string, std::string>> settings;
  std::string status;              // "complete" or "incomplete: ..."
  double t_end = 0.0;
  StepReport totals;
  double H0 = 0.0, H_ref = 0.0, E_ref = 0.0, t_ref = 0.0, H_final = 0.0;  // E_ref = (K + V) at t_ref
  // false when the run ended before the loads did (t_end < loads_end): the "after the loads" figures below are
  // then NaN (run.json: null; printed "n/a (loads still on)"), not 0.
  bool after_loads = false;
  double loads_end = 0.0;          // the system's loads_end()
  double max_rel_drift = 0.0;      // max |H − H_ref|/E_ref for t ≥ t_ref
  double final_rel_drift = 0.0;
  double max_dL = 0.0, max_dJ = 0.0;          // max ‖L − L_ref‖, ‖J − J_ref‖ for t ≥ t_ref
  double ref_L = 0.0, ref_J = 0.0;            // ‖L_ref‖, ‖J_ref‖
  double max_strain_ratio = 0.0;   // max V/(K+V) (rigid-body checks)
  // Rayleigh-damped model (docs/theory.md §8.5): H then includes + W_damp; damping_work = W_damp at the end.
  bool damped = false;
  double damping_work = 0.0;
  // Prescribed displacement histories (docs/theory.md §8.6): H then includes − W_presc; prescribed_work = W_presc
  // at the end.
  bool prescribed = false;
  double prescribed_work = 0.0;
  std::vector<std::pair<std::string, double>> final_monitors;
  double wall_seconds = 0.0;
  // CPU seconds of the run: the calling thread's when the run is single-threaded (as every run of
  // `shelldyn compare`/`study` with 2 jobs), else the whole process's. run.json: cpu_s.
  double cpu_seconds = 0.0;
};

RunSummary run_dynamic(Problem& problem, const RunOptions& options);

// `shelldyn resume`: makes sure the integrator of checkpoint `c` is registered, loading the plugins the run
// recorded (integrators/runs/plugin.hpp) unless they are loaded already (e.g. given again with --plugin).
// Throws PluginError naming the plugin (path, version, hash) and how to provide it when it cannot be loaded.
void load_checkpoint_plugins(const Checkpoint& c);

// Prints the summary block the CLI and the apps show at the end of a run.
void print_run_summary(std::ostream& out, const RunSummary& s);

}  // namespace shelldyn
