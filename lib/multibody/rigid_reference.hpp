// An independent rigid-body reference (docs/theory/multibody.md §6): rigid bodies joined by spherical joints
// (to each other or to the ground) under uniform gravity, integrated in the classical rotation-matrix form by
// an adaptive Dormand–Prince RK5(4) at tight tolerance. It shares no code with the director form of
// rigid_body.hpp or the constraints of constraints.hpp, so it can check them.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

namespace shelldyn::multibody {

// ---- Dormand–Prince 5(4) with FSAL and the standard step-size control (§6.1) ------------------------------
struct Rk45Options {
  double rtol = 1e-12, atol = 1e-14;
  double h0 = 0.0;  // first step (0: chosen from the initial derivative)
  long max_steps = 50'000'000;
};
struct Rk45Stats {
  long accepted = 0, rejected = 0, evaluations = 0;
};
using OdeRhs = std::function<void(double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy)>;

// y at each of the increasing times in `outputs` (≥ t0); the integrator stops exactly on each of them.
// Throws std::runtime_error if the step size underflows, the state turns non-finite or max_steps is exceeded.
std::vector<Eigen::VectorXd> dormand_prince(const OdeRhs& f, double t0, const Eigen::VectorXd& y0,
                                            const std::vector<double>& outputs, const Rk45Options& opt = {},
                                            Rk45Stats* stats = nullptr);

// ---- Newton–Euler equations of spherical-joint chains (§6.2) --------------------------------------------
// Body state: centre of mass x, its velocity v, the rotation R (body → space, columns = body axes) and the
// body-frame angular velocity Ω, with ẋ = v, m v̇ = m g + Σ f, Ṙ = R Ω̂ (Poisson), J Ω̇ = −Ω × JΩ + Σ r × Rᵀf.
// The joint forces f are eliminated at every evaluation from the acceleration-level joint conditions.
struct ReferenceBody {
  double mass = 1.0;
  Eigen::Vector3d J = Eigen::Vector3d::Ones();  // principal inertias about the centre of mass
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d x = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero(),
                  omega_body = Eigen::Vector3d::Zero();
};
struct ReferenceJoint {
  int a = 0;                                     // body index
  Eigen::Vector3d ra = Eigen::Vector3d::Zero();  // joint point in a's body frame (from its centre of mass)
  int b = -1;                                    // body index, −1 for the ground
  Eigen::Vector3d rb = Eigen::Vector3d::Zero();  // in b's body frame, or the ground point
};

class SphericalChainReference {
 public:
  SphericalChainReference(std::vector<ReferenceBody> bodies, std::vector<ReferenceJoint> joints,
                          const Eigen::Vector3d& gravity);
  int num_bodies() const { return static_cast<int>(bodies_.size()); }
  static constexpr int kPerBody = 18;  // x(3) v(3) R(9, column-major) Ω(3)

  Eigen::VectorXd initial_state() const;
  void rhs(double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy) const;

  static Eigen::Vector3d position(const Eigen::VectorXd& y, int i);
  static Eigen::Vector3d velocity(const Eigen::VectorXd& y, int i);
  static Eigen::Matrix3d rotation(const Eigen::VectorXd& y, int i);
  static Eigen::Vector3d omega_body(const Eigen::VectorXd& y, int i);

  double energy(const Eigen::VectorXd& y) const;  // kinetic − m g·x
  Eigen::Vector3d linear_momentum(const Eigen::VectorXd& y) const;
  Eigen::Vector3d angular_momentum(const Eigen::VectorXd& y) const;  // about the origin
  double joint_gap(const Eigen::VectorXd& y) const;  // max over joints of |x_a + R_a r_a − (…)_b|

 private:
  std::vector<ReferenceBody> bodies_;
  std::vector<ReferenceJoint> joints_;
  Eigen::Vector3d gravity_;
};

// Compound pendulum about a fixed horizontal hinge, I_p the inertia about the hinge, l the distance from the
// hinge to the centre of mass: the exact period at amplitude θ0, T = 4 K(sin(θ0/2)) √(I_p/(m g l)) with the
// complete elliptic integral K(k) = π / (2 AGM(1, √(1 − k²))), and its small-amplitude limit 2π √(I_p/(m g
// l)).
double compound_pendulum_period(double Ip, double m, double g, double l, double theta0);
double compound_pendulum_small_period(double Ip, double m, double g, double l);

}  // namespace shelldyn::multibody
