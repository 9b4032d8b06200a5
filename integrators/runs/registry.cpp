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
std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}
// The registry: one line per built-in integrator; register_integrator() adds more.
std::map<std::string, Entry>& registry_table() {
  static std::map<std::string, Entry> r = {
      {"em-galpha", {make_em_galpha, "energy-momentum generalized-alpha of Li & Qian (2025): strain-averaged internal force"}},
      {"em-exact", {make_em_exact, "exactly energy-momentum conserving step: embedded director velocities, corrected element forces (docs/theory/exact-energy-momentum.md)"}},
      {"galpha", {make_galpha, "Chung-Hulbert generalized-alpha: alpha_f-weighted end-point internal forces"}},
      {"midpoint", {make_midpoint, "generalized midpoint: internal force at the midpoint configuration (no strain averaging)"}},
      {"newmark", {make_newmark, "Newmark (beta, gamma): forces at t_{n+1}"}},
      {"ida-bdf", {make_ida_bdf, "SUNDIALS IDA variable-order BDF on the residual form with M(q) (adaptive)"}},
      {"arkode-erk", {make_arkode_erk, "SUNDIALS ARKStep explicit RK, M(q) factorized per RHS (adaptive or fixed)"}},
      {"arkode-dirk", {make_arkode_dirk, "SUNDIALS ARKStep ESDIRK, Schur-complement Newton matrix M + gamma^2 K (adaptive or fixed)"}},
  };
  return r;
}
// A copy, so that factories run without the lock (a factory may itself register or look up integrators).
std::map<std::string, Entry> registry() {
  std::lock_guard<std::mutex> lock(registry_mutex());
  return registry_table();
}
}  // namespace

void register_integrator(const std::string& name, const std::string& summary, IntegratorFactory factory,
                         const std::string& origin) {
  if (name.empty()) throw std::invalid_argument("register_integrator: empty integrator name");
  if (!factory) throw std::invalid_argument("register_integrator: integrator '" + name + "' has no factory");
  std::lock_guard<std::mutex> lock(registry_mutex());
  auto& r = registry_table();
  if (r.count(name))
    throw std::invalid_argument("register_integrator: integrator '" + name + "' is already registered" +
                                (r[name].origin.empty() ? std::string(" (built-in)") : " by " + r[name].origin));
  r[name] = Entry{std::move(factory), summary, origin};
}

bool unregister_integrator(const std::string& name) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  return registry_table().erase(name) > 0;
}

std::string integrator_origin(const std::string& name) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  const auto& r = registry_table();
  const auto it = r.find(name);
  return it == r.end() ? std::string() : it->second.origin;
}

std::vector<std::string> integrator_names() {
  std::vector<std::string> names;
  for (const auto& kv : registry()) names.push_back(kv.first);
  return names;
}

std::vector<std::pair<std::string, std::string>> integrator_catalogue() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& kv : registry()) {
    // The settings it reads, with their defaults (docs/manual.md §3), from a probe instance.
    std::string settings;
    bool prescribed = false;  // follows prescribed_displacements (docs/manual.md §2.12)
    try {
      IntegratorSettings probe(kv.first, {});
      prescribed = kv.second.factory(probe, 1e-3)->supports_prescribed_motion();
      for (const auto& [key, value] : probe.resolved()) settings += (settings.empty() ? "" : ", ") + key + "=" + value;
    } catch (const std::exception&) {
    }
    out.emplace_back(kv.first, kv.second.summary + (prescribed ? "" : " [refuses prescribed_displacements]") +
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
  const auto r = registry();
  const auto it = r.find(settings.name());
  if (it == r.end()) {
    std::string names;
    for (const auto& n : integrator_names()) names += (names.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown integrator '" + settings.name() + "' (see the list below)\navailable: " + names);
  }
  auto integrator = it->second.factory(settings, dt);
  settings.finish();
  return integrator;
}

}  // namespace shelldyn
