#include "integrators/runs/compare.hpp"
#include "integrators/runs/registry.hpp"

#include "integrators/integrator.hpp"
#include "integrators/integrator_settings.hpp"
#include "lib/case_file.hpp"
#include "lib/history_writer.hpp"
#include "lib/problem.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace fs = std::filesystem;

namespace shelldyn {
namespace {

std::string num(double x) {
  if (std::isnan(x)) return "nan";
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", x);
  return b;
}

std::string full(double x) {
  if (std::isnan(x)) return "nan";
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string md_cell(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string label_of(const std::string& name, const std::vector<std::pair<std::string, std::string>>& overrides) {
  std::string s = name;
  for (const auto& [k, v] : overrides) s += "_" + k + "=" + v;
  for (char& c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '=' || c == '+' || c == '-')) c = '-';
  return s;
}

double parse_positive(const std::string& text, const std::string& where) {
  size_t pos = 0;
  double x = 0.0;
  try {
    x = std::stod(text, &pos);
  } catch (const std::exception&) {
    pos = 0;
  }
  if (pos != text.size() || !(x > 0.0) || !std::isfinite(x))
    throw std::invalid_argument(where + ": '" + text + "' is not a positive number");
  return x;
}

std::string settings_text(const std::vector<std::pair<std::string, std::string>>& s, const char* sep) {
  std::string out;
  for (const auto& [k, v] : s) out += (out.empty() ? "" : sep) + k + "=" + v;
  return out;
}

// max_t ‖m(t) − m_ref(t)‖₂ over the shared output times; NaN if none is shared.
double monitor_distance(const CsvTable& a, const CsvTable& b, const std::vector<std::string>& monitors) {
  const auto* ta = a.column("t");
  const auto* tb = b.column("t");
  if (!ta || !tb || monitors.empty()) return std::nan("");
  std::vector<const std::vector<double>*> ca, cb;
  for (const auto& m : monitors) {
    ca.push_back(a.column(m));
    cb.push_back(b.column(m));
    if (!ca.back() || !cb.back()) return std::nan("");
  }
  double worst = -1.0;
  size_t j = 0;
  for (size_t i = 0; i < ta->size(); ++i) {
    const double t = (*ta)[i], tol = 1e-9 * std::max(1.0, std::abs(t));
    while (j < tb->size() && (*tb)[j] < t - tol) ++j;
    if (j == tb->size()) break;
    if (std::abs((*tb)[j] - t) > tol) continue;
    double d2 = 0.0;
    for (size_t k = 0; k < monitors.size(); ++k) d2 += std::pow((*ca[k])[i] - (*cb[k])[j], 2);
    worst = std::max(worst, std::sqrt(d2));
  }
  return worst < 0.0 ? std::nan("") : worst;
}

}  // namespace

const std::vector<double>* CsvTable::column(const std::string& name) const {
  for (size_t k = 0; k < columns.size(); ++k)
    if (columns[k] == name) return &data[k];
  return nullptr;
}

CsvTable read_csv_table(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  CsvTable t;
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ": empty file (no header row)");
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) t.columns.push_back(c);
  t.data.assign(t.columns.size(), {});
  long row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.empty()) continue;
    std::stringstream ls(line);
    size_t k = 0;
    std::vector<double> values;
    for (std::string c; std::getline(ls, c, ','); ++k) {
      char* end = nullptr;
      const double x = std::strtod(c.c_str(), &end);
      values.push_back(end != c.c_str() ? x : std::nan(""));
    }
    if (values.size() != t.columns.size()) break;  // a truncated last row of an interrupted run
    for (size_t c = 0; c < values.size(); ++c) t.data[c].push_back(values[c]);
  }
  return t;
}

double mechanical_energy_drift(const CsvTable& h, double loads_end) {
  const auto *t = h.column("t"), *K = h.column("kinetic"), *V = h.column("strain"), *H = h.column("total");
  if (!t || !K || !V || !H) return std::nan("");
  size_t ref = t->size();
  for (size_t i = 0; i < t->size(); ++i)
    if ((*t)[i] >= loads_end - 1e-12 * std::max(1.0, std::abs(loads_end))) {
      ref = i;
      break;
    }
  if (ref == t->size()) return std::nan("");
  const double scale = (*K)[ref] + (*V)[ref];
  if (!(scale > 0.0)) return std::nan("");
  double worst = 0.0;
  for (size_t i = ref; i < t->size(); ++i) worst = std::max(worst, std::abs((*H)[i] - (*H)[ref]) / scale);
  return worst;
}

CompareRun parse_compare_spec(const std::string& spec) {
  CompareRun r;
  std::vector<std::string> parts;
  std::stringstream ss(spec);
  for (std::string p; std::getline(ss, p, ':');) parts.push_back(p);
  if (parts.empty() || parts[0].empty())
    throw std::invalid_argument("integrator setting '" + spec + "': expected NAME[:KEY=VALUE...], e.g. galpha:rho_inf=0.8");
  r.integrator = parts[0];
  for (size_t k = 1; k < parts.size(); ++k) {
    const auto eq = parts[k].find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == parts[k].size())
      throw std::invalid_argument("integrator setting '" + spec + "': '" + parts[k] +
                                  "' is not KEY=VALUE (syntax NAME[:KEY=VALUE...], e.g. galpha:rho_inf=0.8)");
    const std::string key = parts[k].substr(0, eq), value = parts[k].substr(eq + 1);
    if (key == "dt")
      r.dt = parse_positive(value, "integrator setting '" + spec + "': dt");
    else
      r.overrides.emplace_back(key, value);
  }
  return r;
}

std::vector<CompareRun> expand_compare_runs(const CompareOptions& o) {
  if (o.specs.empty()) throw std::invalid_argument("--integrators: give at least one integrator setting");
  for (double dt : o.dts)
    if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("--dt: every time step must be > 0 (got " + num(dt) + ")");
  for (double r : o.rtols)
    if (!(r > 0.0) || !std::isfinite(r)) throw std::invalid_argument("--rtol: every tolerance must be > 0 (got " + num(r) + ")");
  const auto names = integrator_names();
  const CaseSpec case_spec = load_case(o.case_path);
  std::vector<CompareRun> runs;
  for (const auto& spec : o.specs) {
    CompareRun base = parse_compare_spec(spec);
    if (std::find(names.begin(), names.end(), base.integrator) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      throw std::invalid_argument("integrator setting '" + spec + "': unknown integrator '" + base.integrator +
                                  "' (available: " + list + ")");
    }
    if (base.integrator == "static")
      throw std::invalid_argument("integrator setting '" + spec + "': 'static' is not a time integrator");
    {  // adaptive = has an rtol setting; inherited = the case's settings this integrator understands
      base.adaptive = !settings_understood_by(base.integrator, {{"rtol", ""}}).empty();
      for (const auto& [k, v] : settings_understood_by(base.integrator, case_spec.integrator.settings)) {
        const std::string& key = k;  // (clang: C++17 lambdas cannot capture structured bindings)
        const bool overridden = std::any_of(base.overrides.begin(), base.overrides.end(), [&](const auto& kv) { return kv.first == key; });
        if (!overridden) base.inherited.emplace_back(k, v);
      }
    }
    const bool has_rtol = std::any_of(base.overrides.begin(), base.overrides.end(), [](const auto& kv) { return kv.first == "rtol"; });
    std::vector<CompareRun> expanded;
    if (base.adaptive && !has_rtol && !o.rtols.empty()) {
      for (double r : o.rtols) {
        CompareRun x = base;
        x.overrides.emplace_back("rtol", num(r));
        expanded.push_back(x);
      }
    } else if (!base.adaptive && base.dt == 0.0 && !o.dts.empty()) {
      for (double dt : o.dts) {
        CompareRun x = base;
        x.dt = dt;
        expanded.push_back(x);
      }
    } else {
      expanded.push_back(base);
    }
    for (auto& x : expanded) {
      // Check every setting now: a typo must stop the study before hours are spent on it.
      auto all = x.inherited;
      all.insert(all.end(), x.overrides.begin(), x.overrides.end());
      IntegratorSettings check(x.integrator, all, "integrator setting '" + spec + "'");
      try {
        make_integrator(check, x.dt > 0.0 ? x.dt : 1e-3);
      } catch (const std::exception& e) {
        throw std::invalid_argument("integrator setting '" + spec + "': " + e.what());
      }
      auto label_overrides = x.overrides;
      if (x.dt > 0.0) label_overrides.emplace_back("dt", num(x.dt));
      x.label = label_of(x.integrator, label_overrides);
      runs.push_back(x);
    }
  }
  std::set<std::string> seen;
  for (const auto& r : runs)
    if (!seen.insert(r.label).second) throw std::invalid_argument("--integrators: run '" + r.label + "' is listed twice");
  if (!o.reference.empty() && !seen.count(o.reference))
    throw std::invalid_argument("--reference '" + o.reference + "' is none of the runs (" +
                                [&] {
                                  std::string l;
                                  for (const auto& r : runs) l += (l.empty() ? "" : ", ") + r.label;
                                  return l;
                                }() +
                                ")");
  return runs;
}

CompareResult run_comparison(const CompareOptions& o) {
  if (o.out_dir.empty()) throw std::invalid_argument("compare: an output folder is required");
  const std::vector<CompareRun> runs = expand_compare_runs(o);
  Problem first = load_problem(o.case_path);  // validates the case once, up front
  const double loads_end = first.model->loads_end();
  const double t_end = o.t_end >= 0.0 ? o.t_end : first.spec.time.t_end;
  CompareResult result;
  for (const auto& m : first.disc.monitors) result.monitors.push_back(m.name);
  std::error_code ec;
  fs::create_directories(o.out_dir, ec);
  if (ec) throw std::runtime_error("cannot create the comparison folder '" + o.out_dir + "': " + ec.message());

  result.rows.resize(runs.size());
  std::mutex log_mutex;
  auto say = [&](const std::string& line) {
    if (!o.log) return;
    std::lock_guard<std::mutex> lock(log_mutex);
    *o.log << line << std::endl;
  };
  std::atomic<size_t> next{0};
  const int jobs = std::max(1, std::min<int>(o.jobs, static_cast<int>(runs.size())));
  auto worker = [&]() {
    for (size_t k = next++; k < runs.size(); k = next++) {
      CompareRow& row = result.rows[k];
      row.run = runs[k];
      row.out_dir = (fs::path(o.out_dir) / runs[k].label).string();
      const std::string tag = "[" + std::to_string(k + 1) + "/" + std::to_string(runs.size()) + "] " + runs[k].label;
      say(tag + ": started -> " + row.out_dir);
      try {
        fs::create_directories(row.out_dir);
        std::ofstream log(row.out_dir + "/log.txt");
        Problem problem = load_problem(o.case_path);
        RunOptions ro;
        ro.out_dir = row.out_dir;
        ro.integrator = runs[k].integrator;
        ro.settings = runs[k].inherited;
        ro.settings.insert(ro.settings.end(), runs[k].overrides.begin(), runs[k].overrides.end());
        ro.dt = runs[k].dt;
        ro.t_end = o.t_end;
        ro.output_interval = o.output_interval;
        ro.vtu_every = o.vtu_every;
        ro.threads = jobs > 1 ? 1 : o.threads;
        ro.log = &log;
        ro.command = o.command + "  [run " + runs[k].label + "]";
        ro.label = runs[k].label;
        row.summary = run_dynamic(problem, ro);
        print_run_summary(log, row.summary);
        row.ok = true;
        row.status = "complete";
        if (t_end >= loads_end) row.energy_error = mechanical_energy_drift(read_csv_table(row.out_dir + "/history.csv"), loads_end);
        say(tag + ": complete, " + std::to_string(row.summary.totals.steps) + " steps, " + num(row.summary.wall_seconds) +
            " s, energy error " + num(row.energy_error));
      } catch (const std::exception& e) {
        row.ok = false;
        row.status = "failed: " + one_line(e.what());
        say(tag + ": " + row.status);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int j = 0; j < jobs; ++j) pool.emplace_back(worker);
  for (auto& t : pool) t.join();

  // --- reference run and displacement errors ------------------------------------------------------------
  const CompareRow* ref = nullptr;
  if (!o.reference.empty()) {
    for (const auto& r : result.rows)
      if (r.run.label == o.reference && r.ok) ref = &r;
  } else {
    for (const auto& r : result.rows) {
      if (!r.ok || r.run.adaptive) continue;
      const double dt = r.run.dt > 0.0 ? r.run.dt : first.spec.time.dt;
      const double best = ref ? (ref->run.dt > 0.0 ? ref->run.dt : first.spec.time.dt) : 0.0;
      if (!ref || dt < best * (1.0 - 1e-12)) ref = &r;
    }
    if (!ref)
      for (const auto& r : result.rows)
        if (r.ok && (!ref || r.summary.totals.steps > ref->summary.totals.steps)) ref = &r;
  }
  if (ref) {
    result.reference = ref->run.label;
    try {
      const CsvTable ref_table = read_csv_table(ref->out_dir + "/history.csv");
      for (auto& r : result.rows) {
        if (!r.ok) continue;
        try {
          r.displacement_error = monitor_distance(read_csv_table(r.out_dir + "/history.csv"), ref_table, result.monitors);
        } catch (const std::exception&) {
        }
      }
    } catch (const std::exception& e) {
      say("warning: no displacement errors: " + one_line(e.what()));
    }
  }

  // --- summary.csv ---------------------------------------------------------------------------------------
  result.summary_csv = (fs::path(o.out_dir) / "summary.csv").string();
  {
    std::ofstream csv(result.summary_csv);
    if (!csv) throw std::runtime_error(result.summary_csv + ": cannot write");
    csv << "label,integrator,overrides,settings,dt,t_end,steps,rejected_steps,nonlinear_iterations,linear_setups,"
           "factorizations,rhs_evaluations,chart_switches,wall_s,t_ref,energy_error,max_rel_drift_of_H,"
           "max_dL,max_dJ,norm_L_ref,norm_J_ref";
    for (const auto& m : result.monitors) csv << ",final_" << m;
    csv << ",displacement_error,reference,status\n";
    for (const auto& r : result.rows) {
      const RunSummary& s = r.summary;
      const double dt = r.run.dt > 0.0 ? r.run.dt : first.spec.time.dt;
      csv << csv_field(r.run.label) << "," << r.run.integrator << "," << csv_field(settings_text(r.run.overrides, ";")) << ",";
      if (r.ok) {
        csv << csv_field(settings_text(s.settings, ";")) << "," << full(dt) << "," << full(s.t_end) << "," << s.totals.steps
            << "," << s.totals.rejected_steps << "," << s.totals.nonlinear_iterations << "," << s.totals.linear_setups << ","
            << s.totals.factorizations << "," << s.totals.rhs_evaluations << "," << s.totals.chart_switches << ","
            << full(s.wall_seconds) << "," << full(s.t_ref) << "," << full(r.energy_error) << ","
            << full(t_end >= loads_end ? s.max_rel_drift : std::nan("")) << "," << full(s.max_dL) << "," << full(s.max_dJ)
            << "," << full(s.ref_L) << "," << full(s.ref_J);
        for (const auto& m : result.monitors) {
          double v = std::nan("");
          for (const auto& [name, value] : s.final_monitors)
            if (name == m) v = value;
          csv << "," << full(v);
        }
      } else {
        csv << "," << full(dt) << "," << full(t_end);
        for (int k = 0; k < 15; ++k) csv << ",";
        for (size_t k = 0; k < result.monitors.size(); ++k) csv << ",";
      }
      csv << "," << full(r.displacement_error) << "," << csv_field(result.reference) << "," << csv_field(r.status) << "\n";
    }
    if (!csv) throw std::runtime_error(result.summary_csv + ": write error");
  }

  // --- summary.md ----------------------------------------------------------------------------------------
  result.summary_md = (fs::path(o.out_dir) / "summary.md").string();
  {
    std::ofstream md(result.summary_md);
    if (!md) throw std::runtime_error(result.summary_md + ": cannot write");
    const std::string mon = result.monitors.empty() ? std::string() : result.monitors.front();
    md << "# Integrator comparison: " << first.spec.name << "\n\n";
    md << "- case: `" << o.case_path << "` (" << first.spec.description << ")\n";
    md << "- command: `" << o.command << "`\n";
    md << "- case integrator settings, inherited by every run whose integrator understands them: "
       << (first.spec.integrator.settings.empty() ? std::string("none") : settings_text(first.spec.integrator.settings, ", "))
       << " (full settings per run: summary.csv, <run>/run.json)\n";
    md << "- end time " << num(t_end) << " s; loads end at " << num(loads_end) << " s"
       << (t_end < loads_end ? " (after t_end: no energy-conservation figures)" : "") << "\n";
    md << "- energy error: max |H − H_ref|/(K_ref + V_ref) after the loads end (H = K + V − W_ext; ref = first output at "
          "or after the loads end); ΔL, ΔJ: max ‖L − L_ref‖, ‖J − J_ref‖ after the loads end\n";
    md << "- displacement error: max over shared output times of ‖monitors − reference‖₂ (monitors: ";
    for (size_t k = 0; k < result.monitors.size(); ++k) md << (k ? ", " : "") << result.monitors[k];
    md << "); reference run: " << (result.reference.empty() ? std::string("none (no completed run)") : "`" + result.reference + "`")
       << "\n\n";
    md << "| run | dt | steps | Newton iters | factorizations | wall [s] | energy error | max ‖ΔL‖ | max ‖ΔJ‖ | final " << mon
       << " | displ. error | status |\n";
    md << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : result.rows) {
      const RunSummary& s = r.summary;
      const double dt = r.run.dt > 0.0 ? r.run.dt : first.spec.time.dt;
      md << "| `" << r.run.label << "` | " << num(dt) << (r.run.adaptive ? " (initial)" : "") << " | ";
      if (r.ok) {
        double final_mon = std::nan("");
        for (const auto& [name, value] : s.final_monitors)
          if (name == mon) final_mon = value;
        md << s.totals.steps << " | " << s.totals.nonlinear_iterations << " | " << s.totals.factorizations << " | "
           << num(s.wall_seconds) << " | " << (std::isnan(r.energy_error) ? "n/a" : num(r.energy_error)) << " | "
           << num(s.max_dL) << " | " << num(s.max_dJ) << " | " << num(final_mon) << " | "
           << (std::isnan(r.displacement_error) ? "n/a" : num(r.displacement_error)) << " | complete |\n";
      } else {
        md << "– | – | – | – | – | – | – | – | – | " << md_cell(r.status) << " |\n";
      }
    }
    if (!md) throw std::runtime_error(result.summary_md + ": write error");
  }
  return result;
}

}  // namespace shelldyn
