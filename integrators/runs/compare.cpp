#include "integrators/runs/compare.hpp"

#include "integrators/runs/case_integrator.hpp"
#include "integrators/runs/number_text.hpp"
#include "integrators/runs/executor.hpp"
#include "integrators/runs/registry.hpp"

#include "integrators/integrator.hpp"
#include "integrators/integrator_settings.hpp"
#include "lib/io/case_file.hpp"
#include "lib/io/history_writer.hpp"
#include "lib/model/problem.hpp"
#include "lib/io/run_info.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace fs = std::filesystem;

namespace shelldyn {
namespace {

using number_text::full;
using number_text::num;

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
  const CaseSpec case_spec = load_case(o.case_path);
  load_case_plugins(case_spec);  // its integrators are then valid names below
  const auto names = integrator_names();
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
        const auto made = make_integrator(check, x.dt > 0.0 ? x.dt : 1e-3);
        // A case with prescribed displacements (docs/manual.md §2.12): refuse an integrator that cannot follow them now.
        check_prescribed_motion_support(case_spec, made->name(), made->supports_prescribed_motion());
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

namespace {

// --- one run's result as text: what a worker (thread or MPI rank) sends back, and what --resume reads --------
// "key value" lines; numbers with 17 significant digits (exact round trip), so a summary assembled from
// payloads is identical to one assembled in-process.
std::string encode_outcome(const RunSummary& s, double energy_error) {
  std::ostringstream os;
  os << "integrator " << s.integrator << "\nstatus " << one_line(s.status) << "\n";
  for (const auto& [k, v] : s.settings) os << "setting " << k << "=" << one_line(v) << "\n";
  const StepReport& t = s.totals;
  os << "totals " << t.steps << " " << t.rejected_steps << " " << t.nonlinear_iterations << " " << t.linear_setups << " "
     << t.factorizations << " " << t.rhs_evaluations << " " << t.chart_switches << " " << t.root_events << " "
     << t.reinitializations << " " << full(t.residual_norm) << " " << full(t.energy_ratio) << " " << full(t.last_dt) << " "
     << full(t.wall_seconds) << "\n";
  os << "values " << full(s.t_end) << " " << full(s.H0) << " " << full(s.H_ref) << " " << full(s.E_ref) << " " << full(s.t_ref)
     << " " << full(s.H_final) << " " << full(s.max_rel_drift) << " " << full(s.final_rel_drift) << " " << full(s.max_dL) << " "
     << full(s.max_dJ) << " " << full(s.ref_L) << " " << full(s.ref_J) << " " << full(s.max_strain_ratio) << " "
     << full(s.wall_seconds) << " " << full(energy_error) << "\n";
  os << "cpu " << full(s.cpu_seconds) << "\n";
  os << "damping " << (s.damped ? 1 : 0) << " " << full(s.damping_work) << "\n";
  for (const auto& [name, v] : s.final_monitors) os << "monitor " << full(v) << " " << name << "\n";
  os << "end\n";
  return os.str();
}

double read_number(std::istream& in) {
  std::string w;
  in >> w;
  char* end = nullptr;
  const double x = std::strtod(w.c_str(), &end);
  if (w.empty() || *end != '\0') throw std::runtime_error("bad number '" + w + "'");
  return x;
}

void decode_outcome(const std::string& text, RunSummary& s, double& energy_error) {
  std::istringstream in(text);
  bool ended = false;
  for (std::string line; std::getline(in, line);) {
    const auto sp = line.find(' ');
    const std::string key = line.substr(0, sp), rest = sp == std::string::npos ? "" : line.substr(sp + 1);
    std::istringstream ls(rest);
    if (key == "integrator") {
      s.integrator = rest;
    } else if (key == "status") {
      s.status = rest;
    } else if (key == "setting") {
      const auto eq = rest.find('=');
      s.settings.emplace_back(rest.substr(0, eq), eq == std::string::npos ? "" : rest.substr(eq + 1));
    } else if (key == "totals") {
      StepReport& t = s.totals;
      for (long* p : {&t.steps, &t.rejected_steps, &t.nonlinear_iterations, &t.linear_setups, &t.factorizations,
                      &t.rhs_evaluations, &t.chart_switches, &t.root_events, &t.reinitializations})
        *p = static_cast<long>(read_number(ls));
      for (double* p : {&t.residual_norm, &t.energy_ratio, &t.last_dt, &t.wall_seconds}) *p = read_number(ls);
    } else if (key == "values") {
      for (double* p : {&s.t_end, &s.H0, &s.H_ref, &s.E_ref, &s.t_ref, &s.H_final, &s.max_rel_drift, &s.final_rel_drift,
                        &s.max_dL, &s.max_dJ, &s.ref_L, &s.ref_J, &s.max_strain_ratio, &s.wall_seconds, &energy_error})
        *p = read_number(ls);
    } else if (key == "cpu") {
      s.cpu_seconds = read_number(ls);
    } else if (key == "damping") {
      s.damped = read_number(ls) != 0.0;
      s.damping_work = read_number(ls);
    } else if (key == "monitor") {
      const double v = read_number(ls);
      std::string name;
      std::getline(ls >> std::ws, name);
      s.final_monitors.emplace_back(name, v);
    } else if (key == "end") {
      ended = true;
    } else if (!key.empty()) {
      throw std::runtime_error("unknown key '" + key + "'");
    }
  }
  if (!ended) throw std::runtime_error("truncated (no 'end' line)");
}

uint64_t fnv1a(const std::string& bytes, uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ull;
  return h;
}

// What must match for --resume to reuse a finished run: the case file's bytes, the program version and
// every setting that shapes the run's results.
std::string run_fingerprint(const CompareOptions& o, const CompareRun& r, const std::string& case_bytes) {
  std::ostringstream os;
  os << "shelldyn " << shelldyn_version() << "; case " << std::hex << fnv1a(case_bytes) << std::dec << "; " << r.integrator
     << "; " << settings_text(r.inherited, ",") << "; " << settings_text(r.overrides, ",") << "; dt " << full(r.dt) << "; t_end "
     << full(o.t_end) << "; output " << full(o.output_interval) << "; vtu " << o.vtu_every;
  return one_line(os.str());
}

constexpr const char* kOutcomeFile = "compare-outcome.txt";
constexpr const char* kNotFinished = "failed: not finished (the sweep is still running, or was stopped before this run ended)";

// Expected cost in steps (runs start longest first): t_end/dt for fixed-step runs; for adaptive runs
// 10x the case's step count, times (1e-6/rtol)^(1/4) — a rough fit of the SUNDIALS baselines'
// step counts in the README (about 1e4–1e5 steps per simulated second against 50–1000 fixed steps).
double expected_cost(const CompareRun& r, double t_end, double case_dt) {
  const double steps = t_end / (r.dt > 0.0 ? r.dt : case_dt);
  if (!r.adaptive) return steps;
  double rtol = 1e-6;
  for (const auto& [k, v] : r.overrides)
    if (k == "rtol") rtol = std::strtod(v.c_str(), nullptr);
  return 10.0 * steps * std::pow(1e-6 / std::max(rtol, 1e-300), 0.25);
}

}  // namespace

namespace {

// summary.csv and summary.md from the rows as they are now (unfinished rows included).
void write_compare_summaries(const CompareOptions& o, const Problem& first, double loads_end, double t_end,
                             CompareResult& result, std::map<std::string, CsvTable>& histories) {
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
  result.reference.clear();
  for (auto& r : result.rows) r.displacement_error = std::nan("");
  // histories of finished runs, read once per run (a summary is rewritten after every run)
  auto history = [&](const CompareRow& r) -> const CsvTable& {
    auto it = histories.find(r.run.label);
    if (it == histories.end()) it = histories.emplace(r.run.label, read_csv_table(r.out_dir + "/history.csv")).first;
    return it->second;
  };
  if (ref) {
    result.reference = ref->run.label;
    try {
      const CsvTable& ref_table = history(*ref);
      for (auto& r : result.rows) {
        if (!r.ok) continue;
        try {
          r.displacement_error = monitor_distance(history(r), ref_table, result.monitors);
        } catch (const std::exception&) {
        }
      }
    } catch (const std::exception& e) {
      if (o.log) *o.log << "warning: no displacement errors: " << one_line(e.what()) << std::endl;
    }
  }

  // --- summary.csv ---------------------------------------------------------------------------------------
  result.summary_csv = (fs::path(o.out_dir) / "summary.csv").string();
  {
    std::ofstream csv(result.summary_csv + ".tmp");  // then renamed: a reader never sees half a file
    if (!csv) throw std::runtime_error(result.summary_csv + ": cannot write");
    csv << "label,integrator,overrides,settings,dt,t_end,steps,rejected_steps,nonlinear_iterations,linear_setups,"
           "factorizations,rhs_evaluations,chart_switches,wall_s,cpu_s,t_ref,energy_error,max_rel_drift_of_H,"
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
            << full(s.wall_seconds) << "," << full(s.cpu_seconds) << "," << full(s.t_ref) << "," << full(r.energy_error) << ","
            << full(t_end >= loads_end ? s.max_rel_drift : std::nan("")) << "," << full(t_end >= loads_end ? s.max_dL : std::nan(""))
            << "," << full(t_end >= loads_end ? s.max_dJ : std::nan(""))
            << "," << full(s.ref_L) << "," << full(s.ref_J);
        for (const auto& m : result.monitors) {
          double v = std::nan("");
          for (const auto& [name, value] : s.final_monitors)
            if (name == m) v = value;
          csv << "," << full(v);
        }
      } else {
        csv << "," << full(dt) << "," << full(t_end);
        for (int k = 0; k < 16; ++k) csv << ",";
        for (size_t k = 0; k < result.monitors.size(); ++k) csv << ",";
      }
      csv << "," << full(r.displacement_error) << "," << csv_field(result.reference) << "," << csv_field(r.status) << "\n";
    }
    csv.close();
    if (!csv) throw std::runtime_error(result.summary_csv + ": write error");
    fs::rename(result.summary_csv + ".tmp", result.summary_csv);
  }

  // --- summary.md ----------------------------------------------------------------------------------------
  result.summary_md = (fs::path(o.out_dir) / "summary.md").string();
  {
    std::ofstream md(result.summary_md + ".tmp");
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
    md << "- energy error: max |H − H_ref|/(K_ref + V_ref) after the loads end (H = K + V − W_ext, + W_damp with damping; ref = first output at "
          "or after the loads end); ΔL, ΔJ: max ‖L − L_ref‖, ‖J − J_ref‖ after the loads end\n";
    md << "- displacement error: max over shared output times of ‖monitors − reference‖₂ (monitors: ";
    for (size_t k = 0; k < result.monitors.size(); ++k) md << (k ? ", " : "") << result.monitors[k];
    md << "); reference run: " << (result.reference.empty() ? std::string("none (no completed run)") : "`" + result.reference + "`")
       << "\n\n";
    md << "| run | dt | steps | Newton iters | factorizations | wall [s] | CPU [s] | energy error | max ‖ΔL‖ | max ‖ΔJ‖ | final " << mon
       << " | displ. error | status |\n";
    md << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : result.rows) {
      const RunSummary& s = r.summary;
      const double dt = r.run.dt > 0.0 ? r.run.dt : first.spec.time.dt;
      md << "| `" << r.run.label << "` | " << num(dt) << (r.run.adaptive ? " (initial)" : "") << " | ";
      if (r.ok) {
        double final_mon = std::nan("");
        for (const auto& [name, value] : s.final_monitors)
          if (name == mon) final_mon = value;
        md << s.totals.steps << " | " << s.totals.nonlinear_iterations << " | " << s.totals.factorizations << " | "
           << num(s.wall_seconds) << " | " << num(s.cpu_seconds) << " | " << (std::isnan(r.energy_error) ? "n/a" : num(r.energy_error)) << " | "
           << (t_end >= loads_end ? num(s.max_dL) : "n/a") << " | " << (t_end >= loads_end ? num(s.max_dJ) : "n/a") << " | "
           << num(final_mon) << " | "
           << (std::isnan(r.displacement_error) ? "n/a" : num(r.displacement_error)) << " | complete |\n";
      } else {
        md << "– | – | – | – | – | – | – | – | – | – | " << md_cell(r.status) << " |\n";
      }
    }
    md.close();
    if (!md) throw std::runtime_error(result.summary_md + ": write error");
    fs::rename(result.summary_md + ".tmp", result.summary_md);
  }
}

}  // namespace

namespace {

// One sweep of run_comparisons(): its runs, case, summaries; run(k) and finished(k, …) are called by the
// shared executor batch for the sweep's own run index k.
struct Sweep {
  const CompareOptions& o;
  std::vector<CompareRun> runs;
  Problem first;
  double loads_end = 0.0, t_end = 0.0;
  std::string case_bytes;
  CompareResult result;
  std::map<std::string, CsvTable> histories;
  std::ostream* log = nullptr;
  bool dirty = false;  // rows changed since the summaries were last written

  explicit Sweep(const CompareOptions& options)
      : o(options), runs(expand_compare_runs(options)), first(load_problem(options.case_path)) {  // validates up front
    loads_end = first.model->loads_end();
    t_end = o.t_end >= 0.0 ? o.t_end : first.spec.time.t_end;
    for (const auto& m : first.disc.monitors) result.monitors.push_back(m.name);
    std::error_code ec;
    fs::create_directories(o.out_dir, ec);
    if (ec) throw std::runtime_error("cannot create the comparison folder '" + o.out_dir + "': " + ec.message());
    std::ifstream in(o.case_path, std::ios::binary);
    case_bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    result.rows.resize(runs.size());
    for (size_t k = 0; k < runs.size(); ++k) {
      CompareRow& row = result.rows[k];
      row.run = runs[k];
      row.out_dir = (fs::path(o.out_dir) / runs[k].label).string();
      row.status = kNotFinished;
    }
  }

  // Expected cost for the longest-first order of a batch: steps × unknowns, so that runs of different meshes
  // (run_comparisons of several benchmarks) compare too.
  double cost(size_t k) const {
    return expected_cost(runs[k], t_end, first.spec.time.dt) * static_cast<double>(first.model->num_dofs());
  }

  // One run, on whichever thread or rank the executor chose: its own Problem, its own folder.
  std::string run(size_t k, int threads) const {
    const CompareRun& run = runs[k];
    const std::string dir = (fs::path(o.out_dir) / run.label).string();
    const std::string fingerprint = run_fingerprint(o, run, case_bytes);
    if (o.resume) {  // a finished run of the same settings: reuse its outcome
      std::ifstream in(dir + "/" + kOutcomeFile);
      std::string head, body;
      if (in && std::getline(in, head) && head == "fingerprint " + fingerprint) {
        body.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        RunSummary s;
        double e = 0.0;
        try {
          decode_outcome(body, s, e);
          if (s.status == "complete") return "reused\n" + body;
        } catch (const std::exception&) {
        }
      }
    }
    fs::remove(dir + "/" + kOutcomeFile);
    fs::create_directories(dir);
    std::ofstream runlog(dir + "/log.txt");
    Problem problem = load_problem(o.case_path);
    RunOptions ro;
    ro.out_dir = dir;
    ro.integrator = run.integrator;
    ro.settings = run.inherited;
    ro.settings.insert(ro.settings.end(), run.overrides.begin(), run.overrides.end());
    ro.dt = run.dt;
    ro.t_end = o.t_end;
    ro.output_interval = o.output_interval;
    ro.vtu_every = o.vtu_every;
    ro.max_wall = o.max_wall;
    ro.max_steps = o.max_steps;
    ro.threads = threads;
    ro.log = &runlog;
    ro.command = o.command + "  [run " + run.label + "]";
    ro.label = run.label;
    if (log && o.progress_every >= 0.0) {  // the console sees each run advance (its full log is log.txt)
      ro.progress_every = o.progress_every;
      const std::string prefix = o.log_prefix;
      std::ostream* out = log;
      ro.progress = [out, prefix](const std::string& line) {
        static std::mutex m;
        const std::string text = "  " + prefix + line + "\n";
        std::lock_guard<std::mutex> lock(m);
        *out << text << std::flush;
      };
    }
    const RunSummary summary = run_dynamic(problem, ro);
    print_run_summary(runlog, summary);
    const double energy_error =
        t_end >= loads_end ? mechanical_energy_drift(read_csv_table(dir + "/history.csv"), loads_end) : std::nan("");
    const std::string payload = encode_outcome(summary, energy_error);
    {  // written last: its presence means the run finished (for --resume)
      const std::string tmp = dir + "/" + kOutcomeFile + ".tmp";
      std::ofstream out(tmp);
      out << "fingerprint " << fingerprint << "\n" << payload;
      out.close();
      if (out) fs::rename(tmp, dir + "/" + kOutcomeFile);
    }
    return payload;
  }

  // On the collecting process: fill the row, rewrite the summary (every row, unfinished ones marked), so
  // that a sweep stopped at any point leaves a summary that lists every run.
  // `tag`: "[j/N] " of the run in the executor's batch, as in its start line.
  void finished(size_t k, const RunOutcome& outcome, const std::string& tag) {
    CompareRow& row = result.rows[k];
    row.ok = outcome.ok;
    row.status = outcome.status;
    row.summary = RunSummary{};
    row.energy_error = std::nan("");
    histories.erase(row.run.label);
    if (outcome.ok) {
      std::string payload = outcome.payload;
      const bool reused = payload.rfind("reused\n", 0) == 0;
      if (reused) payload = payload.substr(7);
      try {
        decode_outcome(payload, row.summary, row.energy_error);
        if (log)
          *log << tag << o.log_prefix << row.run.label << ": " << row.summary.totals.steps << " steps, "
               << num(row.summary.wall_seconds) << " s wall, " << num(row.summary.cpu_seconds) << " s CPU, "
               << (std::isnan(row.energy_error) ? std::string("no energy error after the loads (the run ends while they act)")
                                                : "energy error after the loads " + num(row.energy_error))
               << (reused ? " (reused: --resume found it finished with the same settings)" : "") << std::endl;
      } catch (const std::exception& e) {
        row.ok = false;
        row.status = "failed: unreadable result (" + one_line(e.what()) + ")";
      }
    }
    dirty = true;
  }

  void write_summaries() {
    dirty = false;
    write_compare_summaries(o, first, loads_end, t_end, result, histories);
  }
};

}  // namespace

CompareResult run_comparison(const CompareOptions& o) { return std::move(run_comparisons({o}).front()); }

std::vector<CompareResult> run_comparisons(const std::vector<CompareOptions>& sweeps) {
  if (sweeps.empty()) return {};
  for (const auto& o : sweeps)
    if (o.out_dir.empty()) throw std::invalid_argument("compare: an output folder is required");
  std::vector<std::unique_ptr<Sweep>> sw;
  for (const auto& o : sweeps) sw.push_back(std::make_unique<Sweep>(o));
  // One batch for all sweeps: job j is run `index[j].second` of sweep `index[j].first`.
  std::vector<RunJob> jobs;
  std::vector<std::pair<size_t, size_t>> index;
  for (size_t s = 0; s < sw.size(); ++s)
    for (size_t k = 0; k < sw[s]->runs.size(); ++k) {
      jobs.push_back({sweeps[s].log_prefix + sw[s]->runs[k].label, sw[s]->cost(k)});
      index.emplace_back(s, k);
    }
  const CompareOptions& o = sweeps.front();  // the executor and its settings
  std::unique_ptr<RunExecutor> own;
  if (!o.executor) own = make_local_executor(o.jobs, o.threads);
  RunExecutor& executor = o.executor ? *o.executor : *own;
  for (auto& s : sw) s->log = executor.collects() ? s->o.log : nullptr;
  const RunFunction run_one = [&](size_t j, int threads) { return sw[index[j].first]->run(index[j].second, threads); };
  // A terminated job reports its unfinished runs together (more = true until the last one): the summaries of
  // the sweeps whose rows changed are rewritten once, at the last.
  const OutcomeCallback on_outcome = [&](size_t j, const RunOutcome& outcome, bool more) {
    sw[index[j].first]->finished(index[j].second, outcome,
                                 "[" + std::to_string(j + 1) + "/" + std::to_string(jobs.size()) + "] ");
    if (!more)
      for (auto& s : sw)
        if (s->dirty) s->write_summaries();
  };
  if (executor.collects())
    for (auto& s : sw) s->write_summaries();
  execute_runs(jobs, run_one, executor, on_outcome, sw.front()->log);
  std::vector<CompareResult> out;
  for (auto& s : sw) {
    if (executor.collects()) s->write_summaries();
    out.push_back(std::move(s->result));
  }
  return out;
}

}  // namespace shelldyn
