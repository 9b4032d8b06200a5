// The integrator registry (architecture §7: integrators/runs/): the one place that knows every concrete
// scheme, so that the interface below it (integrators/integrator.hpp) depends on none of them.
#pragma once

#include "integrators/integrator.hpp"

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

using IntegratorFactory = std::unique_ptr<Integrator> (*)(IntegratorSettings& settings, double dt);

}  // namespace shelldyn
