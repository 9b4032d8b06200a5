// CR9: co-rotational 9-node shell element with vectorial rotational variables
// (docs/theory.md §§1-6.3; Li & Qian 2025, Li, Izzuddin & Vu-Quoc 2008), MITC9 assumed strains.
//
// Node numbering (docs/theory.md §1, Gmsh type 10; 0-based index in code = node - 1):
//
//      4 ---- 7 ---- 3        eta
//      |             |         ^
//      8      9      6         |
//      |             |         +--> xi
//      1 ---- 5 ---- 2
//
// Corners run counter-clockwise seen from the side the initial normals p_i0 point to (§2.4).
// DOFs, node-major, 5 per node: [d_X, d_Y, d_Z, q_1, q_2]; d = translation from X0, q = the two minor
// components of the CURRENT unit director in the node's DirectorChart (§2.1).
//
// Units: any consistent set (E in force/length^2, rho in mass/length^3, thickness in length).
// Ownership: the element owns only precomputed reference-geometry data; all methods are const, pure
// and thread-safe, and allocate no heap memory.
// Errors: the constructor throws std::invalid_argument on bad material, degenerate geometry or a
// failed orientation check; evaluations throw std::domain_error when a state is inadmissible
// (1 - |q|^2 <= 0 at a node, collapsed current corners) so that an integrator can cut the step.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "elements/corotational_frame.hpp"
#include "elements/director.hpp"

namespace shelldyn {

struct ShellMaterial {
  double E, nu, rho, thickness;
  double shear_factor = 5.0 / 6.0;
};

// Switches for tests: mitc = false gives the plain 3x3 displacement element; geometric_stiffness = false
// drops K_σ. Declared at namespace scope (alias CR9Shell::Options) so that `Options opt = {}` compiles
// with GCC despite the default member initialisers.
struct CR9ShellOptions {
  bool mitc = true;
  bool geometric_stiffness = true;
  // MITC9 membrane strains and force from the 16 tying-point strains (docs/theory.md §4.4, the tying-point
  // form of membrane_strains()); false: the Gauss-point matrices L_m, H_m of §4.5 (the reference path the
  // tests compare against; same quantities to round-off). No effect when mitc = false.
  bool tying_membrane = true;
};

class CR9Shell {
 public:
  using Vec45 = Eigen::Matrix<double, 45, 1>;
  using Mat45 = Eigen::Matrix<double, 45, 45>;
  using Charts = std::array<DirectorChart, 9>;
  using Options = CR9ShellOptions;

  // X0: initial nodal positions; p0: initial unit nodal normals (averaged by the mesh layer, §2.4).
  // Throws std::invalid_argument naming the node if e_z0·p_i0 <= 0 (§2.4), if |p_i0| != 1, or if the
  // element is degenerate; and naming the parameter if the material is invalid.
  CR9Shell(const std::array<Eigen::Vector3d, 9>& X0, const std::array<Eigen::Vector3d, 9>& p0,
           const ShellMaterial& mat, Options opt = {});

  // §3.4, §4: F = T^T f_L, K = T^T k_L T + K_σ (exact symmetric Hessian). F, K may be nullptr.
  // Returns the strain energy U.
  double internal(const Vec45& u, const Charts& charts, Vec45* F, Mat45* K) const;

  // §6.3 strain-averaged force F*_int,mid = T(u_mid)^T f*_L and its symmetric tangent K_mid (w.r.t.
  // u_mid; the integrator applies the (1 - alpha_f) chain factor). Returns U(u_np1).
  double algorithmic_internal(const Vec45& u_n, const Vec45& u_np1, const Charts& charts, double alpha_f,
                              double xi, Vec45* F, Mat45* K) const;

  // What §6.3 needs from the step's start configuration u_n, which is fixed during a step's Newton
  // iterations: the local increments w_n, K_bs w_n and the membrane strains ε_m(t_n) per Gauss point.
  // Computed once per step (step_state()), used by every residual and tangent of the step (the overload of
  // algorithmic_internal below), with results identical to the plain overload.
  struct StepState {
    Vec45 w;
    Vec45 Kw;                          // K_bs w_n (bending + shear force at t_n)
    std::array<Eigen::Vector3d, 9> e;  // ε_m at t_n per Gauss point
    // τ_a of t_n at the 20 τ points of the tying-point membrane form (row = τ point, column = component; zero
    // without it): the residual's strain gradient at t̄ = b1 t1 + b0 t0 then takes τ̄ = b1 τ(t1) + b0 τ(t_n).
    Eigen::Matrix<double, 20, 3> tau;
  };
  void step_state(const Vec45& u_n, const Charts& charts, StepState* st) const;
  // The strain energy U(u_n) of a step state, with the expressions of algorithmic_internal()'s residual path (so
  // bitwise the energy that a step's residual at u_{n+1} = u_n returns; internal()'s to round-off), without a
  // frame or local variables: ½ wᵀ(K_bs w) + Σ_gp ½ dA εᵀ h D1 ε from the state's w, K_bs w and ε.
  double step_energy(const StepState& st) const;
  double algorithmic_internal(const StepState& sn, const Vec45& u_n, const Vec45& u_np1, const Charts& charts,
                              double alpha_f, double xi, Vec45* F, Mat45* K) const;

  void mass(const Vec45& u, const Charts& charts, Mat45* M) const;                        // §5.2
  // M(u) a + F_m(u, v) without forming M (§5.2): ρh Σ_j m_ij a_j on the translations and
  // (ρh³/12) A1_iᵀ Σ_j m_ij p̈_j, p̈_j = A1_j q̈_j + A2_j, on the director unknowns.
  void inertia_force(const Vec45& u, const Vec45& v, const Vec45& a, const Charts& charts, Vec45* f) const;
  void inertial(const Vec45& u, const Vec45& v, const Charts& charts, Vec45* Fm) const;  // §5.2 F_m
  double kinetic(const Vec45& u, const Vec45& v, const Charts& charts) const;             // §5.1
  // §5.4 linear and angular momentum about the origin (J includes the director term). Either may be null.
  void momenta(const Vec45& u, const Vec45& v, const Charts& charts, Eigen::Vector3d* L,
               Eigen::Vector3d* J) const;
  double area() const { return area_; }  // reference mid-surface area

  // Element averages (Σ_gp dA x / A) of the Cartesian strains and stress resultants of §4.5–4.6 in the
  // Gauss points' local tangent bases, and the strain energy per unit area U/A (docs/theory.md §9.1).
  struct Resultants {
    Eigen::Vector3d membrane_strain, curvature, membrane_force, bending_moment;  // (11, 22, 12)
    Eigen::Vector2d shear_strain, shear_force;                                    // (1, 2)
    double energy_density = 0.0;
  };
  Resultants resultants(const Vec45& u, const Charts& charts) const;

  // Diagnostics for tests: local variables u_L = [t_i, θ_i] (absolute θ, §3.2), local force f_L and
  // local tangent k_L (§4.7) at u. Any pointer may be null. Returns U.
  double local(const Vec45& u, const Charts& charts, Vec45* uL, Vec45* fL, Mat45* kL) const;
  // Co-rotational frame at u (gives T via matrix()).
  CorotationalFrame frame(const Vec45& u, const Charts& charts) const;
  const Eigen::Matrix<double, 9, 9>& scalar_mass() const { return m_; }  // m_ij = ∫ N_i N_j dA

 private:
  // Per Gauss point data (§4.5): membrane strain ε_m,c = Lm.row(c)·t + ½ Σ_ij Hm[c](i,j) t_i·t_j.
  struct GaussPoint {
    Eigen::Matrix<double, 3, 27> Lm;
    std::array<Eigen::Matrix<double, 9, 9>, 3> Hm;
    double dA;
  };
  using Mat39 = Eigen::Matrix<double, 3, 9>;

  // Local response of the membrane part with strains from the local translations t1, t0 weighted by
  // c1, c0 and strain gradient evaluated at t̄ = b1 t1 + b0 t0 (§6.3; internal(): c1 = b1 = 1, c0 = b0 = 0).
  // Adds to fL and kL (t rows only); returns the membrane energy at t1.
  // With n0 (the step state of t0), the strains of t0 are taken from there instead of recomputed.
  double membrane(const Mat39& t1, const Mat39& t0, double c1, double c0, double b1, double b0, Vec45* fL,
                  Mat45* kL, const StepState* n0 = nullptr) const;
  // The membrane force alone (kL not wanted), same quantities as membrane() with the step state n0 of t0,
  // evaluated through the Gram matrix G = t1ᵀt1 and the stacked Gauss-point data below: the strains are
  // ε = L·t1 + ½ H:G, and Σ_gp dA B_mᵀ N = Lᵀs + t̄ (Σ s H) with s = dA N (a few matrix–vector products
  // instead of 27 small 3×9·9×9 products). Equal to membrane() to round-off.
  double membrane_force(const Mat39& t1, const Mat39& t0, double c1, double c0, double b1, double b0,
                        const StepState& n0, Vec45* fL) const;
  // The membrane strains ε_m,c at all Gauss points (entry 3g + c) of the local translations t, through the
  // Gram matrix: ε = L·t + ½ H:(tᵀt) (§4.5). The one expression for ε everywhere (internal(), the step state,
  // the residual), so that the energies of the same configuration agree bitwise.
  Eigen::Matrix<double, 27, 1> membrane_strains(const Mat39& t) const;
  // Local increments w = [t_i, Δθ_i] of u and the frame at u. derivatives = false: a frame for w only (the
  // directors' A1 and d2pl are not evaluated; the frame's derivatives cannot be formed).
  // curvature = false: the frame has the directors' A1 but not d²p_l/dq² (F = Tᵀf_L only, no K_σ).
  CorotationalFrame local_increments(const Vec45& u, const Charts& charts, Vec45* w, bool derivatives = true,
                                     bool curvature = true) const;

  std::array<Eigen::Vector3d, 9> X0_;
  std::array<Eigen::Vector3d, 9> xl0_;  // initial local coordinates x_i0 (§3.2)
  std::array<Eigen::Vector3d, 9> rel0_;  // X_i - X_O, the reference offsets of the compensated t_i
  std::array<Eigen::Vector2d, 9> th0_;  // θ_i0 = (r_i0,x, r_i0,y)
  ShellMaterial mat_;
  Options opt_;
  Eigen::Matrix3d D1_;                  // plane-stress matrix (§4.6)
  std::array<GaussPoint, 9> gp_;
  // The data of membrane_force() and of K_bs w in the compact form a residual streams through (per element
  // and residual ~24 kB instead of ~40 kB; a residual of a large mesh reads it from memory, not the cache):
  Eigen::Matrix<double, 27, 27> Lall_;  // row 3g + c = gp_[g].Lm.row(c)
  std::vector<int> lcols_;              // the columns of Lall_ with a nonzero entry (18 of 27 for a flat element)
  Eigen::Matrix<double, 45, 27> Hp_;    // column 3g + c = upper triangle of gp_[g].Hm[c], packed (k = i + j(j+1)/2)
  Eigen::Matrix<double, 27, 1> dAall_;  // entry 3g + c = gp_[g].dA
  Eigen::Matrix<double, 1035, 1> Kbsp_; // upper triangle of Kbs_, packed by columns (k = i + j(j+1)/2)
  // A flat element's K_bs is exactly zero on its in-plane translations (the curvatures and transverse shears
  // of §4.3 do not involve them): K_bs w then runs on the DOFs with a nonzero row only, as a dense block
  // (27 × 27 instead of the packed 45 × 45: 729 multiplications instead of 2 025). Empty when every row is nonzero.
  std::vector<int> kbs_active_;
  Eigen::MatrixXd kbs_block_;  // its product runs as a fixed-size one for the common sizes 27 (flat) and 36
  Vec45 kbs_times(const Vec45& w) const;  // Kbs_ w from Kbsp_ or kbs_block_
  // Tying-point form of the MITC9 membrane strains (§4.4; used when opt_.mitc && opt_.tying_membrane). The
  // covariant membrane strain of tying point k is ê_ab = ½(X_a·τ_b + X_b·τ_a + τ_a·τ_b) with τ_a = Σ_i N_i,a t_i
  // there, and the Gauss-point Cartesian strains are ε = Tm ẽ, ẽ the MITC9 interpolation of ê at the Gauss point.
  // The 20 "τ points": rows 0–5 ∂/∂ξ at family A, 6–11 ∂/∂η at family B, 12–15 ∂/∂ξ and 16–19 ∂/∂η at family C
  // (the shape-function derivatives there are element-independent, tying_dN() in the .cpp). The interpolation
  // weights are element-independent too and sparse: family A's η-quadratic and family B's ξ-quadratic weights
  // are 1 at the tying row through the Gauss point and 0 at the others (the tying rows are the Gauss rows), so a
  // Gauss point reads 2 + 2 + 4 of the 16 ê (mitc9_gauss_weights() in the .cpp).
  bool tying_ = false;
  using TauT = Eigen::Matrix<double, 20, 3>;
  TauT XtT_;                             // X_ξ or X_η (local reference geometry) at the τ points, rows as τ
  std::array<Eigen::Matrix3d, 9> Tm_;    // per Gauss point: [e_ξξ, e_ηη, 2e_ξη] -> [ε_11, ε_22, 2ε_12]
  TauT tying_tau(const Mat39& t) const;  // τ of the local translations t
  // ε (entry 3g + c) and the covariant tying strains from τ.
  Eigen::Matrix<double, 27, 1> tying_strains(const TauT& tau) const;
  // f_t += Σ_k μ_k ∂ê_k/∂t at the τ̄ of the strain gradient, μ = (∂ε/∂ê)ᵀ s for s = dA N per Gauss point.
  void tying_force(const Eigen::Matrix<double, 27, 1>& s, const TauT& taubar, Vec45* fL) const;
  Mat45 Kbs_;                           // constant bending + shear stiffness Σ dA (B_b^T M + B_s^T Q)
  std::array<Eigen::Matrix<double, 5, 45>, 9> Bbs_;  // [B_b; B_s] per Gauss point (output only)
  Eigen::Matrix<double, 9, 9> m_;
  double area_ = 0.0;
};

}  // namespace shelldyn
