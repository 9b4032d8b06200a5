// Test-only: a conserving step for rigid bodies in director form with holonomic constraints
// (docs/theory/multibody.md §5). Constant mass matrix, uniform gravity, multipliers on the discrete gradient:
//     (2/Δt) M (q1 − q0) − 2 M v0 + Δt ∇V + Ḡ(q0, q1)ᵀ μ = 0,      g(q1, t1) = 0,      v1 = 2(q1 − q0)/Δt −
//     v0,
// solved by Newton on the saddle-point system with a dense LU. With GradientChoice::endpoint Ḡ is replaced by
// G(q1) (the non-conserving variant the tests use to show the discrete gradient matters).
#pragma once

#include "lib/multibody/constraints.hpp"
#include "lib/multibody/rigid_body.hpp"

#include <Eigen/Core>
#include <vector>

namespace shelldyn::multibody::testing {

enum class GradientChoice { discrete, endpoint };

// The choice the conservation tests use: discrete, unless SHELLDYN_TEST_ENDPOINT_G=1 in the environment (the
// switch that shows those tests fail with the end-point Jacobian).
GradientChoice default_choice();

struct DirectorSystem {
  std::vector<RigidBody> bodies;  // body i owns q[12 i .. 12 i + 11]
  ConstraintSet constraints;
  Vec3 gravity = Vec3::Zero();

  explicit DirectorSystem(std::vector<RigidBody> b)
      : bodies(std::move(b)), constraints(12 * static_cast<int>(bodies.size())) {}
  int n() const { return 12 * static_cast<int>(bodies.size()); }
  static int base(int body) { return 12 * body; }
  Eigen::VectorXd mass_diagonal() const;
  double potential(const Eigen::VectorXd& q) const;  // −Σ m g·φ
  double energy(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
  Vec3 linear_momentum(const Eigen::VectorXd& v) const;
  Vec3 angular_momentum(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
};

struct StepResult {
  Eigen::VectorXd q, v;
  Eigen::VectorXd lambda;   // λ_{n+1/2} = μ/Δt, the constraint forces are −Ḡᵀλ
  double drive_work = 0.0;  // λ·τ, the driver's discrete work (§4.4)
  int iterations = 0;
};

StepResult step(const DirectorSystem& sys, const Eigen::VectorXd& q0, const Eigen::VectorXd& v0, double t0,
                double dt, GradientChoice choice);

}  // namespace shelldyn::multibody::testing
