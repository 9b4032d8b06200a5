#include "apps/app_common.hpp"

#include "integrators/runs/compare.hpp"
#include "integrators/runs/registry.hpp"
#include "integrators/integrator.hpp"
#include "integrators/integrator_settings.hpp"
#include "integrators/runs/run_driver.hpp"
#ifdef SHELLDYN_HAVE_MPI
#include "integrators/runs/mpi_executor.hpp"
#endif


#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
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

std::vector<fs::path> search_dirs(const std::string& sub_source, const std::string& sub_install) {
  std::vector<fs::path> dirs;
  const std::string src = SHELLDYN_SOURCE_DIR;
  if (!src.empty()) dirs.push_back(fs::path(src) / sub_source);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back(exe.parent_path().parent_path() / sub_install);
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

void check_integrator_name(const std::string& name) {
  const auto names = integrator_names();
  if (std::find(names.begin(), names.end(), name) != names.end()) return;
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  throw std::invalid_argument("--integrator '" + name + "': unknown integrator (available: " + list + ")");
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
  cli_.add_option("--threads", o_.threads, "OpenMP threads for element loops (default: all cores)");
  cli_.add_flag("-q,--quiet", o_.quiet, "No progress lines");
  cli_.add_flag("--no-plots", o_.no_plots, "Do not call scripts/plot_run.py");
}

int BenchmarkApp::main(int argc, char** argv) {
  for (int k = 0; k < argc; ++k) command_ += (k ? " " : "") + std::string(argv[k]);
  try {
    cli_.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return cli_.exit(e);  // --help
    std::cerr << name_ << ": error: " << one_line(e.what()) << " (see '" << name_ << " --help')\n";
    return 2;
  }
  try {
    return run();
  } catch (const std::exception& e) {
    std::cerr << name_ << ": error: " << one_line(e.what()) << "\n";
    return 1;
  }
}

int BenchmarkApp::run() {
  // --- validate everything before anything is written ---------------------------------------------
  if (o_.dt < 0.0 || !std::isfinite(o_.dt) || (o_.dt == 0.0 && cli_.count("--dt")))
    throw std::invalid_argument("--dt must be > 0 (got " + num(o_.dt) + ")");
  if ((o_.t_end < 0.0 && cli_.count("--t-end")) || !std::isfinite(o_.t_end))
    throw std::invalid_argument("--t-end must be >= 0 (got " + num(o_.t_end) + ")");
  if (o_.output_every < 0.0 || !std::isfinite(o_.output_every) || (o_.output_every == 0.0 && cli_.count("--output-every")))
    throw std::invalid_argument("--output-every must be > 0 (got " + num(o_.output_every) + ")");
  if (o_.threads < 0) throw std::invalid_argument("--threads must be >= 0 (got " + std::to_string(o_.threads) + ")");
  if (o_.vtu_every < -1) throw std::invalid_argument("--vtu-every must be >= 0 (got " + std::to_string(o_.vtu_every) + ")");
  if (!o_.integrator.empty()) check_integrator_name(o_.integrator);
  std::vector<std::pair<std::string, std::string>> settings;
  for (const auto& kv : o_.settings) settings.push_back(split_setting(kv));
  if (validate) validate();
  if (!o_.out_dir.empty()) check_output_folder(o_.out_dir);

  const std::string case_path = o_.case_path.empty() ? find_case_file(case_file_) : o_.case_path;
  CaseSpec spec = load_case(case_path);
  if (modify_case) modify_case(spec);
  const std::string integrator = o_.integrator.empty() ? spec.integrator.name : o_.integrator;
  {  // Check the integrator settings now (run_dynamic would, but only after building the model).
    IntegratorSettings check = integrator == spec.integrator.name ? IntegratorSettings(spec.integrator)
                                                                  : IntegratorSettings(integrator, {});
    for (const auto& [k, v] : settings) check.set(k, v);
    if (integrator == "static") throw std::invalid_argument("--integrator static: use `shelldyn static CASE`");
    make_integrator(check, o_.dt > 0.0 ? o_.dt : spec.time.dt);
  }
  auto overrides = settings;
  if (o_.dt > 0.0) overrides.emplace_back("dt", num(o_.dt));
  const std::string out_dir =
      o_.out_dir.empty() ? (fs::path("results") / (spec.name + folder_suffix) / run_label(integrator, overrides)).string()
                         : o_.out_dir;
  if (o_.out_dir.empty()) check_output_folder(out_dir);
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

  std::cout << name_ << ": " << problem.spec.description << "\n";
  if (!provisional.empty()) std::cout << name_ << ": PROVISIONAL: " << provisional << "\n";
  std::cout << name_ << ": " << integrator << " -> " << out_dir << std::endl;
  // Stale plots of an earlier run in the same folder must not pass for this run's.
  for (const char* png : {"energy.png", "momentum.png", "monitors.png"}) {
    std::error_code ec;
    fs::remove(fs::path(out_dir) / png, ec);
  }
  if (before_run) before_run(problem);
  const RunSummary s = run_dynamic(problem, ro);  // throws on failure (run.json: "incomplete: ...")
  print_run_summary(std::cout, s);
  std::cout << "wrote " << out_dir << "/history.csv, " << out_dir << "/fields.pvd, " << out_dir << "/run.json\n";
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
