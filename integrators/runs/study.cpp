#include "integrators/runs/study.hpp"
#include "integrators/runs/number_text.hpp"
#include "integrators/runs/case_integrator.hpp"
#include "integrators/runs/registry.hpp"

#include "lib/model/problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace shelldyn {
namespace {

using number_text::full;
using number_text::num;
using number_text::sci;

const double NaN = std::numeric_limits<double>::quiet_NaN();

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) return "";
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Energy-balance error of a history: max_t |H(t) − H(t₀)| / max_t (K + V)(t), H = K + V − W_ext. The exact
// flow keeps H constant with the loads on as well (W_ext is the work done on the body), so this measures
// every integrator on windows that end before the loads do.
double energy_balance_error(const CsvTable& h) {
  const auto *K = h.column("kinetic"), *V = h.column("strain"), *H = h.column("total");
  if (!K || !V || !H || H->empty()) return NaN;
  double scale = 0.0, worst = 0.0;
  for (size_t i = 0; i < H->size(); ++i) {
    scale = std::max(scale, (*K)[i] + (*V)[i]);
    worst = std::max(worst, std::abs((*H)[i] - (*H)[0]));
  }
  return scale > 0.0 ? worst / scale : NaN;
}

struct PlannedRun {
  std::string spec, kind, integrator;
  double dt = 0.0, rtol = 0.0;
};

std::vector<PlannedRun> plan(const StudyPreset& p, const std::string& group) {
  std::vector<PlannedRun> runs;
  auto in = [](const std::vector<double>& v, double x) { return std::find(v.begin(), v.end(), x) != v.end(); };
  if (group == "window") {
    if (!p.reference_spec.empty()) {
      const CompareRun ref = parse_compare_spec(p.reference_spec);
      runs.push_back({p.reference_spec, "reference", ref.integrator, ref.dt, 0.0});
    }
    // Expensive runs first, so that the two workers finish together: tight tolerances and small steps. Each
    // value of the union of the methods' sweeps, ascending, then the methods in file order that sweep over it
    // (with one shared sweep: every method at the first value, then at the next, ...).
    std::vector<double> rtols, dts;
    for (const auto& m : p.methods)
      if (m.window) (m.adaptive ? rtols : dts).insert((m.adaptive ? rtols : dts).end(), m.sweep.begin(), m.sweep.end());
    for (auto* v : {&rtols, &dts}) {
      std::sort(v->begin(), v->end());
      v->erase(std::unique(v->begin(), v->end()), v->end());
    }
    for (double r : rtols)
      for (const auto& m : p.methods)
        if (m.window && m.adaptive && in(m.sweep, r)) runs.push_back({m.spec + ":rtol=" + num(r), "adaptive", m.integrator, 0.0, r});
    for (double dt : dts)
      for (const auto& m : p.methods)
        if (m.window && !m.adaptive && in(m.sweep, dt)) runs.push_back({m.spec + ":dt=" + num(dt), "fixed", m.integrator, dt, 0.0});
  } else if (group == "full") {
    for (const auto& s : p.full_baselines) {
      const CompareRun b = parse_compare_spec(s);
      double rtol = 0.0;
      for (const auto& [k, v] : b.overrides)
        if (k == "rtol") rtol = std::stod(v);
      runs.push_back({s, "baseline", b.integrator, 0.0, rtol});
    }
    for (const auto& m : p.methods)
      if (m.full && !m.adaptive)
        runs.push_back({p.full_dt > 0.0 ? m.spec + ":dt=" + num(p.full_dt) : m.spec, "fixed", m.integrator, p.full_dt, 0.0});
  } else {
    throw std::invalid_argument("study: unknown group '" + group + "' (use window, full)");
  }
  return runs;
}

}  // namespace

std::pair<std::string, double> stopped_budget(const std::string& status) {
  for (const std::string kind : {"max-wall", "max-steps"}) {
    const std::string key = "stopped: --" + kind + " ";
    if (status.rfind(key, 0) != 0) continue;
    const char* begin = status.c_str() + key.size();
    char* end = nullptr;
    const double x = std::strtod(begin, &end);
    if (end != begin && x > 0.0) return {kind, x};
  }
  return {"", 0.0};
}

std::string run_json_status(const std::string& text) {
  const std::string key = "\"status\": \"";
  const auto p = text.find(key);
  if (p == std::string::npos) return "";
  const auto e = text.find('"', p + key.size());
  return e == std::string::npos ? "" : text.substr(p + key.size(), e - p - key.size());
}

double run_json_number(const std::string& text, const std::string& key) {
  const auto s = text.find("\"summary\"");
  if (s == std::string::npos) return NaN;
  const std::string k = "\"" + key + "\":";
  const auto p = text.find(k, s);
  if (p == std::string::npos) return NaN;
  const char* begin = text.c_str() + p + k.size();
  char* end = nullptr;
  const double x = std::strtod(begin, &end);
  return end == begin ? NaN : x;
}

namespace {

// What a study decided before running anything (plan_study), and what its report needs (report_study).
struct StudyPlan {
  Problem first;  // the case, validated once up front
  double loads_end = 0.0;
  std::vector<std::string> monitors;
  StudyResult result;
  std::map<std::string, std::vector<std::pair<PlannedRun, std::string>>> labelled;  // group -> (run, label)
  std::vector<CompareOptions> batch;  // the groups' pending runs
  std::vector<std::string> groups;    // the requested groups the study has (window without a window: section is none)
  explicit StudyPlan(Problem p) : first(std::move(p)) {}
};

std::unique_ptr<StudyPlan> plan_study(const StudyOptions& o) {
  if (o.out_dir.empty()) throw std::invalid_argument("study: an output folder is required");
  const StudyPreset& p = o.preset;
  {
    // The case as `shelldyn run` would take it (case_integrator.hpp): its own integrator block too, although the
    // study's runs replace the integrator, so that a case `run` refuses (a setting the integrator does not know,
    // the static solver) is not silently accepted here.
    const CaseSpec spec = load_case(o.case_path);
    try {
      make_case_integrator(spec, "", {}, spec.time.dt);
    } catch (const std::invalid_argument& e) {
      const std::string msg = e.what();  // "FILE:LINE: integrator.KEY: ..." where the case's block is the cause
      if (msg.rfind(o.case_path, 0) == 0) throw;
      throw std::invalid_argument(o.case_path + ": " + msg);
    }
  }
  auto sp = std::make_unique<StudyPlan>(load_problem(o.case_path));  // validates the case once, up front
  for (const auto& group : o.groups)
    if ((group == "window" && p.has_window) || (group == "full" && p.has_full)) sp->groups.push_back(group);
    else if (group != "window" && group != "full") throw std::invalid_argument("study: unknown group '" + group + "' (use window, full)");
  // --case: a case of another benchmark is named in a note (the study's steps and windows were chosen for the
  // benchmark's case); the case's own integrator block was checked above as `shelldyn run` checks it.
  const CaseSpec& cs = sp->first.spec;
  if (fs::path(o.case_path).stem() != fs::path(p.case_file).stem() && cs.name != fs::path(p.case_file).stem().string() && o.log)
    *o.log << "note: " << o.case_path << " is not the " << p.name << " benchmark's case (" << p.case_file
           << "); the study's windows and step sizes were chosen for that one" << std::endl;
  sp->loads_end = sp->first.model->loads_end();
  for (const auto& m : sp->first.disc.monitors) sp->monitors.push_back(m.name);
  StudyResult& result = sp->result;
  auto& labelled = sp->labelled;
  auto say = [&](const std::string& line) {
    if (o.log) *o.log << line << std::endl;
  };

  for (const auto& group : sp->groups) {
    const std::vector<PlannedRun> runs = plan(p, group);
    CompareOptions co = o.execution;
    co.case_path = o.case_path;
    co.dts.clear();
    co.rtols.clear();
    co.reference.clear();
    co.vtu_every = 0;
    co.t_end = group == "window" ? p.window_t_end : p.full_t_end;
    co.output_interval = group == "window" ? p.window_output : p.full_output;
    co.out_dir = (fs::path(o.out_dir) / group).string();
    co.max_wall = o.max_wall_per_run;
    co.max_steps = o.max_steps_per_run;
    co.log = o.report ? o.log : nullptr;
    co.command = o.command;
    for (const auto& r : runs) co.specs.push_back(r.spec);
    std::vector<CompareRun> expanded;
    try {
      expanded = expand_compare_runs(co);  // labels; bad specs fail here
    } catch (const std::invalid_argument& e) {
      // compare speaks of its --integrators option; here the runs come from the study file.
      std::string msg = e.what();
      const std::string twice = "--integrators: run '";
      if (msg.rfind(twice, 0) == 0)
        msg = group + ": run '" + msg.substr(twice.size()) + " (the reference, a sweep value or a full.runs entry repeats another run; list each once)";
      throw std::invalid_argument((p.source.empty() ? std::string("study ") + p.name : p.source) + ": " + msg);
    }
    std::vector<std::string> pending;
    for (size_t k = 0; k < runs.size(); ++k) {
      labelled[group].emplace_back(runs[k], expanded[k].label);
      const std::string status = run_json_status(read_text((fs::path(co.out_dir) / expanded[k].label / "run.json").string()));
      // Stopped at a budget at least as large as today's: it would stop again, keep it.
      const auto [kind, budget] = stopped_budget(status);
      const bool budget_kept = (kind == "max-wall" && o.max_wall_per_run > 0.0 && o.max_wall_per_run <= budget) ||
                               (kind == "max-steps" && o.max_steps_per_run > 0 && o.max_steps_per_run <= budget);
      if ((status == "complete" || budget_kept) && !o.rerun) {
        ++result.skipped;
        if (o.dry_run)
          say("  " + group + "/" + expanded[k].label +
              (budget_kept ? ": stopped at budget --" + kind + " " + num(budget) + " (kept; a larger budget reruns it)"
                           : ": complete (kept)"));
      } else {
        pending.push_back(runs[k].spec);
        if (o.dry_run) say("  " + group + "/" + expanded[k].label + ": to run");
      }
    }
    say("study " + p.name + " / " + group + ": " + std::to_string(runs.size()) + " runs, " +
        std::to_string(runs.size() - pending.size()) + " already complete, " + std::to_string(pending.size()) +
        (o.report_only ? " not run (report only)" : " to run") + " -> " + co.out_dir);
    if (o.dry_run || o.report_only || pending.empty()) continue;
    co.specs = pending;
    co.log_prefix = p.name + "/" + group + "/";
    sp->batch.push_back(co);
  }
  return sp;
}

// The rows from the run folders (resumed runs included), study.csv and study.md.
StudyResult report_study(const StudyOptions& o, StudyPlan& plan) {
  const StudyPreset& p = o.preset;
  const Problem& first = plan.first;
  const double loads_end = plan.loads_end;
  const std::vector<std::string>& monitors = plan.monitors;
  StudyResult& result = plan.result;
  auto& labelled = plan.labelled;
  if (!o.report) return result;  // an MPI worker rank: rank 0 reports

  // --- rows from the run folders (resumed runs included) -------------------------------------------------
  std::map<std::string, CsvTable> ref_table;  // group -> reference history
  std::string ref_label;
  for (const auto& [group, runs] : labelled)
    for (const auto& [run, label] : runs)
      if (run.kind == "reference") {
        ref_label = label;
        // Only a complete reference measures errors (one stopped at the budget covers part of the window).
        if (run_json_status(read_text((fs::path(o.out_dir) / group / label / "run.json").string())) != "complete") continue;
        try {
          ref_table[group] = read_csv_table((fs::path(o.out_dir) / group / label / "history.csv").string());
        } catch (const std::exception&) {
        }
      }
  for (const auto& group : plan.groups) {
    for (const auto& [run, label] : labelled[group]) {
      StudyRow row;
      row.group = group;
      row.label = label;
      row.integrator = run.integrator;
      row.kind = run.kind;
      row.dt = run.dt;
      row.rtol = run.rtol;
      row.energy_error = row.energy_error_after_loads = row.displacement_error = row.max_dL = row.max_dJ = NaN;
      const fs::path dir = fs::path(o.out_dir) / group / label;
      const std::string json = read_text((dir / "run.json").string());
      row.status = json.empty() ? "not run" : run_json_status(json);
      // run.json still says "running": the study was stopped (killed) during this run; it has no result.
      if (row.status.rfind("incomplete: running", 0) == 0) row.status = "not run (the study was stopped during this run)";
      if (row.status.rfind("incomplete", 0) == 0) row.status = "failed: " + row.status.substr(std::min<size_t>(12, row.status.size()));
      // Cost of a run that ran (complete or stopped at its budget), from its run.json.
      auto read_cost = [&] {
        row.steps = static_cast<long>(run_json_number(json, "steps"));
        row.rhs_evaluations = static_cast<long>(run_json_number(json, "rhs_evaluations"));
        row.factorizations = static_cast<long>(run_json_number(json, "factorizations"));
        row.nonlinear_iterations = static_cast<long>(run_json_number(json, "nonlinear_iterations"));
        row.cpu_s = run_json_number(json, "cpu_s");
        row.wall_s = run_json_number(json, "wall_s");
        row.t_end = run_json_number(json, "t_end");
      };
      if (!stopped_budget(row.status).first.empty()) {
        // Stopped at the per-run budget: what it cost and how far it got; no error measures (they would
        // cover part of the window only).
        row.stop_note = row.status.substr(0, row.status.find(" at t = "));
        row.status = "stopped at budget";
        ++result.stopped;
        read_cost();
        try {
          const CsvTable h = read_csv_table((dir / "history.csv").string());
          const auto* t = h.column("t");
          row.t_reached = t && !t->empty() ? t->back() : 0.0;
        } catch (const std::exception&) {
          row.t_reached = NaN;
        }
      } else if (row.status == "complete") {
        read_cost();
        row.t_reached = row.t_end;
        row.max_dL = run_json_number(json, "max_abs_dL_after_loads");
        row.max_dJ = run_json_number(json, "max_abs_dJ_after_loads");
        row.ref_L = run_json_number(json, "norm_L_ref");
        row.ref_J = run_json_number(json, "norm_J_ref");
        try {
          const CsvTable h = read_csv_table((dir / "history.csv").string());
          row.energy_error = energy_balance_error(h);
          row.energy_error_after_loads = mechanical_energy_drift(h, loads_end);
          if (std::isnan(row.energy_error_after_loads)) row.max_dL = row.max_dJ = NaN;  // no reference: loads still on
          if (ref_table.count(group) && run.kind != "reference")
            row.displacement_error = monitor_distance(h, ref_table[group], monitors);
        } catch (const std::exception& e) {
          row.status = std::string("failed: history unreadable: ") + e.what();
        }
      } else if (row.status.rfind("not run", 0) != 0) {
        ++result.failed;
      }
      result.rows.push_back(row);
    }
  }
  if (o.dry_run) return result;

  // --- study.csv -------------------------------------------------------------------------------------------
  result.study_csv = (fs::path(o.out_dir) / "study.csv").string();
  {
    std::ofstream csv(result.study_csv);
    if (!csv) throw std::runtime_error(result.study_csv + ": cannot write");
    csv << "group,label,integrator,kind,dt,rtol,t_end,t_reached,steps,rhs_evaluations,factorizations,nonlinear_iterations,cpu_s,wall_s,"
           "energy_error,energy_error_after_loads,displacement_error,max_dL,max_dJ,norm_L_ref,norm_J_ref,status\n";
    for (const auto& r : result.rows) {
      std::string status = r.stop_note.empty() ? r.status : r.status + " (" + r.stop_note + ")";
      for (char& c : status)
        if (c == ',' || c == '\n' || c == '"') c = ';';
      csv << r.group << "," << r.label << "," << r.integrator << "," << r.kind << "," << full(r.dt) << "," << full(r.rtol) << ","
          << full(r.t_end) << "," << full(r.t_reached) << "," << r.steps << "," << r.rhs_evaluations << "," << r.factorizations << ","
          << r.nonlinear_iterations << "," << full(r.cpu_s) << "," << full(r.wall_s) << "," << full(r.energy_error) << ","
          << full(r.energy_error_after_loads) << "," << full(r.displacement_error) << "," << full(r.max_dL) << "," << full(r.max_dJ) << "," << full(r.ref_L) << ","
          << full(r.ref_J) << "," << status << "\n";
    }
    if (!csv) throw std::runtime_error(result.study_csv + ": write error");
  }

  // --- study.md --------------------------------------------------------------------------------------------
  // Reference accuracy: distance between the reference and the finest sweep run of the same integrator and
  // settings, divided by (dt_sweep/dt_ref)^2 − 1 (second-order convergence; Richardson).
  double ref_error = NaN;
  {
    const StudyRow* ref = nullptr;
    for (const auto& r : result.rows)
      if (r.kind == "reference" && r.status == "complete") ref = &r;
    if (ref) {
      const std::string prefix = ref->label.substr(0, ref->label.rfind("_dt="));
      const StudyRow* finest = nullptr;
      for (const auto& r : result.rows)
        if (r.group == "window" && r.kind == "fixed" && r.status == "complete" && r.label.rfind(prefix + "_dt=", 0) == 0 &&
            (!finest || r.dt < finest->dt))
          finest = &r;
      if (finest && finest->dt > ref->dt) ref_error = finest->displacement_error / (std::pow(finest->dt / ref->dt, 2) - 1.0);
    }
  }
  result.study_md = (fs::path(o.out_dir) / "study.md").string();
  {
    std::ofstream md(result.study_md);
    if (!md) throw std::runtime_error(result.study_md + ": cannot write");
    md << "# Integrator study: " << p.name << "\n\n";
    md << "- case: `" << o.case_path << "` (" << first.spec.description << ")\n";
    md << "- command: `" << o.command << "`\n";
    if (!p.source.empty()) md << "- study file: `" << p.source << "`\n";
    if (!p.note.empty()) md << "- " << p.note << "\n";
    md << "- loads end at " << num(loads_end) << " s. Energy error (energy balance): max_t |H(t) − H(0)| / max_t (K + V)(t) "
          "with H = K + V − W_ext, which the exact flow keeps constant with or without loads; after the loads: max |H − "
          "H_ref|/(K + V)_ref from the loads' end on (n/a when the run ends before). Displacement error: max over the output times of ‖(";
    for (size_t k = 0; k < monitors.size(); ++k) md << (k ? ", " : "") << monitors[k];
    md << ") − reference‖₂, reference `" << ref_label << "` (its own error, estimated by Richardson from the finest "
       << "sweep run of the same scheme: " << sci(ref_error) << ").\n";
    md << "- cost: CPU seconds of each run (one core each, two runs at a time) and residual / right-hand-side "
          "evaluations.\n";
    if (o.max_wall_per_run > 0.0 || o.max_steps_per_run > 0)
      md << "- per-run budget: " << (o.max_wall_per_run > 0.0 ? num(o.max_wall_per_run) + " s of wall time" : std::string())
         << (o.max_wall_per_run > 0.0 && o.max_steps_per_run > 0 ? ", " : "")
         << (o.max_steps_per_run > 0 ? std::to_string(o.max_steps_per_run) + " steps" : std::string())
         << ". A run that hits it is listed as \"stopped at budget\" with the time it reached and what it cost; "
            "it is not complete and is no point of the work–precision diagram.\n";
    md << "\n";
    for (const auto& group : plan.groups) {
      md << "## " << (group == "window" ? "Work–precision window, t ≤ " + num(p.window_t_end) + " s" : std::string("Full duration"))
         << "\n\n";
      md << "| run | Δt or rtol | steps | RHS evals | factorizations | CPU [s] | energy error | after loads | displ. error | "
            "max ‖ΔL‖ | max ‖ΔJ‖ | status |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
      for (const auto& r : result.rows) {
        if (r.group != group) continue;
        md << "| `" << r.label << "` | " << (r.rtol > 0 ? "rtol " + num(r.rtol) : r.dt > 0 ? "Δt " + num(r.dt) : "case Δt")
           << " | ";
        if (r.status == "complete")
          md << r.steps << " | " << r.rhs_evaluations << " | " << r.factorizations << " | " << num(r.cpu_s) << " | "
             << sci(r.energy_error) << " | " << sci(r.energy_error_after_loads) << " | " << sci(r.displacement_error) << " | " << sci(r.max_dL) << " | " << sci(r.max_dJ)
             << " | complete |\n";
        else if (r.status == "stopped at budget")
          md << r.steps << " | " << r.rhs_evaluations << " | " << r.factorizations << " | " << num(r.cpu_s)
             << " | – | – | – | – | – | **stopped at budget** (" << r.stop_note << "), t reached = " << num(r.t_reached)
             << " of " << num(r.t_end) << " s |\n";
        else
          md << "– | – | – | – | – | – | – | – | – | " << r.status << " |\n";
      }
      md << "\n";
    }
    // Headline: the cheapest window run of the headline methods (the study file's `headline:`, default the
    // energy-momentum schemes em-galpha and em-exact) against the cheapest baseline run as accurate in energy.
    const StudyRow* em = nullptr;
    for (const auto& r : result.rows)
      if (r.group == "window" && r.kind == "fixed" && r.status == "complete" &&
          std::find(p.headline.begin(), p.headline.end(), r.integrator) != p.headline.end() && (!em || r.cpu_s < em->cpu_s))
        em = &r;
    if (em) {
      const StudyRow* match = nullptr;
      const StudyRow* best = nullptr;
      for (const auto& r : result.rows) {
        if (r.group != "window" || r.kind != "adaptive" || r.status != "complete") continue;
        if (r.energy_error <= em->energy_error && (!match || r.cpu_s < match->cpu_s)) match = &r;
        if (!best || r.energy_error < best->energy_error) best = &r;
      }
      md << "## Headline\n\n";
      if (match)
        md << "`" << em->label << "` reaches energy error " << sci(em->energy_error) << " at " << num(em->cpu_s)
           << " CPU s; the cheapest baseline run as accurate, `" << match->label << "`, needs " << num(match->cpu_s)
           << " CPU s: " << num(match->cpu_s / em->cpu_s) << " times the cost.\n";
      else if (best)
        md << "`" << em->label << "` reaches energy error " << sci(em->energy_error) << " at " << num(em->cpu_s)
           << " CPU s; no baseline run reaches that error: the most accurate, `" << best->label << "`, reaches "
           << sci(best->energy_error) << " at " << num(best->cpu_s) << " CPU s (" << num(best->cpu_s / em->cpu_s)
           << " times the cost, " << num(best->energy_error / std::max(em->energy_error, 1e-300)) << " times the error).\n";
    }
    if (!md) throw std::runtime_error(result.study_md + ": write error");
  }
  return result;
}

}  // namespace

std::vector<StudyResult> run_studies(const std::vector<StudyOptions>& studies) {
  std::vector<std::unique_ptr<StudyPlan>> plans;
  for (const auto& o : studies) plans.push_back(plan_study(o));  // every case and spec checked before any run
  // One batch for all studies and groups (run_comparisons): the longest runs start first wherever they are.
  std::vector<CompareOptions> batch;
  std::vector<size_t> owner;
  for (size_t i = 0; i < plans.size(); ++i)
    for (const auto& co : plans[i]->batch) {
      batch.push_back(co);
      owner.push_back(i);
    }
  const std::vector<CompareResult> ran = run_comparisons(batch);
  for (size_t j = 0; j < ran.size(); ++j) plans[owner[j]]->result.ran += static_cast<int>(ran[j].rows.size());
  std::vector<StudyResult> out;
  for (size_t i = 0; i < plans.size(); ++i) out.push_back(report_study(studies[i], *plans[i]));
  return out;
}

StudyResult run_study(const StudyOptions& o) { return run_studies({o}).front(); }

}  // namespace shelldyn
