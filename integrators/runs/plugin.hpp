// Integrator plugins (docs/tutorials/05-your-own-integrator.md): shared libraries that register integrators
// with register_integrator() (integrators/runs/registry.hpp) when loaded, so that `shelldyn run|check|compare|
// study|resume` run them exactly like the built-ins.
//
// Writing one: in a .cpp built as a shared library (CMake: add_library(NAME MODULE ...) linked to
// shelldyn::shelldyn), define the entry point with the macro below:
//
//     #include "integrators/runs/plugin.hpp"
//     SHELLDYN_PLUGIN("1.0") {   // the plugin's version, recorded in run.json
//       shelldyn::register_integrator("my-scheme", "one-line summary", make_my_scheme);
//     }
//
// Loading one (load_plugin below): `--plugin PATH.so` (repeatable) on the command line, the case-file key
// `plugins: [PATH.so, ...]` (relative to the case file), or the environment variable SHELLDYN_PLUGINS
// (colon-separated paths). The loader dlopen()s the file, calls its entry point shelldyn_plugin_register()
// and attributes every integrator registered during the call to the plugin (integrator_origin() = its path).
// The host program must export its symbols (the shelldyn executable is linked with ENABLE_EXPORTS), so that
// the plugin's call to register_integrator reaches the host's registry.
//
// Errors are one line naming the plugin, "plugin PATH: ...": the file is missing or not a loadable library,
// the entry point is missing, the entry point throws (e.g. a name that is already registered), or it
// registers nothing. Plugins are never unloaded (their code runs until the process ends).
#pragma once

#include "integrators/runs/registry.hpp"

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

// The C entry points a plugin exports (the loader looks them up by these names).
#define SHELLDYN_PLUGIN_REGISTER_SYMBOL "shelldyn_plugin_register"
#define SHELLDYN_PLUGIN_VERSION_SYMBOL "shelldyn_plugin_version"
#define SHELLDYN_PLUGIN_EXPORT __attribute__((visibility("default")))

// Defines the entry point and the version string of a plugin; the braces that follow are the body of the
// registration function (called once, when the plugin is loaded).
#define SHELLDYN_PLUGIN(VERSION)                                                                       \
  static void shelldyn_plugin_body_();                                                                 \
  extern "C" SHELLDYN_PLUGIN_EXPORT const char* shelldyn_plugin_version() { return VERSION; }          \
  extern "C" SHELLDYN_PLUGIN_EXPORT void shelldyn_plugin_register() { shelldyn_plugin_body_(); }       \
  static void shelldyn_plugin_body_()

namespace shelldyn {

// A plugin failed to load or register: the message is one line "plugin PATH: reason".
class PluginError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct PluginInfo {
  std::string path;                      // absolute, normalized
  std::string version;                   // shelldyn_plugin_version(), or "unknown" if the plugin has none
  std::string hash;                      // "fnv1a64:<16 hex digits>" of the file's bytes
  std::vector<std::string> integrators;  // the names it registered
};

// Loads the plugin at `path` (see above) and returns what it registered. Loading the same file again (same
// absolute path) returns the first load's info without calling the entry point again. `where` prefixes the
// error message when the path came from somewhere the user should look (e.g. "case.yaml:3: plugins[0]").
// Throws PluginError.
PluginInfo load_plugin(const std::string& path, const std::string& where = "");

// Every plugin loaded so far, in load order.
std::vector<PluginInfo> loaded_plugins();

// The plugin that registered integrator `name`, or nothing if it came from elsewhere (built-in, user code).
std::optional<PluginInfo> plugin_of_integrator(const std::string& name);

// The paths listed in the environment variable SHELLDYN_PLUGINS (colon-separated; empty entries skipped).
std::vector<std::string> plugin_paths_from_environment();

// FNV-1a 64-bit hash of a file's bytes as "fnv1a64:<hex>"; throws PluginError if it cannot be read.
std::string plugin_file_hash(const std::string& path);

}  // namespace shelldyn
