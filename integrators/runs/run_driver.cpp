#include "integrators/runs/run_driver.hpp"
#include "integrators/runs/registry.hpp"

#include "integrators/sundials/sundials_info.hpp"
#include "lib/history_writer.hpp"
#include "lib/reactions.hpp"
#include "lib/run_info.hpp"
#include "lib/state_output.hpp"

#include <omp.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>

namespace shelldyn {
namespace {

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
  j.set("max_rel_energy_drift_after_loads", s.max_rel_drift);
  j.set("final_rel_energy_drift", s.final_rel_drift);
  j.set("max_abs_dL_after_loads", s.max_dL);
  j.set("max_abs_dJ_after_loads", s.max_dJ);
  j.set("norm_L_ref", s.ref_L);
  j.set("norm_J_ref", s.ref_J);
  j.set("max_strain_over_energy", s.max_strain_ratio);
  for (const auto& [name, value] : s.final_monitors) j.set("final_" + name, value);
  j.set("wall_s", s.wall_seconds);
}

}  // namespace

RunSummary run_dynamic(Problem& problem, const RunOptions& o) {
  const auto start = Clock::now();
  CaseSpec& spec = problem.spec;
  Model& model = *problem.model;
  if (o.threads > 0) omp_set_num_threads(o.threads);

  // --- resolve settings ---------------------------------------------------------------------------
  const double dt = o.dt > 0.0 ? o.dt : spec.time.dt;
  const double t_end = o.t_end >= 0.0 ? o.t_end : spec.time.t_end;
  double out_dt = o.output_interval > 0.0 ? o.output_interval : spec.time.output_interval;
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("time step dt must be > 0 (got " + std::to_string(dt) + ")");
  if (!(t_end >= 0.0) || !std::isfinite(t_end)) throw std::invalid_argument("t_end must be >= 0 (got " + std::to_string(t_end) + ")");
  if (out_dt < dt) out_dt = dt;
  const int vtu_every = o.vtu_every >= 0 ? o.vtu_every : (spec.output.vtu ? spec.output.vtu_every : 0);
  // Another integrator than the case's keeps the case settings it understands (as `shelldyn compare` does).
  IntegratorSettings settings = o.integrator.empty() || o.integrator == spec.integrator.name
                                    ? IntegratorSettings(spec.integrator)
                                    : IntegratorSettings(o.integrator, o.integrator == "static"
                                                                           ? std::vector<std::pair<std::string, std::string>>{}
                                                                           : settings_understood_by(o.integrator, spec.integrator.settings));
  for (const auto& [k, v] : o.settings) settings.set(k, v);
  if (settings.name() == "static")
    throw std::invalid_argument("integrator 'static' is the static solver: use `shelldyn static CASE`");
  std::unique_ptr<Integrator> integrator = make_integrator(settings, dt);

  RunSummary sum;
  sum.integrator = integrator->name();
  sum.settings = integrator->settings();
  sum.t_end = t_end;
  spec.integrator.name = sum.integrator;  // run.json shows what was actually run
  spec.integrator.settings = sum.settings;
  spec.time.dt = dt;
  spec.time.t_end = t_end;
  spec.time.output_interval = out_dt;

  // --- outputs --------------------------------------------------------------------------------------
  const auto& monitors = problem.disc.monitors;
  RunInfo info;
  info.command = o.command;
  info.sundials_version = sundials_version();
  info.status = "incomplete: running";
  info.discretization.set("nodes", model.mesh().num_nodes());
  info.discretization.set("elements", model.mesh().num_elements());
  info.discretization.set("dofs", static_cast<long long>(model.num_dofs()));
  info.discretization.set("constrained_dofs", static_cast<long long>(model.dofs().num_constrained()));
  info.discretization.set("total_mass", problem.disc.total_mass);
  info.discretization.set("loads_end", problem.disc.loads_end);
  std::unique_ptr<HistoryWriter> history;
  std::unique_ptr<PvdWriter> pvd;
  const bool files = !o.out_dir.empty();
  if (files) {
    prepare_output_folder(o.out_dir);
    write_run_json(o.out_dir + "/run.json", spec, info);
    std::vector<std::string> names;
    for (const auto& m : monitors) names.push_back(m.name);
    // damping_work: energy dissipated by Rayleigh damping (docs/theory.md §8.5), only for damped models.
    const std::vector<std::string> extra = model.has_damping() ? std::vector<std::string>{"damping_work"} : std::vector<std::string>{};
    if (spec.output.history) history = std::make_unique<HistoryWriter>(o.out_dir + "/history.csv", extra, names);
    if (vtu_every > 0) pvd = std::make_unique<PvdWriter>(o.out_dir + "/fields.pvd");
  }

  // --- state and reference quantities ----------------------------------------------------------------
  State state = problem.initial_state();
  integrator->initialize(model, state);
  const double loads_end = model.loads_end();
  bool have_ref = false;
  Eigen::Vector3d L_ref = Eigen::Vector3d::Zero(), J_ref = Eigen::Vector3d::Zero();
  double last_print = -1.0;
  long long out_index = 0;
  // Progress (docs/manual.md §1): one line updated in place on a terminal (every 0.2 s of wall time);
  // otherwise a plain line at every 10 % of the simulated time.
  const bool tty = o.log && ((o.log == &std::cout && isatty(STDOUT_FILENO)) || (o.log == &std::cerr && isatty(STDERR_FILENO)));
  bool line_open = false;
  double next_plain_t = 0.0;
  double E_seen = 0.0;  // largest K + V or |W_ext| so far: the scale of the energy balance while loads act

  auto observe = [&](const StepReport& rep, bool last) {
    const Invariants inv = model.invariants(state);
    const double H = inv.kinetic + inv.strain - integrator->external_work() + integrator->damping_work();
    E_seen = std::max({E_seen, inv.kinetic + inv.strain, std::abs(integrator->external_work())});
    if (out_index == 0) sum.H0 = H;
    if (!have_ref && state.t >= loads_end - 1e-12 * dt) {
      have_ref = true;
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
    const double wall = std::chrono::duration<double>(Clock::now() - start).count();
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
      if (model.has_damping()) row.extra = {integrator->damping_work()};
      history->write(row);
    }
    if (vtu_now) {
      const std::string file = "fields/" + vtu_step_file_name(out_index);
      write_vtu(o.out_dir + "/" + file, model.mesh(), state_fields(model, state, &R));
      pvd->add(state.t, file);
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
    if (last)
      for (size_t k = 0; k < monitors.size(); ++k) sum.final_monitors.emplace_back(monitors[k].name, mon[k]);
    ++out_index;
  };

  try {
    observe(StepReport{}, t_end <= 0.0);
    const long long n_out = static_cast<long long>(std::ceil(t_end / out_dt - 1e-9));
    for (long long k = 1; k <= n_out; ++k) {
      const double t_out = std::min(t_end, static_cast<double>(k) * out_dt);
      const StepReport rep = integrator->advance(model, state, t_out);
      sum.totals.accumulate(rep);
      observe(rep, k == n_out);
    }
  } catch (const std::exception& e) {
    if (line_open) *o.log << std::endl;  // end the in-place status line before the error message
    sum.status = std::string("incomplete: ") + e.what();
    sum.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (files) {
      info.status = sum.status;
      fill_summary_json(info.summary, sum);
      write_run_json(o.out_dir + "/run.json", spec, info);
    }
    throw;
  }
  sum.status = "complete";
  sum.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (files) {
    info.status = sum.status;
    fill_summary_json(info.summary, sum);
    write_run_json(o.out_dir + "/run.json", spec, info);
  }
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
  line("energy H = K + V - W_ext: H0, H_ref", num(s.H0) + ", " + num(s.H_ref) + " (at t = " + num(s.t_ref) + ")");
  line("max |H - H_ref|/(K+V)_ref after loads", num(s.max_rel_drift));
  line("max |L - L_ref| after loads", num(s.max_dL) + " (|L_ref| = " + num(s.ref_L) + ")");
  line("max |J - J_ref| after loads", num(s.max_dJ) + " (|J_ref| = " + num(s.ref_J) + ")");
  for (const auto& [name, value] : s.final_monitors) line("final " + name, num(value));
  line("wall time [s]", num(s.wall_seconds));
}

}  // namespace shelldyn
