#include "integrators/nonlinear/path_following.hpp"

#include <cmath>
#include <cstdio>

namespace shelldyn {

std::string ConvergenceTest::Values::describe(const ConvergenceTest& t) const {
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "residual test %s: |R| = %.3g vs residual_tol %.1e x F_ref %.3g; increment test %s: |du| = %.3g vs "
                "increment_tol %.1e x D_ref %.3g, director |dq| = %.3g",
                residual_ok ? "met" : "failed", residual, t.residual_tol, force_ref, increment_ok ? "met" : "failed", dd,
                t.increment_tol, disp_ref, dq);
  return buf;
}

double translational_dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const std::vector<char>& translational) {
  double s = 0.0;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    if (translational[static_cast<size_t>(i)]) s += a[i] * b[i];
  return s;
}

double translational_norm(const Eigen::VectorXd& v, const std::vector<char>& translational) {
  return std::sqrt(translational_dot(v, v, translational));
}

bool arc_length_root(const Eigen::VectorXd& du, const Eigen::VectorXd& du_r, const Eigen::VectorXd& du_f,
                     const std::vector<char>& translational, double dl, double* dlambda) {
  const Eigen::VectorXd w = du + du_r;
  const double a = translational_dot(du_f, du_f, translational);
  const double b = 2.0 * translational_dot(du_f, w, translational);
  const double c = translational_dot(w, w, translational) - dl * dl;
  if (!(a > 0.0)) return false;
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  const double q = -0.5 * (b + (b >= 0 ? sq : -sq));  // stable roots
  const double r1 = q / a, r2 = q != 0.0 ? c / q : -r1;
  // Usual choice: the root whose new increment Δu + δu_R + δλ δu_F points most along the current Δu.
  const double c1 = translational_dot(w + r1 * du_f, du, translational);
  const double c2 = translational_dot(w + r2 * du_f, du, translational);
  *dlambda = c1 >= c2 ? r1 : r2;
  return std::isfinite(*dlambda);
}

}  // namespace shelldyn
