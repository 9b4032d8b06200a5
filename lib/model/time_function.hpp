// Scalar load-amplitude functions of time f(t), used by the case file's `loads[].function`
// (docs/benchmarks.md §1.2 hat, §3.1 triangle) and the joints' `angle` (spin_up, docs/benchmarks.md §7.4).
// All functions are 0 for t < 0 except `constant`.
//
// A TimeFunction is a small immutable value; construct it with the named factories, which validate
// their parameters and throw std::invalid_argument naming the parameter and the accepted range.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

class TimeFunction {
 public:
  enum class Kind { Constant, Ramp, Hat, Triangle, Table, SpinUp };

  // f(t) = 1 for all t.
  static TimeFunction constant();
  // f(t) = min(t/t1, 1) for t >= 0, 0 for t < 0. Requires t1 > 0.
  static TimeFunction ramp(double t1);
  // Symmetric hat of docs/benchmarks.md §1.2: t/t1 on [0, t1], 2 - t/t1 on [t1, 2 t1], 0 after. t1 > 0.
  static TimeFunction hat(double t1);
  // Triangle of docs/benchmarks.md §3.1: 0 -> 1 on [0, t_peak], 1 -> 0 on [t_peak, t_end], 0 after.
  // Requires 0 < t_peak < t_end.
  static TimeFunction triangle(double t_peak, double t_end);
  // Piecewise linear through (t_k, f_k); constant (f_0 resp. f_last) beyond the ends. At least one
  // point, times strictly increasing, all values finite.
  static TimeFunction table(std::vector<std::pair<double, double>> points);
  // The spin-up manoeuvre of Kane, Ryan & Banerjee (J. Guidance 10(2), 1987), per unit final rate:
  // f(t) = (1/T_s)[t²/2 + (T_s/2π)²(cos(2πt/T_s) − 1)] on [0, T_s], then t − T_s/2 (unbounded: a
  // prescribed_rotation's θ = ω_s f). f, f' and f'' are continuous; f(0) = f'(0) = f''(0) = 0, f'(T_s) = 1,
  // f''(T_s) = 0. Requires T_s > 0.
  static TimeFunction spin_up(double T_s);

  TimeFunction() : TimeFunction(constant()) {}

  double operator()(double t) const;
  // Right derivative f'(t⁺): for the piecewise linear functions the slope of the piece that starts at t (0
  // where f is constant); for spin_up (smooth) its derivative. Prescribed displacement histories take their
  // initial velocity from it (docs/theory.md §8.6), prescribed rotations their ∂g/∂t.
  double rate(double t) const;
  // Time after which f is constant for good (0 if it never changes for t > 0; +inf for spin_up). A prescribed displacement
  // a·f(t) stops moving then, and its supports do no more work (docs/theory.md §8.6).
  double end_of_variation() const;
  // Time after which f is identically 0, or +inf if it never vanishes for good. Loads whose
  // functions have all ended leave the system free (docs/benchmarks.md §0: H = K + V_int afterwards).
  double end_of_support() const;

  Kind kind() const { return kind_; }
  const char* kind_name() const;
  // The defining parameters in the case-file vocabulary, e.g. {{"t1", 2.5}} for a hat.
  std::vector<std::pair<std::string, double>> parameters() const;
  const std::vector<std::pair<double, double>>& table_points() const { return points_; }
  // One-line human-readable form, e.g. "hat(t1=2.5)".
  std::string describe() const;

 private:
  TimeFunction(Kind kind, double a, double b) : kind_(kind), a_(a), b_(b) {}
  Kind kind_;
  double a_ = 0.0;  // ramp/hat: t1; triangle: t_peak; spin_up: T_s
  double b_ = 0.0;  // triangle: t_end
  std::vector<std::pair<double, double>> points_;  // table only
};

}  // namespace shelldyn
