// The first-order form shared by the SUNDIALS baselines (ida-bdf, arkode-erk, arkode-dirk) of the
// semi-discrete system M(q) q̈ + F_m(q, q̇) + F_int(q) = F_ext(t, q)   (docs/theory.md §5.3):
//
//     y = [q; v; w; d],  n + n + 2 components,
//     q̇ = v,  M(q) v̇ = F_ext − F_int − F_m,  ẇ = F_ext·v,  ḋ = vᵀ C v,
//
// where w is the external work W_ext (so every integrator reports H = K + V − W_ext the same way) and d the
// energy W_damp dissipated by Rayleigh damping C = a_M M_0 + a_K K_0 (docs/theory.md §8.5). F_m of a damped
// system already contains C v (SemiDiscreteSystem::inertial), so the equations of motion are damped; d is the
// matching quadrature. Why a further integrated component rather than a quadrature over the output times:
// along the exact flow d/dt (K + V) = F_ext·v − vᵀ C v, so H = K + V − w + d is a first integral of this
// system, and the solver integrates w and d with the same step, order and error control (rtol, atol per
// component) as q and v. The balance error of H is then the solver's local error, whatever the output
// interval; a trapezoidal sum over output times would add an O(Δt_out²) error of its own. Undamped
// systems carry d ≡ 0.
// Constrained DOFs c (DofMap, re-resolved at chart switches): q̇_c = v_c and v̇_c = 0, with v_c(0) = 0,
// so q_c stays at its initial value and every component stays differential.
//
// FirstOrderSystem owns the work storage (M, force vectors) and one LinearSolver for the mass matrix
// ("eigen-ldlt" or "cholmod": M is SPD; one symbolic analysis per object). It keeps no charts: callers
// pass the State whose charts are current.
//
// Mass solves (mass_reuse, default on): M(q) changes slowly with q (only its director rows depend on the
// configuration), so acceleration() does not refactorize M(q) for every call. It solves M(q) a = r by
// iterative refinement preconditioned with the last factorization M₀⁻¹,
//     a ← a + M₀⁻¹ (r − M(q) a),
// and stops when ‖r − M(q) a‖∞ ≤ 1e-12 ‖r‖∞ (+ 1e-300): the answer is the solution of the CURRENT M(q)
// to that residual, not an approximation by M₀. When the iteration does not reach the tolerance within
// 4 corrections or contracts by less than 0.25 per correction, M(q) is refactorized and becomes the new M₀.
// mass_factorizations() counts the factorizations, mass_refinements() the corrections.
#pragma once

#include "lib/linalg/linear_solver.hpp"
#include "lib/model/semi_discrete_system.hpp"
#include "lib/model/state.hpp"

#include <Eigen/Core>
#include <memory>
#include <string>

namespace shelldyn {

class FirstOrderSystem {
 public:
  // Throws std::invalid_argument for an unknown or unsuitable mass_solver (names the setting).
  FirstOrderSystem(SemiDiscreteSystem& system, const std::string& mass_solver, bool mass_reuse = true);

  SemiDiscreteSystem& system() const { return *system_; }
  Index n() const { return n_; }
  Index size() const { return 2 * n_ + 2; }
  Index work_index() const { return 2 * n_; }         // w = W_ext
  Index damping_index() const { return 2 * n_ + 1; }  // d = W_damp

  // y = [u; v; w; d] and back (unpack leaves t, a and the charts of s alone).
  void pack(const State& s, double w, double d, double* y) const;
  void unpack(const double* y, State& s) const;

  // The rates of the two energy components: ẇ = F_ext·v and ḋ = vᵀ C v (0 without damping).
  struct Powers {
    double external = 0.0, damping = 0.0;
  };
  // vᵀ C v at s.v (0 for an undamped system).
  double damping_power(const Eigen::VectorXd& v);

  // a = M(q)⁻¹ (F_ext − F_int − F_m) at (t, s.u, s.v, s.charts), a_c = 0 on constrained DOFs.
  // Returns the powers F_ext·v, vᵀ C v. Throws on non-finite input, director overshoot
  // (std::domain_error from the element) or a failed factorization.
  Powers acceleration(double t, const State& s, Eigen::VectorXd& a);

  // Residual of the momentum rows for IDA: r = M(q) a + F_m + F_int − F_ext, r_c = a_c; returns the powers.
  Powers momentum_residual(double t, const State& s, const Eigen::VectorXd& a, Eigen::VectorXd& r);

  // Scales of the absolute tolerances per variable kind (docs/results.md, "Baseline tuning"):
  //   translations d:     length L (diagonal of the initial mesh's bounding box; 1 for systems without a mesh,
  //                       where every q entry counts as a translation)
  //   director unknowns:  1 (components of a unit vector)
  //   velocities ḋ:       L/τ,  director rates: 1/τ   (τ: time scale, see the baselines' time_scale setting)
  //   external work w and damping work d:  max(1, K₀ + |V₀|)
  struct ToleranceScales {
    double length = 1.0, time = 1.0, velocity = 1.0, energy = 1.0;
    bool shell = false;  // a shell Model: 5 DOFs per node, [d_X, d_Y, d_Z, q_1, q_2]
  };
  // length_scale / time_scale <= 0: automatic (L from the mesh; τ = 1).
  ToleranceScales tolerance_scales(const State& s0, double length_scale, double time_scale);
  // atol_k = atol · scale_k for every component of y = [q; v; w; d].
  void absolute_tolerances(const ToleranceScales& scales, double atol, double* out) const;

  long mass_factorizations() const { return mass_solver_->stats().factorizations; }
  long mass_refinements() const { return refinements_; }
  const SparseMatrix& last_mass() const { return M_; }

 private:
  SemiDiscreteSystem* system_;
  Index n_;
  // a = M(q)⁻¹ rhs_ into a (M_ assembled, constraints applied): refinement with M₀ or a refactorization.
  void solve_mass(Eigen::VectorXd& a);

  std::unique_ptr<LinearSolver> mass_solver_;
  bool mass_reuse_ = true;
  long refinements_ = 0;
  SparseMatrix M_;
  Eigen::VectorXd f_int_, f_m_, f_ext_, rhs_, res_, corr_, cv_;
};

// True if all n values are finite.
bool all_finite(const double* x, Index n);

// True if `s` is exactly the state an adaptive integrator holds: same time t, same director charts as
// `held`, and q, v equal to the first 2n entries of y. The caller may re-chart or replace the state
// between advance() calls; the integrator then re-initializes from it.
bool state_in_sync(const State& s, double t, const State& held, const double* y, Index n);

// Throws std::invalid_argument("<who>: rtol must be ...") unless 0 < rtol < 1 and 0 < atol < inf
// (shared settings validation of the baselines).
void check_tolerances(const std::string& who, double rtol, double atol);

}  // namespace shelldyn
