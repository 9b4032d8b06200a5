// The integrator registry (architecture §7: integrators/runs/): the one place that knows every concrete
// scheme, so that the interface below it (integrators/integrator.hpp) depends on none of them.
#pragma once

#include "integrators/integrator.hpp"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

// Creates an integrator from its settings (the case file's integrator block, possibly overridden on the
// command line) and the case's time step. Consumes every setting it understands and rejects the rest
// (IntegratorSettings::finish). Throws std::invalid_argument naming the integrator and listing the
// registered names when the name is unknown.
std::unique_ptr<Integrator> make_integrator(IntegratorSettings& settings, double dt);

// The entries of `settings` (e.g. a case file's integrator block) that integrator `name` understands, i.e.
// whose keys appear among its resolved settings ("dt" excepted). Lets a run with another integrator keep
// the case's solver settings (newton, linear_solver, ...) that still apply, and drop the rest.
std::vector<std::pair<std::string, std::string>> settings_understood_by(
    const std::string& name, const std::vector<std::pair<std::string, std::string>>& settings);

// Names of every registered integrator, for --help and error messages.
std::vector<std::string> integrator_names();

// (name, one-line summary) of every registered integrator. The registry is an explicit table in
// integrator.cpp (static self-registration would be dropped by the linker from a static library).
std::vector<std::pair<std::string, std::string>> integrator_catalogue();

using IntegratorFactory = std::function<std::unique_ptr<Integrator>(IntegratorSettings& settings, double dt)>;

// Adds an integrator by name (TEMP shim of the open registry: same signatures as the public API).
// Throws std::invalid_argument if the name is empty or already registered.
void register_integrator(const std::string& name, const std::string& summary, IntegratorFactory factory,
                         const std::string& origin = "");
// Removes a registered integrator; false if there was none of that name.
bool unregister_integrator(const std::string& name);
// Where an integrator comes from ("" for built-ins, e.g. a plugin path or "python:MODULE.CLASS").
std::string integrator_origin(const std::string& name);

}  // namespace shelldyn
