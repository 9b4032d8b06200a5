#include "integrators/runs/static_run.hpp"

#include "integrators/runs/case_integrator.hpp"

#include "integrators/integrator_settings.hpp"
#include "integrators/sundials/sundials_info.hpp"
#include "lib/model/reactions.hpp"
#include "lib/io/run_info.hpp"
#include "lib/io/state_output.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>

namespace shelldyn {

namespace {

// static.csv through a checked writer: every row is flushed, and a failed write (a full disk) is an error
// naming the file, as for history.csv (lib/io/history_writer.hpp), instead of a silently truncated table.
class CsvFile {
 public:
  explicit CsvFile(std::string path) : path_(std::move(path)), f_(std::fopen(path_.c_str(), "w")) {
    if (!f_) throw std::runtime_error(path_ + ": cannot create static.csv: " + std::strerror(errno));
  }
  ~CsvFile() {
    if (f_) std::fclose(f_);
  }
  CsvFile(const CsvFile&) = delete;
  CsvFile& operator=(const CsvFile&) = delete;
  void write(const std::string& text) {
    errno = 0;
    if (std::fwrite(text.data(), 1, text.size(), f_) != text.size() || std::fflush(f_) != 0) {
      const int err = errno ? errno : EIO;
      throw std::runtime_error(path_ + ": cannot write static.csv: " +
                               (err == ENOSPC ? std::string("the disk is full (free space and rerun)") : std::strerror(err)));
    }
  }

 private:
  std::string path_;
  std::FILE* f_;
};

}  // namespace

StaticOptions static_options(const CaseSpec& spec, const Discretization* disc) {
  IntegratorSettings s(spec.integrator);
  if (s.name() != "static")
    throw std::invalid_argument("integrator.name: '" + s.name() + "' is not the static solver (use name: static)");
  StaticOptions o;
  o.control = parse_path_control(s.get("control", std::string("load")));
  o.increment = s.get("increment", spec.time.dt);
  o.min_increment = s.get("min_increment", o.control == PathControl::load ? o.increment * 1e-4 : 1e-4);
  o.growth = s.get("growth", 1.5);
  o.easy_iterations = s.get("easy_iterations", 6);
  o.target_iterations = s.get("target_iterations", 5);
  o.max_arc_factor = s.get("max_arc_factor", 4.0);
  o.max_steps = s.get("max_steps", 1000);
  o.rechart_hysteresis = s.get("hysteresis", 1.0);
  o.max_iters = s.get("max_iters", 30);
  o.jump_ratio = s.get("jump_ratio", 5.0);
  o.max_turn = s.get("max_turn", 10.0);
  o.locate_tol = s.get("locate_tol", 0.01);
  o.progress_seconds = s.get("progress_seconds", 5.0);
  o.convergence.residual_tol = s.get("tol", 1e-8);
  o.convergence.increment_tol = s.get("step_tol", 1e-10);
  o.linear_solver = s.get("linear_solver", std::string("eigen-ldlt"));
  const std::string control_set = s.get("control_set", std::string());
  const std::string control_dir = s.get("control_dof", std::string("uz"));
  o.displacement_end = s.get("displacement_end", std::numeric_limits<double>::quiet_NaN());
  s.finish();
  if (o.control == PathControl::displacement) {
    if (control_set.empty())
      throw std::invalid_argument("integrator: control: displacement needs control_set (a one-node set) and control_dof (ux|uy|uz)");
    int comp = control_dir == "ux" ? 0 : control_dir == "uy" ? 1 : control_dir == "uz" ? 2 : -1;
    if (comp < 0) throw std::invalid_argument("integrator.control_dof: '" + control_dir + "' is not ux, uy or uz");
    if (disc) {
      const auto it = disc->mesh.node_sets.find(control_set);
      if (it == disc->mesh.node_sets.end() || it->second.size() != 1)
        throw std::invalid_argument("integrator.control_set: '" + control_set + "' must name a node set with exactly one node");
      o.control_dof = DofMap::dof(it->second.front(), comp);
    }
  }
  // λ is a load factor only when every load grows proportionally to it (ramps); otherwise it is a
  // pseudo-time and the messages say so.
  bool proportional = true;
  for (const auto& l : spec.loads) proportional = proportional && l.function.kind() == TimeFunction::Kind::Ramp;
  o.parameter_name = proportional ? "load factor" : "pseudo-time t";
  o.odd_load_extension = proportional && !spec.loads.empty();  // a reversed load below λ = 0 (static_solver.hpp)
  if (!(o.max_turn > 0.0 && o.max_turn < 90.0))
    throw std::invalid_argument("integrator.max_turn: " + std::to_string(o.max_turn) + " is not an angle in (0, 90) degrees");
  if (!(o.locate_tol > 0.0 && o.locate_tol <= 1.0))
    throw std::invalid_argument("integrator.locate_tol: " + std::to_string(o.locate_tol) + " must lie in (0, 1] (a fraction of the first step)");
  if (!(o.progress_seconds >= 0.0))
    throw std::invalid_argument("integrator.progress_seconds: " + std::to_string(o.progress_seconds) + " must be >= 0");
  return o;
}

std::vector<StaticRow> run_static(Problem& problem, const std::string& out_dir, std::ostream* log,
                                  StaticReport* report_out, const State* start) {
  const CaseSpec& spec = problem.spec;
  check_prescribed_motion_support(spec, "static", false);  // load stepping follows no time history
  StaticOptions options = static_options(spec, &problem.disc);
  if (log) options.progress = [log](const std::string& line) { *log << line << std::endl; };
  Model& model = *problem.model;
  // Follower loads have a non-symmetric tangent: in full with the LU solver (quadratic Newton), else its
  // symmetric part (docs/theory.md §8.2).
  model.set_unsymmetric_load_stiffness(options.linear_solver == "klu");
  const auto& monitors = problem.disc.monitors;

  std::unique_ptr<CsvFile> csv;
  std::unique_ptr<PvdWriter> pvd;
  std::unique_ptr<DiskReserve> reserve;  // room for the final run.json on a disk the outputs fill (lib/io/run_info.hpp)
  RunInfo info;
  info.sundials_version = sundials_version();
  info.status = "incomplete: running";
  info.discretization.set("nodes", model.mesh().num_nodes());
  info.discretization.set("elements", model.mesh().num_elements());
  info.discretization.set("dofs", static_cast<long long>(model.num_dofs()));
  info.discretization.set("constrained_dofs", static_cast<long long>(model.dofs().num_constrained()));
  if (!out_dir.empty()) {
    prepare_output_folder(out_dir);
    write_run_json(out_dir + "/run.json", spec, info);
    reserve = std::make_unique<DiskReserve>(out_dir + "/run.json.reserve",
                                            65536 + 4 * static_cast<long long>(run_json(spec, info).size()));
    pvd = std::make_unique<PvdWriter>(out_dir + "/fields.pvd");
  }

  std::vector<StaticRow> rows;
  auto record = [&](const State& s, int step, int iters, double arc, long pivots, const std::string& event) {
    StaticRow row;
    row.step = step;
    row.load_factor = s.t;
    row.newton_iterations = iters;
    const bool write_vtu_now = pvd && spec.output.vtu && step % std::max(1, spec.output.vtu_every) == 0;
    Eigen::VectorXd R;  // reactions (docs/theory.md §9.2), for monitors rx..rz and the VTU
    if (write_vtu_now || monitors_need_reactions(monitors)) R = reactions(model, s, false);
    for (const auto& m : monitors)
      row.monitors.push_back(monitor_value(m, model.mesh(), s.u, s.v, s.charts, R.size() ? &R : nullptr));
    if (csv) {
      char buf[64];
      std::string line = std::to_string(step);
      std::snprintf(buf, sizeof buf, ",%.17g", s.t);
      line += buf;
      for (double x : row.monitors) {
        std::snprintf(buf, sizeof buf, ",%.17g", x);
        line += buf;
      }
      std::snprintf(buf, sizeof buf, ",%d,%.17g,%ld,", iters, arc, pivots);
      line += buf + (event.empty() ? std::string("-") : event) + '\n';
      csv->write(line);
    }
    if (write_vtu_now) {
      const std::string file = "fields/" + vtu_step_file_name(step);  // like run (docs/manual.md §4)
      write_vtu(out_dir + "/" + file, model.mesh(), state_fields(model, s, &R));
      try {
        pvd->add(s.t, file);
      } catch (const std::exception&) {  // (full disk) a VTU that fields.pvd cannot list is not kept
        std::remove((out_dir + "/" + file).c_str());
        throw;
      }
    }
    row.arc_length = arc;
    row.negative_pivots = pivots;
    row.event = event;
    rows.push_back(std::move(row));
  };

  State state = problem.initial_state();  // the reference state, or the case's initial_displacement
  state.v.setZero();                      // statics: velocities play no part
  if (start) {  // a saved state (shelldyn static --state): its configuration at load factor start->t
    if (start->u.size() != state.u.size() || start->charts.size() != state.charts.size())
      throw std::invalid_argument("the start state has " + std::to_string(start->u.size()) + " DOFs, this case's model " +
                                  std::to_string(state.u.size()) + " (a state of another case?)");
    if (!(start->t < spec.time.t_end))
      throw std::invalid_argument("the start state is at load factor " + std::to_string(start->t) +
                                  ", not below time.t_end = " + std::to_string(spec.time.t_end) +
                                  ": nothing to solve (raise time.t_end)");
    state.t = start->t;
    state.u = start->u;
    state.charts = start->charts;
    model.adopt_charts(state.charts);
  }
  StaticReport report;
  try {  // bad settings and I/O errors too must end in "incomplete: <reason>", not "running"
    if (!out_dir.empty()) {
      csv = std::make_unique<CsvFile>(out_dir + "/static.csv");
      std::string header = "step,load_factor";
      for (const auto& m : monitors) header += ',' + m.name;
      csv->write(header + ",newton_iters,arc_length,negative_pivots,event\n");
    }
    record(state, 0, 0, 0.0, 0, "");
    StaticSolver solver(model, options);
    report = solver.solve(state, spec.time.t_end, [&](const State& s, const StaticIncrement& inc) {
      record(s, inc.step, inc.newton_iterations, inc.arc_length, inc.negative_pivots, inc.event);
      if (log) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "%s %4d  %s %.6f  Newton %2d  cuts %d  chart switches %d  neg. pivots %ld",
                      options.control == PathControl::load ? "increment" : "step", inc.step, options.parameter_name.c_str(),
                      inc.load_factor, inc.newton_iterations, inc.cuts, inc.chart_switches, inc.negative_pivots);
        *log << buf;
        for (size_t k = 0; k < monitors.size(); ++k) *log << "  " << monitors[k].name << " " << rows.back().monitors[k];
        if (!inc.event.empty()) *log << "  ** " << (inc.event_note.empty() ? inc.event : inc.event_note);
        *log << std::endl;
      }
    });
  } catch (const std::exception& e) {
    if (!out_dir.empty()) {
      info.status = std::string("incomplete: ") + e.what();
      if (reserve) reserve->release();  // the room kept for this last word
      try {
        write_run_json(out_dir + "/run.json", spec, info);
      } catch (const std::exception& j) {  // e.g. the disk is full: report the cause, then this
        throw std::runtime_error(std::string(e.what()) + "; " + j.what());
      }
    }
    throw;
  }
  info.status = "complete";
  info.summary.set("increments", report.increments);
  info.summary.set("failed_attempts", report.failed_attempts);
  info.summary.set("newton_iterations", report.newton_iterations);
  info.summary.set("jacobian_evaluations", report.jacobian_evaluations);
  info.summary.set("chart_switches", report.chart_switches);
  info.summary.set("wall_s", report.wall_seconds);
  info.summary.set("final_load_factor", state.t);
  info.summary.set("control", path_control_name(options.control));
  info.summary.set("max_load_factor", report.max_load_factor);
  info.summary.set("critical_points", static_cast<int>(report.critical_points.size()));
  info.summary.set("steps_cut_back", report.located_cuts);  // to locate critical points or follow sharp turns
  for (size_t k = 0; k < report.critical_points.size(); ++k) {
    const auto& cp = report.critical_points[k];
    const std::string key = "critical_point_" + std::to_string(k + 1);
    info.summary.set(key + "_kind", cp.kind);
    info.summary.set(key + "_step", cp.step);
    info.summary.set(key + "_load_factor", cp.load_factor);
    info.summary.set(key + "_estimate", cp.estimate);
    info.summary.set(key + "_note", cp.note);
  }
  if (log) {
    for (const auto& cp : report.critical_points) *log << "critical point at step " << cp.step << ": " << cp.note << std::endl;
    // A path jump means the path was not resolved there: everything past it may lie on another branch.
    for (const auto& cp : report.critical_points)
      if (cp.kind == "path jump") {
        *log << "warning: the path jumped at step " << cp.step << " (" << options.parameter_name << " " << cp.load_factor
             << "); the results past it may lie on another branch (check with a smaller increment or max_turn)" << std::endl;
        break;
      }
  }
  if (reserve) reserve->release();
  if (!out_dir.empty()) write_run_json(out_dir + "/run.json", spec, info);
  if (report_out) *report_out = report;
  return rows;
}

}  // namespace shelldyn
