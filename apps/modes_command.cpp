#include "apps/modes_command.hpp"

#include "apps/app_common.hpp"
#include "integrators/runs/static_run.hpp"
#include "integrators/sundials/sundials_info.hpp"
#include "lib/linalg/linear_solver.hpp"
#include "lib/analysis/modal_analysis.hpp"
#include "lib/model/problem.hpp"
#include "lib/io/run_info.hpp"
#include "lib/io/state_output.hpp"
#include "lib/io/vtu_writer.hpp"

#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

namespace fs = std::filesystem;

namespace shelldyn::app {
namespace {

struct ModesOptions {
  std::string case_path, out_dir, state = "initial", linear_solver = "eigen-ldlt", command;
  int num_modes = 10;
  double shift_hz = 0.0, dt = 0.0;
  bool no_vtu = false, overwrite = false;
};

// "initial" -> the reference state; "static" / "static:LAMBDA" -> the case solved statically (its
// integrator block must be `name: static`) to t_end or LAMBDA; anything else -> a saved state FILE
// (app::load_saved_state: checkpoint.cbor, run folder or run VTU), linearised at its time.
State modes_state(Problem& problem, const std::string& which, bool* loaded) {
  *loaded = false;
  if (which == "initial") return problem.initial_state();
  if (which == "static" || which.rfind("static:", 0) == 0) {  // not a file such as static/fields/step_000004.vtu
    double lambda = problem.spec.time.t_end;
    if (which.size() > 6) {
      if (which[6] != ':') throw std::invalid_argument("--state '" + which + "': expected initial, static or static:LAMBDA");
      try {
        lambda = std::stod(which.substr(7));
      } catch (const std::exception&) {
        throw std::invalid_argument("--state '" + which + "': LAMBDA is not a number (e.g. --state static:0.5)");
      }
    }
    if (!(lambda >= 0.0)) throw std::invalid_argument("--state static:LAMBDA needs LAMBDA >= 0");
    State s = problem.initial_state();
    StaticSolver solver(*problem.model, static_options(problem.spec, &problem.disc));
    const StaticReport rep = solver.solve(s, lambda);
    std::cout << "static state: load factor " << s.t << " reached in " << rep.increments << " increments, "
              << rep.newton_iterations << " Newton iterations\n";
    *loaded = true;
    return s;
  }
  // A saved state (docs/manual.md §1): a checkpoint, a run folder holding one, or a run's VTU.
  State s = load_saved_state(problem, which);
  std::cout << "saved state " << which << " at load factor (time) " << s.t << "\n";
  *loaded = true;
  return s;
}

int run_modes(const ModesOptions& o) {
  if (o.dt < 0.0 || !std::isfinite(o.dt)) throw std::invalid_argument("--dt must be > 0 (got " + std::to_string(o.dt) + ")");
  Problem problem = load_problem(o.case_path);
  const Model& model = *problem.model;
  const std::string dir = o.out_dir.empty() ? (fs::path("results") / problem.spec.name / "modes").string() : o.out_dir;
  prepare_result_folder(dir, o.overwrite);  // before the eigensolve: a reused folder is refused at once
  bool loaded = false;
  const State state = modes_state(problem, o.state, &loaded);

  ModalOptions mo;
  mo.num_modes = o.num_modes;
  mo.shift_hz = o.shift_hz;
  mo.linear_solver = o.linear_solver;
  mo.load_stiffness = loaded;
  std::cout << "shelldyn modes: " << problem.spec.name << ", " << o.num_modes << " modes "
            << (o.shift_hz > 0.0 ? "nearest " + std::to_string(o.shift_hz) + " Hz" : std::string("(lowest)")) << " about the "
            << (loaded ? "static state at load factor " + std::to_string(state.t) : std::string("initial state")) << " -> "
            << dir << std::endl;
  const ModalResult r = modal_analysis(model, state, mo);

  char buf[256];
  std::printf("%d free DOFs (%lld constrained), shift sigma = %.6g (rad/s)^2, %ld solves, %d restarts, %.3f s (factorization %.3f s)\n",
              static_cast<int>(r.free_dofs), static_cast<long long>(model.dofs().num_constrained()), r.sigma,
              r.operator_applications, r.restarts, r.total_s, r.factorize_s);
  std::printf("%4s  %14s  %14s  %12s  %-17s  %11s%s\n", "mode", "omega [rad/s]", "f [Hz]", "T [s]", "dominant (share)",
              "dt(20/T)", o.dt > 0.0 ? "  steps/T at dt" : "");
  for (size_t k = 0; k < r.modes.size(); ++k) {
    const Mode& m = r.modes[k];
    std::snprintf(buf, sizeof buf, "%s %3.0f%%", m.dominant().c_str(),
                  100.0 * *std::max_element(m.share.begin(), m.share.end()));
    if (m.rigid || m.unstable) {
      std::printf("%4zu  %14s  %14s  %12s  %-17s  %11s  (omega^2 = %.3g)\n", k + 1, m.rigid ? "rigid" : "UNSTABLE", "-", "-",
                  buf, "-", m.omega2);
      continue;
    }
    std::printf("%4zu  %14.6g  %14.6g  %12.6g  %-17s  %11.4g", k + 1, m.omega, m.frequency, m.period, buf, m.period / 20.0);
    if (o.dt > 0.0) std::printf("  %14.4g", m.period / o.dt);
    std::printf("\n");
  }
  std::printf("rigid-body modes: %d (|omega^2| <= %.1e * max K_ii/M_ii = %.3g)", r.rigid_modes, mo.rigid_tol,
              mo.rigid_tol * r.lambda_scale);
  if (r.unstable_modes) std::printf("; UNSTABLE modes (omega^2 < 0): %d", r.unstable_modes);
  std::printf("\n");
  if (o.dt > 0.0) {
    int under = 0;
    for (const Mode& m : r.modes)
      if (!m.rigid && !m.unstable && m.period / o.dt < 20.0) ++under;
    std::printf("dt = %g: %d of the computed elastic modes have fewer than 20 steps per period\n", o.dt, under);
  }
  std::fflush(stdout);

  prepare_output_folder(dir);
  {
    std::ofstream csv(dir + "/modes.csv");
    csv << "mode,rigid,unstable,omega2,omega_rad_s,frequency_hz,period_s,share_x,share_y,share_z,share_rotation,dominant";
    if (o.dt > 0.0) csv << ",steps_per_period";
    csv << '\n';
    for (size_t k = 0; k < r.modes.size(); ++k) {
      const Mode& m = r.modes[k];
      std::snprintf(buf, sizeof buf, "%zu,%d,%d,%.17g,%.17g,%.17g,%.17g,%.6f,%.6f,%.6f,%.6f,%s", k + 1, m.rigid ? 1 : 0,
                    m.unstable ? 1 : 0, m.omega2, m.omega, m.frequency, std::isfinite(m.period) ? m.period : 0.0, m.share[0],
                    m.share[1], m.share[2], m.share[3], m.dominant().c_str());
      csv << buf;
      if (o.dt > 0.0) csv << ',' << (std::isfinite(m.period) ? m.period / o.dt : 0.0);
      csv << '\n';
    }
    if (!csv) throw std::runtime_error("cannot write " + dir + "/modes.csv");
  }
  // Machine-readable shapes (every DOF kind), e.g. for initial_velocity: {mode: ..., index: k, amplitude: A}.
  write_mode_shapes_csv(dir + "/mode_shapes.csv", model, state, r);
  if (!o.no_vtu) {
    // Scale: largest translation = 10 % of the model's largest extent, so each VTU shows the shape.
    const Mesh& mesh = model.mesh();
    Eigen::Vector3d lo = mesh.X[0], hi = mesh.X[0];
    for (const Vec3& x : mesh.X) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    const double extent = (hi - lo).maxCoeff();
    PvdWriter pvd(dir + "/modes.pvd");
    const VtuFields base = state_fields(model, state);
    for (size_t k = 0; k < r.modes.size(); ++k) {
      const Mode& m = r.modes[k];
      VtuFields f = base;
      double dmax = 0.0;
      for (int i = 0; i < mesh.num_nodes(); ++i)
        dmax = std::max(dmax, m.shape.segment<3>(DofMap::dof(i, 0)).norm());
      const double scale = dmax > 0.0 ? 0.1 * extent / dmax : 0.0;
      ScalarField mx{"mode_translation_x", {}}, my{"mode_translation_y", {}}, mz{"mode_translation_z", {}};
      for (int i = 0; i < mesh.num_nodes(); ++i) {
        const Vec3 d = m.shape.segment<3>(DofMap::dof(i, 0));
        f.displacement[static_cast<size_t>(i)] += scale * d;
        mx.values.push_back(d.x());
        my.values.push_back(d.y());
        mz.values.push_back(d.z());
      }
      f.point_scalars = {std::move(mx), std::move(my), std::move(mz)};
      std::snprintf(buf, sizeof buf, "fields/mode_%03zu.vtu", k + 1);
      write_vtu(dir + "/" + buf, mesh, f);
      pvd.add(static_cast<double>(k + 1), buf);
    }
  }
  RunInfo info;
  info.status = "complete";
  info.command = o.command;
  info.sundials_version = sundials_version();
  info.discretization.set("nodes", model.mesh().num_nodes());
  info.discretization.set("elements", model.mesh().num_elements());
  info.discretization.set("dofs", static_cast<long long>(model.num_dofs()));
  info.discretization.set("free_dofs", static_cast<long long>(r.free_dofs));
  info.summary.set("state", o.state);
  info.summary.set("load_factor", state.t);
  info.summary.set("modes", static_cast<int>(r.modes.size()));
  info.summary.set("rigid_modes", r.rigid_modes);
  info.summary.set("unstable_modes", r.unstable_modes);
  info.summary.set("shift_sigma", r.sigma);
  info.summary.set("linear_solver", o.linear_solver);
  info.summary.set("solves", r.operator_applications);
  info.summary.set("wall_s", r.total_s);
  for (size_t k = 0; k < r.modes.size(); ++k) info.summary.set("f" + std::to_string(k + 1) + "_hz", r.modes[k].frequency);
  write_run_json(dir + "/run.json", problem.spec, info);
  std::cout << "wrote " << dir << "/modes.csv, " << dir << "/mode_shapes.csv" << (o.no_vtu ? "" : ", " + dir + "/modes.pvd") << ", " << dir << "/run.json\n";
  return 0;
}

}  // namespace

void add_modes_command(CLI::App& app, std::function<int()>& action, const std::string& command) {
  auto o = std::make_shared<ModesOptions>();
  o->command = command;
  CLI::App* sub = app.add_subcommand(
      "modes", "Natural frequencies and mode shapes (K phi = omega^2 M phi, shift-invert Lanczos); write modes.csv, mode_shapes.csv, modes.pvd, run.json");
  sub->add_option("case", o->case_path, "Case file (YAML), e.g. apps/cases/plate-modes-ss-thin.yaml")->required();
  // Own checks: CLI11's ranges print their bound 1.79769e+308 in full (a 309-digit number).
  sub->add_option("-n,--modes", o->num_modes, "Number of modes, rigid-body modes included (default 10)")
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            char* end = nullptr;
            const long long n = std::strtoll(v.c_str(), &end, 10);
            return (end && *end == '\0' && !v.empty() && n >= 1 && n <= 100000) ? std::string()
                                                                                 : "must be a whole number in 1..100000, e.g. -n 10";
          },
          "INT in 1..100000"));
  sub->add_option("--shift", o->shift_hz, "Find the modes nearest this frequency [Hz] (default 0: the lowest modes)")
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            char* end = nullptr;
            const double x = std::strtod(v.c_str(), &end);
            return (end && *end == '\0' && !v.empty() && std::isfinite(x) && x >= 0.0 && x <= 1e15)
                       ? std::string()
                       : "must be a frequency in Hz, >= 0 and at most 1e15, e.g. --shift 50";
          },
          "HZ >= 0"));
  sub->add_option("--state", o->state,
                  "Linearise about: initial (default) | static (the case solved statically to t_end; K includes the "
                  "geometric and load stiffness) | static:LAMBDA (to load factor LAMBDA) | FILE (a saved state: a "
                  "checkpoint.cbor or run folder, or a run's DIR/fields/step_N.vtu at the time DIR/fields.pvd gives it)");
  sub->add_option("--dt", o->dt, "Time step to judge: adds steps per period for every mode and counts modes with < 20");
  sub->add_option("--linear-solver", o->linear_solver, "Sparse factorization for (K - sigma M): eigen-ldlt (default), cholmod, klu, mumps");
  sub->add_option("-o,--output", o->out_dir, "Result folder (default: results/<case>/modes)");
  sub->add_flag("--no-vtu", o->no_vtu, "Do not write the mode-shape VTU files");
  sub->add_flag("--overwrite", o->overwrite, "Replace the results of an earlier command in the result folder");
  sub->callback([o, &action] { action = [o] { return run_modes(*o); }; });
}

}  // namespace shelldyn::app
