// What the three benchmark apps (flying_plate, cylindrical_panel, pinched_hemisphere) share, so that
// each app stays a short tutorial (style.md habit 5): the common command line, input validation before
// anything is written, locating case files and plot scripts, the run itself (run_dynamic), the plots
// (scripts/plot_run.py) and the measured period of a signal.
//
// Errors: every bad input ends in ONE line "<app>: error: <what, where, how to fix>" on stderr and a
// non-zero exit (1 bad input / failed run, 2 command-line syntax). Inputs are validated before the
// result folder is created, so a rejected command leaves no folder behind; a run that fails later
// leaves run.json with status "incomplete: <reason>" (never "complete") and no plots.
#pragma once

#include "integrators/runs/executor.hpp"
#include "lib/io/case_file.hpp"
#include "lib/model/problem.hpp"

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

struct RunSummary;

namespace app {

// `--state FILE` of `static` and `modes` (docs/manual.md §1): a checkpoint.cbor, the folder of a run that
// wrote one, or a VTU of a run (DIR/fields/step_N.vtu; its time taken from DIR/fields.pvd). Checks that the
// state belongs to the case's mesh and adopts its director charts in problem.model. Throws
// std::invalid_argument "--state FILE: reason (how to fix)".
State load_saved_state(Problem& problem, const std::string& path);

// A case file of apps/cases/ by file name: first <source>/apps/cases (compile definition
// SHELLDYN_SOURCE_DIR), then <prefix>/share/shelldyn/cases next to the installed executable. Throws
// naming every place searched and suggesting --case.
std::string find_case_file(const std::string& file_name);

// A script of scripts/ (e.g. "plot_run.py"), searched like find_case_file; empty if not found.
std::string find_script(const std::string& file_name);

// The shipped study files (apps/studies/*.yaml, installed to <prefix>/share/shelldyn/studies;
// docs/reference/study-files.md), searched like find_case_file: name (file stem, e.g. "flying-plate") ->
// path, sorted by name; the first folder that holds any wins.
std::vector<std::pair<std::string, std::string>> shipped_study_files();

// Runs `python3 SCRIPT ARGS...` (python: $SHELLDYN_PYTHON, else /usr/bin/python3, else python3 on
// PATH). Never throws: if the interpreter or the script is missing, or it fails, prints ONE warning
// line to `warn` and returns false. The scripts themselves print one warning and exit 0 when
// matplotlib is missing.
bool run_python_script(const std::string& script, const std::vector<std::string>& args, std::ostream& warn);

// Throws std::invalid_argument unless `dir` can be created or written: it must not be an existing
// file, and its nearest existing ancestor must be a writable folder. Creates nothing.
void check_output_folder(const std::string& dir);

// Result folders are not silently reused: if `dir` already holds outputs of a shelldyn command
// (run.json, history.csv, fields.pvd, fields/, checkpoint.cbor, static.csv, summary.csv, plots,
// modes.csv, mode_shapes.csv, modes.pvd), this
// throws "use --overwrite" unless `overwrite`, which deletes exactly those outputs (nothing else) so
// that no stale VTU or row of an earlier run can pass for this one. Also runs check_output_folder().
void prepare_result_folder(const std::string& dir, bool overwrite);

// Validation of numeric command-line values (every command, every flag): ONE line naming the flag,
// the value, the allowed range and an example. Non-finite values are always rejected.
void check_positive(const std::string& flag, double value, const std::string& example);      // 0 < x <= 1e15
void check_non_negative(const std::string& flag, double value, const std::string& example);  // 0 <= x <= 1e15
void check_range(const std::string& flag, long long value, long long lo, long long hi, const std::string& example);

// Prints an error the way every command does: the first line of `what` as "PREFIX<line>", each further
// line (details, e.g. lists of valid names) indented by two spaces.
void print_error(std::ostream& err, const std::string& prefix, const std::string& what);
// Where a sweep's runs execute (integrators/runs/executor.hpp), for `shelldyn compare` and other sweep
// commands: under an MPI launcher (mpirun -n P ..., srun ...) the P ranks (dynamic assignment, rank 0
// collects; `threads` OpenMP threads per run, 0 → 1, `jobs` ignored); otherwise `jobs` worker threads.
// Launched by MPI but built without it (SHELLDYN_WITH_MPI=OFF) is an error, since every rank would run
// the whole sweep into the same folders. Call at most once per process (MPI is initialized here and
// finalized when the executor is destroyed).
std::unique_ptr<RunExecutor> make_sweep_executor(int jobs, int threads);

// Throws std::invalid_argument naming the registered integrators if `name` is not one of them.
void check_integrator_name(const std::string& name);

// "KEY=VALUE" -> (KEY, VALUE); throws std::invalid_argument with an example otherwise.
std::pair<std::string, std::string> split_setting(const std::string& kv, const std::string& where = "--set");

// Folder/row name of a run (style.md habit 9): integrator, then each override as _KEY=VALUE,
// e.g. "em-galpha", "galpha_rho_inf=0.8", "em-galpha_dt=0.002". Characters other than
// [A-Za-z0-9._=+-] are replaced by '-'.
std::string run_label(const std::string& integrator, const std::vector<std::pair<std::string, std::string>>& overrides);

// Period of a signal y(t) over t >= t_from from its upward crossings of the window mean, with a
// Schmitt trigger at ±25 % of the half range (ignores higher-mode ripple). Returns 0 when fewer than
// two upward crossings are found (window shorter than about 1.5 periods).
double measured_period(const std::vector<double>& t, const std::vector<double>& y, double t_from, int* crossings = nullptr);

// The command-line options common to the three apps.
struct AppOptions {
  std::string case_path;   // empty: the app's default case file
  std::string out_dir;     // empty: results/<case>/<run label>
  std::string integrator;  // empty: the case's
  std::vector<std::string> settings;  // KEY=VALUE integrator overrides
  double dt = 0.0;          // 0: the case's
  double t_end = -1.0;      // -1: the case's
  double output_every = 0.0;
  int vtu_every = -1;
  int threads = 0;
  bool quiet = false;
  bool no_plots = false;
  bool overwrite = false;
  std::string checkpoint_every;  // empty: default_checkpoint_policy()
  long long max_steps = 0;
  double max_wall = 0.0;
};

// What an app run produced, for the app's own report after the run.
struct AppResult {
  const Problem* problem = nullptr;
  const RunSummary* summary = nullptr;
  std::string out_dir;
};

// One benchmark app: name, default case, provisional note; main() does the rest.
class BenchmarkApp {
 public:
  BenchmarkApp(std::string name, std::string case_file, std::string description);

  std::string label;        // progress-line label, e.g. "FLP-prov"
  std::string provisional;  // printed once at the start (and saved in the log) when non-empty
  std::string folder_suffix;  // appended to the case name in the default result folder
  // Hooks: modify the case before the model is built (e.g. density), validate app options, and
  // report after a complete run.
  std::function<void(CaseSpec&)> modify_case;
  std::function<void()> validate;
  std::function<void(const Problem&)> before_run;
  std::function<void(const AppResult&)> report;

  CLI::App& cli() { return cli_; }
  // Parse, validate, run, plot, report. Returns the exit code; never throws.
  int main(int argc, char** argv);

 private:
  int run();
  std::string name_, case_file_, command_;
  CLI::App cli_;
  AppOptions o_;
};

}  // namespace app
}  // namespace shelldyn
