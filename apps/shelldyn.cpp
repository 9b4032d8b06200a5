// shelldyn — the command-line front end of the toolkit.
//
// Sample runs:
//   shelldyn --help
//   shelldyn --version
//   shelldyn check apps/cases/flying-plate.yaml              # validate, summarise, write results/flying-plate/
//   shelldyn check apps/cases/pinched-hemisphere.yaml -o /tmp/hemi
//
// `check` reads a case file (lib/case_file.hpp), builds its discretization (mesh, sets, constraints,
// loads; lib/discretization.hpp), prints a summary and writes the initial state as
// DIR/fields/step_000000.vtu + DIR/fields.pvd and DIR/run.json with status "checked", so the set-up
// can be inspected in ParaView before any time is spent integrating.
//
// Exit codes: 0 success; 1 bad input or failure (one line "shelldyn: error: ..." on stderr);
// 2 command-line usage error.
//
// Adding a subcommand (run, static, ...): write `add_<name>_command(CLI::App&, Action&)` next to
// add_check_command: it registers its options and, in its callback, stores the action to run.
// main() stays unchanged apart from one call.
#include "integrators/sundials_info.hpp"
#include "lib/case_file.hpp"
#include "lib/discretization.hpp"
#include "lib/run_info.hpp"
#include "lib/vtu_writer.hpp"

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
  return "shelldyn " + shelldyn_version() + " (SUNDIALS " + sundials_version() + ", Eigen " + eigen_version() + ")";
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

// --- check -------------------------------------------------------------------------------------------
struct CheckOptions {
  std::string case_path;
  std::string out_dir;  // empty: results/<case name>
  std::string command;  // the full command line, recorded in run.json
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
  f.point_scalars = {std::move(fixed), std::move(load)};
  return f;
}

int run_check(const CheckOptions& o) {
  const CaseSpec spec = load_case(o.case_path);
  const Discretization d = build_discretization(spec);
  print_summary(std::cout, spec, d);

  const fs::path dir = o.out_dir.empty() ? fs::path("results") / spec.name : fs::path(o.out_dir);
  std::error_code ec;
  fs::create_directories(dir / "fields", ec);
  if (ec) throw std::runtime_error(dir.string() + ": cannot create the result folder: " + ec.message());
  const std::string vtu = "fields/" + vtu_step_file_name(0);
  write_vtu((dir / vtu).string(), d.mesh, initial_fields(d));
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
  sub->add_option("case", opts->case_path, "Case file (YAML), e.g. apps/cases/flying-plate.yaml")->required();
  sub->add_option("-o,--output", opts->out_dir, "Result folder (default: results/<case name>)");
  sub->callback([opts, &action] { action = [opts] { return run_check(*opts); }; });
}

}  // namespace

int main(int argc, char** argv) {
  std::string command;
  for (int k = 0; k < argc; ++k) command += (k ? " " : "") + std::string(argv[k]);

  CLI::App app{"shelldyn: nonlinear dynamics of thin shells (CR9 shell element, energy-momentum generalized-alpha, "
               "SUNDIALS baselines)"};
  app.name("shelldyn");
  app.set_version_flag("--version", version_text());
  app.require_subcommand(1);
  Action action;
  add_check_command(app, action, command);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::cerr << "shelldyn: error: " << one_line(e.what()) << " (see 'shelldyn --help')\n";
    return 2;
  }
  try {
    return action();
  } catch (const std::exception& e) {
    std::cerr << "shelldyn: error: " << one_line(e.what()) << "\n";
    return 1;
  }
}
