// The first-order form shared by the SUNDIALS baselines (ida-bdf, arkode-erk, arkode-dirk) of the
// semi-discrete system M(q) q̈ + F_m(q, q̇) + F_int(q) = F_ext(t, q)   (docs/theory.md §5.3):
//
//     y = [q; v; w],  n + n + 1 components,   q̇ = v,  M(q) v̇ = F_ext − F_int − F_m,  ẇ = F_ext·v,
//
// where w is the external work W_ext (so every integrator reports H = K + V − W_ext the same way).
// Constrained DOFs c (DofMap, re-resolved at chart switches): q̇_c = v_c and v̇_c = 0, with v_c(0) = 0,
// so q_c stays at its initial value and every component stays differential.
//
// FirstOrderSystem owns the work storage (M, force vectors) and one LinearSolver for the mass matrix
// ("eigen-ldlt" or "cholmod": M is SPD; one symbolic analysis per object, a numeric factorization per
// acceleration()). It keeps no charts: callers pass the State whose charts are current.
#pragma once

#include "lib/linear_solver.hpp"
#include "lib/semi_discrete_system.hpp"
#include "lib/state.hpp"

#include <Eigen/Core>
#include <memory>
#include <string>

namespace shelldyn {

class FirstOrderSystem {
 public:
  // Throws std::invalid_argument for an unknown or unsuitable mass_solver (names the setting).
  FirstOrderSystem(SemiDiscreteSystem& system, const std::string& mass_solver);

  SemiDiscreteSystem& system() const { return *system_; }
  Index n() const { return n_; }
  Index size() const { return 2 * n_ + 1; }

  // y = [u; v; w] and back (unpack leaves t, a and the charts of s alone).
  void pack(const State& s, double w, double* y) const;
  void unpack(const double* y, State& s) const;

  // a = M(q)⁻¹ (F_ext − F_int − F_m) at (t, s.u, s.v, s.charts), a_c = 0 on constrained DOFs.
  // Returns the external power F_ext·v. Throws on non-finite input, director overshoot
  // (std::domain_error from the element) or a failed factorization.
  double acceleration(double t, const State& s, Eigen::VectorXd& a);

  // Residual of the momentum rows for IDA: r = M(q) a + F_m + F_int − F_ext, r_c = a_c; returns F_ext·v.
  double momentum_residual(double t, const State& s, const Eigen::VectorXd& a, Eigen::VectorXd& r);

  // Absolute tolerances per component (spec of the `atol` setting, shared by all three baselines):
  //   q entries: atol (translations in the case's length unit, director components dimensionless),
  //   v entries: atol · max(1, ‖v₀‖∞)   (velocity scale of the initial state),
  //   w:         atol · max(1, K₀ + |V₀|) (energy scale of the initial state).
  void absolute_tolerances(const State& s0, double atol, double* out) const;

  long mass_factorizations() const { return mass_solver_->stats().factorizations; }
  const SparseMatrix& last_mass() const { return M_; }

 private:
  SemiDiscreteSystem* system_;
  Index n_;
  std::unique_ptr<LinearSolver> mass_solver_;
  SparseMatrix M_;
  Eigen::VectorXd f_int_, f_m_, f_ext_, rhs_;
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
