// Typed access to the `integrator:` block of a case file (name + key/value settings as written), with
// command-line overrides. Every key must be consumed: finish() rejects unknown keys and lists the ones
// the integrator understands, so a typo never silently falls back to a default.
#pragma once

#include "lib/io/case_file.hpp"

#include <set>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

class IntegratorSettings {
 public:
  IntegratorSettings(std::string name, std::vector<std::pair<std::string, std::string>> values,
                     std::string where = "integrator");
  explicit IntegratorSettings(const IntegratorSpec& spec, std::string where = "integrator")
      : IntegratorSettings(spec.name, spec.settings, std::move(where)) {}

  const std::string& name() const { return name_; }
  void set(const std::string& key, const std::string& value);  // override (command line)

  double get(const std::string& key, double fallback);
  int get(const std::string& key, int fallback);
  bool get(const std::string& key, bool fallback);
  std::string get(const std::string& key, const std::string& fallback);
  std::string get(const std::string& key, const char* fallback) { return get(key, std::string(fallback)); }

  // Throws std::invalid_argument if a key was given that no get() asked for.
  void finish() const;
  // The settings with the values actually used (defaults included), for run.json.
  const std::vector<std::pair<std::string, std::string>>& resolved() const { return resolved_; }

 private:
  const std::string* find(const std::string& key);
  std::string name_, where_;
  std::vector<std::pair<std::string, std::string>> values_;
  std::set<std::string> asked_;
  std::vector<std::pair<std::string, std::string>> resolved_;
};

}  // namespace shelldyn
