// Newton's method on the bordered (saddle-point) system of a step with holonomic constraints
// (docs/theory/multibody.md §9): the unknowns are u = u_{n+1} and the multipliers λ, the equations
//     r(u) + Ĝ(u)ᵀ λ = 0,        g(u, t_{n+1}) = 0,
// where r is the unconstrained step's residual and Ĝ the matrix the scheme puts the constraint force through
// (G(u_{n+1}) for galpha / newmark, the discrete gradient Ḡ(u_n, u_{n+1}) for em-galpha and em-exact).
//
// Each iteration solves
//     [ K̄ + ∂(Ĝᵀλ)/∂u   Ĝᵀ ] [δu]     [ r + Ĝᵀλ ]
//     [ G(u)             0  ] [δλ] = − [ g        ]
// by the Schur complement: with K̄ factorized once (the unconstrained step's symmetric iteration matrix, plus
// the constraint-force tangent, on the system's pattern), Z = K̄⁻¹Ĝᵀ takes m solves, S = G Z is m × m and
// dense, factorized by LU with full pivoting, and
//     S δλ = g − G K̄⁻¹ ρ,        δu = −K̄⁻¹ρ − Z δλ,          ρ = r + Ĝᵀλ.
// λ is carried in force units. The constraint rows need no scaling here: they never enter K̄'s factorization,
// and the pivoted LU of S (entries ~ βΔt² G Gᵀ/M) is unaffected by a uniform scaling such as μ = Δt²λ
// (multibody.md §9.2).
//
// Why an own loop and not KINSOL (which drives the unconstrained steps): KINSOL's N_Vector would have to carry
// [u; λ] while every residual, Jacobian and basis callback of the integrators works on u's layout over the
// system's sparsity pattern, and its linear-solver adapter expects one matrix on that pattern. The bordered
// solve only needs the K̄ factorization, m extra solves and a dense m × m LU, which this loop does directly.
// The K̄ factorization is kept over iterations (modified Newton) until the observed contraction
// ‖δu_k‖/‖δu_{k−1}‖ exceeds `refresh`; Z and S are recomputed every iteration (m solves), because G and Ĝ
// move with u and the constraint rows must be solved exactly for g → 0.
#pragma once

#include "lib/linalg/linear_solver.hpp"
#include "lib/model/semi_discrete_system.hpp"

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>

namespace shelldyn {

struct BorderedNewtonOptions {
  std::string linear_solver = "cholmod";
  int max_iters = 25;
  double res_tol = 1e-12;   // ‖r + Ĝᵀλ‖∞ / force scale
  double g_tol = 1e-12;     // ‖g‖∞ (absolute; the constraints' own units: lengths and direction cosines)
  double step_tol = 1e-14;  // max_i |δu_i| / max(1, |u_n,i|): round-off reached
  double refresh = 0.1;     // refresh K̄ when ‖δu_k‖/‖δu_{k−1}‖ exceeds this (0: every iteration)
  // Round-off floor (as em-exact's stall rule, docs/theory/newton-iteration.md §3): with ‖g‖∞ ≤ g_tol, an iterate
  // whose scaled residual is below max(stall_tol, ε max_i Σ_j |K̄_ij| max(1, ‖u_n‖∞) / scale) and did not fall
  // below half the best one before is accepted once K̄ is fresh.
  double stall_tol = 1e-8;
};

class BorderedNewton {
 public:
  using ConstraintMatrix = SemiDiscreteSystem::ConstraintMatrix;
  struct Callbacks {
    // r(u) without the constraint force (Dirichlet rows zero); returns the force scale of ‖r‖ (> 0).
    std::function<double(const Eigen::VectorXd& u, Eigen::VectorXd& r)> residual;
    // K̄(u) of the unconstrained step, without constraint tangents and before apply_dirichlet.
    std::function<void(const Eigen::VectorXd& u, SparseMatrix& J)> jacobian;
    // Ĝ(u) (m × n), the matrix of the constraint force.
    std::function<void(const Eigen::VectorXd& u, ConstraintMatrix& Ghat)> force_matrix;
    // J += ∂(Ĝ(u)ᵀλ)/∂u.
    std::function<void(const Eigen::VectorXd& u, const Eigen::VectorXd& lambda, SparseMatrix& J)> force_tangent;
    // g(u, t_{n+1}) and G(u, t_{n+1}).
    std::function<void(const Eigen::VectorXd& u, Eigen::VectorXd& g, ConstraintMatrix& G)> constraints;
  };
  struct Result {
    bool converged = false;
    int iterations = 0, factorizations = 0, residual_evals = 0;
    double residual = 0.0;  // scaled ‖r + Ĝᵀλ‖∞ at the accepted iterate
    double g_norm = 0.0;    // ‖g‖∞ at the accepted iterate
    std::string message;
  };

  BorderedNewton(std::shared_ptr<const SparsePattern> pattern, BorderedNewtonOptions options);
  const BorderedNewtonOptions& options() const { return opt_; }

  // Solves from the guess (u, λ) (λ resized to m if its size differs). `dofs`: the Dirichlet rows of K̄ and r.
  // The accepted iterate's residual and g are evaluated (both tests hold there). u_n: the step's start (scale of
  // the correction test).
  Result solve(const DofMap& dofs, const Eigen::VectorXd& u_n, Eigen::VectorXd& u, Eigen::VectorXd& lambda, Index m,
               const Callbacks& cb);

 private:
  Result solve_impl(const DofMap& dofs, const Eigen::VectorXd& u_n, Eigen::VectorXd& u, Eigen::VectorXd& lambda, Index m,
                    const Callbacks& cb);
  BorderedNewtonOptions opt_;
  std::unique_ptr<LinearSolver> solver_;
  SparseMatrix J_;
};

// Initial accelerations consistent with the constraints (the index-1 form, multibody.md §9.3):
//     M a + Gᵀλ = F_ext − F_int − F_m,        G a = −(d/dt)(G) u̇ − ∂²g/∂t² − …,
// the right side being −d²/ds² g(u + s u̇, t + s) at s = 0 less G a, taken by a central difference of
// G u̇ + ∂g/∂t along (u̇, 1) (exact for quadratic constraints). Also returns λ (size m) if lambda is non-null.
void constrained_acceleration(const SemiDiscreteSystem& sys, const State& s, const std::string& linear_solver,
                              Eigen::VectorXd& a, Eigen::VectorXd* lambda = nullptr);

}  // namespace shelldyn
