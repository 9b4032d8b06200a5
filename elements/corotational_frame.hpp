// Co-rotational frame of the 9-node element and the global <-> local map (docs/theory.md §3).
//
// The element triad follows the unit diagonals of the current corner positions (§3.1):
//   a = x3 - x1, b = x4 - x2, e_x = (â - b̂)/|â - b̂|, e_y = (â + b̂)/|â + b̂|, e_z = e_x × e_y,
// with origin x_O = corner centroid. Local variables per node (§3.2): t_i = R^T (x_i - x_O) - x_i0 and
// θ_i = (e_x·p_i, e_y·p_i). T = ∂u_L/∂u_G (§3.3) is stored in factored form T = D + C P:
// D is block diagonal (R^T on t_i/d_i, [e_x e_y]^T A1_i on θ_i/q_i) and C (45x12) holds the
// dependence of every local variable on the 4 corner translations through the triad and x_O.
// The constructor computes the triad and the origin only; the derivatives (the factors of T, ∂e_α/∂d_k)
// are computed at the first call that needs them, so a frame used for local_variables() alone (the end
// point of a strain-averaged step, docs/theory.md §6.3) costs no more than the triad.
// Node-major DOF order, 5 per node: global [d_X,d_Y,d_Z,q_1,q_2], local [t_x,t_y,t_z,θ_x,θ_y].
#pragma once

#include <Eigen/Core>
#include <array>

#include "elements/director.hpp"

namespace shelldyn {

class CorotationalFrame {
 public:
  using Vec45 = Eigen::Matrix<double, 45, 1>;
  using Mat45 = Eigen::Matrix<double, 45, 45>;

  // x: current nodal positions; p, A1, d2pl, charts: current nodal directors with dp/dq and the
  // second derivative of their dependent component (§2.2). Throws std::domain_error if the current
  // corners are degenerate (zero-length or parallel diagonals).
  CorotationalFrame(const std::array<Eigen::Vector3d, 9>& x, const std::array<Eigen::Vector3d, 9>& p,
                    const std::array<Eigen::Matrix<double, 3, 2>, 9>& A1,
                    const std::array<Eigen::Matrix2d, 9>& d2pl, const std::array<DirectorChart, 9>& charts);
  // A frame for the triad, the origin and local_variables() only (the end point of a strain-averaged step): the
  // director derivatives are not needed then, and any call that needs the frame's derivatives throws
  // std::logic_error.
  CorotationalFrame(const std::array<Eigen::Vector3d, 9>& x, const std::array<Eigen::Vector3d, 9>& p,
                    const std::array<DirectorChart, 9>& charts);
  // A frame for F = Tᵀ f_L (apply_transpose(), matrix()) without the directors' curvature d²p_l/dq² (a residual
  // without a tangent): tangent() and add_geometric_stiffness() (K_σ's group 4 needs it) throw std::logic_error.
  CorotationalFrame(const std::array<Eigen::Vector3d, 9>& x, const std::array<Eigen::Vector3d, 9>& p,
                    const std::array<Eigen::Matrix<double, 3, 2>, 9>& A1, const std::array<DirectorChart, 9>& charts);

  const Eigen::Matrix3d& R() const { return R_; }
  const Eigen::Vector3d& origin() const { return xO_; }

  // Local variables (§3.2): t_i = R^T(x_i - x_O) - x_i0 and θ_i (absolute, not the increment).
  Vec45 local_variables(const std::array<Eigen::Vector3d, 9>& x_local0) const;
  // The same, with t_i evaluated in compensated (double-double) arithmetic from the reference offsets
  // X_i - X_O and the displacements d_i, x_i = X_i + d_i (docs/theory/exact-energy-momentum.md §5.1).
  // t_i is a strain-sized difference of body-sized numbers: in plain double arithmetic it carries an
  // absolute error of ~1e-16 × the element's distance from x_O, which the membrane stiffness turns into a
  // force noise floor. Here only the rounding of the result remains (~1e-16 |t_i|). R is the frame's triad
  // as computed; its own rounding is an infinitesimal rigid rotation of the local configuration, to which
  // the local strains are insensitive to first order.
  Vec45 local_variables(const std::array<Eigen::Vector3d, 9>& x_local0, const std::array<Eigen::Vector3d, 9>& rel_ref,
                        const std::array<Eigen::Vector3d, 9>& disp) const;

  // F_G = T^T f_L (§3.4).
  Vec45 apply_transpose(const Vec45& fL) const;
  // K_G = T^T k_L T + K_σ(f_L) (§3.4); geometric = false drops K_σ (test switch only).
  void tangent(const Mat45& kL, const Vec45& fL, bool geometric, Mat45* K) const;
  // K_σ(f_L) alone, added into *K (§3.4 groups 1-4).
  void add_geometric_stiffness(const Vec45& fL, Mat45* K) const;
  // Dense T (for tests and diagnostics).
  Mat45 matrix() const;

  // ∂e_α/∂d_k for α = x,y,z and corner k = 0..3 (§3.3).
  const Eigen::Matrix3d& dE(int alpha, int corner) const {
    derivatives();
    return E_[alpha][corner];
  }

 private:
  // §3.3 frame derivatives and the factors of T (lazy: once, at the first call that needs them).
  void derivatives() const {
    if (!have_derivatives_) compute_derivatives();
  }
  void compute_derivatives() const;
  // The corner columns C of T (tangent(), matrix(); apply_transpose() contracts them without forming C).
  void corner_columns() const {
    derivatives();
    if (!have_corner_columns_) compute_corner_columns();
  }
  void compute_corner_columns() const;
  // The weight vectors of f_L (§3.4) that Tᵀf_L's corner part and K_σ contract with the triad's derivatives:
  // w_z = Σ_i f_t,i,z (x_i − x_O), and w_x, w_y (w_x = Σ_i f_t,i,x (x_i − x_O) + f_θ,i,x p_i) with e_z = e_x × e_y
  // folded in: ŵ_x = w_x + e_y × w_z, ŵ_y = w_y + w_z × e_x.
  struct Weights {
    Eigen::Vector3d z, xh, yh;
  };
  Weights weights(const Vec45& fL) const;

  std::array<Eigen::Vector3d, 9> rel_;  // x_i - x_O
  std::array<Eigen::Vector3d, 9> p_;
  std::array<Eigen::Matrix<double, 3, 2>, 9> A1_;
  std::array<Eigen::Matrix2d, 9> d2pl_;
  std::array<int, 9> l_;
  Eigen::Vector3d xO_, a_, b_, s_, c_;
  Eigen::Matrix3d R_;
  // Derivative data (compute_derivatives(); mutable: filled lazily by const methods, one frame per thread).
  bool director_derivatives_ = true;  // false: built without A1, d2pl (local_variables() only)
  bool director_curvature_ = true;    // false: built without d2pl (no K_σ)
  mutable bool have_derivatives_ = false, have_corner_columns_ = false;
  mutable Eigen::Matrix3d Pa_, Pb_, Ps_, Pc_;
  mutable std::array<std::array<Eigen::Matrix3d, 4>, 3> E_;
  mutable std::array<Eigen::Matrix<double, 2, 2>, 9> D_theta_;  // [e_x e_y]^T A1_i
  mutable Eigen::Matrix<double, 45, 12> C_;                     // corner columns of T beyond D
};

}  // namespace shelldyn
