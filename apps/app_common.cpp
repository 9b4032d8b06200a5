#include "apps/app_common.hpp"
#include "lib/io/result_folder.hpp"

#include "integrators/runs/case_integrator.hpp"
#include "integrators/runs/compare.hpp"
#include "integrators/runs/registry.hpp"
#include "integrators/integrator.hpp"
#include "integrators/integrator_settings.hpp"
#include "integrators/runs/run_driver.hpp"
#include "lib/linalg/openmp_wait_policy.hpp"  // passive OpenMP waiting in every app (linked into each of them)
#include "integrators/checkpoint/checkpoint.hpp"  // load_saved_state: read_checkpoint (with or without MPI)
#include "lib/io/state_output.hpp"                   // load_saved_state: state_from_vtu
#ifdef SHELLDYN_HAVE_MPI
#include "integrators/runs/mpi_executor.hpp"
#endif


#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace fs = std::filesystem;

namespace shelldyn {
namespace app {

std::unique_ptr<RunExecutor> make_sweep_executor(int jobs, int threads) {
  if (launched_by_mpi()) {
#ifdef SHELLDYN_HAVE_MPI
    return make_mpi_executor(threads);
#else
    throw std::runtime_error(
        "started by an MPI launcher, but this shelldyn was built without MPI (SHELLDYN_WITH_MPI=OFF): run the sweep "
        "without mpirun/srun (--jobs N), or install libopenmpi-dev and rebuild");
#endif
  }
  return make_local_executor(jobs, threads);
}

namespace {

#ifndef SHELLDYN_SOURCE_DIR
#define SHELLDYN_SOURCE_DIR ""
#endif

// Installed files first (<prefix>/share/shelldyn/..., beside <prefix>/bin/ of this executable), then the
// source tree the binary was built from: an installed shelldyn must use, and so test, what was installed.
// A build-tree binary has no build/share/shelldyn and falls through to the source tree.
std::vector<fs::path> search_dirs(const std::string& sub_source, const std::string& sub_install) {
  std::vector<fs::path> dirs;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back(exe.parent_path().parent_path() / sub_install);
  const std::string src = SHELLDYN_SOURCE_DIR;
  if (!src.empty()) dirs.push_back(fs::path(src) / sub_source);
  return dirs;
}

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

std::string num(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

}  // namespace

State load_saved_state(Problem& problem, const std::string& given) {
  namespace fs = std::filesystem;
  std::string path = given;
  if (fs::is_directory(path)) path = (fs::path(path) / checkpoint_file_name()).string();
  if (!fs::exists(path))
    throw std::invalid_argument("--state " + path + ": no such file (give a run's checkpoint.cbor, its folder, or a fields/step_N.vtu)");
  Model& model = *problem.model;
  State s;
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".vtu") {
    bool has_time = false;
    try {
      s = state_from_vtu(model, path, &has_time);
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument("--state " + std::string(e.what()));
    }
    if (!has_time)
      throw std::invalid_argument("--state " + path + ": no fields.pvd of its run folder lists it, so its time (load factor) is "
                                  "unknown (keep the VTU in DIR/fields/ beside DIR/fields.pvd)");
  } else {
    Checkpoint c = read_checkpoint(path);
    if (c.state.u.size() != model.num_dofs() || static_cast<int>(c.state.charts.size()) != model.mesh().num_nodes())
      throw std::invalid_argument("--state " + path + ": the checkpoint holds " + std::to_string(c.state.u.size()) +
                                  " DOFs, this case's model " + std::to_string(model.num_dofs()) +
                                  " (a checkpoint of another case or mesh?)");
    s = c.state;
  }
  model.adopt_charts(s.charts);
  return s;
}

std::string find_case_file(const std::string& file_name) {
  std::string tried;
  for (const auto& d : search_dirs("apps/cases", "share/shelldyn/cases")) {
    const fs::path p = d / file_name;
    if (fs::is_regular_file(p)) return p.string();
    tried += (tried.empty() ? "" : ", ") + p.string();
  }
  throw std::invalid_argument("cannot find the case file " + file_name + " (looked in " + tried +
                              "); give it with --case PATH");
}

std::string find_script(const std::string& file_name) {
  for (const auto& d : search_dirs("scripts", "share/shelldyn/scripts")) {
    const fs::path p = d / file_name;
    if (fs::is_regular_file(p)) return p.string();
  }
  return {};
}

std::vector<std::pair<std::string, std::string>> shipped_study_files() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& d : search_dirs("apps/studies", "share/shelldyn/studies")) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(d, ec))
      if (e.path().extension() == ".yaml" && fs::is_regular_file(e.path(), ec))
        out.emplace_back(e.path().stem().string(), e.path().string());
    if (!out.empty()) break;
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool run_python_script(const std::string& script, const std::vector<std::string>& args, std::ostream& warn) {
  if (script.empty()) {
    warn << "warning: plot script not found (scripts/ of the source tree or share/shelldyn/scripts); no plots written"
         << std::endl;
    return false;
  }
  std::string python = "python3";
  if (const char* env = std::getenv("SHELLDYN_PYTHON"); env && *env)
    python = env;
  else if (fs::exists("/usr/bin/python3"))
    python = "/usr/bin/python3";
  std::vector<std::string> argv_s{python, script};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::cout.flush();
  pid_t pid = 0;
  if (posix_spawnp(&pid, python.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
    warn << "warning: cannot start " << python << " (set SHELLDYN_PYTHON); no plots written" << std::endl;
    return false;
  }
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    warn << "warning: " << fs::path(script).filename().string() << " failed (see above); the run's results are complete"
         << std::endl;
    return false;
  }
  return true;
}

void check_output_folder(const std::string& dir) {
  if (dir.empty()) throw std::invalid_argument("-o: empty output folder name");
  std::error_code ec;
  fs::path p = fs::absolute(dir, ec);
  if (ec) throw std::invalid_argument("-o " + dir + ": " + ec.message());
  if (fs::exists(p, ec) && !fs::is_directory(p, ec))
    throw std::invalid_argument("-o " + dir + ": exists and is not a folder; choose another output folder");
  while (!fs::exists(p, ec)) {
    if (!p.has_parent_path() || p.parent_path() == p) break;
    p = p.parent_path();
  }
  if (!fs::is_directory(p, ec))
    throw std::invalid_argument("-o " + dir + ": " + p.string() + " is not a folder; choose another output folder");
  if (access(p.c_str(), W_OK | X_OK) != 0)
    throw std::invalid_argument("-o " + dir + ": " + p.string() + " is not writable; choose another output folder");
}

void prepare_result_folder(const std::string& dir, bool overwrite) {
  check_output_folder(dir);
  // The folder is this command's until it exits (lib/io/result_folder.hpp, docs/guide/result-folders.md): taken
  // before anything is looked at or removed, so that a second command cannot write or delete under it.
  hold_result_folder(dir, overwrite ? StaleLock::take_over : StaleLock::refuse, &std::cerr);
  static const std::vector<std::string> outputs = {
      "run.json",     "run.json.tmp",   "history.csv",  "fields.pvd",         "fields.pvd.tmp", "checkpoint.cbor",
      "checkpoint.cbor.tmp", "run.json.reserve", "static.csv", "summary.csv", "summary.md", "energy.png",
      "momentum.png", "monitors.png",   "work_precision.png", "modes.csv", "mode_shapes.csv", "modes.pvd"};
  std::error_code ec;
  const fs::path d(dir);
  if (!fs::is_directory(d, ec)) return;
  std::vector<fs::path> found;
  for (const auto& f : outputs)
    if (fs::exists(fs::symlink_status(d / f, ec))) found.push_back(d / f);
  const bool fields = fs::is_directory(d / "fields", ec) && !fs::is_empty(d / "fields", ec);
  if (found.empty() && !fields) return;
  if (!overwrite)
    throw std::invalid_argument("-o " + dir + ": holds results of an earlier run (" +
                                (found.empty() ? std::string("fields/") : found.front().filename().string()) +
                                "); add --overwrite to replace them, or choose another folder");
  // Only regular files shelldyn wrote (its manifest), never through a symbolic link.
  remove_recorded_outputs(dir, outputs);
}

namespace {
[[noreturn]] void bad_number(const std::string& flag, double value, const std::string& what, const std::string& example) {
  std::ostringstream os;
  os << flag << " must be " << what << " (got " << value << "), e.g. " << example;
  throw std::invalid_argument(os.str());
}
}  // namespace

void check_positive(const std::string& flag, double value, const std::string& example) {
  if (!std::isfinite(value) || !(value > 0.0) || value > 1e15) bad_number(flag, value, "> 0 and at most 1e15", example);
}

void check_non_negative(const std::string& flag, double value, const std::string& example) {
  if (!std::isfinite(value) || !(value >= 0.0) || value > 1e15) bad_number(flag, value, ">= 0 and at most 1e15", example);
}

void check_range(const std::string& flag, long long value, long long lo, long long hi, const std::string& example) {
  if (value < lo || value > hi)
    throw std::invalid_argument(flag + " " + std::to_string(value) + ": must be in " + std::to_string(lo) + ".." +
                                std::to_string(hi) + ", e.g. " + example);
}

void print_error(std::ostream& err, const std::string& prefix, const std::string& what_in) {
  // A bare std::bad_alloc (an allocation the memory estimate did not foresee) says what it means.
  const std::string what = what_in == "std::bad_alloc"
                               ? "out of memory (" + memory_text(static_cast<double>(available_memory_bytes())) +
                                     " available); use a coarser mesh or fewer runs at a time (--jobs)"
                               : what_in;
  std::istringstream in(what);
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (first) {
      err << prefix << line << "\n";
      first = false;
    } else {
      const size_t b = line.find_first_not_of(' ');
      if (b != std::string::npos) err << "  " << line.substr(b) << "\n";
    }
  }
  if (first) err << prefix << "\n";
}

void check_integrator_name(const std::string& name) {
  if (name == "static") throw std::invalid_argument("--integrator static: the static solver runs as `shelldyn static CASE`");
  const auto names = integrator_names();
  if (std::find(names.begin(), names.end(), name) != names.end()) return;
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  throw std::invalid_argument("--integrator '" + name + "': unknown integrator (see the list below or --help)\navailable: " + list);
}

std::pair<std::string, std::string> split_setting(const std::string& kv, const std::string& where) {
  const auto eq = kv.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == kv.size())
    throw std::invalid_argument(where + " '" + kv + "': expected KEY=VALUE, e.g. rho_inf=0.8");
  return {kv.substr(0, eq), kv.substr(eq + 1)};
}

std::string run_label(const std::string& integrator, const std::vector<std::pair<std::string, std::string>>& overrides) {
  std::string s = integrator;
  for (const auto& [k, v] : overrides) s += "_" + k + "=" + v;
  for (char& c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '=' || c == '+' || c == '-')) c = '-';
  return s;
}

double measured_period(const std::vector<double>& t, const std::vector<double>& y, double t_from, int* crossings) {
  std::vector<size_t> idx;
  for (size_t i = 0; i < t.size() && i < y.size(); ++i)
    if (t[i] >= t_from && std::isfinite(y[i])) idx.push_back(i);
  if (crossings) *crossings = 0;
  if (idx.size() < 4) return 0.0;
  double lo = y[idx[0]], hi = lo, mean = 0.0;
  for (size_t i : idx) {
    lo = std::min(lo, y[i]);
    hi = std::max(hi, y[i]);
    mean += y[i];
  }
  mean /= static_cast<double>(idx.size());
  const double band = 0.25 * 0.5 * (hi - lo);
  if (!(band > 0.0)) return 0.0;
  std::vector<double> up;
  bool armed = false;  // true once the signal has been below mean - band
  for (size_t k = 1; k < idx.size(); ++k) {
    const size_t i = idx[k], j = idx[k - 1];
    if (y[i] < mean - band) armed = true;
    if (armed && y[j] < mean && y[i] >= mean) {
      up.push_back(t[j] + (mean - y[j]) * (t[i] - t[j]) / (y[i] - y[j]));  // linear interpolation
      armed = false;
    }
  }
  if (crossings) *crossings = static_cast<int>(up.size());
  if (up.size() < 2) return 0.0;
  return (up.back() - up.front()) / static_cast<double>(up.size() - 1);
}

// --- BenchmarkApp ------------------------------------------------------------------------------------
BenchmarkApp::BenchmarkApp(std::string name, std::string case_file, std::string description)
    : name_(std::move(name)), case_file_(std::move(case_file)), cli_(std::move(description), name_) {
  std::string names;
  for (const auto& [n, summary] : integrator_catalogue()) names += "\n  " + n + ": " + summary;
  cli_.add_option("--case", o_.case_path, "Case file (default: apps/cases/" + case_file_ + ")");
  cli_.add_option("-o,--output", o_.out_dir, "Result folder (default: results/<case>/<integrator and overrides>)");
  cli_.add_option("--integrator", o_.integrator, "Integrator (default: the case's integrator.name):" + names);
  cli_.add_option("--set", o_.settings, "Override an integrator setting, KEY=VALUE (repeatable), e.g. --set rho_inf=0.8");
  cli_.add_option("--dt", o_.dt, "Time step (default: the case's time.dt)");
  cli_.add_option("--t-end", o_.t_end, "End time (default: the case's time.t_end)");
  cli_.add_option("--output-every", o_.output_every, "Output interval in time units (default: the case's)");
  cli_.add_option("--vtu-every", o_.vtu_every, "Write a VTU every N output times; 0 disables (default: the case's)");
  cli_.add_option("--threads", o_.threads, "OpenMP threads for element loops and triangular solves (default: all cores)");
  cli_.add_flag("-q,--quiet", o_.quiet, "No progress lines");
  cli_.add_flag("--no-plots", o_.no_plots, "Do not call scripts/plot_run.py");
  cli_.add_flag("--overwrite", o_.overwrite, "Replace the results of an earlier run in the result folder");
  cli_.add_option("--checkpoint-every", o_.checkpoint_every,
                  "Checkpoint every N steps, Ts simulated time (0.5s), Ww wall seconds (60w) or off (default 60w); "
                  "continue a stopped run with `shelldyn resume DIR`");
  cli_.add_option("--max-steps", o_.max_steps, "Stop (resumable) at the first output time after N steps (default 0: no limit)");
  cli_.add_option("--max-wall", o_.max_wall, "Stop (resumable) after S seconds of wall time (default 0: no limit)");
}

int BenchmarkApp::main(int argc, char** argv) {
  for (int k = 0; k < argc; ++k) command_ += (k ? " " : "") + std::string(argv[k]);
  try {
    cli_.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return cli_.exit(e);  // --help
    std::cerr << name_ << ": error: " << one_line(e.what()) << " (see '" << name_ << " --help')\n";  // CLI11: one line
    return 2;
  }
  try {
    return run();
  } catch (const RunStopped& e) {  // signal or limit: everything written, resumable
    print_error(std::cerr, name_ + ": ", e.what());
    return e.exit_code();
  } catch (const std::exception& e) {
    record_failure(e.what());  // a held result folder still "incomplete: running" gets the reason (lib/io/result_folder.hpp)
    print_error(std::cerr, name_ + ": error: ", e.what());
    return 1;
  }
}

int BenchmarkApp::run() {
  // --- validate everything before anything is written ---------------------------------------------
  if (cli_.count("--dt")) check_positive("--dt", o_.dt, "--dt 1e-3");
  if (cli_.count("--t-end")) check_non_negative("--t-end", o_.t_end, "--t-end 6");
  if (cli_.count("--output-every")) check_positive("--output-every", o_.output_every, "--output-every 0.01");
  if (cli_.count("--threads")) check_range("--threads", o_.threads, 0, 1024, "--threads 2");
  if (cli_.count("--vtu-every")) check_range("--vtu-every", o_.vtu_every, 0, 1000000000, "--vtu-every 10 (0: no VTU)");
  if (cli_.count("--max-steps")) check_range("--max-steps", o_.max_steps, 0, 10000000000LL, "--max-steps 100000");
  if (cli_.count("--max-wall")) check_non_negative("--max-wall", o_.max_wall, "--max-wall 3600");
  const CheckpointPolicy policy =
      o_.checkpoint_every.empty() ? default_checkpoint_policy() : parse_checkpoint_policy(o_.checkpoint_every);
  if (!o_.integrator.empty()) check_integrator_name(o_.integrator);
  std::vector<std::pair<std::string, std::string>> settings;
  for (const auto& kv : o_.settings) settings.push_back(split_setting(kv));
  if (validate) validate();
  if (!o_.out_dir.empty()) check_output_folder(o_.out_dir);

  const std::string case_path = o_.case_path.empty() ? find_case_file(case_file_) : o_.case_path;
  CaseSpec spec = load_case(case_path);
  if (modify_case) modify_case(spec);
  const std::string integrator = o_.integrator.empty() ? spec.integrator.name : o_.integrator;
  // Check the integrator settings now, as run_dynamic will (but only after building the model).
  make_case_integrator(spec, o_.integrator, settings, o_.dt > 0.0 ? o_.dt : spec.time.dt);
  auto overrides = settings;
  if (o_.dt > 0.0) overrides.emplace_back("dt", num(o_.dt));
  const std::string out_dir =
      o_.out_dir.empty() ? (fs::path("results") / (spec.name + folder_suffix) / run_label(integrator, overrides)).string()
                         : o_.out_dir;
  prepare_result_folder(out_dir, o_.overwrite);
  Problem problem = make_problem(std::move(spec));

  RunOptions ro;
  ro.out_dir = out_dir;
  ro.integrator = o_.integrator;
  ro.settings = settings;
  ro.dt = o_.dt;
  ro.t_end = o_.t_end;
  ro.output_interval = o_.output_every;
  ro.vtu_every = o_.vtu_every;
  ro.threads = o_.threads;
  ro.log = o_.quiet ? nullptr : &std::cout;
  ro.command = command_;
  ro.label = label;
  ro.checkpoint = policy;
  ro.max_steps = o_.max_steps;
  ro.max_wall = o_.max_wall;
  ro.handle_signals = true;
  for (const char* flag : {"--integrator", "--dt", "--t-end", "--output-every", "--vtu-every", "--threads"})
    if (cli_.count(flag)) ro.overrides.emplace_back(flag, cli_.get_option(flag)->as<std::string>());
  for (const auto& kv : o_.settings) ro.overrides.emplace_back("--set", kv);

  std::cout << name_ << ": " << problem.spec.description << "\n";
  if (!provisional.empty()) std::cout << name_ << ": PROVISIONAL: " << provisional << "\n";
  std::cout << name_ << ": " << integrator << " -> " << out_dir << std::endl;
  if (before_run) before_run(problem);
  const RunSummary s = run_dynamic(problem, ro);  // throws on failure (run.json: "incomplete: ...")
  print_run_summary(std::cout, s);
  std::cout << "wrote " << out_dir << "/history.csv, " << out_dir << "/fields.pvd, " << out_dir << "/run.json\n";
  if (!problem.spec.output.history) {  // the report and the plots read history.csv
    std::cout << name_ << ": no history.csv (output.history is false): no energy report, no plots\n";
    return 0;
  }
  {
    const double drift = mechanical_energy_drift(read_csv_table(out_dir + "/history.csv"), problem.model->loads_end());
    std::cout << name_ << ": energy error max |H - H_ref|/(K_ref + V_ref) after the loads end: "
              << (std::isnan(drift) ? std::string("n/a (t_end before the loads end)") : num(drift)) << "\n";
  }
  if (report) report(AppResult{&problem, &s, out_dir});
  if (!o_.no_plots) {
    // The benchmark cases use SI units (docs/benchmarks.md), so the figures are labelled in SI.
    std::vector<std::string> args{out_dir, "--units", "SI", "--title",
                                  (label.empty() ? problem.spec.name : label) + ", " + run_label(s.integrator, overrides)};
    if (run_python_script(find_script("plot_run.py"), args, std::cout))
      std::cout << "wrote " << out_dir << "/energy.png, " << out_dir << "/momentum.png, " << out_dir << "/monitors.png\n";
  }
  return 0;
}

}  // namespace app
}  // namespace shelldyn
