// Co-rotational triad, T and K_σ: docs/theory.md §3.1-3.4.
#include "elements/corotational_frame.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "elements/simd.hpp"

namespace shelldyn {

namespace {

using Mat312 = Eigen::Matrix<double, 3, 12>;

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v(2), v(1), v(2), 0, -v(0), -v(1), v(0), 0;
  return S;
}

// P(v) = (I - v̂ v̂^T)/|v|: Jacobian of v -> v̂ (§3.3).
Eigen::Matrix3d unit_jacobian(const Eigen::Vector3d& v) {
  const double n = v.norm();
  const Eigen::Vector3d h = v / n;
  return (Eigen::Matrix3d::Identity() - h * h.transpose()) / n;
}

// P(v) w without forming P(v): (w − v̂ (v̂·w)) / |v|.
Eigen::Vector3d unit_jacobian_times(const Eigen::Vector3d& v, const Eigen::Vector3d& w) {
  const double n = v.norm();
  const Eigen::Vector3d h = v / n;
  return (w - h.dot(w) * h) / n;
}

// H(v; u): Hessian of u·v̂ with respect to v (§3.4 group 1).
Eigen::Matrix3d unit_hessian(const Eigen::Vector3d& v, const Eigen::Vector3d& u) {
  const double n = v.norm();
  const Eigen::Vector3d h = v / n;
  const Eigen::Matrix3d Pi = Eigen::Matrix3d::Identity() - h * h.transpose();
  const Eigen::Vector3d Piu = Pi * u;
  return -(h * Piu.transpose() + Piu * h.transpose() + u.dot(h) * Pi) / (n * n);
}

void require_nondegenerate(const Eigen::Vector3d& v, double scale, const char* what) {
  if (!(v.norm() > 1e-12 * scale) || !v.allFinite()) {
    std::ostringstream os;
    os << "CorotationalFrame: " << what << " has length " << v.norm()
       << " (degenerate current element: corners collapsed or diagonals parallel); reject the iterate "
          "and cut the step, or check the mesh";
    throw std::domain_error(os.str());
  }
}

}  // namespace

CorotationalFrame::CorotationalFrame(const std::array<Eigen::Vector3d, 9>& x,
                                     const std::array<Eigen::Vector3d, 9>& p,
                                     const std::array<Eigen::Matrix<double, 3, 2>, 9>& A1,
                                     const std::array<Eigen::Matrix2d, 9>& d2pl,
                                     const std::array<DirectorChart, 9>& charts)
    : CorotationalFrame(x, p, charts) {
  A1_ = A1;
  d2pl_ = d2pl;
  director_derivatives_ = true;
  director_curvature_ = true;
}

CorotationalFrame::CorotationalFrame(const std::array<Eigen::Vector3d, 9>& x, const std::array<Eigen::Vector3d, 9>& p,
                                     const std::array<Eigen::Matrix<double, 3, 2>, 9>& A1,
                                     const std::array<DirectorChart, 9>& charts)
    : CorotationalFrame(x, p, charts) {
  A1_ = A1;
  director_derivatives_ = true;
  director_curvature_ = false;
}

CorotationalFrame::CorotationalFrame(const std::array<Eigen::Vector3d, 9>& x, const std::array<Eigen::Vector3d, 9>& p,
                                     const std::array<DirectorChart, 9>& charts)
    : p_(p), director_derivatives_(false), director_curvature_(false) {
  for (int i = 0; i < 9; ++i) l_[i] = charts[i].l;
  // §3.1 triad from the unit diagonals.
  a_ = x[2] - x[0];
  b_ = x[3] - x[1];
  require_nondegenerate(a_, 1.0, "diagonal x3 - x1");
  require_nondegenerate(b_, 1.0, "diagonal x4 - x2");
  const Eigen::Vector3d ah = a_.normalized(), bh = b_.normalized();
  s_ = ah - bh;
  c_ = ah + bh;
  // |s|^2 + |c|^2 = 4, so one of them is small only for (anti)parallel diagonals.
  require_nondegenerate(s_, 1.0, "difference of the unit diagonals");
  require_nondegenerate(c_, 1.0, "sum of the unit diagonals");
  const Eigen::Vector3d ex = s_.normalized(), ey = c_.normalized();
  R_.col(0) = ex;
  R_.col(1) = ey;
  R_.col(2) = ex.cross(ey);
  xO_ = 0.25 * (x[0] + x[1] + x[2] + x[3]);
  for (int i = 0; i < 9; ++i) rel_[i] = x[i] - xO_;
}

void CorotationalFrame::compute_derivatives() const {
  if (!director_derivatives_)
    throw std::logic_error("CorotationalFrame: derivatives of a frame built for local_variables() only (no A1, d2pl)");
  const Eigen::Vector3d ex = R_.col(0), ey = R_.col(1);
  // §3.3 frame derivatives, per corner: G_a = [-I 0 I 0], G_b = [0 -I 0 I].
  Pa_ = unit_jacobian(a_);
  Pb_ = unit_jacobian(b_);
  Ps_ = unit_jacobian(s_);
  Pc_ = unit_jacobian(c_);
  const Eigen::Matrix3d PsPa = Ps_ * Pa_, PsPb = Ps_ * Pb_, PcPa = Pc_ * Pa_, PcPb = Pc_ * Pb_;
  E_[0][0] = -PsPa, E_[0][2] = PsPa, E_[0][1] = PsPb, E_[0][3] = -PsPb;
  E_[1][0] = -PcPa, E_[1][2] = PcPa, E_[1][1] = -PcPb, E_[1][3] = PcPb;
  const Eigen::Matrix3d Sx = skew(ex), Sy = skew(ey);
  for (int k = 0; k < 4; ++k) E_[2][k] = -Sy * E_[0][k] + Sx * E_[1][k];

  Eigen::Matrix<double, 2, 3> Exy;
  Exy.row(0) = ex.transpose();
  Exy.row(1) = ey.transpose();
  for (int i = 0; i < 9; ++i) D_theta_[i] = Exy * A1_[i];  // ∂θ_i/∂q_i
  have_derivatives_ = true;
}

void CorotationalFrame::compute_corner_columns() const {
  // Factored T = D + C P (§3.3 blocks).
  C_.setZero();
  for (int i = 0; i < 9; ++i) {
    for (int k = 0; k < 4; ++k) {
      // ∂t_i/∂d_k (corner part): -¼R^T + C_ik, C_ik row α = (x_i - x_O)^T E_α,k.
      Eigen::Matrix3d blk = -0.25 * R_.transpose();
      for (int al = 0; al < 3; ++al) blk.row(al) += rel_[i].transpose() * E_[al][k];
      C_.block<3, 3>(5 * i, 3 * k) = blk;
      // ∂θ_i/∂d_k: row α = p_i^T E_α,k.
      for (int al = 0; al < 2; ++al) C_.block<1, 3>(5 * i + 3 + al, 3 * k) = p_[i].transpose() * E_[al][k];
    }
  }
  have_corner_columns_ = true;
}

CorotationalFrame::Vec45 CorotationalFrame::local_variables(const std::array<Eigen::Vector3d, 9>& x_local0) const {
  Vec45 u;
  for (int i = 0; i < 9; ++i) {
    u.segment<3>(5 * i) = R_.transpose() * rel_[i] - x_local0[i];
    u(5 * i + 3) = R_.col(0).dot(p_[i]);
    u(5 * i + 4) = R_.col(1).dot(p_[i]);
  }
  return u;
}

namespace {

// Error-free transformations (Knuth's TwoSum here; TwoProduct, by FMA when the target has it, else Dekker's
// splitting, inline in local_variables() below): a op b = hi + lo exactly in binary64. Used by the compensated local translations below.
struct DD {
  double hi = 0.0, lo = 0.0;
};

inline DD two_sum(double a, double b) {
  const double s = a + b;
  const double bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}

// (hi, lo) + (b_hi, b_lo), renormalised.
inline DD dd_add(const DD& a, const DD& b) {
  const DD s = two_sum(a.hi, b.hi);
  return two_sum(s.hi, s.lo + a.lo + b.lo);
}

// Nine nodes in vector registers: kNodeVectors vectors of kLanes doubles (elements/simd.hpp).
using simd::kLanes;
using simd::splat;
using VNodes = simd::V;
constexpr int kNodeVectors = (9 + kLanes - 1) / kLanes;

// TwoSum lane-wise: returns a + b rounded, *err its rounding error.
inline VNodes two_sum(VNodes a, VNodes b, VNodes* err) {
  const VNodes s = a + b;
  const VNodes bb = s - a;
  *err = (a - (s - bb)) + (b - bb);
  return s;
}

}  // namespace

CorotationalFrame::Vec45 CorotationalFrame::local_variables(const std::array<Eigen::Vector3d, 9>& x_local0,
                                                          const std::array<Eigen::Vector3d, 9>& rel_ref,
                                                          const std::array<Eigen::Vector3d, 9>& disp) const {
  // d_O = ¼ Σ corners, in double-double.
  std::array<DD, 3> dO;
  for (int c = 0; c < 3; ++c) {
    DD acc;
    for (int k = 0; k < 4; ++k) acc = dd_add(acc, {disp[k](c), 0.0});
    dO[c] = {0.25 * acc.hi, 0.25 * acc.lo};  // exact scaling by a power of two
  }
  // All nine nodes at once in vector registers: node k is lane k % W of vector k / W (the padding lanes hold zero
  // nodes). Explicit vector types, because GCC does not vectorize these loops by itself.
  using V = VNodes;
  constexpr int nv = kNodeVectors;
  // rel_i = (X_i - X_O) + (d_i - d_O) = rh + rl: two TwoSums, rl = e1 + e2 - d_O,lo (|rl| ~ ulp(rel); its own
  // rounding is ~u² |rel|).
  V rh[3][nv], rl[3][nv];
  for (int c = 0; c < 3; ++c) {
    V ref[nv], d[nv];
    for (int v = 0; v < nv; ++v) {
      ref[v] = d[v] = splat(0.0);
      for (int k = 0; k < kLanes; ++k) {
        const int i = kLanes * v + k;
        if (i < 9) ref[v][k] = rel_ref[i](c), d[v][k] = disp[i](c);
      }
    }
    const V oh = splat(-dO[c].hi), ol = splat(dO[c].lo);
    for (int v = 0; v < nv; ++v) {
      V e1, e2;
      const V s1 = two_sum(ref[v], d[v], &e1);
      rh[c][v] = two_sum(s1, oh, &e2);
      rl[c][v] = (e1 + e2) - ol;
    }
  }
#ifndef __FMA__
  // Without FMA the Dekker splits of R's entries and of rel's high parts are formed once each instead of once
  // per product.
  constexpr double split = 134217729.0;  // 2^27 + 1 (Dekker)
  V bh[3][nv], bl[3][nv];
  for (int c = 0; c < 3; ++c)
    for (int v = 0; v < nv; ++v) {
      const V cb = split * rh[c][v];
      bh[c][v] = cb - (cb - rh[c][v]);
      bl[c][v] = rh[c][v] - bh[c][v];
    }
#endif
  // t_i,r = -x_i0,r + Σ_c R_cr rel_i,c as a compensated dot product (Ogita, Rump & Oishi's Dot2): the products'
  // high parts are summed by TwoSum into S, every rounding error (TwoSum's, TwoProduct's, and the products of
  // the low parts R_cr rl) into E, and t = S + E. The result is as accurate as if computed in twice the working
  // precision and then rounded: error <= u |t| + O(u²) Σ|terms|.
  Vec45 u;
  for (int r = 0; r < 3; ++r) {
    V S[nv], E[nv];
    for (int v = 0; v < nv; ++v) {
      S[v] = E[v] = splat(0.0);
      for (int k = 0; k < kLanes; ++k) {
        const int i = kLanes * v + k;
        if (i < 9) S[v][k] = -x_local0[i](r);
      }
    }
    for (int c = 0; c < 3; ++c) {
      const double a = R_(c, r);
      const V va = splat(a);
#ifndef __FMA__
      const double ca = split * a, ah = ca - (ca - a), al = a - ah;
      const V vah = splat(ah), val = splat(al);
#endif
      for (int v = 0; v < nv; ++v) {
        const V p = va * rh[c][v];
#ifdef __FMA__
        V pe;
        for (int k = 0; k < kLanes; ++k) pe[k] = std::fma(a, rh[c][v][k], -p[k]);
#else
        const V pe = ((vah * bh[c][v] - p) + vah * bl[c][v] + val * bh[c][v]) + val * bl[c][v];  // two_prod's error
#endif
        V e;
        S[v] = two_sum(S[v], p, &e);
        E[v] += (e + pe) + va * rl[c][v];
      }
    }
    for (int i = 0; i < 9; ++i) u(5 * i + r) = S[i / kLanes][i % kLanes] + E[i / kLanes][i % kLanes];
  }
  for (int i = 0; i < 9; ++i) {
    u(5 * i + 3) = R_.col(0).dot(p_[i]);
    u(5 * i + 4) = R_.col(1).dot(p_[i]);
  }
  return u;
}

CorotationalFrame::Weights CorotationalFrame::weights(const Vec45& fL) const {
  Eigen::Vector3d wx = Eigen::Vector3d::Zero(), wy = Eigen::Vector3d::Zero(), wz = Eigen::Vector3d::Zero();
  for (int i = 0; i < 9; ++i) {
    wx += fL(5 * i) * rel_[i] + fL(5 * i + 3) * p_[i];
    wy += fL(5 * i + 1) * rel_[i] + fL(5 * i + 4) * p_[i];
    wz += fL(5 * i + 2) * rel_[i];
  }
  const Eigen::Vector3d ex = R_.col(0), ey = R_.col(1);
  return {wz, wx + ey.cross(wz), wy + wz.cross(ex)};
}

CorotationalFrame::Vec45 CorotationalFrame::apply_transpose(const Vec45& fL) const {
  if (!director_derivatives_)
    throw std::logic_error("CorotationalFrame: apply_transpose() of a frame built for local_variables() only (no A1)");
  // F = T^T f_L with T = D + C P (§3.3), without forming C. The corner part C^T f_L contracts the corner
  // columns' rows (x_i - x_O)^T E_α,k and p_i^T E_α,k against f_L, so it needs only the weight vectors of
  // §3.4 (the ones K_σ uses): Σ_i [C_ik]^T f_L,i = -¼ R Σ_i f_t,i + E_x,k^T ŵ_x + E_y,k^T ŵ_y, where
  // ŵ_x = w_x + e_y × w_z and ŵ_y = w_y + w_z × e_x absorb e_z = e_x × e_y. With E_x,k = ∓P_s P_a, ±P_s P_b
  // and E_y,k = ∓P_c P_a, ∓P_c P_b (§3.3) and symmetric P's, the four corners need P_s ŵ_x, P_c ŵ_y and one
  // application of P_a and of P_b: ~300 multiplications instead of building the 45 × 12 block C.
  const Eigen::Vector3d ex = R_.col(0), ey = R_.col(1);
  Eigen::Vector3d fsum = Eigen::Vector3d::Zero();
  Vec45 F;
  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector3d ft = fL.segment<3>(5 * i);
    fsum += ft;
    F.segment<3>(5 * i) = R_ * ft;                                                             // D: R^T block, transposed
    F.segment<2>(5 * i + 3) = A1_[i].transpose() * (fL(5 * i + 3) * ex + fL(5 * i + 4) * ey);  // D: ([e_x e_y]^T A1_i)^T
  }
  const Weights w = weights(fL);
  const Eigen::Vector3d gx = unit_jacobian_times(s_, w.xh), gy = unit_jacobian_times(c_, w.yh);
  const Eigen::Vector3d fa = unit_jacobian_times(a_, gx + gy), fb = unit_jacobian_times(b_, gx - gy);
  const Eigen::Vector3d f0 = -0.25 * (R_ * fsum);
  F.segment<3>(0) += f0 - fa;
  F.segment<3>(5) += f0 + fb;
  F.segment<3>(10) += f0 + fa;
  F.segment<3>(15) += f0 - fb;
  return F;
}

CorotationalFrame::Mat45 CorotationalFrame::matrix() const {
  corner_columns();
  Mat45 T = Mat45::Zero();
  for (int i = 0; i < 9; ++i) {
    T.block<3, 3>(5 * i, 5 * i) = R_.transpose();
    T.block<2, 2>(5 * i + 3, 5 * i + 3) = D_theta_[i];
  }
  for (int k = 0; k < 4; ++k) T.middleCols<3>(5 * k) += C_.middleCols<3>(3 * k);
  return T;
}

void CorotationalFrame::tangent(const Mat45& kL, const Vec45& fL, bool geometric, Mat45* K) const {
  corner_columns();
  // T^T k_L T exploiting T = D + C P: ~7e4 multiplications instead of 1.8e5 for dense products.
  Mat45 kT;
  const Eigen::Matrix3d Rt = R_.transpose();
  for (int j = 0; j < 9; ++j) {
    // lazyProduct: thin products are faster coefficient-wise than through Eigen's blocked GEMM path.
    kT.middleCols<3>(5 * j).noalias() = kL.middleCols<3>(5 * j).lazyProduct(Rt);
    kT.middleCols<2>(5 * j + 3).noalias() = kL.middleCols<2>(5 * j + 3).lazyProduct(D_theta_[j]);
  }
  const Eigen::Matrix<double, 45, 12> kC = kL * C_;
  for (int k = 0; k < 4; ++k) kT.middleCols<3>(5 * k) += kC.middleCols<3>(3 * k);
  for (int i = 0; i < 9; ++i) {
    K->middleRows<3>(5 * i).noalias() = R_.lazyProduct(kT.middleRows<3>(5 * i));
    K->middleRows<2>(5 * i + 3).noalias() = D_theta_[i].transpose().lazyProduct(kT.middleRows<2>(5 * i + 3));
  }
  // Cᵀ(k_L T) = Cᵀ k_L D + (Cᵀ k_L C) P = (k_L C)ᵀ D + (Cᵀ kC) P (k_L symmetric): the block-diagonal D and a
  // 12 × 12 product instead of a second 12 × 45 · 45 × 45 one.
  Eigen::Matrix<double, 12, 45> CtkT;
  for (int j = 0; j < 9; ++j) {
    CtkT.middleCols<3>(5 * j).noalias() = kC.middleRows<3>(5 * j).transpose().lazyProduct(Rt);
    CtkT.middleCols<2>(5 * j + 3).noalias() = kC.middleRows<2>(5 * j + 3).transpose().lazyProduct(D_theta_[j]);
  }
  const Eigen::Matrix<double, 12, 12> CtkC = C_.transpose() * kC;
  for (int k = 0; k < 4; ++k) CtkT.middleCols<3>(5 * k) += CtkC.middleCols<3>(3 * k);
  for (int k = 0; k < 4; ++k) K->middleRows<3>(5 * k) += CtkT.middleRows<3>(3 * k);
  if (geometric) add_geometric_stiffness(fL, K);
}

void CorotationalFrame::add_geometric_stiffness(const Vec45& fL, Mat45* K) const {
  if (!director_curvature_)
    throw std::logic_error("CorotationalFrame: K_σ of a frame built without the directors' d²p_l/dq² (residual-only frame)");
  derivatives();
  // K_σ = Σ_j (f_L)_j ∂²(u_L)_j/∂u_G∂u_G, §3.4, through the weight vectors.
  const Weights w = weights(fL);
  const Eigen::Vector3d &wz = w.z, &wxh = w.xh, &wyh = w.yh;
  const Eigen::Vector3d ex = R_.col(0), ey = R_.col(1);

  // Group 1: corner-corner, from the second derivatives of e_x, e_y, e_z = e_x × e_y.
  Mat312 Ga = Mat312::Zero(), Gb = Mat312::Zero();
  Ga.block<3, 3>(0, 0) = -Eigen::Matrix3d::Identity();
  Ga.block<3, 3>(0, 6) = Eigen::Matrix3d::Identity();
  Gb.block<3, 3>(0, 3) = -Eigen::Matrix3d::Identity();
  Gb.block<3, 3>(0, 9) = Eigen::Matrix3d::Identity();
  const Mat312 Gs = Pa_ * Ga - Pb_ * Gb, Gc = Pa_ * Ga + Pb_ * Gb;
  const Mat312 Gx = Ps_ * Gs, Gy = Pc_ * Gc;
  const Eigen::Matrix<double, 12, 12> S = -Gx.transpose() * skew(wz) * Gy;
  const Eigen::Matrix<double, 12, 12> Kcc =
      Gs.transpose() * unit_hessian(s_, wxh) * Gs + Gc.transpose() * unit_hessian(c_, wyh) * Gc +
      Ga.transpose() * unit_hessian(a_, Ps_ * wxh + Pc_ * wyh) * Ga +
      Gb.transpose() * unit_hessian(b_, -Ps_ * wxh + Pc_ * wyh) * Gb + S + S.transpose();
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j) K->block<3, 3>(5 * k, 5 * j) += Kcc.block<3, 3>(3 * k, 3 * j);

  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector3d ft = fL.segment<3>(5 * i);
    const Eigen::Vector2d fth = fL.segment<2>(5 * i + 3);
    for (int k = 0; k < 4; ++k) {
      // Group 2: corner k × translation of node i through t_i = R^T(x_i - x_O), incl. the -¼ origin terms.
      const Eigen::Matrix3d M =
          ft(0) * E_[0][k].transpose() + ft(1) * E_[1][k].transpose() + ft(2) * E_[2][k].transpose();
      K->block<3, 3>(5 * k, 5 * i) += M;
      K->block<3, 3>(5 * i, 5 * k) += M.transpose();
      for (int j = 0; j < 4; ++j) {
        K->block<3, 3>(5 * k, 5 * j) -= 0.25 * M;
        K->block<3, 3>(5 * j, 5 * k) -= 0.25 * M.transpose();
      }
      // Group 3: corner k × director of node i through θ_i = (e_x·p_i, e_y·p_i).
      const Eigen::Matrix<double, 3, 2> N = (fth(0) * E_[0][k].transpose() + fth(1) * E_[1][k].transpose()) * A1_[i];
      K->block<3, 2>(5 * k, 5 * i + 3) += N;
      K->block<2, 3>(5 * i + 3, 5 * k) += N.transpose();
    }
    // Group 4: director × director of the same node, through the curvature of p_l(q).
    K->block<2, 2>(5 * i + 3, 5 * i + 3) += (fth(0) * ex(l_[i]) + fth(1) * ey(l_[i])) * d2pl_[i];
  }
}

}  // namespace shelldyn
