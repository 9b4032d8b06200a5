// The integrator registry (architecture §7: integrators/runs/): integrators are made by name
// (`integrator.name` in a case file, `--integrator`, compare/study specs) from the factories registered here.
//
// The registry is open (docs/tutorials/05-your-own-integrator.md): the built-in schemes register through
// register_builtin_integrators() exactly as user code and plugins (integrators/runs/plugin.hpp) register
// their own. Every lookup calls register_builtin_integrators() first, so the built-ins are always there
// (an explicit call, not static self-registration, which the linker drops from a static library).
// All functions are thread-safe.
#pragma once

#include "integrators/integrator.hpp"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

// Makes an integrator from its settings (the case file's integrator block, possibly overridden on the command
// line with --set) and the case's time step. It reads its settings with settings.get(key, default); keys it
// does not ask for are refused afterwards by make_integrator (IntegratorSettings::finish) with the valid
// names. Throws std::invalid_argument naming the setting on a bad value.
using IntegratorFactory = std::function<std::unique_ptr<Integrator>(IntegratorSettings& settings, double dt)>;

// Adds integrator `name` with a one-line `summary` (shown by `shelldyn integrators` and --help) and its
// factory. `origin` says where it came from: "built-in", a plugin's path, "python:..." (empty: "user code").
// Throws std::invalid_argument when `name` is taken (the message names the existing entry's origin), is empty
// or contains one of the characters ' ', ',', ':', '=' (they separate compare specs), or the factory is empty.
void register_integrator(const std::string& name, const std::string& summary, IntegratorFactory factory,
                         const std::string& origin = "");

// While one is alive (on this thread), registrations that give no origin get `origin` instead of "user code":
// the plugin loader (integrators/runs/plugin.hpp) uses it, so that a plugin's integrators carry its path.
class DefaultOriginScope {
 public:
  explicit DefaultOriginScope(std::string origin);
  ~DefaultOriginScope();
  DefaultOriginScope(const DefaultOriginScope&) = delete;
  DefaultOriginScope& operator=(const DefaultOriginScope&) = delete;

 private:
  std::string previous_;
};

// Removes integrator `name`; returns false if there is none. Built-ins can be removed too (and come back
// only if re-registered by hand: register_builtin_integrators() runs its table once per process).
bool unregister_integrator(const std::string& name);

// The origin given when `name` was registered ("built-in", a plugin path, ...); throws std::invalid_argument
// with the registered names if there is no such integrator.
std::string integrator_origin(const std::string& name);

// Registers em-galpha, em-exact, galpha, midpoint, newmark, ida-bdf, arkode-erk and arkode-dirk with origin
// "built-in". Idempotent and thread-safe (std::call_once); called by every function of this header.
void register_builtin_integrators();

// Creates an integrator from its settings and the case's time step. Consumes every setting it understands
// and rejects the rest (IntegratorSettings::finish). Throws std::invalid_argument naming the integrator and
// listing the registered names when the name is unknown.
std::unique_ptr<Integrator> make_integrator(IntegratorSettings& settings, double dt);

// The entries of `settings` (e.g. a case file's integrator block) that integrator `name` understands, i.e.
// whose keys appear among its resolved settings ("dt" excepted). Lets a run with another integrator keep
// the case's solver settings (newton, linear_solver, ...) that still apply, and drop the rest.
std::vector<std::pair<std::string, std::string>> settings_understood_by(
    const std::string& name, const std::vector<std::pair<std::string, std::string>>& settings);

// Names of every registered integrator (sorted), for --help and error messages.
std::vector<std::string> integrator_names();

// Names of the registered integrators that enforce constraints (Integrator::supports_constraints, from a probe
// instance of each), sorted.
std::vector<std::string> integrators_supporting_constraints();

// (name, one-line summary + the settings it reads with their defaults) of every registered integrator.
std::vector<std::pair<std::string, std::string>> integrator_catalogue();

}  // namespace shelldyn
