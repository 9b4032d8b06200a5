// Biquadratic Lagrange shape functions of the 9-node quadrilateral and 3x3 Gauss rule
// (docs/theory.md §1, §4.1). Node order (0-based index = node - 1):
//
//      4 ---- 7 ---- 3        eta
//      |             |         ^
//      8      9      6         |
//      |             |         +--> xi
//      1 ---- 5 ---- 2
#pragma once

#include <Eigen/Core>
#include <array>

namespace shelldyn {

// Natural coordinates of the nodes, §1.
inline constexpr std::array<double, 9> kNodeXi = {-1, 1, 1, -1, 0, 1, 0, -1, 0};
inline constexpr std::array<double, 9> kNodeEta = {-1, -1, 1, 1, -1, 0, 1, 0, 0};

namespace detail {
// 1-D quadratic Lagrange polynomials through -1, 0, +1 (§4.1), selected by the node coordinate c.
inline double lagrange1d(double c, double s) {
  if (c < -0.5) return 0.5 * s * (s - 1.0);
  if (c > 0.5) return 0.5 * s * (s + 1.0);
  return 1.0 - s * s;
}
inline double lagrange1d_deriv(double c, double s) {
  if (c < -0.5) return s - 0.5;
  if (c > 0.5) return s + 0.5;
  return -2.0 * s;
}
}  // namespace detail

// N_k(xi, eta) = l_{xi_k}(xi) l_{eta_k}(eta).
inline Eigen::Matrix<double, 9, 1> shape_functions(double xi, double eta) {
  Eigen::Matrix<double, 9, 1> N;
  for (int k = 0; k < 9; ++k) N(k) = detail::lagrange1d(kNodeXi[k], xi) * detail::lagrange1d(kNodeEta[k], eta);
  return N;
}

// Column 0: dN/dxi, column 1: dN/deta.
inline Eigen::Matrix<double, 9, 2> shape_derivatives(double xi, double eta) {
  Eigen::Matrix<double, 9, 2> dN;
  for (int k = 0; k < 9; ++k) {
    dN(k, 0) = detail::lagrange1d_deriv(kNodeXi[k], xi) * detail::lagrange1d(kNodeEta[k], eta);
    dN(k, 1) = detail::lagrange1d(kNodeXi[k], xi) * detail::lagrange1d_deriv(kNodeEta[k], eta);
  }
  return dN;
}

// 3-point Gauss-Legendre rule on [-1, 1], used in both directions for every element integral (§4.1).
inline const std::array<double, 3>& gauss3_points() {
  static const std::array<double, 3> x = {-0.7745966692414834, 0.0, 0.7745966692414834};  // ±sqrt(0.6)
  return x;
}
inline const std::array<double, 3>& gauss3_weights() {
  static const std::array<double, 3> w = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  return w;
}

}  // namespace shelldyn
