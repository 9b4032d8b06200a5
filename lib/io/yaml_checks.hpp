// Checks shared by the YAML inputs: case files (lib/io/case_file.cpp) and study files
// (integrators/runs/study_file.cpp). One wording for one mistake in either kind of file: "FILE:LINE: key.path:
// reason (how to fix)". Internal to the library (it needs yaml-cpp, which the installed headers do not):
// not installed.
#pragma once

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

namespace shelldyn::yaml_checks {

/// The items joined by `sep`, for lists of valid choices in messages.
inline std::string join(const std::vector<std::string>& items, const char* sep = ", ") {
  std::string out;
  for (size_t k = 0; k < items.size(); ++k) out += (k ? sep : "") + items[k];
  return out;
}

/// What a node is, for "expected X, got a ..." messages.
inline std::string node_kind(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Null: return "null (empty value)";
    case YAML::NodeType::Scalar: return "scalar '" + n.Scalar() + "'";
    case YAML::NodeType::Sequence: return "list";
    case YAML::NodeType::Map: return "mapping";
    default: return "undefined value";
  }
}

/// Checks that `map` is a mapping whose keys are plain names, all in `allowed`, each once, and include every
/// key of `required`. On the first violation calls fail(node, key_path, reason), which must throw.
template <class Fail>
void check_keys(const YAML::Node& map, const std::string& path, const std::vector<std::string>& allowed,
                const std::vector<std::string>& required, const Fail& fail) {
  if (!map.IsMap()) fail(map, path, "expected a mapping (key: value), got a " + node_kind(map));
  std::set<std::string> seen;
  for (auto it = map.begin(); it != map.end(); ++it) {
    if (!it->first.IsScalar()) fail(it->first, path, "keys must be plain names");
    const std::string key = it->first.Scalar();
    const std::string sub = path.empty() ? key : path + "." + key;
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      fail(it->first, sub, "unknown key '" + key + "' (allowed here: " + join(allowed) + ")");
    if (!seen.insert(key).second) fail(it->first, sub, "duplicate key '" + key + "' (keep only one)");
  }
  for (const auto& key : required)
    if (!seen.count(key))
      fail(map, path.empty() ? key : path + "." + key,
           "missing required key '" + key + "' (add it" + (path.empty() ? "" : " under '" + path + "'") + ")");
}

}  // namespace shelldyn::yaml_checks
