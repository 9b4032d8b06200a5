// Shared single-element fixtures for the element unit tests: flat, distorted-flat and cylindrical
// CR9 geometries, optionally rotated so that the dependent director component is X, Y or Z, and
// random deformed states. Deterministic (fixed seeds).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <random>
#include <string>

#include "elements/cr9_shell.hpp"
#include "elements/director.hpp"
#include "elements/shape_functions.hpp"

namespace shelldyn::testing {

using Vec45 = CR9Shell::Vec45;
using Mat45 = CR9Shell::Mat45;
using Charts = CR9Shell::Charts;
using Nodes = std::array<Eigen::Vector3d, 9>;

enum class Shape { Flat, Distorted, Cylinder };
// Orientation of the element: which global component the (mean) normal points along.
enum class Facing { Z, X, Y, MinusZ };

struct Geometry {
  Nodes X0, p0;
  std::string name;
};

inline std::string to_string(Shape s) {
  return s == Shape::Flat ? "flat" : s == Shape::Distorted ? "distorted" : "cylinder";
}
inline std::string to_string(Facing f) {
  return f == Facing::Z ? "Z" : f == Facing::X ? "X" : f == Facing::Y ? "Y" : "minusZ";
}

inline Eigen::Matrix3d facing_rotation(Facing f) {
  // A small generic tilt first, so that no component is exactly zero, then map +Z to the target.
  const Eigen::Matrix3d tilt =
      (Eigen::AngleAxisd(0.15, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(-0.1, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  Eigen::Matrix3d Q = Eigen::Matrix3d::Identity();
  if (f == Facing::X) Q = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  if (f == Facing::Y) Q = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  if (f == Facing::MinusZ) Q = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return Q * tilt;
}

// Element of size ~L x L. Cylinder: radius 2L, axis along Y, 0.5 rad opening, exact radial normals.
inline Geometry make_geometry(Shape shape, Facing facing, double L = 1.0) {
  Geometry g;
  g.name = to_string(shape) + "_" + to_string(facing);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int k = 0; k < 9; ++k) {
    const double xi = kNodeXi[k], eta = kNodeEta[k];
    if (shape == Shape::Cylinder) {
      const double R = 2.0 * L, phi = 0.25 * xi;
      g.X0[k] = Eigen::Vector3d(R * std::sin(phi), 0.5 * L * eta, R * std::cos(phi) - R);
      g.p0[k] = Eigen::Vector3d(std::sin(phi), 0.0, std::cos(phi));
    } else {
      g.X0[k] = Eigen::Vector3d(0.5 * L * xi, 0.5 * L * eta, 0.0);
      g.p0[k] = Eigen::Vector3d::UnitZ();
    }
  }
  if (shape == Shape::Distorted) {
    // Straight-sided quadrilateral with a general (non-parallelogram) corner set, then in-plane
    // jitter of the non-corner nodes (curved sides, off-centre middle node).
    const Eigen::Vector3d c[4] = {{-0.55 * L, -0.45 * L, 0}, {0.5 * L, -0.6 * L, 0}, {0.65 * L, 0.4 * L, 0},
                                  {-0.4 * L, 0.5 * L, 0}};
    for (int k = 0; k < 9; ++k) {
      const double xi = kNodeXi[k], eta = kNodeEta[k];
      g.X0[k] = 0.25 * ((1 - xi) * (1 - eta) * c[0] + (1 + xi) * (1 - eta) * c[1] + (1 + xi) * (1 + eta) * c[2] +
                        (1 - xi) * (1 + eta) * c[3]);
      if (k >= 4) g.X0[k] += 0.04 * L * Eigen::Vector3d(U(rng), U(rng), 0.0);
    }
  }
  const Eigen::Matrix3d Q = facing_rotation(facing);
  const Eigen::Vector3d shift(0.3 * L, -0.2 * L, 0.1 * L);
  for (int k = 0; k < 9; ++k) {
    g.X0[k] = Q * g.X0[k] + shift;
    g.p0[k] = (Q * g.p0[k]).normalized();
  }
  return g;
}

inline ShellMaterial test_material(double h = 0.05) { return ShellMaterial{1.0e6, 0.3, 7.8, h}; }

inline Charts initial_charts(const Geometry& g) {
  Charts ch;
  for (int k = 0; k < 9; ++k) ch[k] = select_chart(g.p0[k]);
  return ch;
}

// Global DOF vector from current positions x and directors p, with fresh charts selected from p.
inline Vec45 dofs_from_configuration(const Geometry& g, const Nodes& x, const Nodes& p, Charts* ch) {
  Vec45 u;
  for (int k = 0; k < 9; ++k) {
    (*ch)[k] = select_chart(p[k]);
    u.segment<3>(5 * k) = x[k] - g.X0[k];
    u.segment<2>(5 * k + 3) = chart_coordinates(p[k], (*ch)[k]);
  }
  return u;
}

inline void configuration_from_dofs(const Geometry& g, const Vec45& u, const Charts& ch, Nodes* x, Nodes* p) {
  for (int k = 0; k < 9; ++k) {
    (*x)[k] = g.X0[k] + u.segment<3>(5 * k);
    (*p)[k] = director(Eigen::Vector2d(u.segment<2>(5 * k + 3)), ch[k]);
  }
}

inline Eigen::Matrix3d random_rotation(std::mt19937& rng, double angle) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

// 45 values amp·U(−1, 1), drawn in order from std::mt19937(seed) (a random increment or direction of the DOFs).
inline Vec45 random_vector(double amp, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Vec45 v;
  for (int j = 0; j < 45; ++j) v(j) = amp * U(rng);
  return v;
}

// Random deformed state: nodal translations of size amp*L, directors turned by up to amp rad, then
// a rigid rotation by `rigid_angle` (large rotations), charts re-selected from the current directors.
inline Vec45 random_state(const Geometry& g, double amp, double rigid_angle, unsigned seed, Charts* ch,
                          double L = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const Eigen::Matrix3d Q = random_rotation(rng, rigid_angle);
  Nodes x, p;
  for (int k = 0; k < 9; ++k) {
    x[k] = Q * (g.X0[k] + amp * L * Eigen::Vector3d(U(rng), U(rng), U(rng)));
    p[k] = Q * (random_rotation(rng, amp * std::abs(U(rng))) * g.p0[k]);
  }
  return dofs_from_configuration(g, x, p, ch);
}

// Central finite differences of the force (columns) and of the energy.
inline Mat45 fd_tangent(const CR9Shell& e, const Vec45& u, const Charts& ch, double eps) {
  Mat45 K;
  for (int j = 0; j < 45; ++j) {
    Vec45 up = u, um = u, Fp, Fm;
    up(j) += eps;
    um(j) -= eps;
    e.internal(up, ch, &Fp, nullptr);
    e.internal(um, ch, &Fm, nullptr);
    K.col(j) = (Fp - Fm) / (2 * eps);
  }
  return K;
}

inline Vec45 fd_force(const CR9Shell& e, const Vec45& u, const Charts& ch, double eps) {
  Vec45 F;
  for (int j = 0; j < 45; ++j) {
    Vec45 up = u, um = u;
    up(j) += eps;
    um(j) -= eps;
    F(j) = (e.internal(up, ch, nullptr, nullptr) - e.internal(um, ch, nullptr, nullptr)) / (2 * eps);
  }
  return F;
}

}  // namespace shelldyn::testing
