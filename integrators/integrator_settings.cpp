#include "integrators/integrator_settings.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace shelldyn {
namespace {
std::string format(double x) {
  std::ostringstream s;
  s.precision(10);  // shortest faithful form of the usual inputs (1e-12, not 9.9999999999999998e-13)
  s << x;
  return s.str();
}
}  // namespace

IntegratorSettings::IntegratorSettings(std::string name, std::vector<std::pair<std::string, std::string>> values,
                                       std::string where)
    : name_(std::move(name)), where_(std::move(where)), values_(std::move(values)) {}

void IntegratorSettings::set(const std::string& key, const std::string& value) {
  for (auto& kv : values_)
    if (kv.first == key) {
      kv.second = value;
      return;
    }
  values_.emplace_back(key, value);
}

const std::string* IntegratorSettings::find(const std::string& key) {
  asked_.insert(key);
  for (const auto& kv : values_)
    if (kv.first == key) return &kv.second;
  return nullptr;
}

double IntegratorSettings::get(const std::string& key, double fallback) {
  double x = fallback;
  if (const std::string* s = find(key)) {
    char* end = nullptr;
    x = std::strtod(s->c_str(), &end);
    if (s->empty() || *end != '\0' || !std::isfinite(x))
      throw std::invalid_argument(where_ + "." + key + ": '" + *s + "' is not a finite number");
  }
  resolved_.emplace_back(key, format(x));
  return x;
}

int IntegratorSettings::get(const std::string& key, int fallback) {
  int x = fallback;
  if (const std::string* s = find(key)) {
    char* end = nullptr;
    const long v = std::strtol(s->c_str(), &end, 10);
    if (s->empty() || *end != '\0' || v < -1000000000L || v > 1000000000L)
      throw std::invalid_argument(where_ + "." + key + ": '" + *s + "' is not an integer");
    x = static_cast<int>(v);
  }
  resolved_.emplace_back(key, std::to_string(x));
  return x;
}

bool IntegratorSettings::get(const std::string& key, bool fallback) {
  bool x = fallback;
  if (const std::string* s = find(key)) {
    if (*s == "true" || *s == "yes" || *s == "on" || *s == "1")
      x = true;
    else if (*s == "false" || *s == "no" || *s == "off" || *s == "0")
      x = false;
    else
      throw std::invalid_argument(where_ + "." + key + ": '" + *s + "' is not a boolean (use true or false)");
  }
  resolved_.emplace_back(key, x ? "true" : "false");
  return x;
}

std::string IntegratorSettings::get(const std::string& key, const std::string& fallback) {
  std::string x = fallback;
  if (const std::string* s = find(key)) x = *s;
  resolved_.emplace_back(key, x);
  return x;
}

void IntegratorSettings::finish() const {
  for (const auto& kv : values_) {
    if (asked_.count(kv.first)) continue;
    std::string valid;
    for (const auto& k : asked_) valid += (valid.empty() ? "" : ", ") + k;
    throw std::invalid_argument(where_ + "." + kv.first + ": unknown setting for integrator '" + name_ +
                                "' (check the spelling; valid ones below)\nvalid: " + valid);
  }
}

}  // namespace shelldyn
