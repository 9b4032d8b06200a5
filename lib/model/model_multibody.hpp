// Rigid bodies and joints of a shell Model (docs/theory/multibody.md §3, §4, §7; docs/reference/system-interface.md
// "Constraints"): the part of the Model that maps its unknowns u = [shell (5 per node) | 12 per body] to the
// positions and ℝ³ vectors the joints of lib/multibody/constraints.hpp act on, and back.
//
// Constraint space y: for every shell node a joint references, y holds its translation u (3, a node's position
// is X + u) and its director p(q) (3, through the node's chart); then, per body, q_b = q_b(0) + u_b (12). The
// joints are a multibody::ConstraintSet over y. With T = ∂y/∂u (identity for translations and bodies, the chart
// Jacobian A1(q) for directors) the system's Jacobian is G_u = G_y T, and its Hessian contraction is
// Tᵀ (Σλ∇²g_y) T + Σ_nodes w_l ∂²p_l/∂q² with w = G_yᵀλ on the director slots (only p_l is nonlinear in q).
// Columns of DOFs the DofMap fixes are dropped.
#pragma once

#include "elements/director.hpp"
#include "lib/model/dof_map.hpp"
#include "lib/model/semi_discrete_system.hpp"
#include "lib/model/time_function.hpp"
#include "lib/multibody/constraints.hpp"
#include "lib/multibody/rigid_body.hpp"

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace shelldyn {

// A rigid body as the case file gives it: principal inertias about the centre of mass, initial frame
// (columns d1, d2, d3 of `axes`, orthonormal, right-handed), initial velocity of the centre of mass and
// spatial angular velocity.
struct RigidBodyDef {
  std::string name;
  double mass = 0.0;
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
};

// One end of a joint: a shell node (its position), a body's material point (given in space at t = 0) or a
// ground point.
struct JointEnd {
  enum class Kind { none, node, body, ground };
  Kind kind = Kind::none;
  int node = -1;
  int body = -1;
  Eigen::Vector3d at = Eigen::Vector3d::Zero();  // body: the point in space at t = 0; ground: the point
  std::string describe(const std::vector<RigidBodyDef>& bodies) const;
};

struct JointDef {
  enum class Type { fixed_point, spherical, revolute, rigid_connection, prescribed_rotation };
  std::string name;
  Type type = Type::fixed_point;
  JointEnd a, b;                                       // fixed_point: a only; spherical, revolute: a and b
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();     // revolute, prescribed_rotation: in space at t = 0
  int body = -1;                                       // rigid_connection, prescribed_rotation
  std::vector<int> nodes;                              // rigid_connection
  Eigen::Vector3d point = Eigen::Vector3d::Zero();     // prescribed_rotation: the ground point on the axis
  TimeFunction angle;                                  // prescribed_rotation: θ(t) = angle_scale · angle(t)
  double angle_scale = 1.0;
};
const char* joint_type_name(JointDef::Type t);

class ModelMultibody {
 public:
  using ConstraintMatrix = SemiDiscreteSystem::ConstraintMatrix;
  using ConstraintBlock = SemiDiscreteSystem::ConstraintBlock;

  // X, normals: the shell's reference nodes and initial directors; shell_dofs = 5 × nodes. Throws
  // std::invalid_argument with a one-line message naming the body or joint on bad input.
  ModelMultibody(const std::vector<Eigen::Vector3d>& X, const std::vector<Eigen::Vector3d>& normals,
                 std::vector<RigidBodyDef> bodies, std::vector<JointDef> joints, const Eigen::Vector3d& gravity);

  Index shell_dofs() const { return shell_dofs_; }
  int num_bodies() const { return static_cast<int>(bodies_.size()); }
  Index body_first_dof(int b) const { return shell_dofs_ + 12 * static_cast<Index>(b); }
  const multibody::RigidBody& body(int b) const { return rigid_[static_cast<size_t>(b)]; }
  const RigidBodyDef& body_def(int b) const { return bodies_[static_cast<size_t>(b)]; }
  const std::vector<JointDef>& joints() const { return joints_; }
  const Eigen::Vector3d& gravity() const { return gravity_; }
  // q_b(0) = (φ0, d1(0), d2(0), d3(0)); the body's q is q_b(0) + u_b.
  const multibody::Vec12& body_q0(int b) const { return q0_[static_cast<size_t>(b)]; }
  multibody::Vec12 body_q(int b, const Eigen::VectorXd& u) const;
  // The body's initial u̇ block: φ̇ = v, ḋ_i = ω × d_i.
  multibody::Vec12 body_initial_velocity(int b) const;

  Index num_constraints() const { return set_.rows(); }
  std::vector<ConstraintBlock> blocks() const { return blocks_; }
  const multibody::ConstraintSet& set() const { return set_; }
  // DOF groups that the constraint tangents and the body mass couple (dense within a group).
  std::vector<std::vector<Index>> couplings() const;

  void values(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, Eigen::VectorXd& g) const;
  void jacobian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, const DofMap& dofs,
                ConstraintMatrix& G) const;
  void time_derivative(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                       Eigen::VectorXd& g_t) const;
  void discrete_gradient(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                         const std::vector<DirectorChart>& charts, const DofMap& dofs, ConstraintMatrix& G_bar,
                         Eigen::VectorXd& tau) const;
  // Triplets (u-space, fixed DOFs dropped) of c ∂(Gᵀλ)/∂u resp. c ∂(Ḡᵀλ)/∂u1.
  void hessian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, const Eigen::VectorXd& lambda,
               double c, const DofMap& dofs, std::vector<Eigen::Triplet<double, Index>>& out) const;
  void discrete_tangent(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                        const std::vector<DirectorChart>& charts, const Eigen::VectorXd& lambda, double c,
                        const DofMap& dofs, std::vector<Eigen::Triplet<double, Index>>& out) const;

  // Setup checks (docs/manual.md "Rigid bodies and joints"): full row rank of G at the initial state (redundant
  // or conflicting joints named), no joint on DOFs a support fixes, and the initial state satisfying the joints
  // (positions and velocities) to `tol`. Throws std::invalid_argument with one line. `advice`, if not empty, replaces
  // the generic advice of a violated joint (e.g. why the caller's initial state breaks it).
  void check_initial(const Eigen::VectorXd& u0, const Eigen::VectorXd& v0, const std::vector<DirectorChart>& charts,
                     const DofMap& dofs, double tol = 1e-8, const std::string& advice = {}) const;

 private:
  Eigen::VectorXd to_y(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts) const;
  // G_y T (u columns), fixed columns dropped; Ty: per director slot the 3 × 2 map used (A1 or its discrete form).
  void chain(const Eigen::SparseMatrix<double>& Gy, const std::vector<Eigen::Matrix<double, 3, 2>>& A, const DofMap& dofs,
             ConstraintMatrix& G) const;
  std::vector<Eigen::Matrix<double, 3, 2>> director_jacobians(const Eigen::VectorXd& u,
                                                              const std::vector<DirectorChart>& charts) const;
  void add_projected(const Eigen::SparseMatrix<double>& Hy, const std::vector<Eigen::Matrix<double, 3, 2>>& A_left,
                     const std::vector<Eigen::Matrix<double, 3, 2>>& A_right, double c, const DofMap& dofs,
                     std::vector<Eigen::Triplet<double, Index>>& out) const;
  int node_slot(int node);  // y base of a node (created on first use)

  Index shell_dofs_ = 0;
  std::vector<Eigen::Vector3d> X_, normals_;
  std::vector<RigidBodyDef> bodies_;
  std::vector<multibody::RigidBody> rigid_;
  std::vector<multibody::Vec12> q0_;
  std::vector<JointDef> joints_;
  Eigen::Vector3d gravity_;
  std::vector<int> slot_nodes_;   // node of each node slot (slot k at y[6k .. 6k + 5])
  std::vector<int> node_to_slot_; // −1 if unreferenced
  std::vector<bool> director_used_;  // per node slot: some joint reads the director
  int ny_ = 0;
  multibody::ConstraintSet set_{0};
  std::vector<ConstraintBlock> blocks_;
};

}  // namespace shelldyn
