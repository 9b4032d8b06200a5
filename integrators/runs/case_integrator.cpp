#include "integrators/runs/case_integrator.hpp"

#include "integrators/runs/plugin.hpp"
#include "integrators/runs/registry.hpp"

#include <cctype>
#include <stdexcept>

namespace shelldyn {
namespace {

bool is_word_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Does `msg` name `key` as a whole word?
bool names_key(const std::string& msg, const std::string& key) {
  for (size_t p = msg.find(key); p != std::string::npos; p = msg.find(key, p + 1)) {
    const bool left = p == 0 || !is_word_char(msg[p - 1]);
    const bool right = p + key.size() >= msg.size() || !is_word_char(msg[p + key.size()]);
    if (left && right) return true;
  }
  return false;
}

// Strips a leading "integrator.KEY: " (IntegratorSettings' own prefix) so that it is not repeated.
std::string strip_prefix(const std::string& msg, const std::string& key) {
  const std::string p = "integrator." + key + ": ";
  return msg.compare(0, p.size(), p) == 0 ? msg.substr(p.size()) : msg;
}

}  // namespace

void load_case_plugins(const CaseSpec& spec) {
  for (size_t k = 0; k < spec.plugins.size(); ++k)
    load_plugin(spec.plugins[k], spec.plugins_where.empty() ? "" : spec.plugins_where + "[" + std::to_string(k) + "]");
}

std::unique_ptr<Integrator> make_case_integrator(const CaseSpec& spec, const std::string& integrator,
                                                 const std::vector<std::pair<std::string, std::string>>& overrides,
                                                 double dt) {
  load_case_plugins(spec);
  const bool own = integrator.empty() || integrator == spec.integrator.name;
  const std::string name = own ? spec.integrator.name : integrator;
  if (name == "static") throw std::invalid_argument("integrator 'static' is the static solver: use `shelldyn static CASE`");
  std::unique_ptr<Integrator> made;
  try {
    IntegratorSettings settings =
        own ? IntegratorSettings(spec.integrator)
            : IntegratorSettings(name, settings_understood_by(name, spec.integrator.settings));
    for (const auto& [k, v] : overrides) settings.set(k, v);
    made = make_integrator(settings, dt);
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    // 0. IntegratorSettings names the key exactly: "integrator.KEY: ..."
    auto prefixed = [&](const std::string& k) { return msg.rfind("integrator." + k + ": ", 0) == 0; };
    for (const auto& [k, v] : overrides)
      if (prefixed(k)) throw std::invalid_argument("--set " + k + "=" + v + ": " + strip_prefix(msg, k));
    if (own)
      for (size_t i = 0; i < spec.integrator.settings.size() && i < spec.integrator.setting_where.size(); ++i)
        if (prefixed(spec.integrator.settings[i].first))
          throw std::invalid_argument(spec.integrator.setting_where[i] + ": " + msg);
    // 1. a command-line override named in the message
    for (const auto& [k, v] : overrides)
      if (names_key(msg, k)) throw std::invalid_argument("--set " + k + "=" + v + ": " + strip_prefix(msg, k));
    if (!own || spec.integrator.where.empty()) throw;
    // 2. a setting of the case's block (longest key first: max_steps before max_step)
    size_t best = spec.integrator.settings.size();
    for (size_t i = 0; i < spec.integrator.settings.size(); ++i) {
      const std::string& k = spec.integrator.settings[i].first;
      if (names_key(msg, k) && (best == spec.integrator.settings.size() || k.size() > spec.integrator.settings[best].first.size()))
        best = i;
    }
    if (best < spec.integrator.settings.size() && best < spec.integrator.setting_where.size()) {
      const std::string& k = spec.integrator.settings[best].first;
      throw std::invalid_argument(spec.integrator.setting_where[best] + ": integrator." + k + ": " + strip_prefix(msg, k));
    }
    // 3. a setting whose value the message quotes ('magic')
    for (size_t i = 0; i < spec.integrator.settings.size() && i < spec.integrator.setting_where.size(); ++i)
      if (msg.find("'" + spec.integrator.settings[i].second + "'") != std::string::npos)
        throw std::invalid_argument(spec.integrator.setting_where[i] + ": integrator." + spec.integrator.settings[i].first +
                                    ": " + msg);
    // 4. the name, or the block as a whole
    if (msg.rfind("unknown integrator", 0) == 0)
      throw std::invalid_argument(spec.integrator.where + ": integrator.name: " + msg);
    throw std::invalid_argument(spec.integrator.where + ": integrator: " + msg);
  }
  check_prescribed_motion_support(spec, made->name(), made->supports_prescribed_motion());
  return made;
}

void check_prescribed_motion_support(const CaseSpec& spec, const std::string& integrator, bool supported) {
  if (spec.prescribed_displacements.empty() || supported) return;
  throw std::invalid_argument(spec.prescribed_displacements.front().where + ": integrator '" + integrator +
                              "' cannot follow them (use em-galpha, em-exact, galpha, midpoint, newmark)");
}

void validate_case_integrator(const CaseSpec& spec) {
  if (spec.integrator.name == "static") return check_prescribed_motion_support(spec, "static", false);
  make_case_integrator(spec, "", {}, spec.time.dt);
}

}  // namespace shelldyn
