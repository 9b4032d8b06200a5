// shelldyn — the command-line front end of the toolkit.
//
// Sample runs:
//   shelldyn --help
//   shelldyn --version
//   shelldyn check apps/cases/flying-plate.yaml              # validate, summarise, write results/flying-plate/
//   shelldyn check apps/cases/pinched-hemisphere.yaml -o /tmp/hemi
//
// `check` reads a case file (lib/io/case_file.hpp), builds its discretization (mesh, sets, constraints,
// loads; lib/model/discretization.hpp), prints a summary and writes the initial state as
// DIR/fields/step_000000.vtu + DIR/fields.pvd and DIR/run.json with status "checked", so the set-up
// can be inspected in ParaView before any time is spent integrating.
//
// Exit codes: 0 success; 1 bad input or failure (one line "shelldyn: error: ..." on stderr);
// 2 command-line usage error; 3 some runs of `compare` failed; 4 stopped at --max-steps/--max-wall;
// 130 / 143 stopped by SIGINT / SIGTERM (the last three resumable: `shelldyn resume DIR`).
//
// Adding a subcommand (run, static, ...): write `add_<name>_command(CLI::App&, Action&)` next to
// add_check_command: it registers its options and, in its callback, stores the action to run.
// main() stays unchanged apart from one call.
#include "apps/app_common.hpp"
#include "apps/modes_command.hpp"
#include "integrators/runs/case_integrator.hpp"
#include "integrators/runs/compare.hpp"
#include "integrators/runs/study.hpp"
#include "integrators/runs/plugin.hpp"
#include "integrators/runs/registry.hpp"
#include "integrators/integrator.hpp"
#include "integrators/runs/run_driver.hpp"
#include "integrators/runs/static_run.hpp"
#include "integrators/sundials/sundials_info.hpp"
#include "lib/io/case_file.hpp"
#include "lib/model/discretization.hpp"
#include "lib/io/result_folder.hpp"
#include "lib/io/run_info.hpp"
#include "lib/io/state_output.hpp"
#include "lib/io/vtu_writer.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace shelldyn;

namespace {

// What main() runs after a successful parse; set by the chosen subcommand's callback.
using Action = std::function<int()>;

std::string version_text() {
  return "shelldyn " + shelldyn_version() + " (SUNDIALS " + sundials_version() + ", Eigen " + eigen_version() + ")" +
         (shelldyn_git_commit().empty() ? "" : "\ngit commit " + shelldyn_git_commit());
}

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

std::string vec_text(const Vec3& v) {
  std::ostringstream os;
  os << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return os.str();
}

// A case file path, or the name of a shipped case (apps/cases/NAME.yaml, e.g. flying-plate), as `compare` takes.
std::string resolve_case_path(const std::string& given) {
  std::error_code ec;
  if (fs::exists(given, ec) || given.find('/') != std::string::npos) return given;
  return app::find_case_file(given + (fs::path(given).extension() == ".yaml" ? "" : ".yaml"));
}

// --plugin PATH (repeatable) of run, check, compare, study and resume. The plugins are loaded by main() before
// the command line is parsed (so that --help lists their integrators); the option is declared for the parser.
void add_plugin_option(CLI::App* sub, std::vector<std::string>& paths) {
  sub->add_option("--plugin", paths,
                  "Load integrators from a plugin shared library (repeatable; also the case-file key plugins: and the "
                  "environment variable SHELLDYN_PLUGINS, colon-separated); see docs/tutorials/05-your-own-integrator.md")
      ->allow_extra_args(false);  // one path per --plugin (a following case name is not a plugin)
}

// --- check -------------------------------------------------------------------------------------------
struct CheckOptions {
  std::string case_path;
  std::string out_dir;  // empty: results/<case name>
  std::string command;  // the full command line, recorded in run.json
  bool overwrite = false;
  std::string state_file;  // static: start from this checkpoint (or run folder holding one) or run VTU
  std::vector<std::string> plugins;  // loaded by main()
};

void print_summary(std::ostream& out, const CaseSpec& c, const Discretization& d) {
  const auto row = [&out](const char* label) -> std::ostream& {
    char buf[24];
    std::snprintf(buf, sizeof buf, "%-18s", label);
    return out << buf;
  };
  row("case") << c.name << "  (" << c.source << ")\n";
  if (!c.description.empty()) row("") << c.description << "\n";
  row("mesh") << mesh_kind_name(c.mesh) << ": " << d.mesh.num_nodes() << " nodes, " << d.mesh.num_elements()
              << " elements (quad9), size " << d.mesh_size << "\n";
  row("DOFs") << d.dofs.num_dofs() << " (constrained " << d.dofs.num_constrained() << ", free " << d.dofs.num_free()
              << ")\n";
  std::string sets;
  for (const auto& [name, nodes] : d.mesh.node_sets) sets += (sets.empty() ? "" : ", ") + name + " (" + std::to_string(nodes.size()) + ")";
  row("node sets") << sets << "\n";
  std::string esets;
  for (const auto& [name, els] : d.mesh.element_sets) esets += (esets.empty() ? "" : ", ") + name + " (" + std::to_string(els.size()) + ")";
  row("element sets") << (esets.empty() ? "none" : esets) << "\n";
  const CaseMaterial& m = c.material;
  row("material") << "E = " << m.E << ", nu = " << m.nu << ", rho = " << m.rho << ", thickness = " << m.thickness
                  << ", shear factor = " << m.shear_factor << "\n";
  row("area, total mass") << d.surface_area << ", " << d.total_mass << "\n";
  row("boundary cond.") << (c.boundary_conditions.empty() ? std::string("none (free)")
                                                           : std::to_string(c.boundary_conditions.size()) + " entries")
                        << "\n";
  for (const auto& bc : c.boundary_conditions) {
    std::string fixes;
    for (Fix f : bc.fix) fixes += (fixes.empty() ? "" : " ") + std::string(fix_name(f));
    row("") << bc.set << ": " << fixes << "\n";
  }
  const InitialVelocitySpec& iv = c.initial_velocity;
  row("initial velocity") << (iv.given ? "translation " + vec_text(iv.translation) + ", angular " +
                                             vec_text(iv.angular) + " about " +
                                             (iv.about_centroid ? std::string("the centroid") : vec_text(iv.about))
                                       : std::string("none (at rest)"))
                          << "\n";
  row("loads") << c.loads.size() << " entries -> " << d.loads.size() << " nodal loads";
  if (!c.loads.empty()) {
    if (std::isinf(d.loads_end))
      out << "; some never vanish";
    else
      out << "; all vanish for t >= " << d.loads_end;
  }
  out << "\n";
  for (const auto& l : c.loads) {
    row("") << l.set << ": " << load_type_name(l.type) << " " << l.amplitude << " * " << vec_text(l.direction)
            << " * " << l.function.describe() << ", " << load_distribution_name(l.distribution) << "\n";
  }
  if (!c.prescribed_displacements.empty()) {  // docs/manual.md §2.12
    row("prescribed disp.") << c.prescribed_displacements.size() << " entries -> " << d.prescribed.size() << " DOFs";
    double end = 0.0;
    for (const auto& pd : d.prescribed) end = std::max(end, pd.function.end_of_variation());
    out << (std::isinf(end) ? std::string("; some never stop moving") : "; all still for t >= " + std::to_string(end)) << "\n";
    for (const auto& pd : c.prescribed_displacements) {
      std::string dofs;
      for (int k : pd.components) dofs += (dofs.empty() ? "" : " ") + std::string(k == 0 ? "ux" : k == 1 ? "uy" : "uz");
      row("") << pd.set << ": " << dofs << " = " << pd.value << " * " << pd.function.describe() << "\n";
    }
  }
  std::string settings;
  for (const auto& [k, v] : c.integrator.settings) settings += (settings.empty() ? "" : ", ") + k + " = " + v;
  row("integrator") << c.integrator.name << (settings.empty() ? "" : " (" + settings + ")") << "\n";
  const long long outputs = static_cast<long long>(std::floor(c.time.t_end / c.time.output_interval + 1e-9));
  row("time") << "dt = " << c.time.dt << ", t_end = " << c.time.t_end << ", " << c.time.num_steps()
              << " steps, output every " << c.time.output_interval << " (" << outputs << " outputs)\n";
  row("output") << "vtu " << (c.output.vtu ? "every " + std::to_string(c.output.vtu_every) + " outputs" : "off")
                << ", history " << (c.output.history ? "on" : "off") << "\n";
  row("monitors") << (d.monitors.empty() ? std::string("none") : std::to_string(d.monitors.size())) << "\n";
  for (const auto& mon : d.monitors)
    row("") << mon.name << ": " << monitor_quantity_name(mon.quantity) << " at node " << mon.node << " "
            << vec_text(d.mesh.X[static_cast<size_t>(mon.node)]) << "\n";
}

// The initial state as a VTU: zero displacement, the translational initial velocity, p_i0; plus the
// number of fixed DOFs per node and the nodal load magnitudes (per unit f(t)) to check the set-up.
VtuFields initial_fields(const Discretization& d) {
  const size_t n = static_cast<size_t>(d.mesh.num_nodes());
  VtuFields f;
  f.displacement.assign(n, Vec3::Zero());
  f.velocity.resize(n);
  for (size_t i = 0; i < n; ++i)
    f.velocity[i] = d.initial_velocity.segment<3>(static_cast<Eigen::Index>(DofMap::dof(static_cast<int>(i), 0)));
  f.director = d.normals;
  ScalarField fixed{"fixed_dofs", std::vector<double>(n, 0.0)};
  for (Index dof : d.dofs.constrained_dofs()) fixed.values[static_cast<size_t>(dof / kDofsPerNode)] += 1.0;
  ScalarField load{"load_magnitude", std::vector<double>(n, 0.0)};
  for (const auto& l : d.loads) load.values[static_cast<size_t>(l.node)] += l.vector.norm();
  // Director rate ṗ = A1(q0) q̇ (as state_fields writes it), so this VTU can serve as a velocity field.
  ScalarField pdot{"director_rate", std::vector<double>(3 * n, 0.0), 3};
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Index k = static_cast<Eigen::Index>(DofMap::dof(static_cast<int>(i), 3));
    const Vec3 w = director_A1(chart_coordinates(d.normals[i], d.charts[i]), d.charts[i]) * d.initial_velocity.segment<2>(k);
    for (size_t c = 0; c < 3; ++c) pdot.values[3 * i + c] = w[static_cast<Eigen::Index>(c)];
  }
  f.point_scalars = {std::move(pdot), std::move(fixed), std::move(load)};
  return f;
}

// Rigid bodies, joints and the constraint count of a case with a multibody part (docs/manual.md "Rigid bodies
// and joints").
void print_multibody(std::ostream& out, const Model& model) {
  const ModelMultibody* mb = model.multibody();
  if (!mb) return;
  out << "rigid bodies: " << mb->num_bodies() << "\n";
  for (int b = 0; b < mb->num_bodies(); ++b) {
    const RigidBodyDef& d = mb->body_def(b);
    out << "  " << d.name << ": mass " << d.mass << ", inertia " << vec_text(d.inertia) << ", at " << vec_text(d.position)
        << ", unknowns " << mb->body_first_dof(b) << ".." << mb->body_first_dof(b) + 11 << "\n";
  }
  out << "joints: " << mb->joints().size() << ", constraint rows: " << model.num_constraints() << "\n";
  for (const auto& blk : model.constraint_blocks())
    out << "  " << blk.name << ": " << blk.type << ", " << blk.rows << " rows (" << blk.first_row << ".."
        << blk.first_row + blk.rows - 1 << ")\n";
}

int run_check(const CheckOptions& o) {
  const CaseSpec spec = load_case(resolve_case_path(o.case_path));
  validate_case_integrator(spec);  // exactly as `run` will (FILE:LINE: integrator.KEY: ...)
  const Discretization d = build_discretization(spec);
  VtuFields fields = initial_fields(d);
  std::unique_ptr<Problem> multibody;
  if (!spec.rigid_bodies.empty() || !spec.joints.empty())  // joints are checked on the model, as `run` will
    multibody = std::make_unique<Problem>(make_problem(spec));
  if (!spec.initial_displacement.empty() || !d.prescribed.empty()) {  // validate as `run` will, show the displaced state
    const Problem pb = make_problem(spec);
    const State s = pb.initial_state();
    const VtuFields displaced = state_fields(*pb.model, s);
    fields.displacement = displaced.displacement;
    fields.director = displaced.director;
    fields.point_scalars.front() = displaced.point_scalars.front();  // director_rate
  }
  const fs::path dir = o.out_dir.empty() ? fs::path("results") / spec.name : fs::path(o.out_dir);
  app::prepare_result_folder(dir.string(), o.overwrite);
  print_summary(std::cout, spec, d);
  if (multibody) print_multibody(std::cout, *multibody->model);
  prepare_output_folder(dir.string());
  const std::string vtu = "fields/" + vtu_step_file_name(0);
  write_vtu((dir / vtu).string(), d.mesh, fields);
  PvdWriter pvd((dir / "fields.pvd").string());
  pvd.add(0.0, vtu);

  RunInfo info;
  info.status = "checked";
  info.command = o.command;
  info.sundials_version = sundials_version();
  info.discretization.set("nodes", d.mesh.num_nodes());
  info.discretization.set("elements", d.mesh.num_elements());
  info.discretization.set("dofs", static_cast<long long>(d.dofs.num_dofs()));
  info.discretization.set("constrained_dofs", static_cast<long long>(d.dofs.num_constrained()));
  info.discretization.set("free_dofs", static_cast<long long>(d.dofs.num_free()));
  info.discretization.set("nodal_loads", static_cast<long long>(d.loads.size()));
  info.discretization.set("loads_end", d.loads_end);
  info.discretization.set("surface_area", d.surface_area);
  info.discretization.set("total_mass", d.total_mass);
  info.summary.set("steps", 0);
  info.summary.set("t", 0.0);
  write_run_json((dir / "run.json").string(), spec, info);

  std::cout << "wrote " << (dir / vtu).string() << ", " << (dir / "fields.pvd").string() << ", "
            << (dir / "run.json").string() << "\n";
  return 0;
}

void add_check_command(CLI::App& app, Action& action, const std::string& command) {
  auto opts = std::make_shared<CheckOptions>();
  opts->command = command;
  CLI::App* sub = app.add_subcommand(
      "check", "Validate a case file, print a summary and write the initial state (VTU, PVD, run.json)");
  sub->add_option("case", opts->case_path, "Case file (YAML), or a case name of apps/cases such as flying-plate")->required();
  sub->add_option("-o,--output", opts->out_dir, "Result folder (default: results/<case name>)");
  sub->add_flag("--overwrite", opts->overwrite, "Replace the results of an earlier command in the result folder");
  add_plugin_option(sub, opts->plugins);
  sub->callback([opts, &action] { action = [opts] { return run_check(*opts); }; });
}

// --- run ---------------------------------------------------------------------------------------------
struct RunCommandOptions {
  std::string case_path, out_dir, integrator, command, checkpoint_every;
  std::vector<std::string> settings;  // key=value
  std::vector<std::string> plugins;   // loaded by main()
  double dt = 0.0, t_end = -1.0, output_every = 0.0, max_wall = 0.0;
  int vtu_every = -1, threads = 0;
  long long max_steps = 0;
  bool quiet = false, overwrite = false, plots = false;
  bool allow_changed_case = false, allow_other_version = false;  // resume (integrators/checkpoint/checkpoint.hpp)
  std::string max_memory;                                         // --max-memory (lib/io/result_folder.hpp)
  CLI::App* cli = nullptr;  // to ask which flags were given
  bool given(const char* flag) const {
    const CLI::Option* opt = cli ? cli->get_option_no_throw(flag) : nullptr;
    return opt && opt->count() > 0;
  }
};

// Numeric flags of `run` and `resume`: validated before anything is read or written.
void check_run_flags(const RunCommandOptions& o) {
  if (o.given("--dt")) app::check_positive("--dt", o.dt, "--dt 1e-3");
  if (o.given("--t-end")) app::check_non_negative("--t-end", o.t_end, "--t-end 6");
  if (o.given("--output-every")) app::check_positive("--output-every", o.output_every, "--output-every 0.01");
  if (o.given("--vtu-every")) app::check_range("--vtu-every", o.vtu_every, 0, 1000000000, "--vtu-every 10 (0: no VTU)");
  if (o.given("--threads")) app::check_range("--threads", o.threads, 0, 1024, "--threads 2");
  if (o.given("--max-steps")) app::check_range("--max-steps", o.max_steps, 0, 10000000000LL, "--max-steps 100000");
  if (o.given("--max-wall")) app::check_non_negative("--max-wall", o.max_wall, "--max-wall 3600");
  if (o.given("--max-memory")) set_memory_limit(parse_memory_size(o.max_memory));  // lib/io/result_folder.hpp
}

std::pair<std::string, std::string> split_setting(const std::string& kv) {
  const auto eq = kv.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == kv.size())
    throw std::invalid_argument("--set '" + kv + "': expected KEY=VALUE, e.g. --set rho_inf=0.8");
  return {kv.substr(0, eq), kv.substr(eq + 1)};
}

int run_run(const RunCommandOptions& o) {
  check_run_flags(o);
  const CheckpointPolicy policy =
      o.checkpoint_every.empty() ? default_checkpoint_policy() : parse_checkpoint_policy(o.checkpoint_every);
  if (!o.integrator.empty()) app::check_integrator_name(o.integrator);
  RunOptions ro;
  ro.integrator = o.integrator;
  for (const auto& kv : o.settings) ro.settings.push_back(split_setting(kv));
  CaseSpec spec = load_case(resolve_case_path(o.case_path));
  make_case_integrator(spec, o.integrator, ro.settings, o.dt > 0.0 ? o.dt : spec.time.dt);  // before any output
  const std::string integrator_name = o.integrator.empty() ? spec.integrator.name : o.integrator;
  ro.out_dir = o.out_dir.empty() ? (fs::path("results") / spec.name / integrator_name).string() : o.out_dir;
  app::prepare_result_folder(ro.out_dir, o.overwrite);
  Problem problem = make_problem(std::move(spec));
  ro.checkpoint = policy;
  ro.max_steps = o.max_steps;
  ro.max_wall = o.max_wall;
  ro.handle_signals = true;
  for (const char* flag : {"--integrator", "--dt", "--t-end", "--output-every", "--vtu-every", "--threads", "--max-steps", "--max-wall", "--checkpoint-every"})
    if (o.given(flag)) ro.overrides.emplace_back(flag, o.cli->get_option(flag)->as<std::string>());
  for (const auto& kv : o.settings) ro.overrides.emplace_back("--set", kv);
  ro.dt = o.dt;
  ro.t_end = o.t_end;
  ro.output_interval = o.output_every;
  ro.vtu_every = o.vtu_every;
  ro.threads = o.threads;
  ro.command = o.command;
  ro.log = o.quiet ? nullptr : &std::cout;
  std::cout << "shelldyn run: " << problem.spec.name << " with " << integrator_name << " -> " << ro.out_dir << std::endl;
  const RunSummary s = run_dynamic(problem, ro);
  if (o.quiet) {  // one line: status, steps, energy error after the loads
    char drift[96];
    if (s.after_loads) std::snprintf(drift, sizeof drift, "%.3g", s.max_rel_drift);
    else std::snprintf(drift, sizeof drift, "n/a (loads still on until t = %.6g)", s.loads_end);
    std::printf("%s: %s, %ld steps, max |H - H_ref|/(K+V)_ref after loads %s -> %s\n", integrator_name.c_str(),
                s.status.c_str(), s.totals.steps, drift, ro.out_dir.c_str());
  } else {
    print_run_summary(std::cout, s);
    std::cout << "wrote " << ro.out_dir << "/history.csv, " << ro.out_dir << "/fields.pvd, " << ro.out_dir << "/run.json\n";
  }
  if (o.plots) {  // scripts/plot_run.py: energy.png, momentum.png, monitors.png (docs/manual.md §4)
    for (const char* png : {"energy.png", "momentum.png", "monitors.png"}) {
      std::error_code ec;
      fs::remove(fs::path(ro.out_dir) / png, ec);
    }
    if (!app::run_python_script(app::find_script("plot_run.py"), {ro.out_dir, "--title", problem.spec.name + ", " + integrator_name},
                                std::cout))
      return 1;
    if (!o.quiet) std::cout << "wrote " << ro.out_dir << "/energy.png, momentum.png, monitors.png\n";
  }
  return 0;
}

void add_run_command(CLI::App& app, Action& action, const std::string& command) {
  auto o = std::make_shared<RunCommandOptions>();
  o->command = command;
  std::string names;
  for (const auto& [name, summary] : integrator_catalogue()) names += "\n  " + name + ": " + summary;
  CLI::App* sub = app.add_subcommand("run", "Integrate a case in time and write history.csv, VTU/PVD and run.json");
  sub->add_option("case", o->case_path, "Case file (YAML), or a case name of apps/cases such as flying-plate")->required();
  sub->add_option("-o,--output", o->out_dir, "Result folder (default: results/<case>/<integrator>)");
  add_plugin_option(sub, o->plugins);
  sub->add_option("--integrator", o->integrator, "Integrator (default: the case's integrator.name):" + names);
  sub->add_option("--set", o->settings, "Override an integrator setting, KEY=VALUE (repeatable), e.g. --set rho_inf=0.8");
  sub->add_option("--dt", o->dt, "Time step (default: the case's time.dt)");
  sub->add_option("--t-end", o->t_end, "End time (default: the case's time.t_end)");
  sub->add_option("--output-every", o->output_every, "Output interval in time units (default: the case's time.output_interval)");
  sub->add_option("--vtu-every", o->vtu_every, "Write a VTU every N output times; 0 disables (default: the case's output.vtu_every)");
  sub->add_option("--threads", o->threads, "OpenMP threads for element loops and triangular solves (default: all cores)");
  sub->add_flag("-q,--quiet", o->quiet, "No progress line and no summary table: one result line (errors still reported)");
  sub->add_flag("--plots", o->plots, "After the run, write energy.png, momentum.png, monitors.png with scripts/plot_run.py (needs python3-matplotlib)");
  sub->add_option("--checkpoint-every", o->checkpoint_every,
                  "Write DIR/checkpoint.cbor every N steps, Ts of simulated time (e.g. 0.5s) or Ww seconds of wall "
                  "time (e.g. 60w); off disables (default 60w)");
  sub->add_option("--max-steps", o->max_steps, "Stop (resumable, exit 4) at the first output time after N steps (default 0: no limit)");
  sub->add_option("--max-wall", o->max_wall, "Stop (resumable, exit 4) after S seconds of wall time (default 0: no limit)");
  sub->add_flag("--overwrite", o->overwrite, "Replace the results of an earlier run in the result folder");
  sub->add_option("--max-memory", o->max_memory, "Refuse models whose estimated memory exceeds this (e.g. 4G; default: the available memory)");
  o->cli = sub;
  sub->callback([o, &action] { action = [o] { return run_run(*o); }; });
}

// --- resume ------------------------------------------------------------------------------------------
// `shelldyn resume DIR`: continues a run stopped by a signal, --max-wall/--max-steps or a kill from
// DIR/checkpoint.cbor (integrators/runs/run_driver.hpp). The case, options and overrides come from the
// checkpoint; only the limits, the thread count and the progress output can be changed.
int run_resume_locked(const RunCommandOptions& o, const std::string& dir) {
  const std::string ckpt = (fs::path(dir) / checkpoint_file_name()).string();
  const Checkpoint c = read_checkpoint(ckpt);
  check_checkpoint_origin(c, ckpt, o.allow_changed_case, o.allow_other_version, &std::cerr);
  load_checkpoint_plugins(c);  // the run's plugins, unless given again with --plugin
  // A run killed with SIGKILL leaves its disk reserve (lib/io/run_info.hpp DiskReserve) behind, and possibly the
  // temporary of an output it was rewriting (run.json, fields.pvd and checkpoint.cbor are written whole to
  // NAME.tmp, then renamed; the complete file from before is still in place). Both are stale: remove them (the
  // resumed run allocates its own reserve and deletes it at the end, whatever the outcome).
  std::error_code ec;
  for (const char* stale : {"run.json.reserve", "run.json.tmp", "fields.pvd.tmp", "checkpoint.cbor.tmp"})
    fs::remove(fs::path(dir) / stale, ec);
  Problem problem = problem_from_checkpoint(c);
  RunOptions ro = run_options_from_checkpoint(c);
  ro.out_dir = dir;
  ro.resume = &c;
  ro.handle_signals = true;
  ro.log = o.quiet ? nullptr : &std::cout;
  if (o.given("--max-steps")) ro.max_steps = o.max_steps;
  if (o.given("--max-wall")) ro.max_wall = o.max_wall;
  if (o.given("--threads")) ro.threads = o.threads;
  std::cout << "shelldyn resume: " << problem.spec.name << " with " << c.integrator << " from t = " << c.state.t
            << (c.integrator_data.exact ? " (bitwise continuation)" : " (re-initialized from the saved state)") << " -> "
            << dir << std::endl;
  const RunSummary s = run_dynamic(problem, ro);
  print_run_summary(std::cout, s);
  std::cout << "wrote " << dir << "/history.csv, " << dir << "/run.json\n";
  return 0;
}

// The folder is locked first (lib/io/result_folder.hpp): a resume never runs beside the run it continues. A
// failure keeps the folder's earlier status in run.json and records why ("resume_failed").
int run_resume(const RunCommandOptions& o) {
  check_run_flags(o);
  const std::string dir = o.case_path;
  const std::string previous = begin_resume(dir);
  try {
    return run_resume_locked(o, dir);
  } catch (const RunStopped&) {
    throw;
  } catch (const std::exception& e) {
    if (fs::exists(fs::path(dir) / checkpoint_file_name())) record_failed_resume(dir, previous, one_line(e.what()));
    throw;
  }
}

void add_resume_command(CLI::App& app, Action& action, const std::string& command) {
  auto o = std::make_shared<RunCommandOptions>();
  o->command = command;
  CLI::App* sub = app.add_subcommand("resume", "Continue a stopped or killed run from its checkpoint (DIR/checkpoint.cbor)");
  sub->add_option("dir", o->case_path, "Result folder of the run, e.g. results/flying-plate/em-galpha")->required();
  sub->add_option("--max-steps", o->max_steps, "Stop again at the first output time after N steps in total (default: as before)");
  sub->add_option("--max-wall", o->max_wall, "Stop again after S seconds of wall time in total (default: as before)");
  sub->add_option("--threads", o->threads, "OpenMP threads for element loops and triangular solves (default: all cores)");
  sub->add_flag("-q,--quiet", o->quiet, "No progress lines");
  add_plugin_option(sub, o->plugins);
  sub->add_flag("--allow-changed-case", o->allow_changed_case,
                "Continue although the case file was edited since the run started (the run goes on with the case text "
                "the checkpoint keeps)");
  sub->add_flag("--allow-other-version", o->allow_other_version,
                "Continue a checkpoint written by another shelldyn version (not bitwise the uninterrupted run)");
  sub->add_option("--max-memory", o->max_memory, "Refuse models whose estimated memory exceeds this (e.g. 4G; default: the available memory)");
  o->cli = sub;
  sub->callback([o, &action] { action = [o] { return run_resume(*o); }; });
}

// --- static ------------------------------------------------------------------------------------------
int run_static_command(const CheckOptions& o) {
  Problem problem = load_problem(o.case_path);
  const std::string dir = o.out_dir.empty() ? (fs::path("results") / problem.spec.name / "static").string() : o.out_dir;
  app::prepare_result_folder(dir, o.overwrite);
  std::cout << "shelldyn static: " << problem.spec.name << " -> " << dir << std::endl;
  // --state: the configuration of a saved run (its checkpoint) as the starting point, its time as λ₀.
  std::unique_ptr<State> start;
  if (!o.state_file.empty()) {
    start = std::make_unique<State>(app::load_saved_state(problem, o.state_file));
    std::cout << "starting from " << o.state_file << " at load factor " << start->t << std::endl;
  }
  StaticReport report;
  const auto rows = run_static(problem, dir, &std::cout, &report, start.get());
  std::cout << "summary: " << report.levels << " load levels, " << report.increments << " increments ("
            << report.failed_attempts << " failed attempts), " << report.newton_iterations << " Newton iterations, "
            << report.chart_switches << " director chart switches, " << report.wall_seconds << " s\n";
  std::cout << "wrote " << dir << "/static.csv, " << dir << "/fields.pvd, " << dir << "/run.json\n";
  return rows.empty() ? 1 : 0;
}

void add_static_command(CLI::App& app, Action& action, const std::string& command) {
  auto opts = std::make_shared<CheckOptions>();
  opts->command = command;
  CLI::App* sub = app.add_subcommand(
      "static",
      "Solve a static case (integrator: static); write static.csv, VTU/PVD, run.json.\n"
      "Case settings (integrator: {name: static, ...}; docs/statics.md): control=load|arc_length|displacement, "
      "increment=time.dt, min_increment, growth=1.5, easy_iterations=6, target_iterations=5, max_arc_factor=4, "
      "max_steps=1000, max_iters=30, tol=1e-8 (residual relative to max(|F_ext|, |F_int| incl. reactions)), "
      "step_tol=1e-10 (correction relative to the displacement scale), jump_ratio=5, linear_solver=eigen-ldlt (klu: "
      "full non-symmetric follower-load tangent, no inertia), control_set/control_dof/displacement_end, hysteresis=1.");
  sub->add_option("case", opts->case_path, "Case file (YAML), e.g. apps/cases/sze-hemisphere.yaml")->required();
  sub->add_option("-o,--output", opts->out_dir, "Result folder (default: results/<case>/static)");
  sub->add_flag("--overwrite", opts->overwrite, "Replace the results of an earlier command in the result folder");
  sub->add_option("--state", opts->state_file,
                  "Start from a saved state: a checkpoint.cbor of `shelldyn run` (or its run folder), or a VTU of a run "
                  "(DIR/fields/step_N.vtu, its time from DIR/fields.pvd); its time is the starting load factor, velocities are ignored (default: the reference state at load factor 0)");
  sub->callback([opts, &action] { action = [opts] { return run_static_command(*opts); }; });
}


// --- compare -----------------------------------------------------------------------------------------
// `shelldyn compare CASE --integrators A,B:KEY=VALUE,... [--dt LIST] [--rtol LIST]`: the comparison
// study of integrators/runs/compare.hpp (spec syntax, sweeps, reference run and error measures are documented
// there), then scripts/plot_compare.py. Exit 0 when every run completed, 3 when some failed (they are
// rows with status "failed: ..." in summary.csv/summary.md), 1 for bad input.
struct CompareCommandOptions {
  std::string case_path, out_dir, reference, command;
  std::vector<std::string> specs, plugins;
  std::vector<double> dts, rtols;
  double t_end = -1.0, output_every = 0.0, progress_every = 10.0;
  int jobs = 2, threads = 0, vtu_every = 0;
  bool no_plots = false, resume = false;
  CLI::App* cli = nullptr;
};

int run_compare(const CompareCommandOptions& o) {
  CompareOptions co;
  co.case_path = o.case_path;
  if (!fs::exists(co.case_path) && co.case_path.find('/') == std::string::npos)
    co.case_path = app::find_case_file(co.case_path + (fs::path(co.case_path).extension() == ".yaml" ? "" : ".yaml"));
  if (o.cli->count("--t-end")) app::check_non_negative("--t-end", o.t_end, "--t-end 6");
  if (o.cli->count("--output-every")) app::check_positive("--output-every", o.output_every, "--output-every 0.01");
  for (double dt : o.dts) app::check_positive("--dt", dt, "--dt 1e-3,2e-3");
  for (double r : o.rtols) app::check_positive("--rtol", r, "--rtol 1e-6,1e-8");
  app::check_range("--jobs", o.jobs, 1, 64, "--jobs 2");
  app::check_range("--threads", o.threads, 0, 1024, "--threads 2");
  app::check_range("--vtu-every", o.vtu_every, 0, 1000000000, "--vtu-every 10");
  co.specs = o.specs;
  co.dts = o.dts;
  co.rtols = o.rtols;
  co.t_end = o.t_end;
  co.output_interval = o.output_every;
  co.vtu_every = o.vtu_every;
  co.jobs = o.jobs;
  co.threads = o.threads;
  co.reference = o.reference;
  co.command = o.command;
  co.log = &std::cout;
  if (o.cli->count("--progress-every")) app::check_non_negative("--progress-every", o.progress_every, "--progress-every 10");
  co.progress_every = o.progress_every;
  const std::string stem = fs::path(co.case_path).stem().string();
  co.out_dir = o.out_dir.empty() ? (fs::path("results") / stem / "compare").string() : o.out_dir;
  const auto runs = expand_compare_runs(co);  // bad specs fail here, before any folder exists
  app::check_output_folder(co.out_dir);
  // Where the runs execute: the ranks of an MPI job under mpirun/srun, else --jobs threads (docs/cluster-sweeps.md).
  const std::unique_ptr<RunExecutor> executor = app::make_sweep_executor(co.jobs, co.threads);
  co.executor = executor.get();
  co.resume = o.resume;
  const bool root = executor->collects();
  if (!root) co.log = nullptr;
  // The sweep's folder is this command's until it exits (docs/guide/result-folders.md): a second compare into it
  // is refused with one line naming the holder. A stale lock (a killed sweep) is taken over by --resume only.
  if (root) hold_result_folder(co.out_dir, o.resume ? StaleLock::take_over : StaleLock::refuse, &std::cerr);
  if (root)
    std::cout << "shelldyn compare: " << stem << ", " << runs.size() << " runs on " << executor->describe() << " -> "
              << co.out_dir << std::endl;
  const CompareResult r = run_comparison(co);
  if (!root) return 0;  // an MPI worker rank: rank 0 reports
  size_t failed = 0;
  for (const auto& row : r.rows) failed += row.ok ? 0 : 1;
  std::cout << "wrote " << r.summary_csv << ", " << r.summary_md << " (" << r.rows.size() - failed << " complete, " << failed
            << " failed; reference " << (r.reference.empty() ? std::string("none") : r.reference) << ")" << std::endl;
  if (!o.no_plots && app::run_python_script(app::find_script("plot_compare.py"), {co.out_dir}, std::cout))
    std::cout << "wrote " << co.out_dir << "/energy.png, momentum.png, work_precision.png" << std::endl;
  return failed ? 3 : 0;
}

void add_compare_command(CLI::App& app, Action& action, const std::string& command) {
  auto o = std::make_shared<CompareCommandOptions>();
  o->command = command;
  std::string names;
  for (const auto& n : integrator_names()) names += (names.empty() ? "" : ", ") + n;
  CLI::App* sub = app.add_subcommand(
      "compare", "Run one case with several integrator settings (2 at a time, or over the ranks of mpirun -n P); write "
                 "summary.csv, summary.md and plots");
  sub->add_option("case", o->case_path, "Case file (YAML), or a case name of apps/cases such as flying-plate")->required();
  sub->add_option("--integrators", o->specs,
                  "Comma-separated runs NAME[:KEY=VALUE...], e.g. em-galpha,galpha:rho_inf=0.8,em-galpha:dt=2e-3,"
                  "ida-bdf:rtol=1e-8 (integrators: " + names + ")")
      ->required()
      ->delimiter(',');
  sub->add_option("--dt", o->dts, "Comma-separated time steps: one run per dt for every fixed-step setting without its own dt")
      ->delimiter(',');
  sub->add_option("--rtol", o->rtols, "Comma-separated tolerances: one run per rtol for every adaptive setting without its own rtol")
      ->delimiter(',');
  sub->add_option("--t-end", o->t_end, "End time (default: the case's time.t_end)");
  sub->add_option("--output-every", o->output_every, "Output interval (default: the case's)");
  sub->add_option("--vtu-every", o->vtu_every, "VTU every N output times per run (default 0: none)");
  sub->add_option("-o,--output", o->out_dir, "Result folder (default: results/<case>/compare)");
  sub->add_option("--jobs", o->jobs, "Runs at a time, each single-threaded when > 1 (default 2); under mpirun/srun: one run "
                                     "per rank at a time, --jobs is ignored");
  sub->add_option("--threads", o->threads, "OpenMP threads per run when --jobs 1 (default: all cores); under mpirun/srun: per "
                                           "rank (default 1)");
  sub->add_flag("--resume", o->resume, "Do not rerun runs that an earlier sweep into the same folder finished with the same "
                                       "settings (their compare-outcome.txt); run only the missing or failed ones");
  o->cli = sub;
  sub->add_option("--reference", o->reference, "Label of the reference run for displacement errors (default: finest fixed-step run)");
  sub->add_flag("--no-plots", o->no_plots, "Do not call scripts/plot_compare.py");
  sub->add_option("--progress-every", o->progress_every,
                  "A progress line per running run every S seconds of wall time, with its time, steps, wall and CPU "
                  "seconds (default 10; 0: at every output time)");
  add_plugin_option(sub, o->plugins);
  sub->callback([o, &action] { action = [o] { return run_compare(*o); }; });
}

// --- study -------------------------------------------------------------------------------------------
// `shelldyn study BENCHMARK|FILE`: the integrator study of integrators/runs/study.hpp (work–precision sweep on
// a window + full-duration conservation runs, resumable) from a study file (docs/reference/study-files.md: a
// shipped apps/studies/<benchmark>.yaml or the user's own), then scripts/plot_study.py. Exit 0 when every run
// completed or stopped at the per-run budget, 3 when some failed, 1 for bad input.
struct StudyCommandOptions {
  std::string benchmark, case_path, out_dir, command, only = "all";
  std::vector<std::string> add_methods;
  int jobs = 2;
  double max_wall_per_run = 0.0;
  long long max_steps_per_run = 0;
  bool rerun = false, dry_run = false, report_only = false, no_plots = false;
  std::vector<std::string> plugins;  // loaded by main()
};

// The study file `study` names: a shipped study by name, else a file.
std::string study_file_path(const std::string& name) {
  std::string names;
  for (const auto& [n, path] : app::shipped_study_files()) {
    if (n == name) return path;
    names += (names.empty() ? "" : ", ") + n;
  }
  std::error_code ec;
  if (fs::exists(name, ec)) return name;  // load_study_file refuses what is not a regular file
  throw std::invalid_argument("study: unknown benchmark '" + name + "' (available: " + (names.empty() ? "none shipped" : names) +
                              ", all, or the path of a study file)");
}

// The study's case: --case, else the study file's `case:` relative to the study file, else a shipped case.
std::string study_case_path(const StudyPreset& p, const std::string& case_option) {
  if (!case_option.empty()) return case_option;
  if (!p.case_path.empty()) return p.case_path;
  // Not next to the study file (e.g. a copy of a shipped study file elsewhere): the shipped case of that name.
  try {
    return app::find_case_file(fs::path(p.case_file).filename().string());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(p.case_where + ": " + e.what());
  }
}

int run_study_command(const StudyCommandOptions& o) {
  // `all`: the shipped studies in one batch of runs (run_studies), each into its own folder.
  std::vector<std::string> files;
  if (o.benchmark == "all") {
    if (!o.case_path.empty()) throw std::invalid_argument("--case needs one benchmark, not 'all' (each benchmark has its own case)");
    for (const auto& [n, path] : app::shipped_study_files()) files.push_back(path);
    if (files.empty()) throw std::invalid_argument("study all: no shipped study files found (apps/studies or share/shelldyn/studies)");
  } else {
    files.push_back(study_file_path(o.benchmark));
  }
  if (o.jobs < 1) throw std::invalid_argument("--jobs must be >= 1 (got " + std::to_string(o.jobs) + ")");
  if (o.only != "window" && o.only != "full" && o.only != "all")
    throw std::invalid_argument("--only must be window, full or all (got '" + o.only + "')");
  if (!(o.max_wall_per_run >= 0.0) || !std::isfinite(o.max_wall_per_run) || o.max_steps_per_run < 0)
    throw std::invalid_argument("--max-wall-per-run and --max-steps-per-run must be >= 0 (0: no budget)");
  std::vector<StudyOptions> studies;
  for (const auto& file : files) {
    StudyOptions so;
    so.preset = load_study_file(file);
    for (const auto& spec : o.add_methods) add_study_method(so.preset, spec, "--add-method '" + spec + "'");
    if (o.only == "window" && !so.preset.has_window) throw std::invalid_argument("--only window: " + file + " has no window: section");
    if (o.only == "full" && !so.preset.has_full) throw std::invalid_argument("--only full: " + file + " has no full: section");
    so.case_path = study_case_path(so.preset, o.case_path);
    if (o.only != "all") so.groups = {o.only};
    so.out_dir = o.out_dir.empty() ? (fs::path("results") / so.preset.name / "study").string()
                 : files.size() > 1 ? (fs::path(o.out_dir) / so.preset.name).string()
                                    : o.out_dir;
    so.max_wall_per_run = o.max_wall_per_run;
    so.max_steps_per_run = o.max_steps_per_run;
    so.rerun = o.rerun;
    so.dry_run = o.dry_run;
    so.report_only = o.report_only;
    so.command = o.command;
    if (!o.dry_run) app::check_output_folder(so.out_dir);
    studies.push_back(so);
  }
  // Where the runs execute: as `shelldyn compare` (the ranks of mpirun/srun, else --jobs threads).
  const std::unique_ptr<RunExecutor> executor = app::make_sweep_executor(o.jobs, 0);
  // Each study folder is this command's until it exits, as for compare. A study continues the runs an earlier
  // one left (its default), so a stale lock is taken over with a note.
  if (!o.dry_run && executor->collects())
    for (const auto& so : studies) hold_result_folder(so.out_dir, StaleLock::take_over, &std::cerr);
  for (auto& so : studies) {
    so.execution.jobs = o.jobs;
    so.execution.executor = executor.get();
    so.report = executor->collects();
    so.log = so.report ? &std::cout : nullptr;
  }
  const std::vector<StudyResult> results = run_studies(studies);
  if (o.dry_run || !executor->collects()) return 0;
  bool failed = false;
  for (size_t i = 0; i < studies.size(); ++i) {
    const StudyResult& r = results[i];
    failed = failed || r.failed > 0;
    std::cout << "study " << studies[i].preset.name << ": " << r.ran << " runs made, " << r.skipped << " kept from earlier, "
              << r.stopped << " stopped at the per-run budget, " << r.failed << " failed; wrote " << r.study_csv << ", "
              << r.study_md << std::endl;
    if (!o.no_plots && app::run_python_script(app::find_script("plot_study.py"), {studies[i].out_dir}, std::cout))
      std::cout << "wrote " << studies[i].out_dir << "/work_precision.png, full_energy.png, full_momentum.png" << std::endl;
  }
  return failed ? 3 : 0;
}

void add_study_command(CLI::App& app, Action& action, const std::string& command) {
  auto o = std::make_shared<StudyCommandOptions>();
  o->command = command;
  std::string names;
  for (const auto& [n, path] : app::shipped_study_files()) names += (names.empty() ? "" : "|") + n;
  CLI::App* sub = app.add_subcommand(
      "study", "Work-precision sweep of every method of a study file on its case + full-duration conservation runs "
               "(resumable); write study.csv, study.md and plots");
  sub->add_option("benchmark", o->benchmark,
                  "A shipped study: " + names + ", or all (the shipped ones in one batch of runs, longest first; with -o DIR "
                  "each goes to DIR/<name>); or a study file of your own (YAML, docs/reference/study-files.md)")
      ->required();
  sub->add_option("--case", o->case_path, "Case file to use instead of the study file's case: (same methods and sweeps)");
  sub->add_option("--add-method", o->add_methods,
                  "Comma-separated methods NAME[:KEY=VALUE...] (any registered integrator) added to the study: swept over "
                  "the window's dt or rtol list and, fixed-step, run over the full duration")
      ->delimiter(',');
  sub->add_option("-o,--output", o->out_dir, "Result folder (default: results/<name>/study)");
  sub->add_option("--jobs", o->jobs, "Runs at a time, each single-threaded (default 2); the runs of all groups (and with "
                                     "'all' of all studies) form one batch, longest expected first");
  sub->add_option("--only", o->only, "Run only the group window (work-precision sweep) or full (full duration); default all");
  sub->add_option("--max-wall-per-run", o->max_wall_per_run,
                  "Budget per run in wall seconds (default 0: none); a run that hits it is reported as stopped at budget "
                  "with the time reached, never as complete");
  sub->add_option("--max-steps-per-run", o->max_steps_per_run,
                  "Budget per run in steps, checked at output times (default 0: none); reported as --max-wall-per-run");
  sub->add_flag("--rerun", o->rerun, "Run completed runs again (default: keep them; the study resumes)");
  sub->add_flag("--dry-run", o->dry_run, "List the runs and which are complete; run nothing");
  sub->add_flag("--report-only", o->report_only,
                "Run nothing; write study.csv, study.md and the plots from the run folders as they are (runs not made "
                "are listed as not run)");
  sub->add_flag("--no-plots", o->no_plots, "Do not call scripts/plot_study.py");
  add_plugin_option(sub, o->plugins);
  sub->callback([o, &action] { action = [o] { return run_study_command(*o); }; });
}
}  // namespace

int main(int argc, char** argv) {
  std::string command;
  for (int k = 0; k < argc; ++k) command += (k ? " " : "") + std::string(argv[k]);

  // Plugins first (integrators/runs/plugin.hpp): SHELLDYN_PLUGINS, then every --plugin PATH / --plugin=PATH, so
  // that their integrators are known to the option checks and listed by --help. A bad one: one line, exit 1.
  try {
    for (const auto& p : plugin_paths_from_environment()) load_plugin(p, "SHELLDYN_PLUGINS");
    for (int k = 1; k < argc; ++k) {
      const std::string a = argv[k];
      if (a == "--plugin" && k + 1 < argc) load_plugin(argv[++k], "--plugin");
      else if (a.rfind("--plugin=", 0) == 0) load_plugin(a.substr(9), "--plugin");
    }
  } catch (const std::exception& e) {
    app::print_error(std::cerr, "shelldyn: error: ", e.what());
    return 1;
  }

  CLI::App app{"shelldyn: nonlinear dynamics of thin shells (CR9 shell element, energy-momentum generalized-alpha, "
               "SUNDIALS baselines)"};
  app.name("shelldyn");
  app.set_version_flag("--version", version_text());
  app.require_subcommand(1);
  Action action;
  add_check_command(app, action, command);
  add_run_command(app, action, command);
  add_static_command(app, action, command);
  app::add_modes_command(app, action, command);
  add_compare_command(app, action, command);
  add_study_command(app, action, command);
  add_resume_command(app, action, command);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::cerr << "shelldyn: error: " << one_line(e.what()) << " (see 'shelldyn --help')\n";
    return 2;
  }
  try {
    return action();
  } catch (const RunStopped& e) {  // signal or limit: everything written, resumable (exit 130/143/4)
    app::print_error(std::cerr, "shelldyn: ", e.what());
    return e.exit_code();
  } catch (const std::exception& e) {
    record_failure(e.what());  // a held result folder still "incomplete: running" gets the reason (lib/io/result_folder.hpp)
    app::print_error(std::cerr, "shelldyn: error: ", e.what());
    return 1;
  } catch (...) {  // e.g. a plugin throwing something that is not a std::exception
    std::cerr << "shelldyn: error: unknown exception (not a std::exception)\n";
    return 1;
  }
}
