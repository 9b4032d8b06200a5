// MITC9 tying data, docs/theory.md §4.4.
#include "elements/mitc9.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace shelldyn {

namespace {

const double kA = 1.0 / std::sqrt(3.0);
const double kB = std::sqrt(3.0 / 5.0);

// Linear interpolation through -a, +a and quadratic through -b, 0, +b (§4.4).
double lin(int i, double s) { return i == 0 ? 0.5 * (1.0 - s / kA) : 0.5 * (1.0 + s / kA); }
double quad(int i, double s) {
  if (i == 0) return s * (s - kB) / (2.0 * kB * kB);
  if (i == 1) return 1.0 - s * s / (kB * kB);
  return s * (s + kB) / (2.0 * kB * kB);
}

std::array<Mitc9Family, 3> make_families() {
  std::array<Mitc9Family, 3> f;
  const double la[2] = {-kA, kA};
  const double qb[3] = {-kB, 0.0, kB};
  // Point index = i * (#eta values) + j, matching mitc9_weights below.
  f[0].count = 6;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 3; ++j) f[0].xi[i * 3 + j] = la[i], f[0].eta[i * 3 + j] = qb[j];
  f[1].count = 6;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) f[1].xi[i * 2 + j] = qb[i], f[1].eta[i * 2 + j] = la[j];
  f[2].count = 4;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) f[2].xi[i * 2 + j] = la[i], f[2].eta[i * 2 + j] = la[j];
  return f;
}

}  // namespace

const Mitc9Family& mitc9_family(int family) {
  static const std::array<Mitc9Family, 3> families = make_families();
  if (family < 0 || family > 2)
    throw std::invalid_argument("mitc9_family: family " + std::to_string(family) + " not in {0,1,2}");
  return families[family];
}

Eigen::Matrix<double, 6, 1> mitc9_weights(int family, double xi, double eta) {
  Eigen::Matrix<double, 6, 1> w = Eigen::Matrix<double, 6, 1>::Zero();
  if (family == 0) {
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 3; ++j) w(i * 3 + j) = lin(i, xi) * quad(j, eta);
  } else if (family == 1) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 2; ++j) w(i * 2 + j) = quad(i, xi) * lin(j, eta);
  } else if (family == 2) {
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) w(i * 2 + j) = lin(i, xi) * lin(j, eta);
  } else {
    throw std::invalid_argument("mitc9_weights: family " + std::to_string(family) + " not in {0,1,2}");
  }
  return w;
}

}  // namespace shelldyn
