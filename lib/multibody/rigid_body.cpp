// Rigid body in director form (docs/theory/multibody.md §3).
#include "lib/multibody/rigid_body.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace shelldyn::multibody {

namespace {
// The (i, j) pairs of the six orthonormality conditions, in the documented order.
constexpr int kPairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
}  // namespace

RigidBody::RigidBody(std::string name, double mass, const Vec3& J)
    : name_(std::move(name)), mass_(mass), J_(J) {
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("rigid body '" + name_ + "': " + why);
  };
  if (!(std::isfinite(mass) && mass > 0.0)) {
    std::ostringstream os;
    os << "mass " << mass << " must be a positive number";
    fail(os.str());
  }
  for (int i = 0; i < 3; ++i)
    if (!(std::isfinite(J(i)) && J(i) > 0.0)) {
      std::ostringstream os;
      os << "principal inertia J" << i + 1 << " = " << J(i) << " must be a positive number";
      fail(os.str());
    }
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    E_(i) = 0.5 * (J(j) + J(k) - J(i));  // §3 eq. (3.2)
    // E_i = ∫ρX_i² ≥ 0; a tiny negative value from rounding of a flat body (J_i = J_j + J_k) is clipped.
    if (E_(i) < -1e-12 * J.sum()) {
      std::ostringstream os;
      os << "principal inertias (" << J(0) << ", " << J(1) << ", " << J(2) << ") violate J" << i + 1
         << " <= J" << j + 1 << " + J" << k + 1 << " (no mass distribution has them); check the values";
      fail(os.str());
    }
    if (E_(i) < 0.0) E_(i) = 0.0;
  }
}

Mat12 RigidBody::mass_matrix() const {
  return mass_diagonal().asDiagonal();
}

Vec12 RigidBody::mass_diagonal() const {
  Vec12 m;
  m.segment<3>(0).setConstant(mass_);
  for (int i = 0; i < 3; ++i) m.segment<3>(3 + 3 * i).setConstant(E_(i));
  return m;
}

Vec12 RigidBody::state(const Vec3& phi, const Mat3& R) {
  Vec12 q;
  q.segment<3>(0) = phi;
  for (int i = 0; i < 3; ++i) q.segment<3>(3 + 3 * i) = R.col(i);
  return q;
}

Vec12 RigidBody::velocity(const Vec12& q, const Vec3& phidot, const Vec3& omega) {
  Vec12 v;
  v.segment<3>(0) = phidot;
  for (int i = 0; i < 3; ++i) v.segment<3>(3 + 3 * i) = omega.cross(Vec3(q.segment<3>(3 + 3 * i)));
  return v;
}

double RigidBody::kinetic_energy(const Vec12& v) const {
  double T = mass_ * v.segment<3>(0).squaredNorm();
  for (int i = 0; i < 3; ++i) T += E_(i) * v.segment<3>(3 + 3 * i).squaredNorm();
  return 0.5 * T;
}

Vec3 RigidBody::linear_momentum(const Vec12& v) const {
  return mass_ * v.segment<3>(0);
}

Vec3 RigidBody::angular_momentum(const Vec12& q, const Vec12& v) const {
  Vec3 J = mass_ * Vec3(q.segment<3>(0)).cross(Vec3(v.segment<3>(0)));
  for (int i = 0; i < 3; ++i) J += E_(i) * Vec3(q.segment<3>(3 + 3 * i)).cross(Vec3(v.segment<3>(3 + 3 * i)));
  return J;
}

Vec3 RigidBody::point(const Vec12& q, const Vec3& X) {
  return q.segment<3>(0) + body_vector(q, X);
}

Vec3 RigidBody::body_vector(const Vec12& q, const Vec3& a) {
  return a(0) * q.segment<3>(3) + a(1) * q.segment<3>(6) + a(2) * q.segment<3>(9);
}

Eigen::Matrix<double, 6, 1> RigidBody::orthonormality(const Vec12& q) {
  Eigen::Matrix<double, 6, 1> g;
  for (int r = 0; r < 6; ++r) {
    const int i = kPairs[r][0], j = kPairs[r][1];
    g(r) = 0.5 * (q.segment<3>(3 + 3 * i).dot(q.segment<3>(3 + 3 * j)) - (i == j ? 1.0 : 0.0));
  }
  return g;
}

Eigen::Matrix<double, 6, 12> RigidBody::orthonormality_jacobian(const Vec12& q) {
  Eigen::Matrix<double, 6, 12> G = Eigen::Matrix<double, 6, 12>::Zero();
  for (int r = 0; r < 6; ++r) {
    const int i = kPairs[r][0], j = kPairs[r][1];
    // ∂/∂d_i ½ d_i·d_j = ½ d_j (and ½ d_i for d_j; both halves land on d_i when i = j).
    G.block<1, 3>(r, 3 + 3 * i) += 0.5 * q.segment<3>(3 + 3 * j).transpose();
    G.block<1, 3>(r, 3 + 3 * j) += 0.5 * q.segment<3>(3 + 3 * i).transpose();
  }
  return G;
}

}  // namespace shelldyn::multibody
