// CR9 shell element: docs/theory.md §2.4 (set-up), §3.4 (global force/tangent), §4 (local strains,
// MITC9, resultants), §5 (inertia), §6.3 (strain-averaged algorithmic force).
#include "elements/cr9_shell.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "elements/mitc9.hpp"
#include "elements/shape_functions.hpp"
#include "elements/simd.hpp"

namespace shelldyn {

namespace {

using Row27 = Eigen::Matrix<double, 1, 27>;
using Row45 = Eigen::Matrix<double, 1, 45>;

// Membrane energy of one Gauss point, ½ dA εᵀ h D1 ε (§4.6). One expression for membrane(), membrane_force() and
// step_energy(), so that their energies agree bit for bit (em-exact's ΔU relies on it).
double membrane_energy(double dA, const Eigen::Vector3d& e, const Eigen::Matrix3d& hD1) { return 0.5 * dA * e.dot(hD1 * e); }
using Mat9 = Eigen::Matrix<double, 9, 9>;

// Covariant strain functionals at one point (§4.3). Index ab: 0 = ξξ, 1 = ηη, 2 = ξη.
// Membrane e_ab = eL[ab]·t + ½ Σ_ij eH[ab](i,j) t_i·t_j (t = local translations, node-major 27-vector);
// bending k_ab = k[ab]·w, shear g_a = g[a]·w (w = [t_i, Δθ_i], node-major 45-vector).
struct Covariant {
  std::array<Row27, 3> eL;
  std::array<Mat9, 3> eH;
  std::array<Row45, 3> k;
  std::array<Row45, 2> g;
  Eigen::Vector3d Xa[2];
};

Covariant covariant(double xi, double eta, const std::array<Eigen::Vector3d, 9>& x0,
                    const std::array<Eigen::Vector3d, 9>& r0, const std::array<Eigen::Matrix<double, 3, 2>, 9>& L) {
  const Eigen::Matrix<double, 9, 1> N = shape_functions(xi, eta);
  const Eigen::Matrix<double, 9, 2> dN = shape_derivatives(xi, eta);
  // §4.2 reference geometry at the point.
  Eigen::Vector3d Xa[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  Eigen::Vector3d Aa[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  Eigen::Vector3d A = Eigen::Vector3d::Zero();
  for (int i = 0; i < 9; ++i) {
    A += N(i) * r0[i];
    for (int a = 0; a < 2; ++a) Xa[a] += dN(i, a) * x0[i], Aa[a] += dN(i, a) * r0[i];
  }
  Covariant c;
  c.Xa[0] = Xa[0];
  c.Xa[1] = Xa[1];
  const int ia[3] = {0, 1, 0}, ib[3] = {0, 1, 1};
  for (int ab = 0; ab < 3; ++ab) {
    const int a = ia[ab], b = ib[ab];
    c.k[ab].setZero();
    for (int i = 0; i < 9; ++i) {
      // ∂e_ab/∂t_i (linear part), ∂k_ab/∂t_i, ∂k_ab/∂Δθ_i (§4.3 derivative list).
      c.eL[ab].segment<3>(3 * i) = 0.5 * (dN(i, b) * Xa[a] + dN(i, a) * Xa[b]).transpose();
      c.k[ab].segment<3>(5 * i) = 0.5 * (dN(i, b) * Aa[a] + dN(i, a) * Aa[b]).transpose();
      c.k[ab].segment<2>(5 * i + 3) = 0.5 * (dN(i, b) * Xa[a] + dN(i, a) * Xa[b]).transpose() * L[i];
      for (int j = 0; j < 9; ++j) c.eH[ab](i, j) = 0.5 * (dN(i, a) * dN(j, b) + dN(i, b) * dN(j, a));
    }
  }
  for (int a = 0; a < 2; ++a) {
    c.g[a].setZero();
    for (int i = 0; i < 9; ++i) {
      c.g[a].segment<3>(5 * i) = dN(i, a) * A.transpose();              // ∂g_a/∂t_i = N_i,a A^T
      c.g[a].segment<2>(5 * i + 3) = N(i) * Xa[a].transpose() * L[i];  // ∂g_a/∂Δθ_i = N_i X,a^T L_i
    }
  }
  return c;
}

// Shape-function derivatives at the 20 τ points of the tying-point membrane form (cr9_shell.hpp, tying_):
// column j = N_i,ξ (j < 6: family A; 12 ≤ j < 16: family C) or N_i,η (6 ≤ j < 12: family B; j ≥ 16: family C).
const Eigen::Matrix<double, 9, 20>& tying_dN() {
  static const Eigen::Matrix<double, 9, 20> D = [] {
    Eigen::Matrix<double, 9, 20> d;
    for (int k = 0; k < 6; ++k) {
      d.col(k) = shape_derivatives(mitc9_family(0).xi[k], mitc9_family(0).eta[k]).col(0);
      d.col(6 + k) = shape_derivatives(mitc9_family(1).xi[k], mitc9_family(1).eta[k]).col(1);
    }
    for (int k = 0; k < 4; ++k) {
      const Eigen::Matrix<double, 9, 2> dN = shape_derivatives(mitc9_family(2).xi[k], mitc9_family(2).eta[k]);
      d.col(12 + k) = dN.col(0);
      d.col(16 + k) = dN.col(1);
    }
    return d;
  }();
  return D;
}

// D_τ with a zero tenth row (10 × 20, column-major): f_tᵀ = D_τ G runs as five whole SSE2 packets per column.
const Eigen::Matrix<double, 10, 20>& tying_dN10() {
  static const Eigen::Matrix<double, 10, 20> D = [] {
    Eigen::Matrix<double, 10, 20> d = Eigen::Matrix<double, 10, 20>::Zero();
    d.topRows<9>() = tying_dN();
    return d;
  }();
  return D;
}

// Its transpose (20 × 9, column-major): the τ points' products run as 20-long column updates (vectorized).
const Eigen::Matrix<double, 20, 9>& tying_dNT() {
  static const Eigen::Matrix<double, 20, 9> DT = tying_dN().transpose();
  return DT;
}

// The MITC9 interpolation weights of the tying strains at the Gauss points g = 3 ig + jg (ξ = x_ig, η = x_jg):
// family A's point i·3 + j weighs lin_i(ξ) quad_j(η) and quad_j(η) is 1 at j = jg, 0 otherwise (its tying rows
// η = 0, ±√(3/5) are the Gauss rows); likewise family B's point i·2 + j weighs quad_i(ξ) lin_j(η), nonzero for
// i = ig only. a[g][i]: family A's points i·3 + jg, b[g][j]: family B's points ig·2 + j, c[g][k]: family C's four.
// The structure is checked against mitc9_weights(): every other weight must be exactly zero.
struct GaussTyingWeights {
  double a[9][2], b[9][2], c[9][4];
};
const GaussTyingWeights& mitc9_gauss_weights() {
  static const GaussTyingWeights W = [] {
    GaussTyingWeights w{};
    const auto& gx = gauss3_points();
    for (int ig = 0; ig < 3; ++ig)
      for (int jg = 0; jg < 3; ++jg) {
        const int g = 3 * ig + jg;
        const Eigen::Matrix<double, 6, 1> wa = mitc9_weights(0, gx[ig], gx[jg]), wb = mitc9_weights(1, gx[ig], gx[jg]),
                                          wc = mitc9_weights(2, gx[ig], gx[jg]);
        for (int k = 0; k < 6; ++k) {
          const bool a_used = k % 3 == jg, b_used = k / 2 == ig;
          if ((!a_used && wa(k) != 0.0) || (!b_used && wb(k) != 0.0))
            throw std::logic_error("mitc9_gauss_weights: a MITC9 tying weight expected zero at a Gauss point is not");
          if (a_used) w.a[g][k / 3] = wa(k);
          if (b_used) w.b[g][k % 2] = wb(k);
        }
        for (int k = 0; k < 4; ++k) w.c[g][k] = wc(k);
      }
    return w;
  }();
  return W;
}

std::string node_name(int i) { return "node " + std::to_string(i + 1) + " (index " + std::to_string(i) + ")"; }

void validate_material(const ShellMaterial& m) {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("CR9Shell: invalid material: " + what);
  };
  if (!(m.E > 0.0) || !std::isfinite(m.E)) fail("E = " + std::to_string(m.E) + " must be finite and > 0");
  if (!(m.nu > -1.0 && m.nu < 0.5)) fail("nu = " + std::to_string(m.nu) + " must lie in (-1, 0.5)");
  if (!(m.rho >= 0.0) || !std::isfinite(m.rho)) fail("rho = " + std::to_string(m.rho) + " must be finite and >= 0");
  if (!(m.thickness > 0.0) || !std::isfinite(m.thickness))
    fail("thickness = " + std::to_string(m.thickness) + " must be finite and > 0");
  if (!(m.shear_factor > 0.0) || !std::isfinite(m.shear_factor))
    fail("shear_factor = " + std::to_string(m.shear_factor) + " must be finite and > 0 (usually 5/6)");
}

}  // namespace

CR9Shell::CR9Shell(const std::array<Eigen::Vector3d, 9>& X0, const std::array<Eigen::Vector3d, 9>& p0,
                   const ShellMaterial& mat, Options opt)
    : X0_(X0), mat_(mat), opt_(opt) {
  validate_material(mat);
  for (int i = 0; i < 9; ++i) {
    if (!X0[i].allFinite()) throw std::invalid_argument("CR9Shell: X0 of " + node_name(i) + " is not finite");
    if (!p0[i].allFinite() || std::abs(p0[i].norm() - 1.0) > 1e-8) {
      std::ostringstream os;
      os << "CR9Shell: initial normal p0 of " << node_name(i) << " = (" << p0[i].transpose() << ") has length "
         << p0[i].norm() << "; pass unit normals (normalise after averaging, docs/theory.md §2.4)";
      throw std::invalid_argument(os.str());
    }
  }
  // §3.1 initial triad R_0 and origin.
  const Eigen::Vector3d a = X0[2] - X0[0], b = X0[3] - X0[1];
  const double len = std::max(a.norm(), b.norm());
  if (!(a.norm() > 1e-10 * len) || !(b.norm() > 1e-10 * len) || !(len > 0.0))
    throw std::invalid_argument("CR9Shell: degenerate element: a corner diagonal (x3-x1 or x4-x2) has zero length");
  const Eigen::Vector3d s = a.normalized() - b.normalized(), c = a.normalized() + b.normalized();
  if (!(s.norm() > 1e-8) || !(c.norm() > 1e-8))
    throw std::invalid_argument("CR9Shell: degenerate element: the corner diagonals are parallel");
  Eigen::Matrix3d R0;
  R0.col(0) = s.normalized();
  R0.col(1) = c.normalized();
  R0.col(2) = R0.col(0).cross(R0.col(1));
  const Eigen::Vector3d xO = 0.25 * (X0[0] + X0[1] + X0[2] + X0[3]);

  std::array<Eigen::Vector3d, 9> r0;
  std::array<Eigen::Matrix<double, 3, 2>, 9> L;
  for (int i = 0; i < 9; ++i) {
    rel0_[i] = X0[i] - xO;
    xl0_[i] = R0.transpose() * rel0_[i];
    r0[i] = R0.transpose() * p0[i];
    // §2.4 orientation requirement: r_i0,z = e_z0·p_i0 > 0.
    if (!(r0[i](2) > 0.0)) {
      std::ostringstream os;
      os << "CR9Shell: orientation check failed at " << node_name(i) << ": e_z0·p0 = " << r0[i](2)
         << " <= 0 (element normal from the corner numbering points away from the nodal normal); number the "
            "corners counter-clockwise seen from the normal side, or flip the element (docs/theory.md §2.4)";
      throw std::invalid_argument(os.str());
    }
    th0_[i] = r0[i].head<2>();
    // §4.3 linearised director increment Δr_i = L_i Δθ_i (third row from r_i0·Δr_i = 0).
    L[i] << 1.0, 0.0, 0.0, 1.0, -r0[i](0) / r0[i](2), -r0[i](1) / r0[i](2);
  }

  // §4.4 tying-point strain functionals.
  std::array<std::array<Covariant, 6>, 3> tying;
  for (int f = 0; f < 3; ++f) {
    const Mitc9Family& fam = mitc9_family(f);
    for (int k = 0; k < fam.count; ++k) tying[f][k] = covariant(fam.xi[k], fam.eta[k], xl0_, r0, L);
  }
  tying_ = opt_.mitc && opt_.tying_membrane;
  for (int k = 0; k < 6; ++k) XtT_.row(k) = tying[0][k].Xa[0].transpose(), XtT_.row(6 + k) = tying[1][k].Xa[1].transpose();
  for (int k = 0; k < 4; ++k)
    XtT_.row(12 + k) = tying[2][k].Xa[0].transpose(), XtT_.row(16 + k) = tying[2][k].Xa[1].transpose();

  const double h = mat.thickness;
  const double G = mat.E / (2.0 * (1.0 + mat.nu));
  D1_ << 1.0, mat.nu, 0.0, mat.nu, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - mat.nu);
  D1_ *= mat.E / (1.0 - mat.nu * mat.nu);
  const Eigen::Matrix3d Db = (h * h * h / 12.0) * D1_;
  const double Ds = mat.shear_factor * G * h;

  Kbs_.setZero();
  m_.setZero();
  area_ = 0.0;
  const auto& gx = gauss3_points();
  const auto& gw = gauss3_weights();
  for (int ig = 0; ig < 3; ++ig) {
    for (int jg = 0; jg < 3; ++jg) {
      const double xi = gx[ig], eta = gx[jg];
      const Covariant cg = covariant(xi, eta, xl0_, r0, L);
      // Assumed (tied) covariant membrane and shear strains at the Gauss point (§4.4).
      std::array<Row27, 3> eL;
      std::array<Mat9, 3> eH;
      std::array<Row45, 2> g;
      if (opt_.mitc) {
        const int fam_e[3] = {0, 1, 2};
        for (int ab = 0; ab < 3; ++ab) {
          const int f = fam_e[ab];
          const Eigen::Matrix<double, 6, 1> w = mitc9_weights(f, xi, eta);
          eL[ab].setZero();
          eH[ab].setZero();
          for (int k = 0; k < mitc9_family(f).count; ++k) {
            eL[ab] += w(k) * tying[f][k].eL[ab];
            eH[ab] += w(k) * tying[f][k].eH[ab];
          }
        }
        for (int a = 0; a < 2; ++a) {  // g_ξ from family A, g_η from family B
          const Eigen::Matrix<double, 6, 1> w = mitc9_weights(a, xi, eta);
          g[a].setZero();
          for (int k = 0; k < 6; ++k) g[a] += w(k) * tying[a][k].g[a];
        }
      } else {
        eL = cg.eL;
        eH = cg.eH;
        g = cg.g;
      }
      // §4.5 orthonormal tangent basis and Cartesian components.
      const Eigen::Vector3d t1 = cg.Xa[0].normalized();
      const Eigen::Vector3d nrm = cg.Xa[0].cross(cg.Xa[1]);
      if (!(nrm.norm() > 1e-12 * cg.Xa[0].squaredNorm()) || !(nrm(2) > 0.0)) {
        std::ostringstream os;
        os << "CR9Shell: degenerate or folded element: at Gauss point (" << xi << ", " << eta
           << ") the mid-surface Jacobian has normal (" << nrm.transpose()
           << ") in the element frame; check node positions and the counter-clockwise numbering (docs/theory.md §1)";
        throw std::invalid_argument(os.str());
      }
      const Eigen::Vector3d t2 = nrm.normalized().cross(t1);
      Eigen::Matrix2d J;
      J << cg.Xa[0].dot(t1), cg.Xa[0].dot(t2), cg.Xa[1].dot(t1), cg.Xa[1].dot(t2);
      const Eigen::Matrix2d j = J.inverse();
      const double dA = J.determinant() * gw[ig] * gw[jg];
      // Tensor transformation [e_ξξ, e_ηη, e_ξη] -> [ε_11, ε_22, 2ε_12] with j_αa.
      Eigen::Matrix3d Tm;
      Tm << j(0, 0) * j(0, 0), j(0, 1) * j(0, 1), 2.0 * j(0, 0) * j(0, 1),  //
          j(1, 0) * j(1, 0), j(1, 1) * j(1, 1), 2.0 * j(1, 0) * j(1, 1),      //
          2.0 * j(0, 0) * j(1, 0), 2.0 * j(0, 1) * j(1, 1), 2.0 * (j(0, 0) * j(1, 1) + j(0, 1) * j(1, 0));
      GaussPoint& gp = gp_[3 * ig + jg];
      gp.dA = dA;
      Tm_[static_cast<size_t>(3 * ig + jg)] = Tm;  // the tying-point form's ε = Tm ẽ (§4.4–4.5)
      for (int c = 0; c < 3; ++c) {
        gp.Lm.row(c) = Tm(c, 0) * eL[0] + Tm(c, 1) * eL[1] + Tm(c, 2) * eL[2];
        gp.Hm[c] = Tm(c, 0) * eH[0] + Tm(c, 1) * eH[1] + Tm(c, 2) * eH[2];
      }
      Eigen::Matrix<double, 3, 45> Bb;
      for (int c = 0; c < 3; ++c) Bb.row(c) = Tm(c, 0) * cg.k[0] + Tm(c, 1) * cg.k[1] + Tm(c, 2) * cg.k[2];
      Eigen::Matrix<double, 2, 45> Bs;
      for (int al = 0; al < 2; ++al) Bs.row(al) = j(al, 0) * g[0] + j(al, 1) * g[1];
      // §4.7 constant parts of k_L: B_b^T (h^3 D1/12) B_b + B_s^T (h D2) B_s.
      Kbs_.noalias() += dA * (Bb.transpose() * Db * Bb + Ds * Bs.transpose() * Bs);
      Bbs_[static_cast<size_t>(3 * ig + jg)] << Bb, Bs;
      const Eigen::Matrix<double, 9, 1> N = shape_functions(xi, eta);
      m_.noalias() += dA * N * N.transpose();  // §5.1 m_ij
      area_ += dA;
    }
  }
  Kbs_ = 0.5 * (Kbs_ + Kbs_.transpose()).eval();
  for (int g = 0; g < 9; ++g)
    for (int c = 0; c < 3; ++c) {
      const GaussPoint& gp = gp_[static_cast<size_t>(g)];
      Lall_.row(3 * g + c) = gp.Lm.row(c);
      for (int j = 0; j < 9; ++j)
        for (int i = 0; i <= j; ++i) Hp_(i + j * (j + 1) / 2, 3 * g + c) = gp.Hm[static_cast<size_t>(c)](i, j);
      dAall_(3 * g + c) = gp.dA;
    }
  for (int j = 0; j < 45; ++j)
    for (int i = 0; i <= j; ++i) Kbsp_(i + j * (j + 1) / 2) = Kbs_(i, j);
  for (int j = 0; j < 27; ++j)
    if ((Lall_.col(j).array() != 0.0).any()) lcols_.push_back(j);
  std::vector<int> active;
  for (int i = 0; i < 45; ++i)
    if ((Kbs_.row(i).array() != 0.0).any()) active.push_back(i);
  if (active.size() < 45) {
    kbs_active_ = active;
    const Eigen::Index na = static_cast<Eigen::Index>(active.size());
    kbs_block_.resize(na, na);
    for (Eigen::Index j = 0; j < na; ++j)
      for (Eigen::Index i = 0; i < na; ++i) kbs_block_(i, j) = Kbs_(active[static_cast<size_t>(i)], active[static_cast<size_t>(j)]);
  }
}

namespace {
// y(active) = B w(active) for an N × N block B (column-major, N = active.size()): fixed-size columns
// accumulated in order, which the compiler unrolls; the same sums in the same order as Eigen's
// matrix-vector kernel (results bitwise unchanged), without its call and blocking overhead for N ≤ 45.
template <int N>
CR9Shell::Vec45 active_block_times(const double* block, const std::vector<int>& active, const CR9Shell::Vec45& w) {
  const Eigen::Map<const Eigen::Matrix<double, N, N>> B(block);
  Eigen::Matrix<double, N, 1> ya = Eigen::Matrix<double, N, 1>::Zero();
  for (int k = 0; k < N; ++k) ya.noalias() += B.col(k) * w(active[static_cast<size_t>(k)]);
  CR9Shell::Vec45 y = CR9Shell::Vec45::Zero();
  for (int k = 0; k < N; ++k) y(active[static_cast<size_t>(k)]) = ya(k);
  return y;
}
}  // namespace

CR9Shell::Vec45 CR9Shell::kbs_times(const Vec45& w) const {
  // Flat elements (27 active DOFs) and the cylindrical panel's (36): fixed-size products.
  if (kbs_active_.size() == 27) return active_block_times<27>(kbs_block_.data(), kbs_active_, w);
  if (kbs_active_.size() == 36) return active_block_times<36>(kbs_block_.data(), kbs_active_, w);
  if (!kbs_active_.empty()) {  // other sizes: the dense block on the DOFs K_bs acts on
    const Eigen::Index na = kbs_block_.rows();
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 45, 1> wa(na), ya(na);
    for (Eigen::Index k = 0; k < na; ++k) wa(k) = w(kbs_active_[static_cast<size_t>(k)]);
    ya.noalias() = kbs_block_ * wa;
    Vec45 y = Vec45::Zero();
    for (Eigen::Index k = 0; k < na; ++k) y(kbs_active_[static_cast<size_t>(k)]) = ya(k);
    return y;
  }
  // Symmetric packed product (no zero row: doubly curved elements): column j of the upper triangle contributes
  // K_ij w_j to y_i (i < j) and Σ_{i≤j} K_ij w_i to y_j; one pass over the column's off-diagonal part does both,
  // kLanes rows at a time (elements/simd.hpp).
  using simd::kLanes;
  alignas(32) double y[48] = {}, wp[48] = {};
  for (int i = 0; i < 45; ++i) wp[i] = w(i);
  const double* col = Kbsp_.data();
  for (int j = 0; j < 45; ++j) {
    const double wj = w(j);
    const simd::V wjv = simd::splat(wj);
    simd::V dv = simd::splat(0.0);
    int i = 0;
    for (; i + kLanes <= j; i += kLanes) {
      const simd::V k = simd::load(col + i);
      simd::store(y + i, simd::load(y + i) + k * wjv);
      dv += k * simd::load(wp + i);
    }
    double d = 0.0;
    for (int l = 0; l < kLanes; ++l) d += dv[l];
    for (; i < j; ++i) y[i] += col[i] * wj, d += col[i] * wp[i];
    y[j] += d + col[j] * wj;
    col += j + 1;
  }
  return Eigen::Map<const Vec45>(y);
}

CorotationalFrame CR9Shell::local_increments(const Vec45& u, const Charts& charts, Vec45* w, bool derivatives,
                                             bool curvature) const {
  std::array<Eigen::Vector3d, 9> x, p;
  std::array<Eigen::Matrix<double, 3, 2>, 9> A1;
  std::array<Eigen::Matrix2d, 9> d2;
  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector2d q = u.segment<2>(5 * i + 3);
    const DirectorChart& ch = charts[i];
    x[i] = X0_[i] + u.segment<3>(5 * i);
    // p, A1 and d²p_l/dq² of §2.1–2.2 from one p_l: the expressions of director(), director_A1() and
    // director_d2pl() (bitwise their values) without evaluating the square root three times.
    const double r = 1.0 - q.squaredNorm();
    if (!(r > 0.0)) director(q, ch);  // throws the §2.1 guard's std::domain_error
    const double pl = ch.s * std::sqrt(r);
    p[i](ch.n) = q(0);
    p[i](ch.m) = q(1);
    p[i](ch.l) = pl;
    if (derivatives) {
      A1[i].row(ch.n) << 1.0, 0.0;
      A1[i].row(ch.m) << 0.0, 1.0;
      A1[i].row(ch.l) << -q(0) / pl, -q(1) / pl;
      if (curvature) {
        Eigen::Matrix2d H;
        H << 1.0 - q(1) * q(1), q(0) * q(1), q(0) * q(1), 1.0 - q(0) * q(0);
        d2[i] = (-1.0 / (pl * pl * pl)) * H;
      }
    }
  }
  const CorotationalFrame fr = !derivatives ? CorotationalFrame(x, p, charts)
                               : curvature  ? CorotationalFrame(x, p, A1, d2, charts)
                                            : CorotationalFrame(x, p, A1, charts);
  if (w) {
    std::array<Eigen::Vector3d, 9> d;
    for (int i = 0; i < 9; ++i) d[i] = u.segment<3>(5 * i);
    *w = fr.local_variables(xl0_, rel0_, d);  // compensated t_i (docs/theory/exact-energy-momentum.md §5.1)
    for (int i = 0; i < 9; ++i) w->segment<2>(5 * i + 3) -= th0_[i];  // Δθ_i = θ_i - θ_i0 (§2.5)
  }
  return fr;
}

CorotationalFrame CR9Shell::frame(const Vec45& u, const Charts& charts) const {
  return local_increments(u, charts, nullptr);
}

CR9Shell::TauT CR9Shell::tying_tau(const Mat39& t) const {
  // τ(j, c) = Σ_i N_i,a(point j) t_i,c: per component a 20-long accumulator (ten SSE2 packets, kept in registers)
  // updated by the nine columns of D_τᵀ in node order.
  const double* D = tying_dNT().data();
  TauT tau;
  for (int c = 0; c < 3; ++c) {
    alignas(16) double acc[20];
    const double t0 = t(c, 0);
    for (int k = 0; k < 20; ++k) acc[k] = D[k] * t0;
#pragma GCC unroll 8
    for (int i = 1; i < 9; ++i) {
      const double ti = t(c, i);
      const double* Di = D + 20 * i;
      for (int k = 0; k < 20; ++k) acc[k] += Di[k] * ti;
    }
    for (int k = 0; k < 20; ++k) tau(k, c) = acc[k];
  }
  return tau;
}

Eigen::Matrix<double, 27, 1> CR9Shell::tying_strains(const TauT& tau) const {
  // §4.4 tying-point strains ê_ab = ½(X_a·τ_b + X_b·τ_a + τ_a·τ_b): families A, B (rows 0–11) ê = X·τ + ½|τ|²,
  // family C (rows 12–15 ξ, 16–19 η) ê = ½(X_ξ·τ_η + X_η·τ_ξ + τ_ξ·τ_η).
  alignas(16) double eh[16];
  const double *X0 = XtT_.col(0).data(), *X1 = XtT_.col(1).data(), *X2 = XtT_.col(2).data();
  const double *u0 = tau.col(0).data(), *u1 = tau.col(1).data(), *u2 = tau.col(2).data();
  for (int k = 0; k < 12; ++k)
    eh[k] = (X0[k] * u0[k] + X1[k] * u1[k] + X2[k] * u2[k]) + 0.5 * (u0[k] * u0[k] + u1[k] * u1[k] + u2[k] * u2[k]);
  for (int k = 12; k < 16; ++k)
    eh[k] = 0.5 * ((X0[k] * u0[k + 4] + X1[k] * u1[k + 4] + X2[k] * u2[k + 4]) +
                   (X0[k + 4] * u0[k] + X1[k + 4] * u1[k] + X2[k + 4] * u2[k]) +
                   (u0[k] * u0[k + 4] + u1[k] * u1[k + 4] + u2[k] * u2[k + 4]));
  // ε = Tm ẽ per Gauss point, ẽ = (family A's 2, family B's 2, family C's 4 weighted tying strains).
  const GaussTyingWeights& W = mitc9_gauss_weights();
  Eigen::Matrix<double, 27, 1> e;
  for (int ig = 0; ig < 3; ++ig)
    for (int jg = 0; jg < 3; ++jg) {
      const int g = 3 * ig + jg;
      const double ea = W.a[g][0] * eh[jg] + W.a[g][1] * eh[3 + jg];
      const double eb = W.b[g][0] * eh[6 + 2 * ig] + W.b[g][1] * eh[7 + 2 * ig];
      const double ec = (W.c[g][0] * eh[12] + W.c[g][1] * eh[13]) + (W.c[g][2] * eh[14] + W.c[g][3] * eh[15]);
      const Eigen::Matrix3d& T = Tm_[static_cast<size_t>(g)];
      e.segment<3>(3 * g) = T.col(0) * ea + T.col(1) * eb + T.col(2) * ec;
    }
  return e;
}

void CR9Shell::tying_force(const Eigen::Matrix<double, 27, 1>& s, const TauT& taubar, Vec45* fL) const {
  // Σ_gp dA B_mᵀ N = Σ_k μ_k ∂ê_k/∂t at t̄ (§4.4), μ = (∂ε/∂ê)ᵀ s: per Gauss point r = Tmᵀ s_gp, spread onto the
  // tying points with the interpolation weights of tying_strains(). ∂ê_ab/∂t_i = ½[N_i,b (X_a + τ̄_a) +
  // N_i,a (X_b + τ̄_b)], so f_tᵀ = D_τ G with G's row j the weight of τ point j.
  const GaussTyingWeights& W = mitc9_gauss_weights();
  double mu[16] = {};
  for (int ig = 0; ig < 3; ++ig)
    for (int jg = 0; jg < 3; ++jg) {
      const int g = 3 * ig + jg;
      const Eigen::Vector3d r = Tm_[static_cast<size_t>(g)].transpose() * s.segment<3>(3 * g);
      mu[jg] += W.a[g][0] * r(0);
      mu[3 + jg] += W.a[g][1] * r(0);
      mu[6 + 2 * ig] += W.b[g][0] * r(1);
      mu[7 + 2 * ig] += W.b[g][1] * r(1);
      for (int k = 0; k < 4; ++k) mu[12 + k] += W.c[g][k] * r(2);
    }
  alignas(16) double m20[20];
  for (int k = 0; k < 12; ++k) m20[k] = mu[k];
  for (int k = 12; k < 16; ++k) m20[k] = m20[k + 4] = 0.5 * mu[k];
  // G(j, c) = m_j (X + τ̄)(j', c), j' = j for families A, B and the partner row (j ± 4) for family C.
  alignas(16) double G[3][20];
  for (int c = 0; c < 3; ++c) {
    const double *X = XtT_.col(c).data(), *u = taubar.col(c).data();
    for (int k = 0; k < 12; ++k) G[c][k] = m20[k] * (X[k] + u[k]);
    for (int k = 12; k < 16; ++k) G[c][k] = m20[k] * (X[k + 4] + u[k + 4]);
    for (int k = 16; k < 20; ++k) G[c][k] = m20[k] * (X[k - 4] + u[k - 4]);
  }
  // f_tᵀ = D_τ G: per component a 10-long accumulator (row 9 of the padded D_τ is zero) over the 20 τ points.
  // (Eigen's packet expressions: plain loops here are turned into scalar dot products by GCC.)
  const Eigen::Matrix<double, 10, 20>& D = tying_dN10();
  for (int c = 0; c < 3; ++c) {
    Eigen::Matrix<double, 10, 1> acc = D.col(0) * G[c][0];
    for (int j = 1; j < 20; ++j) acc.noalias() += D.col(j) * G[c][j];
    for (int i = 0; i < 9; ++i) (*fL)(5 * i + c) += acc(i);
  }
}

Eigen::Matrix<double, 27, 1> CR9Shell::membrane_strains(const Mat39& t) const {
  if (tying_) return tying_strains(tying_tau(t));
  // ε_m,c at every Gauss point: L_m,c·t + ½ Σ_ij H_c(i,j) t_i·t_j = L_m,c·t + ½ H_c : (tᵀt)  (§4.5)
  // Packed Gram matrix with the off-diagonal entries doubled: Σ_ij H_ij G_ij = Σ_k Hp_k g_k.
  Eigen::Matrix<double, 45, 1> g;
  for (int j = 0; j < 9; ++j) {
    for (int i = 0; i < j; ++i) g(i + j * (j + 1) / 2) = 2.0 * t.col(i).dot(t.col(j));
    g(j + j * (j + 1) / 2) = t.col(j).squaredNorm();
  }
  const Eigen::Map<const Eigen::Matrix<double, 27, 1>> v(t.data());
  // L·t column by column (fixed-size axpys), over the columns of L that are not zero: a flat element's linear
  // membrane strains do not involve the normal translations t_z, a third of the columns.
  Eigen::Matrix<double, 27, 1> e = Eigen::Matrix<double, 27, 1>::Zero();
  for (const int j : lcols_) e.noalias() += Lall_.col(j) * v(j);
  e.noalias() += 0.5 * Hp_.transpose().lazyProduct(g);
  return e;
}

double CR9Shell::membrane(const Mat39& t1, const Mat39& t0, double c1, double c0, double b1, double b0, Vec45* fL,
                          Mat45* kL, const StepState* n0) const {
  const Eigen::Matrix3d hD1 = mat_.thickness * D1_;
  const bool need0 = (c0 != 0.0 || b0 != 0.0);
  const Eigen::Matrix<double, 27, 1> e1all = membrane_strains(t1);
  Eigen::Matrix<double, 27, 1> e0all = Eigen::Matrix<double, 27, 1>::Zero();
  if (need0 && n0)
    for (int g = 0; g < 9; ++g) e0all.segment<3>(3 * g) = n0->e[static_cast<size_t>(g)];
  else if (need0)
    e0all = membrane_strains(t0);
  // Gradient B_m = L_m + H_m t̄ at t̄ = b1 t1 + b0 t0 (§4.7), all Gauss points stacked: row 3g + c of Ball.
  const Mat39 tb = need0 ? Mat39(b1 * t1 + b0 * t0) : Mat39(b1 * t1);
  Eigen::Matrix<double, 27, 27> Ball, DBall;
  Eigen::Matrix<double, 27, 1> sN;  // dA N* per Gauss point, N* = h D1 ε*_m (§6.3)
  double U = 0.0;
  for (int g = 0; g < 9; ++g) {
    const GaussPoint& gp = gp_[static_cast<size_t>(g)];
    for (int c = 0; c < 3; ++c) {
      // lazyProduct: a small fixed-size product (3×9·9×9) is 2-3x faster coefficient-wise than through
      // Eigen's blocked GEMM path, which it picks when rows + cols + depth > 20.
      const Mat39 tH = tb.lazyProduct(gp.Hm[static_cast<size_t>(c)]);
      Ball.row(3 * g + c) = gp.Lm.row(c) + Eigen::Map<const Row27>(tH.data());
    }
    const Eigen::Vector3d e1 = e1all.segment<3>(3 * g), e0 = e0all.segment<3>(3 * g);
    U += membrane_energy(gp.dA, e1, hD1);
    sN.segment<3>(3 * g) = gp.dA * (hD1 * (c1 * e1 + c0 * e0));
    if (kL) DBall.middleRows<3>(3 * g) = (gp.dA * hD1) * Ball.middleRows<3>(3 * g);
  }
  if (fL) {
    const Eigen::Matrix<double, 27, 1> fm = Ball.transpose() * sN;  // Σ_gp dA B_mᵀ N*
    for (int i = 0; i < 9; ++i) fL->segment<3>(5 * i) += fm.segment<3>(3 * i);
  }
  if (kL) {
    // Σ_gp dA B_mᵀ h D1 B_m as one 27×27·27×27 product, and Σ_gp,c dA N_c H_m,c from the packed H columns.
    const Eigen::Matrix<double, 27, 27> km = Ball.transpose() * DBall;
    const Eigen::Matrix<double, 45, 1> hs = Hp_ * sN;
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i < 9; ++i) {
        kL->block<3, 3>(5 * i, 5 * j) += km.block<3, 3>(3 * i, 3 * j);
        kL->block<3, 3>(5 * i, 5 * j).diagonal().array() += hs(i <= j ? i + j * (j + 1) / 2 : j + i * (i + 1) / 2);
      }
  }
  return U;
}

double CR9Shell::membrane_force(const Mat39& t1, const Mat39& t0, double c1, double c0, double b1, double b0,
                                const StepState& n0, Vec45* fL) const {
  const Eigen::Matrix3d hD1 = mat_.thickness * D1_;
  TauT tau1;
  if (tying_) tau1 = tying_tau(t1);
  const Eigen::Matrix<double, 27, 1> e1 = tying_ ? tying_strains(tau1) : membrane_strains(t1);
  // N* = h D1 (c1 ε1 + c0 ε0) per Gauss point (§6.3), weighted by dA: s = dA N*.
  Eigen::Matrix<double, 27, 1> sN;
  double U = 0.0;
  for (int g = 0; g < 9; ++g) {
    const Eigen::Vector3d eg = e1.segment<3>(3 * g);
    const Eigen::Vector3d N = hD1 * (c1 * eg + c0 * n0.e[static_cast<size_t>(g)]);
    const double dA = dAall_(3 * g);
    U += membrane_energy(dA, eg, hD1);
    sN.segment<3>(3 * g) = dA * N;
  }
  if (tying_) {
    // τ̄ = τ(t̄) = b1 τ(t1) + b0 τ(t0) (τ is linear in t), with τ(t0) from the step state.
    TauT taubar;
    if (b0 != 0.0) taubar = b1 * tau1 + b0 * n0.tau;
    else taubar = b1 * tau1;
    tying_force(sN, taubar, fL);
    return U;
  }
  // Σ_gp dA B_mᵀ N with B_m,c = L_m,c + (t̄ H_c) rows, t̄ = b1 t1 + b0 t0: Lᵀ s + t̄ Σ_gp,c s_gp,c H_c.
  Eigen::Matrix<double, 27, 1> fm = Eigen::Matrix<double, 27, 1>::Zero();
  for (const int j : lcols_) fm(j) = Lall_.col(j).dot(sN);
  Eigen::Matrix<double, 45, 1> hs = Hp_.col(0) * sN(0);
  for (int k = 1; k < 27; ++k) hs.noalias() += Hp_.col(k) * sN(k);
  Mat9 Hs;
  for (int j = 0; j < 9; ++j)
    for (int i = 0; i <= j; ++i) Hs(i, j) = Hs(j, i) = hs(i + j * (j + 1) / 2);
  const Mat39 tb = b1 * t1 + b0 * t0;
  const Mat39 ft = tb.lazyProduct(Hs);
  for (int i = 0; i < 9; ++i) fL->segment<3>(5 * i) += fm.segment<3>(3 * i) + ft.col(i);
  return U;
}

namespace {
Eigen::Matrix<double, 3, 9> translations(const Eigen::Matrix<double, 45, 1>& w) {
  Eigen::Matrix<double, 3, 9> t;
  for (int i = 0; i < 9; ++i) t.col(i) = w.segment<3>(5 * i);
  return t;
}
}  // namespace

double CR9Shell::local(const Vec45& u, const Charts& charts, Vec45* uL, Vec45* fL, Mat45* kL) const {
  Vec45 w;
  const CorotationalFrame fr = local_increments(u, charts, &w);
  if (uL) *uL = fr.local_variables(xl0_);
  Vec45 f = Kbs_ * w;  // bending + shear: f = K_bs w (linear, §4.7)
  double U = 0.5 * w.dot(f);
  if (kL) *kL = Kbs_;
  const Mat39 t = translations(w);
  U += membrane(t, t, 1.0, 0.0, 1.0, 0.0, &f, kL);
  if (fL) *fL = f;
  return U;
}

double CR9Shell::internal(const Vec45& u, const Charts& charts, Vec45* F, Mat45* K) const {
  Vec45 w;
  const CorotationalFrame fr = local_increments(u, charts, &w, true, K != nullptr);
  // K_bs w: the dense product with K (the tangent's own path) and for an element without zero rows of K_bs (where
  // it takes fewer instructions than the packed one), else the residual's active block.
  Vec45 fL = (K || kbs_active_.empty()) ? Vec45(Kbs_ * w) : kbs_times(w);
  double U = 0.5 * w.dot(fL);
  const Mat39 t = translations(w);
  if (K) {
    Mat45 kL = Kbs_;
    U += membrane(t, t, 1.0, 0.0, 1.0, 0.0, &fL, &kL);
    fr.tangent(kL, fL, opt_.geometric_stiffness, K);  // §3.4 K = T^T k_L T + K_σ
  } else {
    // The force alone: membrane_force() (no B_m matrices formed) with c0 = b0 = 0, so the state of t0 is unused.
    static const StepState unused = [] {
      StepState z;
      z.w.setZero(), z.Kw.setZero(), z.tau.setZero();
      for (auto& e : z.e) e.setZero();
      return z;
    }();
    U += membrane_force(t, t, 1.0, 0.0, 1.0, 0.0, unused, &fL);
  }
  if (F) *F = fr.apply_transpose(fL);  // §3.4 F = T^T f_L
  return U;
}

double CR9Shell::algorithmic_internal(const Vec45& u_n, const Vec45& u_np1, const Charts& charts, double alpha_f,
                                      double xi, Vec45* F, Mat45* K) const {
  if (!(alpha_f >= 0.0 && alpha_f <= 1.0) || !std::isfinite(xi)) {
    std::ostringstream os;
    os << "CR9Shell::algorithmic_internal: alpha_f = " << alpha_f << " must lie in [0,1] and xi = " << xi
       << " must be finite";
    throw std::invalid_argument(os.str());
  }
  // §6.3 steps 1-5: local states from each end configuration (same charts), strain averaging,
  // strain gradient at w̄ = (1-α_f) w_1 + α_f w_n, T and K_σ at u_mid.
  Vec45 wn, w1;
  local_increments(u_n, charts, &wn, false);
  local_increments(u_np1, charts, &w1, false);
  const Vec45 u_mid = (1.0 - alpha_f) * u_np1 + alpha_f * u_n;
  const CorotationalFrame fr = local_increments(u_mid, charts, nullptr);
  const double c1 = 1.0 - alpha_f + xi, c0 = alpha_f - xi;
  Vec45 fL = Kbs_ * (c1 * w1 + c0 * wn);  // B_b^T M* + B_s^T Q* (B_b, B_s constant)
  double U = 0.5 * w1.dot(Kbs_ * w1);
  const Mat39 t1 = translations(w1), t0 = translations(wn);  // w̄ = (1-α_f) w1 + α_f wn enters membrane()
  if (K) {
    Mat45 kL = Kbs_;
    U += membrane(t1, t0, c1, c0, 1.0 - alpha_f, alpha_f, &fL, &kL);
    fr.tangent(kL, fL, opt_.geometric_stiffness, K);
  } else {
    U += membrane(t1, t0, c1, c0, 1.0 - alpha_f, alpha_f, &fL, nullptr);
  }
  if (F) *F = fr.apply_transpose(fL);
  return U;
}

void CR9Shell::step_state(const Vec45& u_n, const Charts& charts, StepState* st) const {
  local_increments(u_n, charts, &st->w, false);
  st->Kw = kbs_times(st->w);
  const Mat39 t = translations(st->w);
  // membrane()'s and the residual's strains, bitwise: tying_strains(tying_tau(t)) is membrane_strains(t)
  if (tying_) st->tau = tying_tau(t);
  else st->tau.setZero();
  const Eigen::Matrix<double, 27, 1> e = tying_ ? tying_strains(st->tau) : membrane_strains(t);
  for (int g = 0; g < 9; ++g) st->e[static_cast<size_t>(g)] = e.segment<3>(3 * g);
}

double CR9Shell::step_energy(const StepState& st) const {
  // The residual's expressions (algorithmic_internal() without K): U = ½ wᵀ(K_bs w) with the state's K_bs w
  // (kbs_times), then Σ_gp ½ dA εᵀ h D1 ε with the state's ε. So the U(u_{n+1}) a step ends with and the
  // U(u_n) the next step starts from are the same number, and em-exact's ΔU telescope over the steps.
  const Eigen::Matrix3d hD1 = mat_.thickness * D1_;
  double Um = 0.0;
  for (size_t g = 0; g < gp_.size(); ++g) Um += membrane_energy(gp_[g].dA, st.e[g], hD1);
  return 0.5 * st.w.dot(st.Kw) + Um;
}

double CR9Shell::algorithmic_internal(const StepState& sn, const Vec45& u_n, const Vec45& u_np1, const Charts& charts,
                                      double alpha_f, double xi, Vec45* F, Mat45* K) const {
  if (!(alpha_f >= 0.0 && alpha_f <= 1.0) || !std::isfinite(xi)) {
    std::ostringstream os;
    os << "CR9Shell::algorithmic_internal: alpha_f = " << alpha_f << " must lie in [0,1] and xi = " << xi
       << " must be finite";
    throw std::invalid_argument(os.str());
  }
  // As the plain overload, with w_n, K_bs w_n and ε_m(t_n) from the step state.
  const Vec45& wn = sn.w;
  Vec45 w1;
  local_increments(u_np1, charts, &w1, false);  // the frame at u_np1 serves w1 only (its derivatives are never formed)
  const Vec45 u_mid = (1.0 - alpha_f) * u_np1 + alpha_f * u_n;
  const CorotationalFrame fr = local_increments(u_mid, charts, nullptr, true, K != nullptr);
  const double c1 = 1.0 - alpha_f + xi, c0 = alpha_f - xi;
  if (!K) {  // residual: K_bs w_n from the step state, membrane force without its tangent
    const Vec45 Kw1 = kbs_times(w1);
    Vec45 fL = c1 * Kw1 + c0 * sn.Kw;
    double U = 0.5 * w1.dot(Kw1);
    U += membrane_force(translations(w1), translations(wn), c1, c0, 1.0 - alpha_f, alpha_f, sn, &fL);
    if (F) *F = fr.apply_transpose(fL);
    return U;
  }
  Vec45 fL = Kbs_ * (c1 * w1 + c0 * wn);
  double U = 0.5 * w1.dot(Kbs_ * w1);
  const Mat39 t1 = translations(w1), t0 = translations(wn);
  if (K) {
    Mat45 kL = Kbs_;
    U += membrane(t1, t0, c1, c0, 1.0 - alpha_f, alpha_f, &fL, &kL, &sn);
    fr.tangent(kL, fL, opt_.geometric_stiffness, K);
  } else {
    U += membrane(t1, t0, c1, c0, 1.0 - alpha_f, alpha_f, &fL, nullptr, &sn);
  }
  if (F) *F = fr.apply_transpose(fL);
  return U;
}

void CR9Shell::mass(const Vec45& u, const Charts& charts, Mat45* M) const {
  const double rh = mat_.rho * mat_.thickness;
  const double rh3 = rh * mat_.thickness * mat_.thickness / 12.0;
  std::array<Eigen::Matrix<double, 3, 2>, 9> A1;
  for (int i = 0; i < 9; ++i) A1[i] = director_A1(u.segment<2>(5 * i + 3), charts[i]);
  M->setZero();
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) {
      // §5.2 node-pair block: ρh m_ij I_3 and (ρh³/12) m_ij A1_i^T A1_j.
      M->block<3, 3>(5 * i, 5 * j).diagonal().setConstant(rh * m_(i, j));
      M->block<2, 2>(5 * i + 3, 5 * j + 3).noalias() = (rh3 * m_(i, j)) * A1[i].transpose() * A1[j];
    }
}

void CR9Shell::inertia_force(const Vec45& u, const Vec45& v, const Vec45& a, const Charts& charts, Vec45* f) const {
  const double rh = mat_.rho * mat_.thickness;
  const double rh3 = rh * mat_.thickness * mat_.thickness / 12.0;
  std::array<Eigen::Matrix<double, 3, 2>, 9> A1;
  Eigen::Matrix<double, 3, 9> at, pdd;
  for (int j = 0; j < 9; ++j) {
    const Eigen::Vector2d q = u.segment<2>(5 * j + 3);
    A1[j] = director_A1(q, charts[j]);
    at.col(j) = a.segment<3>(5 * j);
    pdd.col(j) = A1[j] * a.segment<2>(5 * j + 3) + director_A2(q, v.segment<2>(5 * j + 3), charts[j]);  // p̈_j
  }
  // Column i of X m is Σ_j m_ij X_j (m symmetric).
  const Eigen::Matrix<double, 3, 9> mat = at.lazyProduct(m_), mpdd = pdd.lazyProduct(m_);
  for (int i = 0; i < 9; ++i) {
    f->segment<3>(5 * i) = rh * mat.col(i);
    f->segment<2>(5 * i + 3) = rh3 * (A1[i].transpose() * mpdd.col(i));
  }
}

void CR9Shell::inertial(const Vec45& u, const Vec45& v, const Charts& charts, Vec45* Fm) const {
  const double rh3 = mat_.rho * std::pow(mat_.thickness, 3) / 12.0;
  std::array<Eigen::Vector3d, 9> A2;
  for (int j = 0; j < 9; ++j) A2[j] = director_A2(u.segment<2>(5 * j + 3), v.segment<2>(5 * j + 3), charts[j]);
  Fm->setZero();
  for (int i = 0; i < 9; ++i) {
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    for (int j = 0; j < 9; ++j) s += m_(i, j) * A2[j];
    // §5.2: F_m at node i = (ρh³/12) A1_i^T Σ_j m_ij A2_j (no translational part).
    Fm->segment<2>(5 * i + 3) = rh3 * director_A1(u.segment<2>(5 * i + 3), charts[i]).transpose() * s;
  }
}

CR9Shell::Resultants CR9Shell::resultants(const Vec45& u, const Charts& charts) const {
  Vec45 w;
  local_increments(u, charts, &w, false);
  const Mat39 t = translations(w);
  const Eigen::Map<const Eigen::Matrix<double, 27, 1>> v(t.data());
  const double h = mat_.thickness, G = mat_.E / (2.0 * (1.0 + mat_.nu));
  Resultants r;
  r.membrane_strain.setZero(), r.curvature.setZero(), r.shear_strain.setZero();
  r.membrane_force.setZero(), r.bending_moment.setZero(), r.shear_force.setZero();
  double U = 0.0;
  for (size_t g = 0; g < gp_.size(); ++g) {
    const GaussPoint& gp = gp_[g];
    Eigen::Vector3d e;
    for (int c = 0; c < 3; ++c) e(c) = gp.Lm.row(c).dot(v) + 0.5 * t.lazyProduct(gp.Hm[c]).cwiseProduct(t).sum();
    const Eigen::Matrix<double, 5, 1> bs = Bbs_[g] * w;
    const Eigen::Vector3d chi = bs.head<3>();
    const Eigen::Vector2d gam = bs.tail<2>();
    const Eigen::Vector3d N = h * D1_ * e, M = (h * h * h / 12.0) * D1_ * chi;
    const Eigen::Vector2d Q = mat_.shear_factor * G * h * gam;
    r.membrane_strain += gp.dA * e, r.curvature += gp.dA * chi, r.shear_strain += gp.dA * gam;
    r.membrane_force += gp.dA * N, r.bending_moment += gp.dA * M, r.shear_force += gp.dA * Q;
    U += 0.5 * gp.dA * (e.dot(N) + chi.dot(M) + gam.dot(Q));
  }
  const double A = area_;
  r.membrane_strain /= A, r.curvature /= A, r.shear_strain /= A;
  r.membrane_force /= A, r.bending_moment /= A, r.shear_force /= A;
  r.energy_density = U / A;
  return r;
}

double CR9Shell::kinetic(const Vec45& u, const Vec45& v, const Charts& charts) const {
  const double rh = mat_.rho * mat_.thickness;
  const double rh3 = rh * mat_.thickness * mat_.thickness / 12.0;
  Eigen::Matrix<double, 3, 9> dd, pd;
  for (int i = 0; i < 9; ++i) {
    dd.col(i) = v.segment<3>(5 * i);
    pd.col(i) = director_A1(u.segment<2>(5 * i + 3), charts[i]) * v.segment<2>(5 * i + 3);  // ṗ = A1 q̇
  }
  // §5.1: K = ½ρh Σ m_ij ḋ_i·ḋ_j + ½(ρh³/12) Σ m_ij ṗ_i·ṗ_j.
  return 0.5 * rh * (dd * m_ * dd.transpose()).trace() + 0.5 * rh3 * (pd * m_ * pd.transpose()).trace();
}

void CR9Shell::momenta(const Vec45& u, const Vec45& v, const Charts& charts, Eigen::Vector3d* L,
                       Eigen::Vector3d* J) const {
  const double rh = mat_.rho * mat_.thickness;
  const double h2 = mat_.thickness * mat_.thickness / 12.0;
  Eigen::Matrix<double, 3, 9> dd, pd, x, p;
  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector2d q = u.segment<2>(5 * i + 3);
    dd.col(i) = v.segment<3>(5 * i);
    x.col(i) = X0_[i] + u.segment<3>(5 * i);
    p.col(i) = director(q, charts[i]);
    pd.col(i) = director_A1(q, charts[i]) * v.segment<2>(5 * i + 3);
  }
  // §5.4: L = Σ ρh m_ij ḋ_j, J = Σ ρh m_ij [x_i × ḋ_j + (h²/12) p_i × ṗ_j].
  const Eigen::Matrix<double, 3, 9> mdd = dd * m_, mpd = pd * m_;  // column i = Σ_j m_ij ḋ_j (m symmetric)
  if (L) *L = rh * mdd.rowwise().sum();
  if (J) {
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    for (int i = 0; i < 9; ++i)
      s += Eigen::Vector3d(x.col(i)).cross(Eigen::Vector3d(mdd.col(i))) +
           h2 * Eigen::Vector3d(p.col(i)).cross(Eigen::Vector3d(mpd.col(i)));
    *J = rh * s;
  }
}

}  // namespace shelldyn
