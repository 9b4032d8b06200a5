// Study files (docs/reference/study-files.md): the methods, sweeps, window, reference and full-duration runs of
// `shelldyn study` as YAML, read into a StudyPreset (study.hpp). Messages share the case files' form
// "FILE:LINE: key.path: reason (how to fix)" (lib/io/case_file.cpp). Methods are looked up only by name through
// the registry (make_integrator, settings_understood_by), so a registered plug-in integrator is a method like
// any built-in.
#include "integrators/runs/number_text.hpp"
#include "integrators/runs/registry.hpp"
#include "integrators/runs/study.hpp"

#include "lib/io/yaml_checks.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace shelldyn {
namespace {

using number_text::num;

using yaml_checks::join;
using yaml_checks::node_kind;

bool is_plain_name(const std::string& s) {
  if (s.empty() || s[0] == '.' || s[0] == '-') return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'; });
}

class Parser {
 public:
  explicit Parser(std::string source) : source_(std::move(source)) {}

  std::string where(const YAML::Node& at) const {
    const YAML::Mark m = at.Mark();
    return m.is_null() ? source_ : source_ + ":" + std::to_string(m.line + 1);
  }

  [[noreturn]] void fail(const YAML::Node& at, const std::string& path, const std::string& reason) const {
    throw std::invalid_argument(where(at) + (path.empty() ? "" : ": " + path) + ": " + reason);
  }

  void check_keys(const YAML::Node& map, const std::string& path, const std::vector<std::string>& allowed,
                  const std::vector<std::string>& required) const {
    yaml_checks::check_keys(map, path, allowed, required,
                            [this](const YAML::Node& at, const std::string& p, const std::string& r) { fail(at, p, r); });
  }

  double positive(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar() || n.Tag() == "!") fail(n, path, "expected a number > 0, got a " + node_kind(n));
    double v = 0.0;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      fail(n, path, "expected a number > 0, got '" + n.Scalar() + "'");
    }
    if (!std::isfinite(v) || !(v > 0.0)) fail(n, path, "must be a finite number > 0, got " + n.Scalar());
    return v;
  }

  // A number or a list of numbers, each > 0, no value twice (each is one run).
  std::vector<double> positive_list(const YAML::Node& n, const std::string& path) const {
    std::vector<double> out;
    if (n.IsScalar()) return {positive(n, path)};
    if (!n.IsSequence() || n.size() == 0) fail(n, path, "expected a number or a non-empty list of numbers, e.g. [1e-3, 5e-4], got a " + node_kind(n));
    for (size_t k = 0; k < n.size(); ++k) {
      const std::string sub = path + "[" + std::to_string(k) + "]";
      const double v = positive(n[k], sub);
      if (std::find(out.begin(), out.end(), v) != out.end()) fail(n[k], sub, "value " + n[k].Scalar() + " is listed twice (each value is one run)");
      out.push_back(v);
    }
    return out;
  }

  bool boolean(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar() || n.Tag() == "!") fail(n, path, "expected true or false, got a " + node_kind(n));
    try {
      return n.as<bool>();
    } catch (const YAML::Exception&) {
      fail(n, path, "expected true or false, got '" + n.Scalar() + "'");
    }
  }

  std::string text(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar()) fail(n, path, "expected a text value, got a " + node_kind(n));
    return n.Scalar();
  }

 private:
  std::string source_;
};

// An integrator with its settings, as written: `NAME[:KEY=VALUE...]` or {name: NAME, settings: {KEY: VALUE}}.
struct MethodText {
  std::string name;
  std::vector<std::pair<std::string, std::string>> settings;
  std::vector<YAML::Node> setting_nodes;  // the key node of each setting (its line), empty for a spec string
  double dt = 0.0;                        // a spec string's dt= (0: none)
};

std::string spec_of(const MethodText& m) {
  std::string s = m.name;
  for (const auto& [k, v] : m.settings) s += ":" + k + "=" + v;
  return s;
}

// Does `msg` name `word` as a whole word (letters, digits and '_' on neither side)?
bool names_word(const std::string& msg, const std::string& word) {
  auto is_word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (size_t at = msg.find(word); at != std::string::npos; at = msg.find(word, at + 1))
    if ((at == 0 || !is_word(msg[at - 1])) && (at + word.size() >= msg.size() || !is_word(msg[at + word.size()]))) return true;
  return false;
}

// The registry's names, for messages.
std::string registered() { return join(integrator_names()); }

bool is_registered(const std::string& name) {
  const auto names = integrator_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

bool has_rtol(const std::string& name) { return !settings_understood_by(name, {{"rtol", ""}}).empty(); }

// Makes the integrator once (by name, through the registry) so that unknown settings and bad values fail at
// the line that gave them. Throws through p.fail.
void check_method(const Parser& p, const YAML::Node& at, const std::string& path, const MethodText& m, double dt,
                  const std::vector<std::pair<std::string, std::string>>& extra = {}) {
  auto all = m.settings;
  all.insert(all.end(), extra.begin(), extra.end());
  const std::string settings_path = path + ".settings";
  IntegratorSettings s(m.name, all, settings_path);
  try {
    make_integrator(s, dt);
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    for (size_t i = 0; i < m.settings.size(); ++i) {
      const std::string prefix = settings_path + "." + m.settings[i].first + ": ";
      if (msg.rfind(prefix, 0) == 0) {
        if (i < m.setting_nodes.size()) p.fail(m.setting_nodes[i], settings_path + "." + m.settings[i].first, msg.substr(prefix.size()));
        p.fail(at, path, "setting '" + m.settings[i].first + "': " + msg.substr(prefix.size()));
      }
    }
    // A range check of the integrator names the offending setting as a word (as case_integrator.cpp attributes them).
    for (size_t i = 0; i < m.settings.size(); ++i)
      if (names_word(msg, m.settings[i].first)) {
        if (i < m.setting_nodes.size()) p.fail(m.setting_nodes[i], settings_path + "." + m.settings[i].first, msg);
        p.fail(at, path, "setting '" + m.settings[i].first + "': " + msg);
      }
    p.fail(at, path, msg);
  }
}

MethodText parse_method_text(const Parser& p, const YAML::Node& n, const std::string& path, bool allow_dt) {
  MethodText m;
  if (n.IsScalar()) {
    const std::string spec = n.Scalar();
    CompareRun r;
    try {
      r = parse_compare_spec(spec);
    } catch (const std::invalid_argument& e) {
      p.fail(n, path, e.what());
    }
    m.name = r.integrator;
    m.settings = r.overrides;
    m.dt = r.dt;
    if (r.dt > 0.0 && !allow_dt)
      p.fail(n, path, "'" + spec + "': dt is swept here, not part of a method (give the method's own list: {name: " + m.name + ", dt: [...]})");
  } else if (n.IsMap()) {
    if (!n["name"]) p.fail(n, path + ".name", "missing required key 'name' (the integrator, e.g. name: em-galpha)");
    m.name = p.text(n["name"], path + ".name");
    if (const YAML::Node s = n["settings"]) {
      if (!s.IsMap()) p.fail(s, path + ".settings", "expected a mapping of integrator settings (e.g. {rho_inf: 0.8}), got a " + node_kind(s));
      std::set<std::string> seen;
      for (auto it = s.begin(); it != s.end(); ++it) {
        const std::string key = p.text(it->first, path + ".settings");
        const std::string sub = path + ".settings." + key;
        if (!seen.insert(key).second) p.fail(it->first, sub, "duplicate key '" + key + "' (keep only one)");
        if (key == "dt") p.fail(it->first, sub, "dt is not an integrator setting (use the method's dt: list)");
        if (!it->second.IsScalar()) p.fail(it->second, sub, "integrator settings must be single values, got a " + node_kind(it->second));
        const std::string value = it->second.Scalar();
        if (value.empty() || value.find_first_of(":=,") != std::string::npos)
          p.fail(it->second, sub, "'" + value + "' is not a valid setting value (non-empty, without ':', '=' or ',')");
        m.settings.emplace_back(key, value);
        m.setting_nodes.push_back(it->first);
      }
    }
  } else {
    p.fail(n, path, "expected a method: NAME[:KEY=VALUE...] or {name: NAME, settings: {...}}, got a " + node_kind(n));
  }
  if (m.name == "static")
    p.fail(n.IsMap() ? n["name"] : n, n.IsMap() ? path + ".name" : path,
           "'static' is the static solver, not a time integrator (registered ones below)\nvalid: " + registered());
  if (!is_plain_name(m.name) || !is_registered(m.name))
    p.fail(n.IsMap() ? n["name"] : n, n.IsMap() ? path + ".name" : path,
           "unknown integrator '" + m.name + "' (check the spelling; registered ones below)\nvalid: " + registered());
  return m;
}

// One `methods:` entry (or an --add-method spec, at == the spec node). Returns false for an optional method
// whose integrator this build does not register.
bool parse_method(const Parser& p, const YAML::Node& n, const std::string& path, StudyPreset& s, StudyMethod& out) {
  if (n.IsMap()) {
    p.check_keys(n, path, {"name", "settings", "dt", "rtol", "window", "full", "optional"}, {"name"});
    if (n["optional"] && p.boolean(n["optional"], path + ".optional") && n["name"].IsScalar() && !is_registered(n["name"].Scalar()))
      return false;
  }
  const MethodText m = parse_method_text(p, n, path, false);
  out.integrator = m.name;
  out.spec = spec_of(m);
  out.adaptive = has_rtol(m.name);
  out.where = p.where(n);
  for (const auto& [k, v] : m.settings)
    if (k == "rtol" && out.adaptive)
      p.fail(n, path, "rtol is swept here, not part of a method (give the method's own list: {name: " + m.name + ", rtol: [...]})");
  // Groups: by default every method is in each group the study has (adaptive ones in the window only).
  out.window = s.has_window;
  out.full = s.has_full && !out.adaptive;
  if (n.IsMap()) {
    if (n["dt"] && out.adaptive)
      p.fail(n["dt"], path + ".dt", "'" + m.name + "' is adaptive (it has an rtol setting): sweep it with rtol: [...], not dt");
    if (n["rtol"] && !out.adaptive)
      p.fail(n["rtol"], path + ".rtol", "'" + m.name + "' is a fixed-step integrator (no rtol setting): sweep it with dt: [...], not rtol");
    if (n["dt"]) out.sweep = p.positive_list(n["dt"], path + ".dt");
    if (n["rtol"]) out.sweep = p.positive_list(n["rtol"], path + ".rtol");
    if (n["window"]) {
      out.window = p.boolean(n["window"], path + ".window");
      if (out.window && !s.has_window) p.fail(n["window"], path + ".window", "the study has no window: section (add one, or drop this key)");
    }
    if (n["full"]) {
      out.full = p.boolean(n["full"], path + ".full");
      if (out.full && out.adaptive)
        p.fail(n["full"], path + ".full", "'" + m.name + "' is adaptive: a full-duration run needs its tolerance; list it under full.runs (e.g. " +
                                              m.name + ":rtol=1e-4) instead");
      if (out.full && !s.has_full) p.fail(n["full"], path + ".full", "the study has no full: section (add one, or drop this key)");
    }
    if (!out.window && (n["dt"] || n["rtol"]))
      p.fail(n["dt"] ? n["dt"] : n["rtol"], path + (n["dt"] ? ".dt" : ".rtol"), "a sweep of a method that is not in the window (window: false); drop one of them");
  }
  if (out.window && out.sweep.empty()) {
    out.sweep = out.adaptive ? s.rtols : s.dts;
    if (out.sweep.empty())
      p.fail(n, path, std::string("no ") + (out.adaptive ? "rtol" : "dt") + " values to sweep: give window." + (out.adaptive ? "rtol" : "dt") +
                          " or this method's own " + (out.adaptive ? "rtol" : "dt") + ": [...]");
  }
  if (!out.window && !out.full)
    p.fail(n, path, out.adaptive && !s.has_window ? "an adaptive method runs over the full duration only as a full.runs entry with its tolerance; list it there"
                                                  : "this method is in no group (window: false, full: false); drop it");
  check_method(p, n, path, m, out.adaptive ? 1e-3 : out.sweep.empty() ? 1e-3 : out.sweep.front(),
               out.adaptive && !out.sweep.empty() ? std::vector<std::pair<std::string, std::string>>{{"rtol", num(out.sweep.front())}}
                                                  : std::vector<std::pair<std::string, std::string>>{});
  for (const auto& other : s.methods)
    if (other.spec == out.spec)
      p.fail(n, path, "the same method as the entry at " + other.where + " ('" + out.spec + "'); list each method once");
  return true;
}

// A complete spec with its own dt (window.reference) or tolerance (full.runs): a spec string or a map.
std::string parse_run(const Parser& p, const YAML::Node& n, const std::string& path, bool reference) {
  if (n.IsMap()) p.check_keys(n, path, {"name", "settings", "dt"}, {"name"});
  MethodText m = parse_method_text(p, n, path, true);
  if (n.IsMap() && n["dt"]) m.dt = p.positive(n["dt"], path + ".dt");
  const bool adaptive = has_rtol(m.name);
  if (reference && (adaptive || m.dt <= 0.0))
    p.fail(n, path, adaptive ? "the reference must be a fixed-step integrator with its dt ('" + m.name + "' is adaptive)"
                             : "the reference needs its dt, well below the sweep's (e.g. " + m.name + ":dt=1.25e-4)");
  check_method(p, n, path, m, m.dt > 0.0 ? m.dt : 1e-3);
  std::string spec = n.IsScalar() ? n.Scalar() : spec_of(m) + (m.dt > 0.0 ? ":dt=" + num(m.dt) : "");
  return spec;
}

StudyPreset parse_study(const Parser& p, const YAML::Node& root, const std::string& source, const std::string& base_dir) {
  p.check_keys(root, "", {"name", "case", "note", "window", "methods", "full", "headline"}, {"case", "methods"});
  StudyPreset s;
  s.source = source;
  s.name = fs::path(source).stem().string();
  if (root["name"]) {
    s.name = p.text(root["name"], "name");
    if (!is_plain_name(s.name))
      p.fail(root["name"], "name", "'" + s.name + "' is not a valid name (use letters, digits, '_', '-', '.'; it names the result folder)");
  }
  s.case_file = p.text(root["case"], "case");
  s.case_where = p.where(root["case"]) + ": case";
  if (s.case_file.empty()) p.fail(root["case"], "case", "give the case file (a path relative to this file, or a shipped case such as flying-plate.yaml)");
  {
    const fs::path c = fs::path(s.case_file).is_absolute() ? fs::path(s.case_file) : fs::path(base_dir) / s.case_file;
    std::error_code ec;
    // (A case of the study file's own name in its folder is the study file itself: not a case.)
    if (fs::is_regular_file(c, ec) && !fs::equivalent(c, source, ec)) s.case_path = c.string();
    else if (fs::path(s.case_file).is_absolute())
      p.fail(root["case"], "case", "cannot open the case file '" + s.case_file + "' (check the path)");
  }
  if (root["note"]) s.note = p.text(root["note"], "note");

  s.has_window = static_cast<bool>(root["window"]);
  s.has_full = static_cast<bool>(root["full"]);
  if (!s.has_window && !s.has_full) p.fail(root, "window", "a study needs a window: section, a full: section or both");
  if (s.has_window) {
    const YAML::Node w = root["window"];
    p.check_keys(w, "window", {"t_end", "output_interval", "dt", "rtol", "reference"}, {"t_end"});
    s.window_t_end = p.positive(w["t_end"], "window.t_end");
    if (w["output_interval"]) s.window_output = p.positive(w["output_interval"], "window.output_interval");
    if (w["dt"]) s.dts = p.positive_list(w["dt"], "window.dt");
    if (w["rtol"]) s.rtols = p.positive_list(w["rtol"], "window.rtol");
  }
  if (s.has_full) {
    const YAML::Node f = root["full"];
    if (!f.IsNull()) {
      p.check_keys(f, "full", {"t_end", "dt", "output_interval", "runs"}, {});
      if (f["t_end"]) s.full_t_end = p.positive(f["t_end"], "full.t_end");
      if (f["dt"]) s.full_dt = p.positive(f["dt"], "full.dt");
      if (f["output_interval"]) s.full_output = p.positive(f["output_interval"], "full.output_interval");
    }
  }

  const YAML::Node methods = root["methods"];
  if (!methods.IsSequence() || methods.size() == 0)
    p.fail(methods, "methods", "expected a non-empty list of methods (NAME[:KEY=VALUE...] or {name: ..., settings: {...}}), got a " + node_kind(methods));
  std::vector<std::string> known;  // integrator names of the methods, optional ones left out included
  for (size_t k = 0; k < methods.size(); ++k) {
    const std::string path = "methods[" + std::to_string(k) + "]";
    StudyMethod m;
    if (methods[k].IsMap() && methods[k]["name"] && methods[k]["name"].IsScalar() &&
        std::find(known.begin(), known.end(), methods[k]["name"].Scalar()) == known.end())
      known.push_back(methods[k]["name"].Scalar());
    if (parse_method(p, methods[k], path, s, m)) {
      s.methods.push_back(m);
      if (std::find(known.begin(), known.end(), m.integrator) == known.end()) known.push_back(m.integrator);
    }
  }

  if (s.has_window && root["window"]["reference"]) s.reference_spec = parse_run(p, root["window"]["reference"], "window.reference", true);
  if (s.has_full && root["full"].IsMap() && root["full"]["runs"]) {
    const YAML::Node runs = root["full"]["runs"];
    if (!runs.IsSequence()) p.fail(runs, "full.runs", "expected a list of runs (e.g. [ida-bdf:rtol=1e-4:atol=1e-6]), got a " + node_kind(runs));
    for (size_t k = 0; k < runs.size(); ++k) s.full_baselines.push_back(parse_run(p, runs[k], "full.runs[" + std::to_string(k) + "]", false));
  }
  if (root["headline"]) {
    const YAML::Node h = root["headline"];
    if (!h.IsSequence()) p.fail(h, "headline", "expected a list of integrator names (e.g. [em-galpha, em-exact]), got a " + node_kind(h));
    s.headline.clear();
    for (size_t k = 0; k < h.size(); ++k) {
      const std::string path = "headline[" + std::to_string(k) + "]";
      const std::string name = p.text(h[k], path);
      if (std::find(known.begin(), known.end(), name) == known.end())
        p.fail(h[k], path, "'" + name + "' is not the integrator of any method of this study (methods: " + join(known) + ")");
      s.headline.push_back(name);
    }
  }
  return s;
}

}  // namespace

StudyPreset load_study_from_string(const std::string& text, const std::string& source, const std::string& base_dir) {
  const Parser p(source);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::ostringstream os;
    os << source;
    if (!e.mark.is_null()) os << ":" << e.mark.line + 1;
    os << ": YAML syntax error: " << e.msg << " (check indentation, brackets and quotes)";
    throw std::invalid_argument(os.str());
  }
  try {
    return parse_study(p, root, source, base_dir);
  } catch (const YAML::Exception& e) {
    // Safety net: a yaml-cpp access error not anticipated above still gets the file name and line.
    std::ostringstream os;
    os << source;
    if (!e.mark.is_null()) os << ":" << e.mark.line + 1;
    os << ": " << e.msg;
    throw std::invalid_argument(os.str());
  }
}

StudyPreset load_study_file(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw std::invalid_argument(path + ": cannot open the study file (not a regular file; check the path)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot open the study file (check the path)");
  std::ostringstream text;
  text << in.rdbuf();
  return load_study_from_string(text.str(), path, fs::absolute(fs::path(path)).parent_path().string());
}

void add_study_method(StudyPreset& preset, const std::string& spec, const std::string& where) {
  const Parser p(where);
  const YAML::Node n(spec);  // a scalar without a mark: messages start with `where`
  StudyMethod m;
  parse_method(p, n, "", preset, m);
  m.where = where;
  preset.methods.push_back(m);
}

}  // namespace shelldyn
