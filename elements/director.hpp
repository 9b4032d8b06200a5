// Nodal director (unit normal) parametrised by its two minor components (docs/theory.md §2).
//
// A director p (unit 3-vector) is stored per node as q = (p_n, p_m), the two global components that
// had the smallest magnitude when the node's chart was last selected; the dependent component is
// p_l = s * sqrt(1 - q1^2 - q2^2) (§2.1). All functions are pure and thread-safe.
#pragma once

#include <Eigen/Core>

namespace shelldyn {

// Choice record ch = (n, m, l, s) of docs/theory.md §2.1: n < m are the global components stored
// as the nodal unknowns q = (p_n, p_m); l is the dependent (largest) component, s = sign(p_l).
struct DirectorChart {
  int n = 0;
  int m = 1;
  int l = 2;
  double s = 1.0;
};

// §2.3 initial selection: l = argmax |p_k| (lowest index on ties), s = sign(p_l), n < m the others.
// Throws std::invalid_argument if p is zero or not finite.
DirectorChart select_chart(const Eigen::Vector3d& p);

// Throws std::invalid_argument if ch is not a permutation with n < m and s = +-1.
void check_chart(const DirectorChart& ch);

// Minor components of p in chart ch: q = (p_n, p_m) (the 2x3 selector S of §2.3 applied to p).
Eigen::Vector2d chart_coordinates(const Eigen::Vector3d& p, const DirectorChart& ch);

// p(q) of §2.1. Throws std::domain_error if 1 - |q|^2 <= 0 (the §2.1 guard: the Newton iterate
// overshot; the caller must reject the iteration and cut the step, never clamp).
Eigen::Vector3d director(const Eigen::Vector2d& q, const DirectorChart& ch);

// A1 = dp/dq (3x2), §2.2. Same guard as director().
Eigen::Matrix<double, 3, 2> director_A1(const Eigen::Vector2d& q, const DirectorChart& ch);

// d^2 p_l / dq dq (2x2), §2.2; the only nonzero second derivative of p(q).
Eigen::Matrix2d director_d2pl(const Eigen::Vector2d& q, const DirectorChart& ch);

// A2 = sum_ab (d^2 p / dq_a dq_b) qdot_a qdot_b = -(|pdot|^2 / p_l) e_l (3-vector), §2.2.
Eigen::Vector3d director_A2(const Eigen::Vector2d& q, const Eigen::Vector2d& qdot, const DirectorChart& ch);

// Re-charting between steps (§2.3). If some component of p(q) exceeds hysteresis * |p_l| in magnitude
// (hysteresis = 1: switch whenever argmax |p| != l), select the new chart and convert q, qdot, qddot
// in place so that p, pdot, pddot are unchanged (q' = S'p, qdot' = S'pdot, qddot' = S'pddot).
// Returns true if the chart was switched. Never call inside a Newton loop. hysteresis must be >= 1.
bool rechart(Eigen::Vector2d& q, Eigen::Vector2d& qdot, Eigen::Vector2d& qddot, DirectorChart& ch,
             double hysteresis = 1.0);

}  // namespace shelldyn
