// The interface every time integrator sees (architecture.md §1, §4.2): a semi-discrete second-order system
//     M(q) q̈ + F_m(q, q̇) + F_int(q) = F_ext(t, q)          (paper eq. 26; docs/theory.md §5.3)
// on a fixed sparsity pattern, with Dirichlet constraints and per-node director charts.
//
// The shell Model implements it; tests implement it for small linear systems (e.g. the spring–mass
// oscillator of docs/theory.md §7 item 13) so that the integrators' code is checked on problems with
// exact answers. Evaluations write into caller-owned storage; matrices are unconstrained (the
// integrator applies dofs() with apply_dirichlet).
//
// The contract for integrator authors (docs/reference/system-interface.md, which states it in full):
//   - evaluations are const and deterministic; only rechart() changes the system (its DofMap);
//   - Dirichlet rows: every iteration matrix and right-hand side goes through apply_dirichlet(dofs(), J, r), so
//     constrained entries of u stay put (0, or g(t) for prescribed DOFs) and of v, a at 0 (or the prescribed
//     rates); read dofs() afresh after each rechart() (director constraints follow the chart);
//   - chart switches: call rechart() between steps only, never inside a step's iterations; it converts u, v, a
//     (p, ṗ, p̈ and hence K, V, L, J unchanged) but nothing else the integrator carries in chart coordinates;
//   - energy: accumulate W_ext (and W_presc, W_damp) consistently with the scheme's own time discretization.
// em-exact needs more (element energies, embedded directors): the extension lib/model/exact_energy_system.hpp.
#pragma once

#include "lib/model/dof_map.hpp"
#include "lib/linalg/sparse_matrix.hpp"
#include "lib/model/state.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

namespace shelldyn {

struct Invariants {
  double kinetic = 0.0;                            // ½ q̇ᵀ M(q) q̇  (docs/theory.md §5.4)
  double strain = 0.0;                             // V(q)
  Eigen::Vector3d L = Eigen::Vector3d::Zero();     // linear momentum
  Eigen::Vector3d J = Eigen::Vector3d::Zero();     // angular momentum about the origin, director term included
};

class SemiDiscreteSystem {
 public:
  virtual ~SemiDiscreteSystem() = default;

  virtual Index num_dofs() const = 0;
  virtual std::shared_ptr<const SparsePattern> pattern() const = 0;
  virtual const DofMap& dofs() const = 0;
  virtual State initial_state() const = 0;

  // F_int(q) and its exact symmetric tangent; returns V(q). F or K may be null.
  virtual double internal(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, double* F,
                          SparseMatrix* K) const = 0;
  // Strain-averaged force of docs/theory.md §6.3 and its symmetric tangent; returns V(u_np1).
  virtual double algorithmic_internal(const Eigen::VectorXd& u_n, const Eigen::VectorXd& u_np1,
                                      const std::vector<DirectorChart>& charts, double alpha_f, double xi,
                                      double* F, SparseMatrix* K) const = 0;
  virtual void mass(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, SparseMatrix& M) const = 0;
  virtual void inertial(const Eigen::VectorXd& u, const Eigen::VectorXd& v, const std::vector<DirectorChart>& charts,
                        double* Fm) const = 0;
  // M(q) a + F_m(q, v) in one pass (overwrites out). The default assembles M; the Model multiplies
  // element by element, which is what a residual evaluation needs.
  virtual void inertia_force(const Eigen::VectorXd& u, const Eigen::VectorXd& v, const Eigen::VectorXd& a,
                             const std::vector<DirectorChart>& charts, double* out) const;
  // F_ext(t, q) (overwrites F).
  virtual void external(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                        double* F) const = 0;
  // K += −sym ∂F_ext/∂q (configuration-dependent loads); default: dead loads, nothing to add.
  virtual void add_load_stiffness(double /*t*/, const Eigen::VectorXd& /*u*/,
                                  const std::vector<DirectorChart>& /*charts*/, SparseMatrix& /*K*/) const {}
  // Rayleigh damping C = a_M M_0 + a_K K_0 (docs/theory.md §8.5). Systems with damping include C q̇ in
  // inertial() and inertia_force(); integrators add c·C to iteration matrices (c = ∂q̇/∂q of their
  // scheme) and accumulate the dissipated work with damping_force(). Default: no damping.
  virtual bool has_damping() const { return false; }
  virtual void damping_force(const Eigen::VectorXd& /*v*/, double* /*out*/) const {}       // out = C v
  virtual void add_damping_matrix(double /*c*/, SparseMatrix& /*J*/) const {}              // J += c C
  // Prescribed displacement histories (docs/theory.md §8.6): constrained translation DOFs whose value follows
  // g(t) instead of staying 0. Integrators set them at t_{n+1} before solving the step (the constrained rows of
  // the residual are zero, so Newton keeps them there), take their rates from the scheme's own relations, and
  // accumulate the work of their reactions. Default: none.
  virtual bool has_prescribed_motion() const { return false; }
  // The prescribed DOFs (sorted, all of them constrained by dofs()).
  virtual const std::vector<Index>& prescribed_dofs() const;
  // Writes g(t) into the prescribed entries of u, resp. the right derivative ġ(t⁺) into those of v; other
  // entries are left unchanged.
  virtual void prescribed_displacement(double /*t*/, double* /*u*/) const {}
  virtual void prescribed_velocity(double /*t*/, double* /*v*/) const {}
  virtual Invariants invariants(const State& s) const = 0;
  // Time after which F_ext vanishes identically and prescribed displacements stop moving (+inf if never; 0 if
  // there are no loads).
  virtual double loads_end() const = 0;

  // ---- Holonomic constraints (docs/theory/multibody.md §1, §7; docs/reference/system-interface.md) ----------
  // m = num_constraints() equations g(u, t) = 0, enforced with multipliers λ (size m):
  //     M(q) q̈ + F_m + F_int + G(u, t)ᵀ λ = F_ext,      g(u, t) = 0,      G = ∂g/∂u   (m × num_dofs()).
  // A system without joints keeps the defaults (m = 0) and every integrator behaves as before. Rows and columns
  // are over the same unknowns u as everything above (the system maps them to positions and ℝ³ directors);
  // columns of DOFs that dofs() constrains are left out (zero), so apply_dirichlet and G commute. Integrators
  // that cannot treat constraints refuse a system with m > 0 in one line.
  struct ConstraintBlock {
    std::string type;        // "fixed point", "spherical joint", "revolute joint", "orthonormality", ...
    std::string name;        // the user's name of the joint (or body), for messages and history columns
    Index first_row = 0;     // rows first_row .. first_row + rows − 1 of g
    Index rows = 0;
  };
  using ConstraintMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, Index>;  // m × num_dofs()
  virtual Index num_constraints() const { return 0; }
  virtual std::vector<ConstraintBlock> constraint_blocks() const { return {}; }
  // g(u, t) (resized to m).
  virtual void constraint_values(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                                 Eigen::VectorXd& g) const;
  // G = ∂g/∂u at (u, t) (resized to m × num_dofs()).
  virtual void constraint_jacobian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                                   ConstraintMatrix& G) const;
  // ∂g/∂t at (u, t) (resized to m; zero for scleronomic joints): the velocity-level condition is G u̇ + ∂g/∂t = 0.
  virtual void constraint_time_derivative(double t, const Eigen::VectorXd& u,
                                          const std::vector<DirectorChart>& charts, Eigen::VectorXd& g_t) const;
  // A discrete gradient (Ḡ, τ) over one step (multibody.md §2.1–2.3): exactly, to round-off,
  //     Ḡ (u1 − u0) + τ = g(u1, t1) − g(u0, t0),
  // with τ = 0 for scleronomic joints; λ·τ is a driver's discrete work. Linear g: Ḡ = G; quadratic: G(u_mid).
  // Both ends share `charts` (charts change only between steps).
  virtual void constraint_discrete_gradient(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                            const std::vector<DirectorChart>& charts, ConstraintMatrix& G_bar,
                                            Eigen::VectorXd& tau) const;
  // Newton tangents of the constraint force (multibody.md §5.1), added into K on entries of pattern() (the
  // system's pattern includes the couplings its constraints create):
  //   add_constraint_hessian:           K += c ∂(G(u, t)ᵀ λ)/∂u             (index-3 schemes, GGL);
  //   add_constraint_discrete_tangent:  K += c ∂(Ḡ(u0, u1)ᵀ λ)/∂u1          (conserving steps).
  // Both are zero for linear constraints (the defaults add nothing).
  virtual void add_constraint_hessian(double /*t*/, const Eigen::VectorXd& /*u*/,
                                      const std::vector<DirectorChart>& /*charts*/, const Eigen::VectorXd& /*lambda*/,
                                      double /*c*/, SparseMatrix& /*K*/) const {}
  virtual void add_constraint_discrete_tangent(double /*t0*/, const Eigen::VectorXd& /*u0*/, double /*t1*/,
                                               const Eigen::VectorXd& /*u1*/,
                                               const std::vector<DirectorChart>& /*charts*/,
                                               const Eigen::VectorXd& /*lambda*/, double /*c*/,
                                               SparseMatrix& /*K*/) const {}

  // Re-selects director charts between steps (docs/theory.md §2.3), converting u, v, a so that p, ṗ, p̈
  // are unchanged; returns the number of switched nodes. Systems without directors return 0.
  virtual int rechart(State& s, double hysteresis = 1.0) = 0;
  // How far each director may still turn before its chart should switch: min over nodes of
  // |p_l| − max(|p_n|, |p_m|) (≥ 0 while the chart is the best one). Root functions of adaptive
  // integrators stop where this crosses zero. Systems without directors return +1.
  virtual double chart_margin(const State& s) const = 0;

  // A kept iteration matrix seen from another configuration (docs/theory.md §6.9). The matrix was formed at
  // (u_ref, charts_ref); the unknowns now are (u, charts). Returns true when some block T_i of δu_ref = T δu
  // differs from the identity, and then fills, per node i, the inverse of the 5 × 5 block T_i as
  // node_inverse[25 i ..] (row-major); returns false (T = I) without touching node_inverse. `rotate`: T carries the rigid rotation R that best maps the nodes at u_ref onto those at u
  // (T_d = Rᵀ, T_q = S_ref Rᵀ A1(q)); otherwise R = I and only nodes whose chart switched have T_i ≠ I.
  // Throws std::domain_error when the change cannot be represented (the caller then refreshes the matrix).
  // Systems without directors return false (no change).
  virtual bool kept_matrix_basis(const Eigen::VectorXd& /*u_ref*/, const std::vector<DirectorChart>& /*charts_ref*/,
                                 const Eigen::VectorXd& /*u*/, const std::vector<DirectorChart>& /*charts*/,
                                 bool /*rotate*/, std::vector<double>& /*node_inverse*/) const {
    return false;
  }
};

}  // namespace shelldyn
