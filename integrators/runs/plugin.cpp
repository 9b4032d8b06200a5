#include "integrators/runs/plugin.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>

namespace fs = std::filesystem;

namespace shelldyn {
namespace {
std::mutex& plugin_mutex() {
  static std::mutex m;
  return m;
}
std::vector<PluginInfo>& plugins() {
  static std::vector<PluginInfo> p;
  return p;
}
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}
}  // namespace

std::string plugin_file_hash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PluginError("plugin " + path + ": cannot read the file");
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a 64 offset basis
  char buf[65536];
  while (in) {
    in.read(buf, sizeof buf);
    for (std::streamsize k = 0; k < in.gcount(); ++k) {
      h ^= static_cast<unsigned char>(buf[k]);
      h *= 1099511628211ULL;  // FNV prime
    }
  }
  char hex[32];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return std::string("fnv1a64:") + hex;
}

PluginInfo load_plugin(const std::string& path_in, const std::string& where) {
  const std::string prefix = (where.empty() ? "" : where + ": ") + "plugin " + path_in + ": ";
  std::error_code ec;
  if (path_in.empty()) throw PluginError((where.empty() ? "" : where + ": ") + "plugin: empty path");
  if (!fs::exists(path_in, ec))
    throw PluginError(prefix + "no such file (give the path of the plugin's shared library, e.g. build/libmy_integrator.so)");
  if (!fs::is_regular_file(path_in, ec)) throw PluginError(prefix + "not a regular file");
  const std::string path = fs::weakly_canonical(fs::absolute(path_in), ec).string();
  std::lock_guard<std::mutex> lock(plugin_mutex());
  for (const auto& p : plugins())
    if (p.path == path) return p;
  PluginInfo info;
  info.path = path;
  info.hash = plugin_file_hash(path);
  // RTLD_NOW: unresolved symbols are an error here, not a crash later; RTLD_LOCAL: plugins do not see each other.
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* err = dlerror();
    throw PluginError(prefix + "cannot load it: " + one_line(err ? err : "unknown dlopen error"));
  }
  dlerror();
  using Register = void (*)();
  using Version = const char* (*)();
  const auto reg = reinterpret_cast<Register>(dlsym(handle, SHELLDYN_PLUGIN_REGISTER_SYMBOL));
  if (!reg) {
    dlclose(handle);
    throw PluginError(prefix + "no entry point '" SHELLDYN_PLUGIN_REGISTER_SYMBOL
                      "' (define it with SHELLDYN_PLUGIN(\"version\") { ... } from integrators/runs/plugin.hpp)");
  }
  const auto ver = reinterpret_cast<Version>(dlsym(handle, SHELLDYN_PLUGIN_VERSION_SYMBOL));
  info.version = "unknown";
  if (ver) {
    const char* v = ver();
    if (v && *v) info.version = v;
  }
  // What it registers is the difference of the registry before and after; names it registered before it threw
  // are removed again, so a failed plugin leaves nothing behind.
  const auto before = integrator_names();
  const auto added = [&before] {
    std::vector<std::string> out;
    for (const auto& n : integrator_names())
      if (!std::binary_search(before.begin(), before.end(), n)) out.push_back(n);
    return out;
  };
  std::string failure;
  try {
    const DefaultOriginScope origin(path);  // what it registers without an origin of its own carries its path
    reg();
  } catch (const std::exception& e) {
    failure = one_line(e.what());
  } catch (...) {
    failure = "a non-standard exception";
  }
  info.integrators = added();
  if (!failure.empty()) {
    for (const auto& n : info.integrators) unregister_integrator(n);
    throw PluginError(prefix + "registration failed: " + failure);
  }
  if (info.integrators.empty())
    throw PluginError(prefix + "registered no integrator (does its SHELLDYN_PLUGIN body call shelldyn::register_integrator? "
                      "the host program must export its symbols, as the shelldyn executable does)");
  plugins().push_back(info);
  return info;
}

std::vector<PluginInfo> loaded_plugins() {
  std::lock_guard<std::mutex> lock(plugin_mutex());
  return plugins();
}

std::optional<PluginInfo> plugin_of_integrator(const std::string& name) {
  std::lock_guard<std::mutex> lock(plugin_mutex());
  for (const auto& p : plugins())
    if (std::find(p.integrators.begin(), p.integrators.end(), name) != p.integrators.end()) return p;
  return std::nullopt;
}

std::vector<std::string> plugin_paths_from_environment() {
  std::vector<std::string> out;
  const char* env = std::getenv("SHELLDYN_PLUGINS");
  if (!env) return out;
  std::string s(env);
  size_t start = 0;
  while (start <= s.size()) {
    const size_t colon = s.find(':', start);
    const std::string item = s.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    if (!item.empty()) out.push_back(item);
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  return out;
}

}  // namespace shelldyn
