// Test-only: rigid bodies in director form (docs/theory/multibody.md §3) with joints and uniform gravity behind
// the system contract (lib/model/exact_energy_system.hpp), so that the production integrators (em-exact,
// em-galpha, galpha, newmark) are checked on constrained systems with exact invariants. No shell nodes: the
// bodies are the whole unknown vector, body b owns u[12 b .. 12 b + 11] = q_b − q_b(0).
#pragma once

#include "lib/model/exact_energy_system.hpp"
#include "lib/multibody/constraints.hpp"
#include "lib/multibody/rigid_body.hpp"

#include <Eigen/Core>
#include <memory>
#include <vector>

namespace shelldyn::multibody::testing {

class RigidSystem final : public ExactEnergySystem {
 public:
  // q0: the bodies' initial configurations (12 per body), v0 their velocities. Constraints are added to
  // constraints() on the full q = q0 + u (PointMap bases 12 b).
  RigidSystem(std::vector<RigidBody> bodies, Eigen::VectorXd q0, Eigen::VectorXd v0, Vec3 gravity);

  ConstraintSet& constraints() { return set_; }
  const ConstraintSet& constraints() const { return set_; }
  const std::vector<RigidBody>& bodies() const { return bodies_; }
  Eigen::VectorXd configuration(const Eigen::VectorXd& u) const { return q0_ + u; }
  double potential(const Eigen::VectorXd& u) const;
  // Test switch: constraint_discrete_gradient returns the end-point Jacobian G(u1) (τ = 0) and its tangent the
  // Hessian at u1, to show that the conservation tests fail without the discrete gradient (multibody.md §8, §9.5).
  void use_endpoint_gradient(bool on) { endpoint_ = on; }

  // SemiDiscreteSystem
  Index num_dofs() const override { return n_; }
  std::shared_ptr<const SparsePattern> pattern() const override { return pattern_; }
  const DofMap& dofs() const override { return dofs_; }
  State initial_state() const override;
  double internal(const Eigen::VectorXd& u, const std::vector<DirectorChart>&, double* F, SparseMatrix* K) const override;
  double algorithmic_internal(const Eigen::VectorXd&, const Eigen::VectorXd& u1, const std::vector<DirectorChart>& c,
                              double, double, double* F, SparseMatrix* K) const override {
    return internal(u1, c, F, K);
  }
  void mass(const Eigen::VectorXd&, const std::vector<DirectorChart>&, SparseMatrix& M) const override;
  void inertial(const Eigen::VectorXd&, const Eigen::VectorXd&, const std::vector<DirectorChart>&, double* Fm) const override;
  void external(double, const Eigen::VectorXd&, const std::vector<DirectorChart>&, double* F) const override;
  Invariants invariants(const State& s) const override;
  double loads_end() const override { return 0.0; }
  int rechart(State&, double) override { return 0; }
  double chart_margin(const State&) const override { return 1.0; }

  Index num_constraints() const override { return set_.rows(); }
  std::vector<ConstraintBlock> constraint_blocks() const override;
  void constraint_values(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>&, Eigen::VectorXd& g) const override;
  void constraint_jacobian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>&, ConstraintMatrix& G) const override;
  void constraint_time_derivative(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>&,
                                  Eigen::VectorXd& g_t) const override;
  void constraint_discrete_gradient(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                    const std::vector<DirectorChart>&, ConstraintMatrix& G_bar, Eigen::VectorXd& tau) const override;
  void add_constraint_hessian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>&, const Eigen::VectorXd& lambda,
                              double c, SparseMatrix& K) const override;
  void add_constraint_discrete_tangent(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                       const std::vector<DirectorChart>&, const Eigen::VectorXd& lambda, double c,
                                       SparseMatrix& K) const override;

  // ExactEnergySystem: no shell nodes or elements; the bodies are rigid blocks.
  int num_rigid_bodies() const override { return static_cast<int>(bodies_.size()); }
  RigidBlock rigid_block(int b) const override;
  int num_nodes() const override { return 0; }
  int num_elements() const override { return 0; }
  double translational_density() const override { return 0.0; }
  double director_density() const override { return 0.0; }
  bool has_follower_loads() const override { return false; }
  void scalar_mass_times(const Eigen::VectorXd& x, const Eigen::VectorXd& y, Eigen::VectorXd& mx, Eigen::VectorXd& my) const override {
    mx.setZero(x.size());
    my.setZero(y.size());
  }
  void step_energies(const Eigen::VectorXd&, const std::vector<DirectorChart>&, std::vector<double>& U) const override { U.clear(); }
  ElementStiffness reference_local_stiffness(int) const override { return ElementStiffness::Zero(); }
  double exact_internal(const Eigen::VectorXd&, const Eigen::VectorXd& u1, const std::vector<DirectorChart>& c,
                        const std::vector<double>&, bool, double, const std::vector<ElementStiffness>*, double* F,
                        SparseMatrix* K, std::vector<double>* U, ExactForceInfo*, const Eigen::VectorXd*,
                        double) const override {
    if (U) U->clear();
    return internal(u1, c, F, K);
  }
  void embedded_external(double, const Eigen::VectorXd& p_mid, Eigen::VectorXd& Fd, Eigen::VectorXd& g) const override {
    Fd.setZero(p_mid.size());
    g.setZero(p_mid.size());
  }

 private:
  void add_dense(const Eigen::SparseMatrix<double>& A, double c, SparseMatrix& K) const;
  static ConstraintMatrix convert(const Eigen::SparseMatrix<double>& A);
  std::vector<RigidBody> bodies_;
  Eigen::VectorXd q0_, v0_;
  Vec3 gravity_;
  Index n_;
  DofMap dofs_;
  std::shared_ptr<const SparsePattern> pattern_;
  ConstraintSet set_;
  bool endpoint_ = false;
};

}  // namespace shelldyn::multibody::testing
