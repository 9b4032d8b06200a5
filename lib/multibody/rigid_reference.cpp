// Rigid-body reference: Dormand–Prince RK5(4) and the Newton–Euler equations of spherical-joint chains
// (docs/theory/multibody.md §6).
#include "lib/multibody/rigid_reference.hpp"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace shelldyn::multibody {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;

// ---- Dormand–Prince 5(4) ---------------------------------------------------------------------------------
// Tableau of Dormand & Prince (1980), RK5(4)7M; the 5th-order solution propagates (local extrapolation) and
// the last stage is the next step's first (FSAL). e = b − b̂ gives the embedded error estimate.
std::vector<VectorXd> dormand_prince(const OdeRhs& f, double t0, const VectorXd& y0,
                                     const std::vector<double>& outputs, const Rk45Options& opt,
                                     Rk45Stats* st) {
  static constexpr double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
  static constexpr double a21 = 1.0 / 5;
  static constexpr double a31 = 3.0 / 40, a32 = 9.0 / 40;
  static constexpr double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
  static constexpr double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561,
                          a54 = -212.0 / 729;
  static constexpr double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247, a64 = 49.0 / 176,
                          a65 = -5103.0 / 18656;
  static constexpr double b1 = 35.0 / 384, b3 = 500.0 / 1113, b4 = 125.0 / 192, b5 = -2187.0 / 6784,
                          b6 = 11.0 / 84;
  static constexpr double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200,
                          e6 = 22.0 / 525, e7 = -1.0 / 40;
  Rk45Stats local;
  Rk45Stats& s = st ? *st : local;
  const Eigen::Index n = y0.size();
  VectorXd y = y0, k1(n), k2(n), k3(n), k4(n), k5(n), k6(n), k7(n), yt(n), yn(n), err(n);
  double t = t0;
  f(t, y, k1);
  ++s.evaluations;
  auto norm = [&](const VectorXd& e, const VectorXd& ya, const VectorXd& yb) {
    double acc = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double sc = opt.atol + opt.rtol * std::max(std::abs(ya(i)), std::abs(yb(i)));
      acc += (e(i) / sc) * (e(i) / sc);
    }
    return std::sqrt(acc / static_cast<double>(std::max<Eigen::Index>(n, 1)));
  };
  double h = opt.h0;
  if (h <= 0.0) {  // Hairer–Nørsett–Wanner's starting-step heuristic, simplified
    const double d0 = norm(y, y, y), d1 = norm(k1, y, y);
    h = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
  }
  std::vector<VectorXd> out;
  out.reserve(outputs.size());
  for (double tout : outputs) {
    if (tout < t) throw std::invalid_argument("dormand_prince: output times must be increasing and >= t0");
    while (t < tout) {
      if (s.accepted + s.rejected >= opt.max_steps)
        throw std::runtime_error(
            "dormand_prince: more than max_steps steps (raise max_steps or loosen rtol)");
      bool last = false;
      double hs = h;
      if (t + hs >= tout) {
        hs = tout - t;
        last = true;
      }
      if (hs <= 1e-14 * std::max(1.0, std::abs(t)) && !last)
        throw std::runtime_error("dormand_prince: step size underflow (the solution is not smooth here)");
      yt = y + hs * a21 * k1;
      f(t + c2 * hs, yt, k2);
      yt = y + hs * (a31 * k1 + a32 * k2);
      f(t + c3 * hs, yt, k3);
      yt = y + hs * (a41 * k1 + a42 * k2 + a43 * k3);
      f(t + c4 * hs, yt, k4);
      yt = y + hs * (a51 * k1 + a52 * k2 + a53 * k3 + a54 * k4);
      f(t + c5 * hs, yt, k5);
      yt = y + hs * (a61 * k1 + a62 * k2 + a63 * k3 + a64 * k4 + a65 * k5);
      f(t + hs, yt, k6);
      yn = y + hs * (b1 * k1 + b3 * k3 + b4 * k4 + b5 * k5 + b6 * k6);
      f(t + hs, yn, k7);
      s.evaluations += 6;
      err = hs * (e1 * k1 + e3 * k3 + e4 * k4 + e5 * k5 + e6 * k6 + e7 * k7);
      const double en = norm(err, y, yn);
      if (!std::isfinite(en)) throw std::runtime_error("dormand_prince: the state became non-finite");
      const double fac = std::clamp(0.9 * std::pow(std::max(en, 1e-16), -0.2), 0.2, 5.0);
      if (en <= 1.0) {
        t = last ? tout : t + hs;
        y = yn;
        k1 = k7;
        ++s.accepted;
        if (!last)
          h = hs * fac;  // a shortened last step does not shrink the next one
        else
          h = std::max(h, hs * fac);
      } else {
        ++s.rejected;
        h = hs * std::min(1.0, fac);
      }
    }
    out.push_back(y);
  }
  return out;
}

// ---- spherical-joint chains -------------------------------------------------------------------------------
namespace {
Matrix3d hat(const Vector3d& w) {
  Matrix3d W;
  W << 0, -w(2), w(1), w(2), 0, -w(0), -w(1), w(0), 0;
  return W;
}
}  // namespace

SphericalChainReference::SphericalChainReference(std::vector<ReferenceBody> bodies,
                                                 std::vector<ReferenceJoint> joints, const Vector3d& gravity)
    : bodies_(std::move(bodies)), joints_(std::move(joints)), gravity_(gravity) {
  const int nb = num_bodies();
  for (size_t j = 0; j < joints_.size(); ++j) {
    const auto& jt = joints_[j];
    if (jt.a < 0 || jt.a >= nb || jt.b < -1 || jt.b >= nb || jt.a == jt.b) {
      std::ostringstream os;
      os << "SphericalChainReference: joint " << j << " connects body " << jt.a << " to " << jt.b
         << " but there are " << nb << " bodies (use −1 for the ground, and two different bodies)";
      throw std::invalid_argument(os.str());
    }
  }
  for (const auto& b : bodies_)
    if (!(b.mass > 0.0) || !(b.J.minCoeff() > 0.0))
      throw std::invalid_argument("SphericalChainReference: every body needs a positive mass and inertias");
}

Vector3d SphericalChainReference::position(const VectorXd& y, int i) {
  return y.segment<3>(kPerBody * i);
}
Vector3d SphericalChainReference::velocity(const VectorXd& y, int i) {
  return y.segment<3>(kPerBody * i + 3);
}
Matrix3d SphericalChainReference::rotation(const VectorXd& y, int i) {
  return Eigen::Map<const Matrix3d>(y.data() + kPerBody * i + 6);
}
Vector3d SphericalChainReference::omega_body(const VectorXd& y, int i) {
  return y.segment<3>(kPerBody * i + 15);
}

VectorXd SphericalChainReference::initial_state() const {
  VectorXd y(kPerBody * num_bodies());
  for (int i = 0; i < num_bodies(); ++i) {
    const auto& b = bodies_[i];
    y.segment<3>(kPerBody * i) = b.x;
    y.segment<3>(kPerBody * i + 3) = b.v;
    Eigen::Map<Matrix3d>(y.data() + kPerBody * i + 6) = b.R;
    y.segment<3>(kPerBody * i + 15) = b.omega_body;
  }
  return y;
}

void SphericalChainReference::rhs(double, const VectorXd& y, VectorXd& dy) const {
  const int nb = num_bodies(), nj = static_cast<int>(joints_.size());
  dy.resize(y.size());
  // Body accelerations for given joint forces F (3 per joint, acting +F on a and −F on b), then the
  // acceleration-level joint mismatch; it is affine in F, so F follows from one dense solve.
  auto accelerations = [&](const VectorXd& F, std::vector<Vector3d>& acc, std::vector<Vector3d>& wdot) {
    acc.assign(nb, Vector3d::Zero());
    wdot.assign(nb, Vector3d::Zero());
    std::vector<Vector3d> force(nb, Vector3d::Zero()), torque(nb, Vector3d::Zero());
    for (int j = 0; j < nj; ++j) {
      const auto& jt = joints_[j];
      const Vector3d f = F.segment<3>(3 * j);
      force[jt.a] += f;
      torque[jt.a] += jt.ra.cross(rotation(y, jt.a).transpose() * f);
      if (jt.b >= 0) {
        force[jt.b] -= f;
        torque[jt.b] -= jt.rb.cross(rotation(y, jt.b).transpose() * f);
      }
    }
    for (int i = 0; i < nb; ++i) {
      const auto& b = bodies_[i];
      const Vector3d W = omega_body(y, i);
      acc[i] = gravity_ + force[i] / b.mass;
      wdot[i] = (torque[i] - W.cross(Vector3d(b.J.cwiseProduct(W)))).cwiseQuotient(b.J);
    }
  };
  auto mismatch = [&](const VectorXd& F) {
    std::vector<Vector3d> acc, wdot;
    accelerations(F, acc, wdot);
    VectorXd r(3 * nj);
    for (int j = 0; j < nj; ++j) {
      const auto& jt = joints_[j];
      auto point_acc = [&](int i, const Vector3d& r0) {
        const Vector3d W = omega_body(y, i);
        return Vector3d(acc[i] + rotation(y, i) * (wdot[i].cross(r0) + W.cross(W.cross(r0))));
      };
      r.segment<3>(3 * j) = point_acc(jt.a, jt.ra) - (jt.b >= 0 ? point_acc(jt.b, jt.rb) : Vector3d::Zero());
    }
    return r;
  };
  VectorXd F = VectorXd::Zero(3 * nj);
  if (nj > 0) {
    const VectorXd r0 = mismatch(F);
    Eigen::MatrixXd A(3 * nj, 3 * nj);
    for (int k = 0; k < 3 * nj; ++k) {
      VectorXd e = VectorXd::Zero(3 * nj);
      e(k) = 1.0;
      A.col(k) = mismatch(e) - r0;
    }
    F = A.fullPivLu().solve(-r0);
  }
  std::vector<Vector3d> acc, wdot;
  accelerations(F, acc, wdot);
  for (int i = 0; i < nb; ++i) {
    dy.segment<3>(kPerBody * i) = velocity(y, i);
    dy.segment<3>(kPerBody * i + 3) = acc[i];
    Eigen::Map<Matrix3d>(dy.data() + kPerBody * i + 6) = rotation(y, i) * hat(omega_body(y, i));
    dy.segment<3>(kPerBody * i + 15) = wdot[i];
  }
}

double SphericalChainReference::energy(const VectorXd& y) const {
  double H = 0.0;
  for (int i = 0; i < num_bodies(); ++i) {
    const auto& b = bodies_[i];
    const Vector3d W = omega_body(y, i);
    H += 0.5 * b.mass * velocity(y, i).squaredNorm() + 0.5 * W.dot(b.J.cwiseProduct(W)) -
         b.mass * gravity_.dot(position(y, i));
  }
  return H;
}

Vector3d SphericalChainReference::linear_momentum(const VectorXd& y) const {
  Vector3d L = Vector3d::Zero();
  for (int i = 0; i < num_bodies(); ++i) L += bodies_[i].mass * velocity(y, i);
  return L;
}

Vector3d SphericalChainReference::angular_momentum(const VectorXd& y) const {
  Vector3d J = Vector3d::Zero();
  for (int i = 0; i < num_bodies(); ++i) {
    const auto& b = bodies_[i];
    J += b.mass * position(y, i).cross(velocity(y, i)) + rotation(y, i) * b.J.cwiseProduct(omega_body(y, i));
  }
  return J;
}

double SphericalChainReference::joint_gap(const VectorXd& y) const {
  double gap = 0.0;
  for (const auto& jt : joints_) {
    const Vector3d xa = position(y, jt.a) + rotation(y, jt.a) * jt.ra;
    const Vector3d xb = jt.b >= 0 ? Vector3d(position(y, jt.b) + rotation(y, jt.b) * jt.rb) : jt.rb;
    gap = std::max(gap, (xa - xb).norm());
  }
  return gap;
}

// ---- compound pendulum ----------------------------------------------------------------------------------
double compound_pendulum_period(double Ip, double m, double g, double l, double theta0) {
  if (!(Ip > 0 && m > 0 && g > 0 && l > 0) || !(std::abs(theta0) < M_PI))
    throw std::invalid_argument("compound_pendulum_period: need I_p, m, g, l > 0 and |θ0| < π");
  const double k = std::sin(0.5 * std::abs(theta0));
  double a = 1.0, b = std::sqrt(1.0 - k * k);  // AGM: K(k) = π / (2 AGM(1, √(1 − k²)))
  for (int i = 0; i < 60 && std::abs(a - b) > 1e-16 * a; ++i) {
    const double an = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = an;
  }
  const double K = M_PI / (2.0 * a);
  return 4.0 * K * std::sqrt(Ip / (m * g * l));
}

double compound_pendulum_small_period(double Ip, double m, double g, double l) {
  return 2.0 * M_PI * std::sqrt(Ip / (m * g * l));
}

}  // namespace shelldyn::multibody
