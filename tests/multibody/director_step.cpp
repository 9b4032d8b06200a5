// Test-only conserving director-form step (docs/theory/multibody.md §5).
#include "director_step.hpp"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace shelldyn::multibody::testing {

GradientChoice default_choice() {
  const char* e = std::getenv("SHELLDYN_TEST_ENDPOINT_G");
  return (e && std::strcmp(e, "1") == 0) ? GradientChoice::endpoint : GradientChoice::discrete;
}

Eigen::VectorXd DirectorSystem::mass_diagonal() const {
  Eigen::VectorXd m(n());
  for (size_t i = 0; i < bodies.size(); ++i) m.segment<12>(12 * i) = bodies[i].mass_diagonal();
  return m;
}

double DirectorSystem::potential(const Eigen::VectorXd& q) const {
  double V = 0.0;
  for (size_t i = 0; i < bodies.size(); ++i) V -= bodies[i].mass() * gravity.dot(q.segment<3>(12 * i));
  return V;
}

double DirectorSystem::energy(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const {
  double T = 0.0;
  for (size_t i = 0; i < bodies.size(); ++i) T += bodies[i].kinetic_energy(v.segment<12>(12 * i));
  return T + potential(q);
}

Vec3 DirectorSystem::linear_momentum(const Eigen::VectorXd& v) const {
  Vec3 L = Vec3::Zero();
  for (size_t i = 0; i < bodies.size(); ++i) L += bodies[i].linear_momentum(v.segment<12>(12 * i));
  return L;
}

Vec3 DirectorSystem::angular_momentum(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const {
  Vec3 J = Vec3::Zero();
  for (size_t i = 0; i < bodies.size(); ++i)
    J += bodies[i].angular_momentum(q.segment<12>(12 * i), v.segment<12>(12 * i));
  return J;
}

namespace {
// The constraint force term Bᵀμ with B = Ḡ(q0, q1) (or G(q1)) and the driver's τ.
Eigen::VectorXd force_term(const DirectorSystem& s, const Eigen::VectorXd& q0, double t0,
                           const Eigen::VectorXd& q1, double t1, const Eigen::VectorXd& mu, GradientChoice c,
                           Eigen::VectorXd* tau) {
  Eigen::VectorXd tl;
  const Eigen::SparseMatrix<double> B =
      c == GradientChoice::discrete ? s.constraints.Gbar(q0, t0, q1, t1, tl) : s.constraints.G(q1, t1);
  if (tau) *tau = c == GradientChoice::discrete ? tl : Eigen::VectorXd::Zero(s.constraints.rows());
  return B.transpose() * mu;
}
}  // namespace

StepResult step(const DirectorSystem& s, const Eigen::VectorXd& q0, const Eigen::VectorXd& v0, double t0,
                double dt, GradientChoice choice) {
  const int n = s.n(), m = s.constraints.rows();
  const double t1 = t0 + dt;
  const Eigen::VectorXd M = s.mass_diagonal();
  Eigen::VectorXd gradV = Eigen::VectorXd::Zero(n);  // V linear: its discrete gradient is ∇V (§5)
  for (size_t i = 0; i < s.bodies.size(); ++i) gradV.segment<3>(12 * i) = -s.bodies[i].mass() * s.gravity;
  Eigen::VectorXd q1 = q0 + dt * v0, mu = Eigen::VectorXd::Zero(m);
  auto residual = [&](const Eigen::VectorXd& q, const Eigen::VectorXd& u, Eigen::VectorXd& r) {
    r.resize(n + m);
    r.head(n) = (2.0 / dt) * M.cwiseProduct(q - q0) - 2.0 * M.cwiseProduct(v0) + dt * gradV +
                force_term(s, q0, t0, q, t1, u, choice, nullptr);
    r.tail(m) = s.constraints.g(q, t1);
  };
  Eigen::VectorXd r;
  StepResult out;
  const double scale = 1.0 + q0.cwiseAbs().maxCoeff();
  bool converged = false;
  for (int it = 1; it <= 40 && !converged; ++it) {
    residual(q1, mu, r);
    // Saddle-point Jacobian [[(2/Δt)M + ∂(Bᵀμ)/∂q1, Bᵀ], [G(q1), 0]] with the constraints' force tangents
    // (docs/theory/multibody.md §5.1).
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + m, n + m);
    K.topLeftCorner(n, n).diagonal() = (2.0 / dt) * M;
    K.topLeftCorner(n, n) += Eigen::MatrixXd(choice == GradientChoice::discrete
                                                 ? s.constraints.discrete_tangent(q0, t0, q1, t1, mu)
                                                 : s.constraints.hessian_contraction(q1, t1, mu));
    Eigen::VectorXd tl;
    const Eigen::MatrixXd B = choice == GradientChoice::discrete
                                  ? Eigen::MatrixXd(s.constraints.Gbar(q0, t0, q1, t1, tl))
                                  : Eigen::MatrixXd(s.constraints.G(q1, t1));
    K.topRightCorner(n, m) = B.transpose();
    K.bottomLeftCorner(m, n) = Eigen::MatrixXd(s.constraints.G(q1, t1));
    const Eigen::VectorXd dz = K.fullPivLu().solve(-r);
    if (!dz.allFinite()) throw std::runtime_error("director step: the Newton system is singular");
    q1 += dz.head(n);
    mu += dz.tail(m);
    out.iterations = it;
    converged = dz.head(n).cwiseAbs().maxCoeff() <= 1e-14 * scale && it >= 2;
  }
  residual(q1, mu, r);
  if (!converged && r.tail(m).cwiseAbs().maxCoeff() > 1e-12)
    throw std::runtime_error("director step: Newton did not converge in 40 iterations");
  Eigen::VectorXd tau;
  force_term(s, q0, t0, q1, t1, mu, choice, &tau);
  out.q = q1;
  out.v = 2.0 * (q1 - q0) / dt - v0;
  out.lambda = mu / dt;
  out.drive_work = out.lambda.dot(tau);
  return out;
}

}  // namespace shelldyn::multibody::testing
