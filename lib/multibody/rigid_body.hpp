// A rigid body in director (rotationless) form (docs/theory/multibody.md §3).
//
// The body's unknowns are q_rb = (φ, d1, d2, d3) ∈ ℝ¹²: the centre of mass φ and the body frame d_i, which
// is orthonormal only through the six quadratic constraints ½(d_i·d_j − δ_ij) = 0. A material point with
// principal-axis coordinates X (relative to the centre of mass) sits at x = φ + Σ X_k d_k, linear in q_rb,
// so the kinetic energy ½∫ρ|ẋ|² dV = ½ m|φ̇|² + ½ Σ E_i |ḋ_i|² has the constant mass matrix
// diag(m I, E1 I, E2 I, E3 I) with the Euler-tensor entries E_i = ∫ρ X_i² dV = ½(J_j + J_k − J_i).
#pragma once

#include <Eigen/Core>
#include <string>

namespace shelldyn::multibody {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

class RigidBody {
 public:
  // mass > 0 and the principal inertias J (about the centre of mass, along d1, d2, d3) > 0 satisfying the
  // triangle inequalities J_i ≤ J_j + J_k (otherwise E_i < 0: no body has that inertia). Throws
  // std::invalid_argument with a one-line reason naming the body.
  RigidBody(std::string name, double mass, const Vec3& principal_inertia);

  const std::string& name() const { return name_; }
  double mass() const { return mass_; }
  const Vec3& principal_inertia() const { return J_; }
  // E_i = ½(J_j + J_k − J_i), §3 eq. (3.2).
  const Vec3& euler_tensor() const { return E_; }

  // Constant 12 × 12 mass matrix diag(m I, E1 I, E2 I, E3 I) and its diagonal.
  Mat12 mass_matrix() const;
  Vec12 mass_diagonal() const;

  // q from the centre of mass and a rotation matrix (d_i = R e_i); q̇ from the centre-of-mass velocity and
  // the spatial angular velocity ω (ḋ_i = ω × d_i).
  static Vec12 state(const Vec3& phi, const Mat3& R);
  static Vec12 velocity(const Vec12& q, const Vec3& phidot, const Vec3& omega);

  double kinetic_energy(const Vec12& qdot) const;
  Vec3 linear_momentum(const Vec12& qdot) const;
  // About the origin: φ × mφ̇ + Σ E_i d_i × ḋ_i (§3 eq. (3.4)).
  Vec3 angular_momentum(const Vec12& q, const Vec12& qdot) const;

  // Attachment point x = φ + Σ X_k d_k and the body vector Σ a_k d_k (no φ).
  static Vec3 point(const Vec12& q, const Vec3& X);
  static Vec3 body_vector(const Vec12& q, const Vec3& a);

  // The six orthonormality conditions ½(d_i·d_j − δ_ij), ordered (11, 22, 33, 12, 13, 23), and their 6 × 12
  // Jacobian (zero in the φ columns).
  static Eigen::Matrix<double, 6, 1> orthonormality(const Vec12& q);
  static Eigen::Matrix<double, 6, 12> orthonormality_jacobian(const Vec12& q);

 private:
  std::string name_;
  double mass_;
  Vec3 J_, E_;
};

}  // namespace shelldyn::multibody
