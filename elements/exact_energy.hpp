// Element-level pieces of the exactly energy–momentum conserving step `em-exact`
// (docs/theory/exact-energy-momentum.md; notation of the CR9 element, DOFs [d_i, q_i] node-major).
//
// 1. Rigid rows R (6×45) at the step's midpoint configuration x_mid,i = X_i + (d_n + d_{n+1})/2,
//    p_mid,i = (p_n + p_{n+1})/2 (p_mid is not unit): three translations t_k (d-slots e_k, q-slots 0) and
//    three rotations about the midpoint centroid c (d-slots e_k × (x_mid,i − c), q-slots S_i (e_k × p_mid,i)),
//    S_i the 2×3 selector of node i's chart. For a nodal force vector f, R f = (resultant, moment about c)
//    with the director forces taken as S_iᵀ f_q,i (theory §3). A finite rigid step (Cayley form
//    Δx = c' + W x_mid, Δp = W p_mid) lies exactly in the row space of R.
// 2. The energy–momentum correction F* = F + Rᵀa + β z of a force F (theory §3):
//      a = −(RRᵀ)⁻¹ R F,   z = Δu − Rᵀ(RRᵀ)⁻¹ R Δu,   β = [ΔU − Δuᵀ(F + Rᵀa)] / zᵀz,
//    so that R F* = 0 (zero resultant and zero midpoint moment) and Δuᵀ F* = ΔU exactly. When
//    zᵀz ≤ guard · ΔuᵀΔu (a rigid step, for which ΔU − Δuᵀ(F + Rᵀa) vanishes analytically) β = 0.
// 3. The embedded kinetic energy and momenta with director velocities w_i ∈ ℝ³ (theory §2): the element's
//    consistent scalar mass m_ij = ∫ N_i N_j dA is constant, so K, L and J are quadratic/bilinear forms
//    with constant coefficients.
// All functions are pure, allocation-free and thread-safe.
#pragma once

#include "elements/director.hpp"

#include <Eigen/Core>
#include <array>

namespace shelldyn {

using Vec45E = Eigen::Matrix<double, 45, 1>;
using RigidRows = Eigen::Matrix<double, 6, 45>;
using NodeVectors = std::array<Eigen::Vector3d, 9>;

// The rigid rows of item 1 (about the midpoint centroid c, r_i = x_mid,i − c), applied from the nine nodal
// vectors instead of as a dense 6 × 45 matrix (theory §3.1):
//   R f  = (Σ_i f_d,i,  Σ_i r_i × f_d,i + p_i × S_iᵀ f_q,i),
//   Rᵀa  = (a_t + a_r × r_i,  S_i (a_r × p_i)) at node i,
//   RRᵀ  = [[9 I, −[s]ₓ], [[s]ₓ, Σ_i (|r_i|² I − r_i r_iᵀ) + (e_j × p_i)·S_iᵀS_i(e_k × p_i)]],  s = Σ_i r_i,
// about 400 flops where the dense products take some 3 000. The rows are those of dense(); the products
// round differently (test ExactEnergy.StructuredRigidRowsEqualTheDenseRows).
class MidpointRigidRows {
 public:
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  MidpointRigidRows(const NodeVectors& x_mid, const NodeVectors& p_mid, const std::array<DirectorChart, 9>& charts);
  Vec6 times(const Vec45E& f) const;                        // R f
  void subtract_transpose_times(const Vec6& a, Vec45E& y) const;  // y −= Rᵀa
  const Eigen::Matrix<double, 6, 6>& gram() const { return gram_; }  // R Rᵀ
  // The rotation block of R Rᵀ split into its d-slot part Σ_i (e_j × r_i)·(e_k × r_i) and its director part
  // Σ_i (S_i(e_j × p_i))·(S_i(e_k × p_i)) (their sum is the block up to rounding).
  const Eigen::Matrix3d& translation_gram() const { return Jd_; }
  const Eigen::Matrix3d& director_gram() const { return Jq_; }
  RigidRows dense() const;                                  // the 6 × 45 rows (projector, tests)

 private:
  NodeVectors r_, p_;
  std::array<DirectorChart, 9> charts_;
  Eigen::Matrix<double, 6, 6> gram_;
  Eigen::Matrix3d Jd_, Jq_;
};

struct CorrectionInfo {
  double beta = 0.0;         // the coefficient of z
  double z_norm2 = 0.0;      // zᵀz (= Δuᵀz; Δuᵀz with a director weight)
  double correction_norm = 0.0;  // ‖β z‖₂
  bool rigid_guard = false;  // β set to 0 because the step is (numerically) rigid
};

// Replaces F by F* of item 2. du = u_{n+1} − u_n (element DOFs, same charts), dU = U(u_{n+1}) − U(u_n).
// director_weight w ≠ 1 takes the correction's direction in the metric W = diag(1 on the translations, w on the
// director coordinates): z = W(Δu − Rᵀy) with R W Rᵀ y = R W Δu, so R z = 0 and Δuᵀz = ‖Δu − Rᵀy‖²_W, and β = m/Δuᵀz
// (z_norm2 reports Δuᵀz). The Model uses w = h ℓ_e (thickness times element size)
// (docs/theory/exact-energy-momentum.md §3: with w = 1 the β z term swamps the director stiffness of thin shells).
CorrectionInfo energy_momentum_correction(const MidpointRigidRows& R, const Vec45E& du, double dU, Vec45E& F,
                                          double guard = 1e-20, double director_weight = 1.0);

// Projector Π = I − Rᵀ(RRᵀ)⁻¹R onto the complement of the rigid rows (ΠRᵀ = 0, Π symmetric).
Eigen::Matrix<double, 45, 45> rigid_complement_projector(const RigidRows& R);

// Embedded kinetic energy ½ρh Σ m_ij v_i·v_j + ½(ρh³/12) Σ m_ij w_i·w_j (theory §2).
double embedded_kinetic(const Eigen::Matrix<double, 9, 9>& m, double rho_h, double rho_h3_12, const NodeVectors& v,
                        const NodeVectors& w);
// Embedded momenta: L = ρh Σ m_ij v_j, J = Σ m_ij [ρh x_i × v_j + (ρh³/12) p_i × w_j]. Either may be null.
void embedded_momenta(const Eigen::Matrix<double, 9, 9>& m, double rho_h, double rho_h3_12, const NodeVectors& x,
                      const NodeVectors& p, const NodeVectors& v, const NodeVectors& w, Eigen::Vector3d* L,
                      Eigen::Vector3d* J);

// A1 of the chart evaluated at a (not necessarily unit) vector p: rows n, m = identity, row l =
// (−p_n/p_l, −p_m/p_l). Its columns are orthogonal to p and S·A1 = I, so A1ᵀ y = 0 ⇔ y ∥ p (theory §2).
// Throws std::domain_error if p_l = 0.
Eigen::Matrix<double, 3, 2> embedded_A1(const Eigen::Vector3d& p, const DirectorChart& ch);

}  // namespace shelldyn
