// Element pieces of the exactly conserving step; derivation in docs/theory/exact-energy-momentum.md §§2-4.
#include "elements/exact_energy.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

MidpointRigidRows::MidpointRigidRows(const NodeVectors& x_mid, const NodeVectors& p_mid,
                                     const std::array<DirectorChart, 9>& charts)
    : p_(p_mid), charts_(charts) {
  // Rotations about the midpoint centroid c instead of the origin: the same row space (a rotation about
  // the origin is one about c plus a translation), but RRᵀ stays well conditioned far from the origin.
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& x : x_mid) c += x;
  c /= 9.0;
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  Jd_.setZero();
  Jq_.setZero();
  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector3d r = x_mid[i] - c;
    r_[i] = r;
    s += r;
    // d-slots of the rotation rows: (e_j × r)·(e_k × r) = δ_jk |r|² − r_j r_k.
    J.noalias() -= r * r.transpose();
    J.diagonal().array() += r.squaredNorm();
    // q-slots: the n and m components of u_j = e_j × p, i.e. u_j·u_k − u_j[l] u_k[l] (u_j·u_k = δ_jk|p|² − p_j p_k).
    const Eigen::Vector3d& p = p_mid[i];
    const int l = charts[i].l;
    Eigen::Vector3d ul;  // u_j[l] = (e_j × p)[l]
    for (int j = 0; j < 3; ++j) ul[j] = Eigen::Vector3d::Unit(j).cross(p)[l];
    J.noalias() -= p * p.transpose() + ul * ul.transpose();
    J.diagonal().array() += p.squaredNorm();
    // The two parts of the rotation block apart (the weighted correction of theory §3 scales the director part).
    Jd_.noalias() -= r * r.transpose();
    Jd_.diagonal().array() += r.squaredNorm();
    Jq_.noalias() -= p * p.transpose() + ul * ul.transpose();
    Jq_.diagonal().array() += p.squaredNorm();
  }
  gram_.setZero();
  gram_.topLeftCorner<3, 3>().diagonal().setConstant(9.0);
  // Translation × rotation: Σ_i e_j·(e_k × r_i) = (e_k × s)_j, zero up to the rounding of c.
  Eigen::Matrix3d B;
  for (int k = 0; k < 3; ++k) B.col(k) = Eigen::Vector3d::Unit(k).cross(s);
  gram_.topRightCorner<3, 3>() = B;
  gram_.bottomLeftCorner<3, 3>() = B.transpose();
  gram_.bottomRightCorner<3, 3>() = J;
}

MidpointRigidRows::Vec6 MidpointRigidRows::times(const Vec45E& f) const {
  Eigen::Vector3d res = Eigen::Vector3d::Zero(), mom = Eigen::Vector3d::Zero();
  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector3d fd = f.segment<3>(5 * i);
    Eigen::Vector3d g = Eigen::Vector3d::Zero();  // S_iᵀ f_q,i
    g[charts_[i].n] = f[5 * i + 3];
    g[charts_[i].m] = f[5 * i + 4];
    res += fd;
    mom += r_[i].cross(fd) + p_[i].cross(g);
  }
  Vec6 y;
  y << res, mom;
  return y;
}

void MidpointRigidRows::subtract_transpose_times(const Vec6& a, Vec45E& y) const {
  const Eigen::Vector3d at = a.head<3>(), ar = a.tail<3>();
  for (int i = 0; i < 9; ++i) {
    y.segment<3>(5 * i) -= at + ar.cross(r_[i]);
    const Eigen::Vector3d q = ar.cross(p_[i]);
    y[5 * i + 3] -= q[charts_[i].n];
    y[5 * i + 4] -= q[charts_[i].m];
  }
}

RigidRows MidpointRigidRows::dense() const {
  RigidRows R = RigidRows::Zero();
  for (int i = 0; i < 9; ++i) {
    const DirectorChart& ch = charts_[i];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d ek = Eigen::Vector3d::Unit(k);
      R(k, 5 * i + k) = 1.0;                                        // translation t_k
      R.block<1, 3>(3 + k, 5 * i) = ek.cross(r_[i]).transpose();    // rotation r_k: d-slots e_k × (x − c)
      const Eigen::Vector3d ep = ek.cross(p_[i]);                   //               q-slots S_i (e_k × p)
      R(3 + k, 5 * i + 3) = ep[ch.n];
      R(3 + k, 5 * i + 4) = ep[ch.m];
    }
  }
  return R;
}

CorrectionInfo energy_momentum_correction(const MidpointRigidRows& R, const Vec45E& du, double dU, Vec45E& F,
                                          double guard, double director_weight) {
  // (RRᵀ)⁻¹ [R F, R Δu] by block elimination: RRᵀ = [9I, B; Bᵀ, J] (the translation block is 9I, B is zero up to the
  // rounding of the centroid), so the rotation part solves with the 3 × 3 Schur complement J − BᵀB/9 and the
  // translation part follows. Cheaper than a 6 × 6 Cholesky per element and residual, and as accurate.
  const Eigen::Matrix<double, 6, 6>& G = R.gram();
  const Eigen::Matrix3d B = G.topRightCorner<3, 3>();
  const Eigen::LLT<Eigen::Matrix3d> S(G.bottomRightCorner<3, 3>() - B.transpose() * B / 9.0);
  if (S.info() != Eigen::Success) throw std::domain_error("energy_momentum_correction: singular rigid rows");
  Eigen::Matrix<double, 6, 2> sol;
  sol.col(0) = R.times(F);
  sol.col(1) = R.times(du);
  sol.bottomRows<3>() = S.solve(sol.bottomRows<3>() - B.transpose() * sol.topRows<3>() / 9.0);
  sol.topRows<3>() = (sol.topRows<3>() - B * sol.bottomRows<3>()) / 9.0;
  // a = −(RRᵀ)⁻¹ R F: removes the resultant and the midpoint moment of F.
  R.subtract_transpose_times(sol.col(0), F);
  // z = Δu with its midpoint-rigid part removed (R z = 0, Δuᵀ z = zᵀ z).
  Vec45E z = du;
  CorrectionInfo info;
  if (director_weight == 1.0) {
    R.subtract_transpose_times(sol.col(1), z);
    info.z_norm2 = z.squaredNorm();
  } else {
    // In the metric W = diag(1 on d, w on q) (theory §3): R W Rᵀ y = R W Δu, z = W(Δu − Rᵀy). R W Rᵀ is RRᵀ with the
    // director part of its rotation block scaled by w (the translation rows have no q-slots).
    Vec45E Wdu = du;
    for (int i = 0; i < 9; ++i) Wdu.segment<2>(5 * i + 3) *= director_weight;
    const Eigen::Matrix3d Jw = R.translation_gram() + director_weight * R.director_gram();
    const Eigen::LLT<Eigen::Matrix3d> Sw(Jw - B.transpose() * B / 9.0);
    if (Sw.info() != Eigen::Success) throw std::domain_error("energy_momentum_correction: singular rigid rows");
    Eigen::Matrix<double, 6, 1> y = R.times(Wdu);
    y.tail<3>() = Sw.solve(y.tail<3>() - B.transpose() * y.head<3>() / 9.0);
    y.head<3>() = (y.head<3>() - B * y.tail<3>()) / 9.0;
    R.subtract_transpose_times(y, z);
    for (int i = 0; i < 9; ++i) z.segment<2>(5 * i + 3) *= director_weight;
    info.z_norm2 = du.dot(z);  // ‖Δu − Rᵀy‖²_W
  }
  if (info.z_norm2 <= guard * du.squaredNorm() || info.z_norm2 == 0.0) {
    info.rigid_guard = true;  // rigid step: ΔU = 0 = Δuᵀ(F + Rᵀa) analytically (theory §3, Cayley)
    return info;
  }
  info.beta = (dU - du.dot(F)) / info.z_norm2;
  F.noalias() += info.beta * z;
  info.correction_norm = std::abs(info.beta) * z.norm();
  return info;
}

Eigen::Matrix<double, 45, 45> rigid_complement_projector(const RigidRows& R) {
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> RRt(R * R.transpose());
  if (RRt.info() != Eigen::Success) throw std::domain_error("rigid_complement_projector: singular rigid rows");
  Eigen::Matrix<double, 45, 45> P = -R.transpose() * RRt.solve(R);
  P.diagonal().array() += 1.0;
  return P;
}

double embedded_kinetic(const Eigen::Matrix<double, 9, 9>& m, double rho_h, double rho_h3_12, const NodeVectors& v,
                        const NodeVectors& w) {
  double kv = 0.0, kw = 0.0;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) {
      kv += m(i, j) * v[i].dot(v[j]);
      kw += m(i, j) * w[i].dot(w[j]);
    }
  return 0.5 * rho_h * kv + 0.5 * rho_h3_12 * kw;
}

void embedded_momenta(const Eigen::Matrix<double, 9, 9>& m, double rho_h, double rho_h3_12, const NodeVectors& x,
                      const NodeVectors& p, const NodeVectors& v, const NodeVectors& w, Eigen::Vector3d* L,
                      Eigen::Vector3d* J) {
  Eigen::Vector3d l = Eigen::Vector3d::Zero(), j = Eigen::Vector3d::Zero();
  for (int i = 0; i < 9; ++i) {
    Eigen::Vector3d mv = Eigen::Vector3d::Zero(), mw = Eigen::Vector3d::Zero();
    for (int k = 0; k < 9; ++k) {
      mv += m(i, k) * v[k];
      mw += m(i, k) * w[k];
    }
    l += mv;
    j += rho_h * x[i].cross(mv) + rho_h3_12 * p[i].cross(mw);
  }
  if (L) *L = rho_h * l;
  if (J) *J = j;
}

Eigen::Matrix<double, 3, 2> embedded_A1(const Eigen::Vector3d& p, const DirectorChart& ch) {
  if (p[ch.l] == 0.0) {
    std::ostringstream os;
    os << "embedded_A1: dependent component " << ch.l << " of the midpoint director is zero";
    throw std::domain_error(os.str());
  }
  Eigen::Matrix<double, 3, 2> A = Eigen::Matrix<double, 3, 2>::Zero();
  A(ch.n, 0) = 1.0;
  A(ch.m, 1) = 1.0;
  A(ch.l, 0) = -p[ch.n] / p[ch.l];
  A(ch.l, 1) = -p[ch.m] / p[ch.l];
  return A;
}

}  // namespace shelldyn
