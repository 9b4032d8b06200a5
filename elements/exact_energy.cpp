// Element pieces of the exactly conserving step; derivation in docs/theory/exact-energy-momentum.md §§2-4.
#include "elements/exact_energy.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

RigidRows midpoint_rigid_rows(const NodeVectors& x_mid, const NodeVectors& p_mid,
                              const std::array<DirectorChart, 9>& charts) {
  // Rotations about the midpoint centroid c instead of the origin: the same row space (a rotation about
  // the origin is one about c plus a translation), but RRᵀ stays well conditioned far from the origin.
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& x : x_mid) c += x;
  c /= 9.0;
  RigidRows R = RigidRows::Zero();
  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector3d r = x_mid[i] - c;
    const DirectorChart& ch = charts[i];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d ek = Eigen::Vector3d::Unit(k);
      R(k, 5 * i + k) = 1.0;                                        // translation t_k
      R.block<1, 3>(3 + k, 5 * i) = ek.cross(r).transpose();        // rotation r_k: d-slots e_k × (x − c)
      const Eigen::Vector3d ep = ek.cross(p_mid[i]);                //               q-slots S_i (e_k × p)
      R(3 + k, 5 * i + 3) = ep[ch.n];
      R(3 + k, 5 * i + 4) = ep[ch.m];
    }
  }
  return R;
}

CorrectionInfo energy_momentum_correction(const RigidRows& R, const Vec45E& du, double dU, Vec45E& F, double guard) {
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> RRt(R * R.transpose());
  if (RRt.info() != Eigen::Success) throw std::domain_error("energy_momentum_correction: singular rigid rows");
  // a = −(RRᵀ)⁻¹ R F: removes the resultant and the midpoint moment of F.
  F.noalias() -= R.transpose() * RRt.solve(R * F);
  // z = Δu with its midpoint-rigid part removed (R z = 0, Δuᵀ z = zᵀ z).
  const Vec45E z = du - R.transpose() * RRt.solve(R * du);
  CorrectionInfo info;
  info.z_norm2 = z.squaredNorm();
  if (info.z_norm2 <= guard * du.squaredNorm() || info.z_norm2 == 0.0) {
    info.rigid_guard = true;  // rigid step: ΔU = 0 = Δuᵀ(F + Rᵀa) analytically (theory §3, Cayley)
    return info;
  }
  info.beta = (dU - du.dot(F)) / info.z_norm2;
  F.noalias() += info.beta * z;
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
