#include "integrators/runs/static_run.hpp"

#include "integrators/integrator_settings.hpp"
#include "integrators/sundials/sundials_info.hpp"
#include "lib/reactions.hpp"
#include "lib/run_info.hpp"
#include "lib/state_output.hpp"

#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace shelldyn {

StaticOptions static_options(const CaseSpec& spec) {
  IntegratorSettings s(spec.integrator);
  if (s.name() != "static")
    throw std::invalid_argument("integrator.name: '" + s.name() + "' is not the static solver (use name: static)");
  StaticOptions o;
  o.increment = s.get("increment", spec.time.dt);
  o.min_increment = s.get("min_increment", o.increment * 1e-4);
  o.growth = s.get("growth", 1.5);
  o.easy_iterations = s.get("easy_iterations", 6);
  o.rechart_hysteresis = s.get("hysteresis", 1.0);
  o.newton.max_iters = s.get("max_iters", 30);
  o.newton.fnorm_tol = s.get("tol", 1e-9);
  o.newton.linear_solver = s.get("linear_solver", "eigen-ldlt");
  o.newton.line_search = s.get("line_search", false);
  s.finish();
  return o;
}

std::vector<StaticRow> run_static(Problem& problem, const std::string& out_dir, std::ostream* log,
                                  StaticReport* report_out) {
  const CaseSpec& spec = problem.spec;
  const StaticOptions options = static_options(spec);
  Model& model = *problem.model;
  // Follower loads have a non-symmetric tangent: in full with the LU solver (quadratic Newton), else its
  // symmetric part (docs/theory.md §8.2).
  model.set_unsymmetric_load_stiffness(options.newton.linear_solver == "klu");
  const auto& monitors = problem.disc.monitors;

  std::unique_ptr<std::ofstream> csv;
  std::unique_ptr<PvdWriter> pvd;
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
    csv = std::make_unique<std::ofstream>(out_dir + "/static.csv");
    *csv << "step,load_factor";
    for (const auto& m : monitors) *csv << ',' << m.name;
    *csv << ",newton_iters\n";
    pvd = std::make_unique<PvdWriter>(out_dir + "/fields.pvd");
  }

  std::vector<StaticRow> rows;
  auto record = [&](const State& s, int step, int iters) {
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
      *csv << step;
      std::snprintf(buf, sizeof buf, ",%.17g", s.t);
      *csv << buf;
      for (double x : row.monitors) {
        std::snprintf(buf, sizeof buf, ",%.17g", x);
        *csv << buf;
      }
      *csv << ',' << iters << '\n' << std::flush;
    }
    if (write_vtu_now) {
      const std::string file = "fields/" + vtu_step_file_name(step);  // like run (docs/manual.md §4)
      write_vtu(out_dir + "/" + file, model.mesh(), state_fields(model, s, &R));
      pvd->add(s.t, file);
    }
    rows.push_back(std::move(row));
  };

  State state = model.initial_state();
  record(state, 0, 0);
  StaticSolver solver(model, options);
  StaticReport report;
  try {
    report = solver.solve(state, spec.time.t_end, [&](const State& s, const StaticIncrement& inc) {
      record(s, inc.step, inc.newton_iterations);
      if (log) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "increment %4d  load factor %.6f  Newton %2d  cuts %d  chart switches %d",
                      inc.step, inc.load_factor, inc.newton_iterations, inc.cuts, inc.chart_switches);
        *log << buf;
        for (size_t k = 0; k < monitors.size(); ++k) *log << "  " << monitors[k].name << " " << rows.back().monitors[k];
        *log << std::endl;
      }
    });
  } catch (const std::exception& e) {
    if (!out_dir.empty()) {
      info.status = std::string("incomplete: ") + e.what();
      write_run_json(out_dir + "/run.json", spec, info);
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
  if (!out_dir.empty()) write_run_json(out_dir + "/run.json", spec, info);
  if (report_out) *report_out = report;
  return rows;
}

}  // namespace shelldyn
