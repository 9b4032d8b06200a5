// Building blocks of nonlinear statics (docs/statics.md): the scale-aware convergence test and the
// arc-length constraint of Crisfield's cylindrical method with the usual root choice.
#pragma once

#include "lib/model/dof_map.hpp"

#include <Eigen/Core>
#include <string>

namespace shelldyn {

// Convergence of one Newton solve of R(u, λ) = F_int(u) − F_ext(λ, u) = 0 (free DOFs). Converged when
// EITHER test holds (docs/statics.md §Convergence):
//   residual:  ‖R_free‖₂ ≤ residual_tol · F_ref,   F_ref = max(‖F_ext(λ)‖₂, ‖F_int(u)‖₂ over ALL DOFs)
//              (the second norm includes the support reactions, so F_ref measures the forces the
//              model actually carries, at any load level and wherever the model sits in space);
//   increment: ‖δd‖∞ ≤ increment_tol · D_ref and ‖δq‖∞ ≤ increment_tol,   D_ref = max(‖d‖∞, ‖Δd‖∞) over
//              the translations d (Δd: change since the last converged state), q the director unknowns
//              (dimensionless, scale 1).
// The increment test is what ends an iteration whose residual has reached its round-off floor (which grows
// with the distance of the model from the origin); the residual test ends one whose correction is still
// large relative to a tiny displacement (first increments).
struct ConvergenceTest {
  double residual_tol = 1e-8;
  double increment_tol = 1e-10;

  struct Values {
    double residual = 0, force_ref = 0;      // ‖R_free‖₂, F_ref
    double dd = 0, disp_ref = 0, dq = 0;     // ‖δd‖∞, D_ref, ‖δq‖∞
    bool residual_ok = false, increment_ok = false;
    bool converged() const { return residual_ok || increment_ok; }
    // "residual 3.1e-05 > 1e-08 x 2.2e+03 and increment 4e-06 > 1e-10 x 1.2 (directors 2e-7)": names
    // both tests and their values (for failure messages).
    std::string describe(const ConvergenceTest& t) const;
  };
};

// Crisfield's cylindrical arc-length constraint on the translational DOFs (mask):
//     ‖Δu + δu_R + δλ δu_F‖²_t = Δl²
// returns the root δλ whose new increment makes the smaller angle with the current increment Δu
// (Crisfield 1981: the larger Δu_newᵀ Δu), or false when the roots are complex (the caller cuts Δl).
bool arc_length_root(const Eigen::VectorXd& du, const Eigen::VectorXd& du_r, const Eigen::VectorXd& du_f,
                     const std::vector<char>& translational, double dl, double* dlambda);

// ‖v‖₂ over the translational DOFs, and the dot product over them.
double translational_norm(const Eigen::VectorXd& v, const std::vector<char>& translational);
double translational_dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const std::vector<char>& translational);

}  // namespace shelldyn
