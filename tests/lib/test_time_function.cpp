// Time functions of the case file's loads (lib/model/time_function.hpp; docs/benchmarks.md §1.2, §3.1).
#include "lib/model/time_function.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using shelldyn::TimeFunction;

TEST(TimeFunction, ConstantIsOneEverywhereAndNeverEnds) {
  const TimeFunction f = TimeFunction::constant();
  EXPECT_EQ(f(-1.0), 1.0);
  EXPECT_EQ(f(0.0), 1.0);
  EXPECT_EQ(f(1e9), 1.0);
  EXPECT_TRUE(std::isinf(f.end_of_support()));
}

TEST(TimeFunction, RampRisesToOneAndStays) {
  const TimeFunction f = TimeFunction::ramp(2.0);
  EXPECT_EQ(f(-0.5), 0.0);
  EXPECT_DOUBLE_EQ(f(0.5), 0.25);
  EXPECT_DOUBLE_EQ(f(2.0), 1.0);
  EXPECT_DOUBLE_EQ(f(7.0), 1.0);
  EXPECT_TRUE(std::isinf(f.end_of_support()));
}

TEST(TimeFunction, HatMatchesBenchmarkDefinition) {
  // docs/benchmarks.md §1.2: t/t1 on [0,t1], 2 - t/t1 on [t1, 2 t1], 0 after.
  const double t1 = 2.5;
  const TimeFunction f = TimeFunction::hat(t1);
  EXPECT_EQ(f(-1.0), 0.0);
  EXPECT_DOUBLE_EQ(f(1.0), 1.0 / t1);
  EXPECT_DOUBLE_EQ(f(t1), 1.0);
  EXPECT_DOUBLE_EQ(f(4.0), 2.0 - 4.0 / t1);
  EXPECT_EQ(f(5.0), 0.0);
  EXPECT_EQ(f(6.0), 0.0);
  EXPECT_DOUBLE_EQ(f.end_of_support(), 5.0);
}

TEST(TimeFunction, TriangleMatchesHemisphereLoad) {
  // docs/benchmarks.md §3.1: P(t) = (20000/3) t before 0.015, 200 - (20000/3) t until 0.03; peak 100.
  const TimeFunction f = TimeFunction::triangle(0.015, 0.03);
  for (double t : {0.001, 0.007, 0.0149}) EXPECT_NEAR(100.0 * f(t), 20000.0 / 3.0 * t, 1e-10);
  for (double t : {0.0151, 0.022, 0.0299}) EXPECT_NEAR(100.0 * f(t), 200.0 - 20000.0 / 3.0 * t, 1e-10);
  EXPECT_DOUBLE_EQ(f(0.015), 1.0);
  EXPECT_EQ(f(0.031), 0.0);
  EXPECT_DOUBLE_EQ(f.end_of_support(), 0.03);
}

TEST(TimeFunction, AsymmetricTriangle) {
  const TimeFunction f = TimeFunction::triangle(1.0, 4.0);
  EXPECT_DOUBLE_EQ(f(0.5), 0.5);
  EXPECT_DOUBLE_EQ(f(2.5), 0.5);
  EXPECT_NEAR(f(3.7), 0.1, 1e-15);
}

TEST(TimeFunction, TableInterpolatesAndHoldsEnds) {
  const TimeFunction f = TimeFunction::table({{1.0, 2.0}, {3.0, 6.0}, {4.0, 0.0}});
  EXPECT_DOUBLE_EQ(f(0.0), 2.0);   // constant before the first point
  EXPECT_DOUBLE_EQ(f(2.0), 4.0);
  EXPECT_DOUBLE_EQ(f(3.5), 3.0);
  EXPECT_DOUBLE_EQ(f(10.0), 0.0);  // constant after the last point
  EXPECT_DOUBLE_EQ(f.end_of_support(), 4.0);
}

TEST(TimeFunction, TableEndOfSupportSkipsTrailingZeros) {
  EXPECT_DOUBLE_EQ(TimeFunction::table({{0.0, 1.0}, {1.0, 0.0}, {2.0, 0.0}}).end_of_support(), 1.0);
  EXPECT_TRUE(std::isinf(TimeFunction::table({{0.0, 0.0}, {1.0, 1.0}}).end_of_support()));
  EXPECT_EQ(TimeFunction::table({{0.0, 0.0}, {1.0, 0.0}}).end_of_support(), 0.0);
  EXPECT_DOUBLE_EQ(TimeFunction::table({{2.0, 5.0}})(0.0), 5.0);
}

TEST(TimeFunction, RejectsBadParameters) {
  EXPECT_THROW(TimeFunction::hat(0.0), std::invalid_argument);
  EXPECT_THROW(TimeFunction::hat(-1.0), std::invalid_argument);
  EXPECT_THROW(TimeFunction::ramp(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(TimeFunction::triangle(0.03, 0.015), std::invalid_argument);
  EXPECT_THROW(TimeFunction::triangle(0.02, 0.02), std::invalid_argument);
  EXPECT_THROW(TimeFunction::table({}), std::invalid_argument);
  EXPECT_THROW(TimeFunction::table({{1.0, 0.0}, {1.0, 2.0}}), std::invalid_argument);
  EXPECT_THROW(TimeFunction::table({{2.0, 0.0}, {1.0, 2.0}}), std::invalid_argument);
  try {
    TimeFunction::triangle(0.03, 0.015);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("t_end"), std::string::npos) << e.what();
  }
}

TEST(TimeFunction, DescribeNamesKindAndParameters) {
  EXPECT_EQ(TimeFunction::hat(2.5).describe(), "hat(t1=2.5)");
  EXPECT_EQ(TimeFunction::triangle(1, 2).describe(), "triangle(t_peak=1, t_end=2)");
  EXPECT_EQ(TimeFunction().describe(), "constant");
}

// Spin-up of Kane, Ryan & Banerjee (1987): θ/ω_s = (1/T)[t²/2 + (T/2π)²(cos(2πt/T) − 1)] on [0, T], t − T/2 after.
TEST(TimeFunction, SpinUpMatchesKaneRyanBanerjee) {
  const double T = 15.0, pi = 3.14159265358979323846;
  const TimeFunction f = TimeFunction::spin_up(T);
  const auto theta = [&](double t) {
    return t <= T ? (t * t / 2.0 + std::pow(T / (2 * pi), 2) * (std::cos(2 * pi * t / T) - 1.0)) / T : t - T / 2;
  };
  const auto theta_dot = [&](double t) { return t <= T ? (t - T / (2 * pi) * std::sin(2 * pi * t / T)) / T : 1.0; };
  const auto theta_ddot = [&](double t) { return t <= T ? (1.0 - std::cos(2 * pi * t / T)) / T : 0.0; };
  EXPECT_EQ(f(-1.0), 0.0);
  EXPECT_EQ(f(0.0), 0.0);
  EXPECT_EQ(f.rate(0.0), 0.0);
  EXPECT_NEAR(f(T), T / 2, 1e-14 * T);
  EXPECT_NEAR(f.rate(T), 1.0, 1e-14);
  EXPECT_DOUBLE_EQ(f(25.0), 25.0 - T / 2);
  EXPECT_EQ(f.rate(25.0), 1.0);
  const double h = 1e-4;
  for (double t : {0.3, 1.0, 4.0, 7.5, 11.0, 14.9, 15.0, 15.1, 20.0}) {
    EXPECT_NEAR(f(t), theta(t), 1e-13 * (1 + theta(t))) << "t = " << t;
    EXPECT_NEAR(f.rate(t), theta_dot(t), 1e-14) << "t = " << t;
    // Central differences: f' from f and f'' from f' (C² across T, so also at t = T).
    EXPECT_NEAR((f(t + h) - f(t - h)) / (2 * h), f.rate(t), 1e-8) << "t = " << t;
    EXPECT_NEAR((f.rate(t + h) - f.rate(t - h)) / (2 * h), theta_ddot(t), 1e-7) << "t = " << t;
  }
  EXPECT_TRUE(std::isinf(f.end_of_variation()));
  EXPECT_TRUE(std::isinf(f.end_of_support()));
  EXPECT_EQ(f.describe(), "spin_up(T_s=15)");
  EXPECT_THROW(TimeFunction::spin_up(0.0), std::invalid_argument);
  EXPECT_THROW(TimeFunction::spin_up(-2.0), std::invalid_argument);
}
