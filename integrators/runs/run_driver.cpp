#include "integrators/runs/run_driver.hpp"
#include "integrators/runs/case_integrator.hpp"
#include "integrators/runs/registry.hpp"

#include "integrators/runs/plugin.hpp"
#include "integrators/sundials/sundials_info.hpp"
#include "lib/io/append_file.hpp"
#include "lib/io/history_writer.hpp"
#include "lib/model/reactions.hpp"
#include "lib/io/result_folder.hpp"
#include "lib/io/run_info.hpp"
#include "lib/io/state_output.hpp"

#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>

namespace shelldyn {
namespace {

// Whether the run reports W_presc (docs/theory.md §8.6): prescribed displacement histories, or a prescribed_rotation
// joint, whose multipliers do the driver's work λ·∂g/∂t (docs/manual.md §2.13).
bool reports_prescribed_work(const Model& model) {
  if (model.has_prescribed_motion()) return true;
  if (const ModelMultibody* mb = model.multibody())
    for (const JointDef& j : mb->joints())
      if (j.type == JointDef::Type::prescribed_rotation) return true;
  return false;
}

using Clock = std::chrono::steady_clock;

void fill_summary_json(JsonFields& j, const RunSummary& s) {
  j.set("t_end", s.t_end);
  j.set("steps", s.totals.steps);
  j.set("rejected_steps", s.totals.rejected_steps);
  j.set("nonlinear_iterations", s.totals.nonlinear_iterations);
  j.set("linear_setups", s.totals.linear_setups);
  j.set("factorizations", s.totals.factorizations);
  j.set("rhs_evaluations", s.totals.rhs_evaluations);
  j.set("chart_switches", s.totals.chart_switches);
  j.set("root_events", s.totals.root_events);
  j.set("reinitializations", s.totals.reinitializations);
  j.set("H0", s.H0);
  j.set("t_ref", s.t_ref);
  j.set("H_ref", s.H_ref);
  j.set("E_ref", s.E_ref);
  j.set("H_final", s.H_final);
  if (s.damped) j.set("damping_work", s.damping_work);
  if (s.prescribed) j.set("prescribed_work", s.prescribed_work);
  // A run that ends while the loads act has no "after the loads" figures: null, not 0 (which reads as exact).
  const double nan = std::nan("");
  j.set("loads_still_on_at_end", !s.after_loads);
  j.set("max_rel_energy_drift_after_loads", s.after_loads ? s.max_rel_drift : nan);
  j.set("final_rel_energy_drift", s.after_loads ? s.final_rel_drift : nan);
  j.set("max_abs_dL_after_loads", s.after_loads ? s.max_dL : nan);
  j.set("max_abs_dJ_after_loads", s.after_loads ? s.max_dJ : nan);
  j.set("norm_L_ref", s.after_loads ? s.ref_L : nan);
  j.set("norm_J_ref", s.after_loads ? s.ref_J : nan);
  j.set("max_strain_over_energy", s.max_strain_ratio);
  for (const auto& [name, value] : s.final_monitors) j.set("final_" + name, value);
  j.set("wall_s", s.wall_seconds);
  j.set("cpu_s", s.cpu_seconds);
}

// CPU seconds of this thread (single-threaded runs: several may share the process) or of the process.
double cpu_now(bool thread_only) {
  timespec ts{};
  clock_gettime(thread_only ? CLOCK_THREAD_CPUTIME_ID : CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// --- signals ---------------------------------------------------------------------------------------
volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void on_stop_signal(int sig) {
  if (g_stop_signal != 0) _exit(128 + sig);  // second signal: leave at once (async-signal-safe)
  g_stop_signal = sig;
}

// Installs the handlers for the lifetime of a run and restores the previous ones.
class SignalGuard {
 public:
  explicit SignalGuard(bool on) : on_(on) {
    if (!on_) return;
    g_stop_signal = 0;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~SignalGuard() {
    if (!on_) return;
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

 private:
  bool on_;
  struct sigaction old_int_ {}, old_term_ {};
};

std::string g17(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", x);
  return b;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string encode_pairs(const std::vector<std::pair<std::string, std::string>>& kv) {
  std::string s;
  for (const auto& [k, v] : kv) s += k + "=" + v + "\n";
  return s;
}

std::vector<std::pair<std::string, std::string>> decode_pairs(const std::string& s) {
  std::vector<std::pair<std::string, std::string>> kv;
  std::istringstream in(s);
  for (std::string line; std::getline(in, line);) {
    const auto eq = line.find('=');
    if (eq != std::string::npos) kv.emplace_back(line.substr(0, eq), line.substr(eq + 1));
  }
  return kv;
}

// The driver's numbers in a checkpoint, by name (one list, so save and restore cannot disagree).
struct DriverNumbers {
  RunSummary& sum;
  bool& have_ref;
  long long& out_index;
  long long& k_next;
  double& E_seen;  // scale of rel_drift while loads act (observe())
  template <class F>
  void each(F&& f) {
    f("E_seen", E_seen);
    double ref = have_ref ? 1.0 : 0.0, oi = static_cast<double>(out_index), kn = static_cast<double>(k_next);
    f("have_ref", ref), f("out_index", oi), f("k_next", kn);
    f("H0", sum.H0), f("H_ref", sum.H_ref), f("E_ref", sum.E_ref), f("t_ref", sum.t_ref), f("H_final", sum.H_final);
    f("max_rel_drift", sum.max_rel_drift), f("final_rel_drift", sum.final_rel_drift);
    f("max_dL", sum.max_dL), f("max_dJ", sum.max_dJ), f("ref_L", sum.ref_L), f("ref_J", sum.ref_J);
    f("max_strain_ratio", sum.max_strain_ratio);
    StepReport& r = sum.totals;
    double c[] = {double(r.steps), double(r.rejected_steps), double(r.nonlinear_iterations), double(r.linear_setups),
                  double(r.factorizations), double(r.rhs_evaluations), double(r.chart_switches), double(r.root_events),
                  double(r.reinitializations)};
    const char* names[] = {"steps", "rejected_steps", "nonlinear_iterations", "linear_setups", "factorizations",
                           "rhs_evaluations", "chart_switches", "root_events", "reinitializations"};
    for (int i = 0; i < 9; ++i) f(names[i], c[i]);
    f("residual_norm", r.residual_norm), f("energy_ratio", r.energy_ratio), f("last_dt", r.last_dt);
    have_ref = ref != 0.0, out_index = static_cast<long long>(oi), k_next = static_cast<long long>(kn);
    long* counters[] = {&r.steps, &r.rejected_steps, &r.nonlinear_iterations, &r.linear_setups, &r.factorizations,
                        &r.rhs_evaluations, &r.chart_switches, &r.root_events, &r.reinitializations};
    for (int i = 0; i < 9; ++i) *counters[i] = static_cast<long>(c[i]);
  }
};

}  // namespace

std::string CheckpointPolicy::text() const {
  if (steps > 0) return std::to_string(steps);
  if (sim_time > 0.0) return g17(sim_time) + "s";
  if (wall > 0.0) return g17(wall) + "w";
  return "off";
}

CheckpointPolicy parse_checkpoint_policy(const std::string& text) {
  CheckpointPolicy p;
  p.requested = true;
  const std::string how = " (use N steps, e.g. 500; Ts simulated time, e.g. 0.5s; Ww wall seconds, e.g. 60w; or off)";
  if (text == "off" || text == "0") return p;
  if (text.empty()) throw std::invalid_argument("--checkpoint-every: empty" + how);
  const char unit = text.back();
  const std::string number = (unit == 's' || unit == 'w') ? text.substr(0, text.size() - 1) : text;
  char* end = nullptr;
  const double x = std::strtod(number.c_str(), &end);
  if (number.empty() || *end != '\0' || !std::isfinite(x) || !(x > 0.0) || x > 1e12)
    throw std::invalid_argument("--checkpoint-every '" + text + "': not a positive value" + how);
  if (unit == 's')
    p.sim_time = x;
  else if (unit == 'w')
    p.wall = x;
  else if (x != std::floor(x))
    throw std::invalid_argument("--checkpoint-every '" + text + "': a step count must be whole" + how);
  else
    p.steps = static_cast<long long>(x);
  return p;
}

CheckpointPolicy default_checkpoint_policy() {
  CheckpointPolicy p;
  p.wall = 60.0;
  return p;
}

void load_checkpoint_plugins(const Checkpoint& c) {
  if (!c.texts.count("plugins")) return;  // a checkpoint from before plugins were recorded
  const std::string wanted = c.texts.count("integrator_registered") ? c.text("integrator_registered") : c.integrator;
  const auto registered = [&wanted] {
    const auto names = integrator_names();
    return std::find(names.begin(), names.end(), wanted) != names.end();
  };
  std::istringstream in(c.text("plugins"));
  for (std::string line; !registered() && std::getline(in, line);) {  // given again with --plugin: nothing to load
    if (line.empty()) continue;
    const auto t1 = line.find('\t');
    const auto t2 = t1 == std::string::npos ? t1 : line.find('\t', t1 + 1);
    const std::string path = line.substr(0, t1);
    const std::string version = t1 == std::string::npos ? "unknown" : line.substr(t1 + 1, t2 == std::string::npos ? t2 : t2 - t1 - 1);
    const std::string hash = t2 == std::string::npos ? "" : line.substr(t2 + 1);
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
      throw PluginError("resume: plugin " + path + " (version " + version + ", " + hash + "), recorded for this run's integrator '" +
                        wanted + "', is missing: rebuild it there or give it with --plugin PATH");
    const PluginInfo p = load_plugin(path, "resume");
    if (!hash.empty() && p.hash != hash)
      std::cerr << "warning: plugin " << path << " changed since the checkpoint (" << hash << ", now " << p.hash
                << "); the continued run may differ from an uninterrupted one" << std::endl;
  }
  if (!registered())
    throw PluginError("resume: integrator '" + wanted + "' of this run is not registered and no recorded plugin provides it; "
                      "give its plugin with --plugin PATH");
}

Problem problem_from_checkpoint(const Checkpoint& c) {
  CaseSpec spec = load_case_from_string(c.text("case_text"), c.text("case_source"), c.text("case_base_dir"));
  if (const auto* m = std::get_if<MeshFileSpec>(&spec.mesh)) {
    const std::filesystem::path mesh = std::filesystem::path(spec.base_dir) / m->path;
    if (content_hash(read_file(mesh.string())) != c.text("mesh_hash"))
      throw std::runtime_error(mesh.string() + ": the mesh file changed since the checkpoint; rerun from the start");
  }
  // What the caller changed after reading the case (e.g. pinched_hemisphere --density).
  spec.name = c.text("case_name");
  spec.description = c.text("case_description");
  spec.material.E = c.number("material_E");
  spec.material.nu = c.number("material_nu");
  spec.material.rho = c.number("material_rho");
  spec.material.thickness = c.number("material_thickness");
  spec.material.shear_factor = c.number("material_shear_factor");
  spec.output.history = c.number("output_history") != 0.0;
  return make_problem(std::move(spec));
}

RunOptions run_options_from_checkpoint(const Checkpoint& c) {
  RunOptions o;
  o.integrator = c.text("integrator");
  o.settings = decode_pairs(c.text("settings"));
  o.overrides = decode_pairs(c.text("overrides"));
  o.dt = c.number("dt");
  o.t_end = c.number("t_end");
  o.output_interval = c.number("output_interval");
  o.vtu_every = static_cast<int>(c.number("vtu_every"));
  o.label = c.text("label");
  o.command = c.text("command");
  o.checkpoint = parse_checkpoint_policy(c.text("checkpoint_policy"));
  o.checkpoint.requested = false;
  // The limits that stopped the run are not carried over: `shelldyn resume` sets new ones if asked.
  o.max_steps = 0;
  o.max_wall = 0.0;
  return o;
}

RunSummary run_dynamic(Problem& problem, const RunOptions& o) {
  const auto start = Clock::now();
  CaseSpec& spec = problem.spec;
  Model& model = *problem.model;
  if (o.threads > 0) omp_set_num_threads(o.threads);
  const bool thread_cpu = omp_get_max_threads() == 1;
  const double cpu0 = cpu_now(thread_cpu);
  const Checkpoint* resume = o.resume;
  const std::string case_text = resume ? resume->text("case_text") : read_file(spec.source);
  const std::string mesh_hash =
      resume ? resume->text("mesh_hash")
             : (std::holds_alternative<MeshFileSpec>(spec.mesh)
                    ? content_hash(read_file((std::filesystem::path(spec.base_dir) / std::get<MeshFileSpec>(spec.mesh).path).string()))
                    : std::string());
  const CaseMaterial material = spec.material;
  const std::string case_name = spec.name, case_description = spec.description;

  // --- resolve settings ---------------------------------------------------------------------------
  const double dt = o.dt > 0.0 ? o.dt : spec.time.dt;
  const double t_end = o.t_end >= 0.0 ? o.t_end : spec.time.t_end;
  double out_dt = o.output_interval > 0.0 ? o.output_interval : spec.time.output_interval;
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("time step dt must be > 0 (got " + g17(dt) + ")");
  if (!(t_end >= 0.0) || !std::isfinite(t_end)) throw std::invalid_argument("t_end must be >= 0 (got " + g17(t_end) + ")");
  if (out_dt < dt) out_dt = dt;
  if (t_end / dt > 1e10 || t_end / out_dt > 1e9)
    throw std::invalid_argument("t_end = " + g17(t_end) + " needs more than 1e10 steps of dt = " + g17(dt) +
                                " (or 1e9 outputs); check t_end, dt and the output interval");
  if (o.max_steps < 0) throw std::invalid_argument("max_steps must be >= 0");
  if (!(o.max_wall >= 0.0) || !std::isfinite(o.max_wall)) throw std::invalid_argument("max_wall must be >= 0");
  const int vtu_every = o.vtu_every >= 0 ? o.vtu_every : (spec.output.vtu ? spec.output.vtu_every : 0);
  std::unique_ptr<Integrator> integrator = make_case_integrator(spec, o.integrator, o.settings, dt);
  // Where the integrator came from (registry.hpp): a plugin's failures are reported with its path.
  const std::string registered_name = o.integrator.empty() ? spec.integrator.name : o.integrator;
  const std::string origin = integrator_origin(registered_name);
  const std::optional<PluginInfo> plugin = plugin_of_integrator(registered_name);
  const std::string blame = origin == "built-in" ? std::string() : "integrator '" + registered_name + "' from " + origin + ": ";
  // Joints (docs/reference/system-interface.md "Constraints"): an integrator that does not enforce them must not
  // run the system as if they were absent.
  if (model.num_constraints() > 0 && !integrator->supports_constraints()) {
    std::string able;
    for (const auto& n : integrators_supporting_constraints()) able += (able.empty() ? "" : ", ") + n;
    throw std::invalid_argument("integrator '" + integrator->name() + "' does not enforce joints (" +
                                std::to_string(model.num_constraints()) + " constraint rows); use " +
                                (able.empty() ? std::string("one that does (none registered)") : "one of: " + able));
  }

  RunSummary sum;
  sum.integrator = integrator->name();
  sum.settings = integrator->settings();
  sum.t_end = t_end;
  sum.damped = model.has_damping();  // the summary then names H = K + V − W_ext + W_damp
  sum.prescribed = reports_prescribed_work(model);  // ... and − W_presc
  spec.integrator.name = sum.integrator;  // run.json shows what was actually run
  spec.integrator.settings = sum.settings;
  spec.time.dt = dt;
  spec.time.t_end = t_end;
  spec.time.output_interval = out_dt;
  spec.output.vtu = vtu_every > 0;
  spec.output.vtu_every = vtu_every > 0 ? vtu_every : spec.output.vtu_every;

  // --- outputs --------------------------------------------------------------------------------------
  const auto& monitors = problem.disc.monitors;
  RunInfo info;
  info.command = o.command;
  info.sundials_version = sundials_version();
  info.status = "incomplete: running";  // what a killed run leaves (with its last checkpoint)
  for (const auto& [k, v] : o.overrides) info.overrides.set(k, v);
  info.integrator_origin = origin;
  for (const auto& p : loaded_plugins()) {  // every plugin of the process (run.json "plugins"), the run's first
    JsonFields f;
    f.set("path", p.path);
    f.set("version", p.version);
    f.set("hash", p.hash);
    std::string names;
    for (const auto& n : p.integrators) names += (names.empty() ? "" : ",") + n;
    f.set("integrators", names);
    if (plugin && p.path == plugin->path) info.plugins.insert(info.plugins.begin(), f);
    else info.plugins.push_back(f);
  }
  info.discretization.set("nodes", model.mesh().num_nodes());
  info.discretization.set("elements", model.mesh().num_elements());
  info.discretization.set("dofs", static_cast<long long>(model.num_dofs()));
  info.discretization.set("constrained_dofs", static_cast<long long>(model.dofs().num_constrained()));
  info.discretization.set("total_mass", problem.disc.total_mass);
  info.discretization.set("loads_end", problem.disc.loads_end);
  std::unique_ptr<HistoryWriter> history;
  std::unique_ptr<PvdWriter> pvd;
  std::unique_ptr<AppendFile> bodies_csv;
  const bool files = !o.out_dir.empty();
  const std::string run_json_path = o.out_dir + "/run.json";
  const std::string checkpoint_path = o.out_dir + "/" + checkpoint_file_name();
  std::unique_ptr<DiskReserve> reserve;  // room for the final run.json on a disk the outputs fill (lib/io/run_info.hpp)
  // One writer per result folder (lib/io/result_folder.hpp); re-entrant: the CLI commands already hold theirs.
  const FolderLock folder_lock = files ? FolderLock(o.out_dir, StaleLock::take_over, &std::cerr) : FolderLock();
  if (files) {
    prepare_output_folder(o.out_dir);
    write_run_json(run_json_path, spec, info);
    reserve = std::make_unique<DiskReserve>(o.out_dir + "/run.json.reserve",
                                            65536 + 4 * static_cast<long long>(run_json(spec, info).size()));
    std::vector<std::string> names;
    for (const auto& m : monitors) names.push_back(m.name);
    // damping_work: energy dissipated by Rayleigh damping (docs/theory.md §8.5), only for damped models.
    // prescribed_work: work of the prescribed displacement histories (docs/theory.md §8.6) or of the driven joints
    // (prescribed_rotation), only when there are some.
    std::vector<std::string> extra;
    if (model.has_damping()) extra.push_back("damping_work");
    if (sum.prescribed) extra.push_back("prescribed_work");
    // g_norm = ‖g(u)‖∞, gdot_norm = ‖G u̇ + ∂g/∂t‖∞: constraint drift at the output state (joints only).
    if (model.num_constraints() > 0) {
      extra.push_back("g_norm");
      extra.push_back("gdot_norm");
    }
    if (spec.output.history)
      history = resume ? std::make_unique<HistoryWriter>(o.out_dir + "/history.csv", extra, names,
                                                         static_cast<long long>(resume->number("history_bytes")))
                       : std::make_unique<HistoryWriter>(o.out_dir + "/history.csv", extra, names);
    if (vtu_every > 0) pvd = std::make_unique<PvdWriter>(o.out_dir + "/fields.pvd");
    if (model.num_rigid_bodies() > 0) {  // bodies.csv: the rigid bodies' states per output (docs/manual.md)
      // A resumed run keeps the rows up to its checkpoint (checkpoints without `bodies_bytes` predate the
      // file's resume position: their rows are kept and appended to, as before).
      const std::string path = o.out_dir + "/bodies.csv";
      if (!resume) bodies_csv = std::make_unique<AppendFile>(path, body_state_header());
      else if (resume->numbers.count("bodies_bytes"))
        bodies_csv = std::make_unique<AppendFile>(path, body_state_header(), static_cast<long long>(resume->number("bodies_bytes")));
      else {
        std::error_code ec;  // (a missing file: AppendFile says so)
        const auto size = std::filesystem::file_size(path, ec);
        bodies_csv = std::make_unique<AppendFile>(path, body_state_header(), ec ? 0LL : static_cast<long long>(size));
      }
    }
  }

  // --- state and reference quantities ----------------------------------------------------------------
  State state = problem.initial_state();
  // Progress (docs/manual.md §1): one line updated in place on a terminal (every 0.2 s of wall time);
  // otherwise a plain line at every 10 % of the simulated time. Adaptive integrators add lines inside
  // long output intervals (in place on a terminal as well).
  const bool tty = o.log && ((o.log == &std::cout && isatty(STDOUT_FILENO)) || (o.log == &std::cerr && isatty(STDERR_FILENO)));
  integrator->set_progress_log(o.log, o.label.empty() ? sum.integrator : o.label, tty);
  integrator->initialize(model, state);
  // Integrators may resolve settings at initialize() (e.g. the baselines' absolute tolerances): report those.
  sum.settings = integrator->settings();
  spec.integrator.settings = sum.settings;
  const double loads_end = model.loads_end();
  sum.loads_end = loads_end;
  bool have_ref = false;
  Eigen::Vector3d L_ref = Eigen::Vector3d::Zero(), J_ref = Eigen::Vector3d::Zero();
  double last_print = -1.0, last_progress = -1.0;
  long long out_index = 0, k_next = 1;
  bool line_open = false;
  double next_plain_t = 0.0;
  double E_seen = 0.0;  // largest K + V or |W_ext| so far: the scale of the energy balance while loads act
  double wall_before = 0.0, cpu_before = 0.0;  // wall and CPU time of the run before its last resume
  const long long n_out = static_cast<long long>(std::ceil(t_end / out_dt - 1e-9));
  if (resume) {
    if (resume->integrator != integrator->name())
      throw std::runtime_error("checkpoint of integrator '" + resume->integrator + "', run of '" + integrator->name() + "'");
    state = resume->state;
    if (state.u.size() != model.num_dofs() || static_cast<int>(state.charts.size()) != model.mesh().num_nodes())
      throw std::runtime_error("the checkpoint does not fit this case's model (" + std::to_string(state.u.size()) + " DOFs)");
    model.adopt_charts(state.charts);
    integrator->restore(model, state, resume->integrator_data);
    // A restore may settle a setting too (em-exact's certify = auto keeps the rule the run started with).
    sum.settings = integrator->settings();
    spec.integrator.settings = sum.settings;
    DriverNumbers{sum, have_ref, out_index, k_next, E_seen}.each([&](const char* key, double& x) { x = resume->number(key); });
    sum.after_loads = have_ref;
    L_ref = resume->vector("L_ref");
    J_ref = resume->vector("J_ref");
    wall_before = resume->number("wall_s");
    cpu_before = resume->numbers.count("cpu_s") ? resume->number("cpu_s") : 0.0;
    if (pvd) {
      const Eigen::VectorXd& times = resume->vector("pvd_times");
      std::istringstream files_in(resume->text("pvd_files"));
      std::vector<std::pair<double, std::string>> entries;
      std::string f;
      for (Eigen::Index i = 0; i < times.size() && std::getline(files_in, f); ++i) entries.emplace_back(times[i], f);
      pvd->restore(std::move(entries));
    }
  }
  auto elapsed = [&] { return wall_before + std::chrono::duration<double>(Clock::now() - start).count(); };
  auto cpu_used = [&] { return cpu_before + cpu_now(thread_cpu) - cpu0; };

  // Checkpoints: is the integrator able to? (An explicit request must not be silently dropped.)
  const CheckpointPolicy policy = files ? o.checkpoint : CheckpointPolicy{};
  bool can_checkpoint = files;
  if (files) {
    try {
      IntegratorCheckpoint probe;
      integrator->save(probe);
    } catch (const std::exception& e) {
      if (policy.requested && policy.enabled()) throw std::invalid_argument(blame + e.what());
      can_checkpoint = false;
      if (o.log && policy.enabled()) *o.log << "note: " << e.what() << "; this run writes no checkpoints" << std::endl;
    }
  }

  auto write_ckpt = [&](long long next_k) {
    Checkpoint c;
    c.state = state;
    c.integrator = integrator->name();
    integrator->save(c.integrator_data);
    long long oi = out_index, kn = next_k;
    bool hr = have_ref;
    double es = E_seen;
    DriverNumbers{sum, hr, oi, kn, es}.each([&](const char* key, double& x) { c.numbers[key] = x; });
    c.vectors["L_ref"] = L_ref;
    c.vectors["J_ref"] = J_ref;
    c.numbers["wall_s"] = elapsed();
    c.numbers["cpu_s"] = cpu_used();
    c.numbers["history_bytes"] = history ? static_cast<double>(history->bytes()) : 0.0;
    if (bodies_csv) c.numbers["bodies_bytes"] = static_cast<double>(bodies_csv->bytes());
    std::string pvd_files;
    Eigen::VectorXd pvd_times(pvd ? static_cast<Eigen::Index>(pvd->entries().size()) : 0);
    if (pvd)
      for (size_t i = 0; i < pvd->entries().size(); ++i) {
        pvd_times[static_cast<Eigen::Index>(i)] = pvd->entries()[i].first;
        pvd_files += pvd->entries()[i].second + "\n";
      }
    c.vectors["pvd_times"] = pvd_times;
    c.texts["pvd_files"] = pvd_files;
    // How to rebuild the run (shelldyn resume): case text, what the caller changed, the options.
    c.texts["case_text"] = case_text;
    c.texts["case_source"] = spec.source;
    c.texts["case_base_dir"] = spec.base_dir;
    c.texts["mesh_hash"] = mesh_hash;
    c.texts["case_name"] = case_name;
    c.texts["case_description"] = case_description;
    c.numbers["material_E"] = material.E;
    c.numbers["material_nu"] = material.nu;
    c.numbers["material_rho"] = material.rho;
    c.numbers["material_thickness"] = material.thickness;
    c.numbers["material_shear_factor"] = material.shear_factor;
    c.numbers["output_history"] = spec.output.history ? 1.0 : 0.0;
    c.texts["integrator"] = o.integrator;
    c.texts["settings"] = encode_pairs(o.settings);
    c.texts["overrides"] = encode_pairs(o.overrides);
    c.numbers["dt"] = o.dt;
    c.numbers["t_end"] = o.t_end;
    c.numbers["output_interval"] = o.output_interval;
    c.numbers["vtu_every"] = o.vtu_every;
    c.texts["label"] = o.label;
    c.texts["command"] = o.command;
    c.texts["checkpoint_policy"] = policy.text();
    {  // the plugins loaded (path, version, hash per line), for load_checkpoint_plugins()
      std::string pl;
      for (const auto& p : loaded_plugins()) pl += p.path + "\t" + p.version + "\t" + p.hash + "\n";
      c.texts["plugins"] = pl;
      c.texts["integrator_origin"] = origin;
      c.texts["integrator_registered"] = registered_name;
    }
    c.numbers["max_steps"] = static_cast<double>(o.max_steps);
    c.numbers["max_wall"] = o.max_wall;
    if (history) history->sync();  // the rows the checkpoint counts are on the disk before it is
    if (bodies_csv) bodies_csv->sync();
    write_checkpoint(checkpoint_path, c);
    info.checkpoint.set("file", checkpoint_file_name());
    info.checkpoint.set("t", state.t);
    info.checkpoint.set("step", sum.totals.steps);
    info.checkpoint.set("exact", c.integrator_data.exact);
  };

  auto observe = [&](const StepReport& rep, bool last) {
    const Invariants inv = model.invariants(state);
    const double H = inv.kinetic + inv.strain - integrator->external_work() - integrator->prescribed_work() +
                     integrator->damping_work();
    E_seen = std::max({E_seen, inv.kinetic + inv.strain, std::abs(integrator->external_work()),
                       std::abs(integrator->prescribed_work())});
    if (out_index == 0) sum.H0 = H;
    if (!have_ref && state.t >= loads_end - 1e-12 * dt) {
      have_ref = true;
      sum.after_loads = true;
      sum.H_ref = H;
      // Scale of relative drifts: the energy the body holds then (K + V). H itself can be ~0 (a body
      // started at rest holds exactly the work done on it, H = K + V − W_ext ≈ 0).
      sum.E_ref = inv.kinetic + inv.strain;
      sum.t_ref = state.t;
      L_ref = inv.L;
      J_ref = inv.J;
      sum.ref_L = L_ref.norm();
      sum.ref_J = J_ref.norm();
    }
    // rel_drift (docs/manual.md §4): while loads act, the error of the discrete energy balance
    // (H − H0)/max(K + V, |W_ext|) so far; after the loads, (H − H_ref)/(K + V)_ref.
    double drift = E_seen > 0.0 ? (H - sum.H0) / E_seen : 0.0;
    if (have_ref) {
      const double scale = sum.E_ref > 0.0 ? sum.E_ref : (std::abs(sum.H_ref) > 0.0 ? std::abs(sum.H_ref) : 1.0);
      drift = (H - sum.H_ref) / scale;
      sum.max_rel_drift = std::max(sum.max_rel_drift, std::abs(drift));
      sum.final_rel_drift = drift;
      sum.max_dL = std::max(sum.max_dL, (inv.L - L_ref).norm());
      sum.max_dJ = std::max(sum.max_dJ, (inv.J - J_ref).norm());
    }
    if (inv.kinetic + inv.strain > 0.0)
      sum.max_strain_ratio = std::max(sum.max_strain_ratio, inv.strain / (inv.kinetic + inv.strain));
    sum.H_final = H;
    sum.damping_work = integrator->damping_work();
    sum.prescribed_work = integrator->prescribed_work();
    const double wall = elapsed();
    std::vector<double> mon;
    const bool vtu_now = pvd && out_index % vtu_every == 0;
    Eigen::VectorXd R;  // reaction forces (docs/theory.md §9.2), for monitors rx..rz and the VTU
    if (vtu_now || monitors_need_reactions(monitors)) R = reactions(model, state, true);
    for (const auto& m : monitors)
      mon.push_back(monitor_value(m, model.mesh(), state.u, state.v, state.charts, R.size() ? &R : nullptr));
    if (history) {
      HistoryRow row;
      row.step = sum.totals.steps;
      row.t = state.t;
      row.dt = rep.last_dt;
      row.kinetic = inv.kinetic;
      row.strain = inv.strain;
      row.external_work = integrator->external_work();
      row.total = H;
      row.rel_drift = drift;
      row.L = inv.L;
      row.J = inv.J;
      row.nonlinear_iters = sum.totals.nonlinear_iterations;
      row.linear_setups = sum.totals.linear_setups;
      row.wall_s = wall;
      row.monitors = mon;
      if (model.has_damping()) row.extra.push_back(integrator->damping_work());
      if (sum.prescribed) row.extra.push_back(integrator->prescribed_work());
      if (model.num_constraints() > 0) {
        const auto [g_norm, gdot_norm] = constraint_drift(model, state);
        row.extra.push_back(g_norm);
        row.extra.push_back(gdot_norm);
      }
      history->write(row);
    }
    if (bodies_csv) bodies_csv->append(body_state_rows(model, state));
    if (vtu_now) {
      const std::string file = "fields/" + vtu_step_file_name(out_index);
      write_vtu(o.out_dir + "/" + file, model.mesh(), state_fields(model, state, &R));
      try {
        pvd->add(state.t, file);
      } catch (const std::exception&) {  // (full disk) a VTU that fields.pvd cannot list is not kept
        std::remove((o.out_dir + "/" + file).c_str());
        throw;
      }
    }
    const bool due = tty ? (last || wall - last_print >= 0.2) : (last || out_index == 0 || state.t >= next_plain_t);
    if (o.log && due) {
      last_print = wall;
      while (next_plain_t <= state.t) next_plain_t += 0.1 * t_end > 0.0 ? 0.1 * t_end : 1.0;
      const double eta = state.t > 0.0 ? wall * (t_end - state.t) / state.t : 0.0;
      char dr[48];
      std::snprintf(dr, sizeof dr, have_ref ? "drift %+.2e" : "balance %+.2e (loads on)", drift);
      char buf[360];
      std::snprintf(buf, sizeof buf, "%s%st = %.6g/%.6g  steps %ld  iters %ld  K %.4e  V %.4e  H %.6e  %s  wall %.1f s  ETA %.0f s",
                    o.label.c_str(), o.label.empty() ? "" : " | ", state.t, t_end, sum.totals.steps,
                    sum.totals.nonlinear_iterations, inv.kinetic, inv.strain, H, dr, wall, eta);
      if (tty) {
        *o.log << '\r' << buf << "\x1b[K" << (last ? "\n" : "") << std::flush;
        line_open = !last;
      } else {
        *o.log << buf << std::endl;
      }
    }
    if (o.progress && (last || out_index == 0 || wall - last_progress >= o.progress_every)) {
      last_progress = wall;
      const double eta = state.t > 0.0 ? wall * (t_end - state.t) / state.t : 0.0;
      char buf[320];
      std::snprintf(buf, sizeof buf, "%s | t = %.6g/%.6g  steps %ld  iters %ld  %s %+.2e  wall %.1f s  CPU %.1f s  ETA %.0f s",
                    o.label.empty() ? sum.integrator.c_str() : o.label.c_str(), state.t, t_end, sum.totals.steps,
                    sum.totals.nonlinear_iterations, have_ref ? "drift" : "balance (loads on)", drift, wall, cpu_used(), eta);
      o.progress(buf);
    }
    if (last)
      for (size_t k = 0; k < monitors.size(); ++k) sum.final_monitors.emplace_back(monitors[k].name, mon[k]);
    ++out_index;
  };

  // Writes run.json; if that fails too (full disk), the caller's cause stays the error reported. The
  // final status (`last`) first frees the disk reserve, so that it can be written on a full disk.
  auto write_status = [&](const std::string& status, bool last) -> std::string {
    sum.status = status;
    sum.wall_seconds = elapsed();
    sum.cpu_seconds = cpu_used();
    if (!files) return {};
    if (last && reserve) reserve->release();
    info.status = status;
    fill_summary_json(info.summary, sum);
    try {
      write_run_json(run_json_path, spec, info);
    } catch (const std::exception& e) {
      return e.what();
    }
    return {};
  };

  SignalGuard signals(o.handle_signals);
  integrator->set_stop_request([&] { return g_stop_signal != 0 || (o.max_wall > 0.0 && elapsed() >= o.max_wall); });
  std::string stop_reason;  // non-empty: orderly stop
  int stop_code = 0;
  double next_ckpt_time = policy.sim_time > 0.0 ? (std::floor(state.t / policy.sim_time) + 1.0) * policy.sim_time : 0.0;
  long long next_ckpt_step = policy.steps > 0 ? (sum.totals.steps / policy.steps + 1) * policy.steps : 0;
  double next_ckpt_wall = policy.wall > 0.0 ? elapsed() + policy.wall : 0.0;
  auto stop_requested = [&](long long next_k) {
    if (g_stop_signal != 0) {
      stop_code = 128 + g_stop_signal;
      stop_reason = std::string("interrupted: ") + (g_stop_signal == SIGINT ? "SIGINT" : "SIGTERM");
    } else if (o.max_wall > 0.0 && elapsed() >= o.max_wall) {
      stop_code = 4;
      stop_reason = "stopped: --max-wall " + g17(o.max_wall) + " s reached";
    } else if (o.max_steps > 0 && sum.totals.steps >= o.max_steps && next_k <= n_out) {
      stop_code = 4;
      stop_reason = "stopped: --max-steps " + std::to_string(o.max_steps) + " reached";
    }
    return stop_code != 0;
  };

  try {
    if (!resume) observe(StepReport{}, t_end <= 0.0);
    for (long long k = k_next; k <= n_out; ++k) {
      const double t_out = std::min(t_end, static_cast<double>(k) * out_dt);
      StepReport rep;
      bool abandoned = false;
      try {
        rep = integrator->advance(model, state, t_out);
      } catch (const RunInterrupted&) {
        abandoned = true;  // state is still the last output state
      }
      sum.totals.accumulate(rep);
      const bool reached = !abandoned && state.t >= t_out - 1e-9 * dt;
      if (reached) observe(rep, k == n_out);
      const long long next_k = reached ? k + 1 : k;
      if (!reached || (k < n_out && stop_requested(next_k))) {
        if (!reached && !stop_requested(next_k)) throw std::logic_error(sum.integrator + " stopped before t_out without a request");
        std::string where = " at t = " + g17(state.t) + " of " + g17(t_end) + " (step " + std::to_string(sum.totals.steps) + ")";
        std::string resume_hint;
        if (can_checkpoint) {
          write_ckpt(next_k);
          resume_hint = "; continue with: shelldyn resume " + o.out_dir;
        } else {
          resume_hint = files ? "; no checkpoint (not supported by this integrator)" : "";
        }
        if (line_open) *o.log << std::endl;  // end the in-place status line before the message
        line_open = false;
        const std::string msg = stop_reason + where + resume_hint;
        const std::string json_error = write_status(msg, true);
        throw RunStopped(msg + (json_error.empty() ? "" : "; " + json_error), stop_code);
      }
      if (k == n_out) break;
      const bool due = (policy.steps > 0 && sum.totals.steps >= next_ckpt_step) ||
                       (policy.sim_time > 0.0 && state.t >= next_ckpt_time - 1e-9 * dt) ||
                       (policy.wall > 0.0 && elapsed() >= next_ckpt_wall);
      if (due && can_checkpoint) {
        write_ckpt(next_k);
        // run.json names the checkpoint; if it cannot be written (the disk filled up), stop: the catch below
        // releases the disk reserve and records the cause, instead of run.json silently lagging behind.
        const std::string json_error = write_status(info.status, false);
        if (!json_error.empty()) throw std::runtime_error(json_error);
        if (policy.steps > 0) next_ckpt_step = (sum.totals.steps / policy.steps + 1) * policy.steps;
        if (policy.sim_time > 0.0) next_ckpt_time = (std::floor(state.t / policy.sim_time + 1e-9) + 1.0) * policy.sim_time;
        if (policy.wall > 0.0) next_ckpt_wall = elapsed() + policy.wall;
      }
    }
  } catch (const RunStopped&) {
    throw;
  } catch (const std::exception& e) {
    if (line_open) *o.log << std::endl;  // end the in-place status line before the error message
    const std::string json_error = write_status(std::string("incomplete: ") + blame + e.what(), true);
    if (!json_error.empty()) throw std::runtime_error(blame + e.what() + "; " + json_error);
    if (blame.empty()) throw;
    // Names the plugin (integrators/runs/plugin.hpp) and keeps the kind of failure: a step that could not be
    // completed stays a StepFailure and bad input stays std::invalid_argument, as for a built-in.
    if (dynamic_cast<const StepFailure*>(&e)) throw StepFailure(blame + e.what());
    if (dynamic_cast<const std::invalid_argument*>(&e)) throw std::invalid_argument(blame + e.what());
    throw std::runtime_error(blame + e.what());
  } catch (...) {  // a plugin may throw anything
    const std::string what = blame + "threw a non-standard exception";
    write_status("incomplete: " + what, true);
    throw std::runtime_error(what);
  }
  if (files) {
    std::error_code ec;
    std::filesystem::remove(checkpoint_path, ec);  // the run is complete: nothing to resume
    info.checkpoint = JsonFields{};
  }
  const std::string json_error = write_status("complete", true);
  if (!json_error.empty()) throw std::runtime_error(json_error);
  return sum;
}

void print_run_summary(std::ostream& out, const RunSummary& s) {
  auto line = [&](const std::string& label, const std::string& value) {
    out << "  " << label << std::string(label.size() < 38 ? 38 - label.size() : 1, ' ') << value << "\n";
  };
  auto num = [](double x) {
    char b[64];
    std::snprintf(b, sizeof b, "%.6g", x);
    return std::string(b);
  };
  out << "summary (" << s.integrator << ", " << s.status << ")\n";
  std::string settings;
  for (const auto& [k, v] : s.settings) settings += (settings.empty() ? "" : ", ") + k + "=" + v;
  line("settings", settings);
  line("simulated time", num(s.t_end));
  line("steps (rejected)", std::to_string(s.totals.steps) + " (" + std::to_string(s.totals.rejected_steps) + ")");
  line("nonlinear iterations", std::to_string(s.totals.nonlinear_iterations));
  line("linear setups / factorizations", std::to_string(s.totals.linear_setups) + " / " + std::to_string(s.totals.factorizations));
  line("director chart switches", std::to_string(s.totals.chart_switches));
  // Damped models (docs/theory.md §8.5): the conserved total includes the dissipated energy W_damp.
  line(std::string("energy H = K + V - W_ext") + (s.prescribed ? " - W_presc" : "") + (s.damped ? " + W_damp" : "") +
           ": H0, H_ref",
       num(s.H0) + ", " + num(s.H_ref) + " (at t = " + num(s.t_ref) + ")");
  if (s.damped) line("damping work W_damp (end)", num(s.damping_work));
  if (s.prescribed) line("prescribed-motion work W_presc (end)", num(s.prescribed_work));
  if (s.after_loads) {
    line("max |H - H_ref|/(K+V)_ref after loads", num(s.max_rel_drift));
    line("max |L - L_ref| after loads", num(s.max_dL) + " (|L_ref| = " + num(s.ref_L) + ")");
    line("max |J - J_ref| after loads", num(s.max_dJ) + " (|J_ref| = " + num(s.ref_J) + ")");
  } else {  // not 0: nothing was measured after the loads
    const std::string na = "n/a (loads still on: the run ends at t = " + num(s.t_end) + ", the loads at t = " + num(s.loads_end) + ")";
    line("max |H - H_ref|/(K+V)_ref after loads", na);
    line("max |L - L_ref|, |J - J_ref| after loads", "n/a");
  }
  for (const auto& [name, value] : s.final_monitors) line("final " + name, num(value));
  line("wall time [s]", num(s.wall_seconds));
  line("CPU time [s]", num(s.cpu_seconds));
}

}  // namespace shelldyn
