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
// Energy bookkeeping: total H = K + V − W_ext, with W_ext accumulated by the integrator consistently with
// its own time discretization. rel_drift = (H − H_ref)/(K + V)_ref, where H_ref and (K + V)_ref are taken at
// the first output time at or after the loads end (t = 0 for unloaded cases); it is NaN before that. (K + V,
// not H, is the scale: a body started at rest holds exactly the work done on it, so H_ref ≈ 0.) Momentum changes ΔL, ΔJ are
// measured from the same reference time.
//
// Failure (StepFailure, bad settings, I/O): run.json gets status "incomplete: <reason>", the history and
// fields written so far stay, and the exception propagates (the CLI exits non-zero).
#pragma once

#include "integrators/integrator.hpp"
#include "lib/problem.hpp"

#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

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
};

struct RunSummary {
  std::string integrator;
  std::vector<std::pair<std::string, std::string>> settings;
  std::string status;              // "complete" or "incomplete: ..."
  double t_end = 0.0;
  StepReport totals;
  double H0 = 0.0, H_ref = 0.0, E_ref = 0.0, t_ref = 0.0, H_final = 0.0;  // E_ref = (K + V) at t_ref
  double max_rel_drift = 0.0;      // max |H − H_ref|/E_ref for t ≥ t_ref
  double final_rel_drift = 0.0;
  double max_dL = 0.0, max_dJ = 0.0;          // max ‖L − L_ref‖, ‖J − J_ref‖ for t ≥ t_ref
  double ref_L = 0.0, ref_J = 0.0;            // ‖L_ref‖, ‖J_ref‖
  double max_strain_ratio = 0.0;   // max V/(K+V) (rigid-body checks)
  std::vector<std::pair<std::string, double>> final_monitors;
  double wall_seconds = 0.0;
  // CPU seconds of the run: the calling thread's when the run is single-threaded (as every run of
  // `shelldyn compare`/`study` with 2 jobs), else the whole process's. run.json: cpu_s.
  double cpu_seconds = 0.0;
};

RunSummary run_dynamic(Problem& problem, const RunOptions& options);

// Prints the summary block the CLI and the apps show at the end of a run.
void print_run_summary(std::ostream& out, const RunSummary& s);

}  // namespace shelldyn
