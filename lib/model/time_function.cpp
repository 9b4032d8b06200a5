#include "lib/model/time_function.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

namespace {

constexpr double kPi = 3.14159265358979323846;

void require_positive(double v, const char* name, const char* kind) {
  if (!std::isfinite(v) || v <= 0.0) {
    std::ostringstream os;
    os << kind << " time function: " << name << " = " << v << " must be a finite number > 0";
    throw std::invalid_argument(os.str());
  }
}

}  // namespace

TimeFunction TimeFunction::constant() { return TimeFunction(Kind::Constant, 0.0, 0.0); }

TimeFunction TimeFunction::ramp(double t1) {
  require_positive(t1, "t1", "ramp");
  return TimeFunction(Kind::Ramp, t1, 0.0);
}

TimeFunction TimeFunction::hat(double t1) {
  require_positive(t1, "t1", "hat");
  return TimeFunction(Kind::Hat, t1, 0.0);
}

TimeFunction TimeFunction::triangle(double t_peak, double t_end) {
  require_positive(t_peak, "t_peak", "triangle");
  require_positive(t_end, "t_end", "triangle");
  if (!(t_end > t_peak)) {
    std::ostringstream os;
    os << "triangle time function: t_end = " << t_end << " must be greater than t_peak = " << t_peak;
    throw std::invalid_argument(os.str());
  }
  return TimeFunction(Kind::Triangle, t_peak, t_end);
}

TimeFunction TimeFunction::table(std::vector<std::pair<double, double>> points) {
  if (points.empty()) throw std::invalid_argument("table time function: needs at least one point [t, f]");
  for (size_t k = 0; k < points.size(); ++k) {
    if (!std::isfinite(points[k].first) || !std::isfinite(points[k].second)) {
      std::ostringstream os;
      os << "table time function: point " << k << " is not finite";
      throw std::invalid_argument(os.str());
    }
    if (k > 0 && !(points[k].first > points[k - 1].first)) {
      std::ostringstream os;
      os << "table: times must increase (point " << k << ": t = " << points[k].first << " after "
         << points[k - 1].first << ")";
      throw std::invalid_argument(os.str());
    }
  }
  TimeFunction f(Kind::Table, 0.0, 0.0);
  f.points_ = std::move(points);
  return f;
}

TimeFunction TimeFunction::spin_up(double T_s) {
  require_positive(T_s, "T_s", "spin_up");
  return TimeFunction(Kind::SpinUp, T_s, 0.0);
}

double TimeFunction::operator()(double t) const {
  switch (kind_) {
    case Kind::Constant:
      return 1.0;
    case Kind::Ramp:
      if (t <= 0.0) return 0.0;
      return std::min(t / a_, 1.0);
    case Kind::Hat:
      if (t <= 0.0 || t >= 2.0 * a_) return 0.0;
      return t <= a_ ? t / a_ : 2.0 - t / a_;
    case Kind::Triangle:
      if (t <= 0.0 || t >= b_) return 0.0;
      return t <= a_ ? t / a_ : (b_ - t) / (b_ - a_);
    case Kind::Table: {
      if (t <= points_.front().first) return points_.front().second;
      if (t >= points_.back().first) return points_.back().second;
      // First point with time > t; it exists and is not the first one (checked above).
      auto hi = std::upper_bound(points_.begin(), points_.end(), t,
                                 [](double v, const std::pair<double, double>& p) { return v < p.first; });
      auto lo = hi - 1;
      const double w = (t - lo->first) / (hi->first - lo->first);
      return (1.0 - w) * lo->second + w * hi->second;
    }
    case Kind::SpinUp: {
      // Kane, Ryan & Banerjee 1987: θ/ω_s = (1/T)[t²/2 + (T/2π)²(cos(2πt/T) − 1)] for t ≤ T, t − T/2 after.
      if (t <= 0.0) return 0.0;
      if (t >= a_) return t - 0.5 * a_;
      const double c = a_ / (2.0 * kPi);  // T/2π
      return (0.5 * t * t + c * c * (std::cos(t / c) - 1.0)) / a_;
    }
  }
  return 0.0;  // unreachable; keeps -Wreturn-type quiet
}

double TimeFunction::rate(double t) const {
  switch (kind_) {
    case Kind::Constant:
      return 0.0;
    case Kind::Ramp:
      return (t >= 0.0 && t < a_) ? 1.0 / a_ : 0.0;
    case Kind::Hat:
      if (t < 0.0 || t >= 2.0 * a_) return 0.0;
      return t < a_ ? 1.0 / a_ : -1.0 / a_;
    case Kind::Triangle:
      if (t < 0.0 || t >= b_) return 0.0;
      return t < a_ ? 1.0 / a_ : -1.0 / (b_ - a_);
    case Kind::Table: {
      if (t < points_.front().first || t >= points_.back().first) return 0.0;
      // The piece [t_k, t_{k+1}) that holds t.
      auto hi = std::upper_bound(points_.begin(), points_.end(), t,
                                 [](double v, const std::pair<double, double>& p) { return v < p.first; });
      auto lo = hi - 1;
      return (hi->second - lo->second) / (hi->first - lo->first);
    }
    case Kind::SpinUp: {
      // d/dt of the above: (1/T)[t − (T/2π) sin(2πt/T)], 1 after T.
      if (t <= 0.0) return 0.0;
      if (t >= a_) return 1.0;
      const double c = a_ / (2.0 * kPi);  // T/2π
      return (t - c * std::sin(t / c)) / a_;
    }
  }
  return 0.0;
}

double TimeFunction::end_of_variation() const {
  switch (kind_) {
    case Kind::Constant:
      return 0.0;
    case Kind::Ramp:
      return a_;
    case Kind::Hat:
      return 2.0 * a_;
    case Kind::Triangle:
      return b_;
    case Kind::Table: {
      // Walk back over the trailing run of equal values: f is constant from the first of them on.
      size_t k = points_.size() - 1;
      while (k > 0 && points_[k - 1].second == points_.back().second) --k;
      return k == 0 ? 0.0 : std::max(points_[k].first, 0.0);
    }
    case Kind::SpinUp:
      return std::numeric_limits<double>::infinity();  // grows linearly for ever
  }
  return std::numeric_limits<double>::infinity();
}

double TimeFunction::end_of_support() const {
  const double inf = std::numeric_limits<double>::infinity();
  switch (kind_) {
    case Kind::Constant:
    case Kind::Ramp:
    case Kind::SpinUp:
      return inf;
    case Kind::Hat:
      return 2.0 * a_;
    case Kind::Triangle:
      return b_;
    case Kind::Table: {
      if (points_.back().second != 0.0) return inf;
      // Walk back over the trailing zeros: the function is 0 from the first of them on.
      size_t k = points_.size() - 1;
      while (k > 0 && points_[k - 1].second == 0.0) --k;
      // If every value is 0 the function is 0 everywhere, including before the first point.
      return k == 0 ? 0.0 : points_[k].first;
    }
  }
  return inf;
}

const char* TimeFunction::kind_name() const {
  switch (kind_) {
    case Kind::Constant: return "constant";
    case Kind::Ramp: return "ramp";
    case Kind::Hat: return "hat";
    case Kind::Triangle: return "triangle";
    case Kind::Table: return "table";
    case Kind::SpinUp: return "spin_up";
  }
  return "?";
}

std::vector<std::pair<std::string, double>> TimeFunction::parameters() const {
  switch (kind_) {
    case Kind::Ramp:
    case Kind::Hat:
      return {{"t1", a_}};
    case Kind::Triangle:
      return {{"t_peak", a_}, {"t_end", b_}};
    case Kind::SpinUp:
      return {{"T_s", a_}};
    default:
      return {};
  }
}

std::string TimeFunction::describe() const {
  std::ostringstream os;
  os.precision(12);
  os << kind_name();
  if (kind_ == Kind::Table) {
    os << "(" << points_.size() << " points)";
    return os.str();
  }
  const auto params = parameters();
  if (!params.empty()) {
    os << "(";
    for (size_t k = 0; k < params.size(); ++k) os << (k ? ", " : "") << params[k].first << "=" << params[k].second;
    os << ")";
  }
  return os.str();
}

}  // namespace shelldyn
