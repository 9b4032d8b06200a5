// The integrator a run would use for a case, built and validated the same way by `shelldyn check`,
// `shelldyn run` and the benchmark apps, so that `check` rejects exactly what `run` would reject.
//
// Errors (std::invalid_argument) point at the case file when the cause is there:
//   "FILE:LINE: integrator.KEY: reason"   a setting of the case's integrator block
//   "FILE:LINE: integrator.name: ..."     an unknown integrator name in the case
//   "--set KEY: reason"                   a command-line override
// A message is attributed to KEY when it names the key (IntegratorSettings errors always do; range
// checks of the integrators name the offending setting).
#pragma once

#include "integrators/integrator.hpp"
#include "lib/io/case_file.hpp"

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

// `integrator`: empty or the case's name = the case's block (with its settings); another name keeps
// only the case settings that integrator understands (as `shelldyn compare` does). `overrides`: --set.
std::unique_ptr<Integrator> make_case_integrator(const CaseSpec& spec, const std::string& integrator,
                                                 const std::vector<std::pair<std::string, std::string>>& overrides,
                                                 double dt);

// Loads the plugins of the case file's `plugins:` key (integrators/runs/plugin.hpp); make_case_integrator calls it.
// Throws PluginError "FILE:LINE: plugins[k]: plugin PATH: ...".
void load_case_plugins(const CaseSpec& spec);

// make_case_integrator(spec, "", {}, spec.time.dt), result discarded ("static" passes: it is checked
// by the static solver, except that it refuses prescribed displacement histories).
void validate_case_integrator(const CaseSpec& spec);

// Throws std::invalid_argument "FILE:LINE: prescribed_displacements[0]: integrator 'X'
// cannot follow them ..." if the case prescribes displacement histories and the integrator (or solver) named
// `integrator` does not support them (`supported`); make_case_integrator calls it (docs/manual.md §2.12).
void check_prescribed_motion_support(const CaseSpec& spec, const std::string& integrator, bool supported);

}  // namespace shelldyn
