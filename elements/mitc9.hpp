// MITC9 assumed covariant strain tying (Bucalem & Bathe 1993), docs/theory.md §4.4 (a substitution
// for the unreachable scheme of the paper's ref. [13], see §0).
//
// Three families of tying points in (xi, eta), a = 1/sqrt(3), b = sqrt(3/5):
//   A (6 points): e_xixi and g_xi,   xi in {-a,+a} x eta in {-b,0,+b},  weight L_i(xi) Q_j(eta)
//   B (6 points): e_etaeta and g_eta, xi in {-b,0,+b} x eta in {-a,+a}, weight Q_i(xi) L_j(eta)
//   C (4 points): e_xieta,            xi, eta in {-a,+a},               weight L_i(xi) L_j(eta)
#pragma once

#include <Eigen/Core>
#include <array>

namespace shelldyn {

struct Mitc9Family {
  int count = 0;
  std::array<double, 6> xi{}, eta{};  // tying point coordinates (first `count` used)
};

// Tying points of families 0 = A, 1 = B, 2 = C.
const Mitc9Family& mitc9_family(int family);

// Interpolation weights of the family's tying points at (xi, eta); entries beyond `count` are 0.
Eigen::Matrix<double, 6, 1> mitc9_weights(int family, double xi, double eta);

}  // namespace shelldyn
