// Director parametrisation by minor components: docs/theory.md §2.1-2.3.
#include "elements/director.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

namespace {

// p_l^2 = 1 - |q|^2 must stay positive (§2.1 guard); returns p_l.
double dependent_component(const Eigen::Vector2d& q, const DirectorChart& ch) {
  const double r = 1.0 - q.squaredNorm();
  if (!(r > 0.0)) {
    std::ostringstream os;
    os << "director: minor components q = (" << q(0) << ", " << q(1) << ") give 1 - |q|^2 = " << r
       << " <= 0 (dependent component " << "XYZ"[ch.l]
       << " lost); the Newton iterate overshot -- reject the iteration and cut the step (docs/theory.md §2.1)";
    throw std::domain_error(os.str());
  }
  return ch.s * std::sqrt(r);
}

}  // namespace

void check_chart(const DirectorChart& ch) {
  const bool perm = ch.n >= 0 && ch.m >= 0 && ch.l >= 0 && ch.n <= 2 && ch.m <= 2 && ch.l <= 2 &&
                    ch.n < ch.m && ch.l != ch.n && ch.l != ch.m;
  if (!perm || !(ch.s == 1.0 || ch.s == -1.0)) {
    std::ostringstream os;
    os << "DirectorChart (n=" << ch.n << ", m=" << ch.m << ", l=" << ch.l << ", s=" << ch.s
       << ") is invalid: need a permutation of {0,1,2} with n < m and s = +1 or -1 (use select_chart)";
    throw std::invalid_argument(os.str());
  }
}

DirectorChart select_chart(const Eigen::Vector3d& p) {
  if (!p.allFinite() || p.norm() == 0.0) {
    std::ostringstream os;
    os << "select_chart: director (" << p.transpose() << ") is zero or not finite; pass a unit normal";
    throw std::invalid_argument(os.str());
  }
  DirectorChart ch;
  ch.l = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(p(k)) > std::abs(p(ch.l))) ch.l = k;
  ch.n = ch.l == 0 ? 1 : 0;
  ch.m = ch.l == 2 ? 1 : 2;
  ch.s = p(ch.l) >= 0.0 ? 1.0 : -1.0;
  return ch;
}

Eigen::Vector2d chart_coordinates(const Eigen::Vector3d& p, const DirectorChart& ch) {
  return Eigen::Vector2d(p(ch.n), p(ch.m));
}

Eigen::Vector3d director(const Eigen::Vector2d& q, const DirectorChart& ch) {
  Eigen::Vector3d p;
  p(ch.n) = q(0);
  p(ch.m) = q(1);
  p(ch.l) = dependent_component(q, ch);  // §2.1: p_l = s sqrt(1 - q1^2 - q2^2)
  return p;
}

Eigen::Matrix<double, 3, 2> director_A1(const Eigen::Vector2d& q, const DirectorChart& ch) {
  const double pl = dependent_component(q, ch);
  Eigen::Matrix<double, 3, 2> A1;
  A1.row(ch.n) << 1.0, 0.0;
  A1.row(ch.m) << 0.0, 1.0;
  A1.row(ch.l) << -q(0) / pl, -q(1) / pl;  // §2.2: row l = [-p_n/p_l, -p_m/p_l]
  return A1;
}

Eigen::Matrix2d director_d2pl(const Eigen::Vector2d& q, const DirectorChart& ch) {
  const double pl = dependent_component(q, ch);
  Eigen::Matrix2d H;
  H << 1.0 - q(1) * q(1), q(0) * q(1), q(0) * q(1), 1.0 - q(0) * q(0);
  return (-1.0 / (pl * pl * pl)) * H;  // §2.2
}

Eigen::Vector3d director_A2(const Eigen::Vector2d& q, const Eigen::Vector2d& qdot, const DirectorChart& ch) {
  const double pl = dependent_component(q, ch);
  const double pl_dot = -(q(0) * qdot(0) + q(1) * qdot(1)) / pl;
  const double pdot2 = qdot.squaredNorm() + pl_dot * pl_dot;
  Eigen::Vector3d A2 = Eigen::Vector3d::Zero();
  A2(ch.l) = -pdot2 / pl;  // §2.2 closed form, from d^2/dt^2 (p.p) = 0
  return A2;
}

bool rechart(Eigen::Vector2d& q, Eigen::Vector2d& qdot, Eigen::Vector2d& qddot, DirectorChart& ch,
             double hysteresis) {
  if (!(hysteresis >= 1.0)) {
    std::ostringstream os;
    os << "rechart: hysteresis = " << hysteresis << " must be >= 1 (1 = switch whenever argmax|p| != l)";
    throw std::invalid_argument(os.str());
  }
  const Eigen::Vector3d p = director(q, ch);
  const DirectorChart nc = select_chart(p);
  if (nc.l == ch.l || !(std::abs(p(nc.l)) > hysteresis * std::abs(p(ch.l)))) return false;
  // §2.3 conversion: p, pdot, pddot are kept; only their coordinates change.
  const Eigen::Matrix<double, 3, 2> A1 = director_A1(q, ch);
  const Eigen::Vector3d pdot = A1 * qdot;
  const Eigen::Vector3d pddot = A1 * qddot + director_A2(q, qdot, ch);
  q = chart_coordinates(p, nc);
  qdot = chart_coordinates(pdot, nc);
  qddot = chart_coordinates(pddot, nc);
  ch = nc;
  return true;
}

}  // namespace shelldyn
