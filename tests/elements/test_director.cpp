// docs/theory.md §7.1 (A1/A2 vs finite differences) and §7.2 (switching invariance of p, ṗ, p̈),
// plus the §2.1 guard and §2.3 chart selection.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "elements/director.hpp"

namespace shelldyn {
namespace {

// Random unit vectors whose largest component is X, Y or Z, with either sign.
Eigen::Vector3d random_unit(std::mt19937& rng, int dominant, double sign) {
  std::uniform_real_distribution<double> U(-0.55, 0.55);
  Eigen::Vector3d p(U(rng), U(rng), U(rng));
  p(dominant) = sign;
  return p.normalized();
}

TEST(Director, SelectChartPicksLargestComponentAndSortedMinors) {
  const DirectorChart c = select_chart(Eigen::Vector3d(0.2, -0.9, 0.3).normalized());
  EXPECT_EQ(c.l, 1);
  EXPECT_EQ(c.n, 0);
  EXPECT_EQ(c.m, 2);
  EXPECT_EQ(c.s, -1.0);
  EXPECT_THROW(select_chart(Eigen::Vector3d::Zero()), std::invalid_argument);
}

TEST(Director, GuardThrowsInsteadOfClamping) {
  const DirectorChart c = select_chart(Eigen::Vector3d::UnitZ());
  EXPECT_THROW(director(Eigen::Vector2d(0.8, 0.6), c), std::domain_error);  // 1 - |q|^2 = 0
  EXPECT_THROW(director_A1(Eigen::Vector2d(1.0, 0.5), c), std::domain_error);
  EXPECT_NO_THROW(director(Eigen::Vector2d(0.7, 0.7), c));
}

// §7.1: quadratic trajectory q(t) = q0 + q1 t + q2 t^2; A1 q̇ and A1 q̈ + A2 against central FD of p(q(t)).
TEST(Director, A1A2MatchFiniteDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  double worst1 = 0, worst2 = 0, worst_closed = 0;
  for (int dom = 0; dom < 3; ++dom) {
    for (double sign : {1.0, -1.0}) {
      const Eigen::Vector3d p = random_unit(rng, dom, sign);
      const DirectorChart ch = select_chart(p);
      ASSERT_EQ(ch.l, dom);
      const Eigen::Vector2d q0(p(ch.n), p(ch.m)), q1(U(rng), U(rng)), q2(U(rng), U(rng));
      auto P = [&](double t) { return director(q0 + q1 * t + q2 * t * t, ch); };
      const double h = 1e-4;
      const Eigen::Vector3d pd_fd = (P(h) - P(-h)) / (2 * h);
      const Eigen::Vector3d pdd_fd = (P(h) - 2 * P(0) + P(-h)) / (h * h);
      const Eigen::Vector2d qd = q1, qdd = 2 * q2;
      const Eigen::Vector3d pd = director_A1(q0, ch) * qd;
      const Eigen::Vector3d A2 = director_A2(q0, qd, ch);
      const Eigen::Vector3d pdd = director_A1(q0, ch) * qdd + A2;
      worst1 = std::max(worst1, (pd - pd_fd).norm() / pd.norm());
      worst2 = std::max(worst2, (pdd - pdd_fd).norm() / pdd.norm());
      // A2 from the general second-derivative definition Σ_ab ∂²p/∂q_a∂q_b q̇_a q̇_b (only component l).
      Eigen::Vector3d A2_def = Eigen::Vector3d::Zero();
      A2_def(ch.l) = qd.dot(director_d2pl(q0, ch) * qd);
      worst_closed = std::max(worst_closed, (A2 - A2_def).norm() / A2.norm());
      // The unit-length constraint implies p·ṗ = 0 and p·p̈ = -|ṗ|^2.
      EXPECT_NEAR(P(0).dot(pd), 0.0, 1e-14);
      EXPECT_NEAR(P(0).dot(pdd), -pd.squaredNorm(), 1e-13);
    }
  }
  // FD error: truncation h^2 ~ 1e-8 relative for ṗ is dominated by the h^2 term; p̈ adds round-off
  // 1e-16/h^2 = 1e-8. Both are bounded by 1e-7.
  EXPECT_LT(worst1, 1e-7) << worst1;
  EXPECT_LT(worst2, 1e-6) << worst2;
  EXPECT_LT(worst_closed, 1e-14) << worst_closed;
  RecordProperty("A1_fd_rel_err", std::to_string(worst1));
  RecordProperty("A2_fd_rel_err", std::to_string(worst2));
}

// §7.2: converting (q, q̇, q̈) to another admissible chart and back leaves p, ṗ, p̈ unchanged.
TEST(Director, RechartKeepsPVelocityAndAcceleration) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    // A director just past the X/Z diagonal so that the chart selected for Z is out of date.
    Eigen::Vector3d p(0.70 + 0.02 * std::abs(U(rng)), 0.2 * U(rng), 0.65);
    p.normalize();
    DirectorChart ch{0, 1, 2, 1.0};  // stale chart: Z dependent
    Eigen::Vector2d q = chart_coordinates(p, ch), qd(U(rng), U(rng)), qdd(U(rng), U(rng));
    const Eigen::Vector3d pd = director_A1(q, ch) * qd;
    const Eigen::Vector3d pdd = director_A1(q, ch) * qdd + director_A2(q, qd, ch);
    ASSERT_TRUE(rechart(q, qd, qdd, ch));
    EXPECT_EQ(ch.l, 0);
    EXPECT_EQ(ch.n, 1);
    EXPECT_EQ(ch.m, 2);
    EXPECT_LT((director(q, ch) - p).norm(), 1e-15);
    EXPECT_LT((director_A1(q, ch) * qd - pd).norm(), 1e-14 * pd.norm());
    EXPECT_LT((director_A1(q, ch) * qdd + director_A2(q, qd, ch) - pdd).norm(), 1e-14 * pdd.norm());
    EXPECT_FALSE(rechart(q, qd, qdd, ch));  // now up to date: no switch
  }
}

TEST(Director, RechartHysteresisDelaysTheSwitch) {
  Eigen::Vector3d p(0.72, 0.1, 0.68);
  p.normalize();
  DirectorChart ch{0, 1, 2, 1.0};
  Eigen::Vector2d q = chart_coordinates(p, ch), qd(0.1, 0.2), qdd(0.0, 0.3);
  EXPECT_FALSE(rechart(q, qd, qdd, ch, 1.2));  // |p_x| < 1.2 |p_z|: keep chart
  EXPECT_TRUE(rechart(q, qd, qdd, ch, 1.0));
  EXPECT_THROW(rechart(q, qd, qdd, ch, 0.5), std::invalid_argument);
}

}  // namespace
}  // namespace shelldyn
