#include "integrators/runs/registry.hpp"

#include "integrators/baselines/arkode_integrators.hpp"
#include "integrators/baselines/ida_bdf.hpp"
#include "integrators/newmark/em_exact.hpp"
#include "integrators/newmark/em_generalized_alpha.hpp"

#include <map>
#include <mutex>
#include <stdexcept>

namespace shelldyn {
namespace {
struct Entry {
  IntegratorFactory factory;
  std::string summary;
  std::string origin;
};
struct Registry {
  std::mutex mutex;
  std::map<std::string, Entry> entries;
};
thread_local std::string default_origin;  // DefaultOriginScope
Registry& raw_registry() {
  static Registry r;
  return r;
}
// The registry with the built-ins in it.
Registry& registry() {
  register_builtin_integrators();
  return raw_registry();
}
std::string joined_names(const std::map<std::string, Entry>& entries) {
  std::string names;
  for (const auto& kv : entries) names += (names.empty() ? "" : ", ") + kv.first;
  return names;
}
void add(Registry& r, const std::string& name, const std::string& summary, IntegratorFactory factory,
         const std::string& origin) {
  if (name.empty() || name.find_first_of(" ,:=\t\n") != std::string::npos)
    throw std::invalid_argument("register_integrator: bad name '" + name +
                                "' (non-empty, without spaces, ',', ':' or '=', which separate compare specs)");
  if (!factory) throw std::invalid_argument("register_integrator: '" + name + "' has no factory");
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.entries.find(name);
  if (it != r.entries.end())
    throw std::invalid_argument("integrator '" + name + "' is already registered (by " + it->second.origin +
                                "); choose another name");
  r.entries.emplace(name, Entry{std::move(factory), summary,
                                origin.empty() ? (default_origin.empty() ? "user code" : default_origin) : origin});
}
// Copy of an entry (the factory runs outside the lock: it may itself look up the registry).
bool find(const std::string& name, Entry& out) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.entries.find(name);
  if (it == r.entries.end()) return false;
  out = it->second;
  return true;
}
}  // namespace

void register_builtin_integrators() {
  static std::once_flag once;
  std::call_once(once, [] {
    Registry& r = raw_registry();
    const std::string b = "built-in";
    add(r, "em-galpha", "energy-momentum generalized-alpha of Li & Qian (2025): strain-averaged internal force", make_em_galpha, b);
    add(r, "em-exact", "exactly energy-momentum conserving step: embedded director velocities, corrected element forces (docs/theory/exact-energy-momentum.md)", make_em_exact, b);
    add(r, "galpha", "Chung-Hulbert generalized-alpha: alpha_f-weighted end-point internal forces", make_galpha, b);
    add(r, "midpoint", "generalized midpoint: internal force at the midpoint configuration (no strain averaging)", make_midpoint, b);
    add(r, "newmark", "Newmark (beta, gamma): forces at t_{n+1}", make_newmark, b);
    add(r, "ida-bdf", "SUNDIALS IDA variable-order BDF on the residual form with M(q) (adaptive)", make_ida_bdf, b);
    add(r, "arkode-erk", "SUNDIALS ARKStep explicit RK, M(q) factorized per RHS (adaptive or fixed)", make_arkode_erk, b);
    add(r, "arkode-dirk", "SUNDIALS ARKStep ESDIRK, Schur-complement Newton matrix M + gamma^2 K (adaptive or fixed)", make_arkode_dirk, b);
  });
}

DefaultOriginScope::DefaultOriginScope(std::string origin) : previous_(std::move(default_origin)) {
  default_origin = std::move(origin);
}
DefaultOriginScope::~DefaultOriginScope() { default_origin = std::move(previous_); }

void register_integrator(const std::string& name, const std::string& summary, IntegratorFactory factory,
                         const std::string& origin) {
  add(registry(), name, summary, std::move(factory), origin);
}

bool unregister_integrator(const std::string& name) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  return r.entries.erase(name) > 0;
}

std::string integrator_origin(const std::string& name) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.entries.find(name);
  if (it == r.entries.end())
    throw std::invalid_argument("unknown integrator '" + name + "'\navailable: " + joined_names(r.entries));
  return it->second.origin;
}

std::vector<std::string> integrator_names() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& kv : r.entries) names.push_back(kv.first);
  return names;
}

std::vector<std::string> integrators_supporting_constraints() {
  std::vector<std::pair<std::string, Entry>> entries;
  {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    for (const auto& kv : r.entries) entries.emplace_back(kv.first, kv.second);
  }
  std::vector<std::string> out;
  for (const auto& [name, entry] : entries) {
    try {
      IntegratorSettings probe(name, {});
      if (entry.factory(probe, 1e-3)->supports_constraints()) out.push_back(name);
    } catch (const std::exception&) {
    }
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> integrator_catalogue() {
  std::vector<std::pair<std::string, Entry>> entries;
  {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    for (const auto& kv : r.entries) entries.emplace_back(kv.first, kv.second);
  }
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [name, entry] : entries) {
    // The settings it reads, with their defaults (docs/manual.md §3), from a probe instance.
    std::string settings;
    bool prescribed = false;  // follows prescribed_displacements (docs/manual.md §2.12)
    try {
      IntegratorSettings probe(name, {});
      prescribed = entry.factory(probe, 1e-3)->supports_prescribed_motion();
      for (const auto& [key, value] : probe.resolved()) settings += (settings.empty() ? "" : ", ") + key + "=" + value;
    } catch (const std::exception&) {
    }
    out.emplace_back(name, entry.summary + (prescribed ? "" : " [refuses prescribed_displacements]") +
                               (entry.origin == "built-in" ? "" : " [from " + entry.origin + "]") +
                               (settings.empty() ? "" : "\n      settings: " + settings));
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> settings_understood_by(
    const std::string& name, const std::vector<std::pair<std::string, std::string>>& settings) {
  IntegratorSettings probe(name, {});
  const auto integrator = make_integrator(probe, 1e-3);
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [key, value] : settings) {
    if (key == "dt") continue;
    for (const auto& [known, unused] : integrator->settings())
      if (known == key) {
        out.emplace_back(key, value);
        break;
      }
  }
  return out;
}

std::unique_ptr<Integrator> make_integrator(IntegratorSettings& settings, double dt) {
  Entry entry;
  if (!find(settings.name(), entry)) {
    std::string names;
    for (const auto& n : integrator_names()) names += (names.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown integrator '" + settings.name() + "' (see the list below)\navailable: " + names);
  }
  std::unique_ptr<Integrator> integrator;
  if (entry.origin == "built-in") {
    integrator = entry.factory(settings, dt);
  } else {
    // A user factory's failure names where the integrator came from (a plugin path, ...), so that a bad plugin
    // is identified in the one-line error. std::invalid_argument stays one (bad settings are the user's to fix).
    try {
      integrator = entry.factory(settings, dt);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(e.what()) + " (integrator '" + settings.name() + "' from " + entry.origin + ")");
    } catch (const std::exception& e) {
      throw std::runtime_error("integrator '" + settings.name() + "' from " + entry.origin + ": factory failed: " + e.what());
    } catch (...) {
      throw std::runtime_error("integrator '" + settings.name() + "' from " + entry.origin + ": factory threw a non-standard exception");
    }
    if (!integrator) throw std::runtime_error("integrator '" + settings.name() + "' from " + entry.origin + ": factory returned null");
  }
  settings.finish();
  return integrator;
}

}  // namespace shelldyn
