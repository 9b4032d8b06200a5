// The extension of the system interface that an exactly energy–momentum conserving step with embedded
// director velocities needs (em-exact, docs/theory/exact-energy-momentum.md; contract:
// docs/reference/system-interface.md "Extension: ExactEnergySystem").
//
// SemiDiscreteSystem (lib/model/semi_discrete_system.hpp) speaks of generalized coordinates q only. em-exact works on
// nodal translations d_i and unit directors p_i (3 + 3 numbers per node, the chart-free "embedded" form) and
// corrects element forces so that each element's energy balance holds exactly; that needs the element level.
// A system offers it by deriving from ExactEnergySystem instead of SemiDiscreteSystem (the shell Model does);
// em-exact refuses any other system with one line. Layout assumptions: 5 DOFs per node (DofMap: ux, uy, uz and
// the two chart coordinates of the director), elements with 9 nodes (45 element DOFs).
#pragma once

#include "lib/model/semi_discrete_system.hpp"

#include <Eigen/Core>
#include <vector>

namespace shelldyn {

class ExactEnergySystem : public SemiDiscreteSystem {
 public:
  using ElementStiffness = Eigen::Matrix<double, 45, 45>;  // 9 nodes × 5 DOFs
  struct ExactForceInfo {
    int rigid_guards = 0;     // elements whose step was rigid (β = 0)
    double max_beta_z = 0.0;  // max over elements of ‖β z‖∞ / ‖F‖∞ (size of the energy correction)
    double dissipation = 0.0; // Σ_e ξ Δuᵀ G_e Δu ≥ 0 removed by the dissipative force
  };

  // Rigid bodies in director form (docs/theory/multibody.md §3) carried after the shell's unknowns: body b owns
  // u[first_dof .. first_dof + 11] = q_b − q_b(0), q_b = (φ, d₁, d₂, d₃), with the constant mass block
  // diag(m I₃, E₁ I₃, E₂ I₃, E₃ I₃) and no strain energy. The shell's unknowns are u[0 .. 5 num_nodes() − 1].
  struct RigidBlock {
    Index first_dof = 0;
    double mass = 0.0;
    Eigen::Vector3d E = Eigen::Vector3d::Zero();  // E_i = ½(J_j + J_k − J_i), J the principal inertias
  };
  virtual int num_rigid_bodies() const { return 0; }
  virtual RigidBlock rigid_block(int /*b*/) const { return {}; }

  virtual int num_nodes() const = 0;
  virtual int num_elements() const = 0;
  // Mass per unit area of the translations (ρh) and of the directors (ρh³/12): the embedded mass matrices are
  // these times the scalar mass m of scalar_mass_times().
  virtual double translational_density() const = 0;
  virtual double director_density() const = 0;
  // Configuration-dependent (follower) loads present: em-exact refuses them (its load work assumes dead loads).
  virtual bool has_follower_loads() const = 0;

  // mx = (m ⊗ I₃) x and my = (m ⊗ I₃) y in one element pass: x, y, mx, my hold one 3-vector per node;
  // m = Σ_e ∫ N_i N_j dA (consistent scalar mass).
  virtual void scalar_mass_times(const Eigen::VectorXd& x, const Eigen::VectorXd& y, Eigen::VectorXd& mx,
                                 Eigen::VectorXd& my) const = 0;
  // Strain energy U_e(u_n) of every element at the start u_n of a step (U.size() = num_elements()), bitwise the
  // energy a residual evaluated at u_n returns.
  virtual void step_energies(const Eigen::VectorXd& u_n, const std::vector<DirectorChart>& charts,
                             std::vector<double>& U) const = 0;
  // Linear local stiffness k_L at the stress-free reference state of element e (symmetric PSD, zero on rigid modes).
  virtual ElementStiffness reference_local_stiffness(int e) const = 0;
  // The corrected element forces of em-exact (theory §§3, 5): per element the strain-averaged midpoint force
  // corrected so that it does no work on rigid motions and Δuᵀ F* = U_e(u_np1) − U_n[e]; `correct` = false skips
  // the correction. xi > 0 adds the dissipative force ξ G_e Δu (k0 = (*k0)[e]). K (optional): the symmetric
  // tangent with respect to u_mid. U_np1 (optional): element energies at u_np1. p_mid (optional, 3 per node):
  // the nodal midpoint directors if the caller has them. director_weight: the director weight w of the
  // correction's metric W = diag(1 on d, w on q) (docs/theory/exact-energy-momentum.md §3); 0 = the system's own
  // choice (the Model: w = h ℓ_e per element), > 0 = this w for every element (em-exact retries a failed step with
  // w = 1, docs/theory/newton-iteration.md §4). Any w keeps both balances exact. Returns V(u_np1).
  virtual double exact_internal(const Eigen::VectorXd& u_n, const Eigen::VectorXd& u_np1,
                                const std::vector<DirectorChart>& charts, const std::vector<double>& U_n, bool correct,
                                double xi, const std::vector<ElementStiffness>* k0, double* F, SparseMatrix* K,
                                std::vector<double>* U_np1, ExactForceInfo* info,
                                const Eigen::VectorXd* p_mid = nullptr, double director_weight = 0.0) const = 0;
  // Dead loads at time t in embedded form: translational forces Fd and director loads g_i = m_i × p_mid,i
  // (3 per node each, overwritten); p_mid holds one 3-vector per node.
  virtual void embedded_external(double t, const Eigen::VectorXd& p_mid, Eigen::VectorXd& Fd, Eigen::VectorXd& g) const = 0;
};

}  // namespace shelldyn
