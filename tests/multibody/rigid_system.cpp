// Test-only rigid-body system behind the system contract (rigid_system.hpp).
#include "rigid_system.hpp"

namespace shelldyn::multibody::testing {

// No shell nodes: the bodies' unknowns are the DofMap's extra (free) unknowns.
RigidSystem::RigidSystem(std::vector<RigidBody> bodies, Eigen::VectorXd q0, Eigen::VectorXd v0, Vec3 gravity)
    : bodies_(std::move(bodies)), q0_(std::move(q0)), v0_(std::move(v0)), gravity_(gravity),
      n_(12 * static_cast<Index>(bodies_.size())), dofs_(0), set_(static_cast<int>(n_)) {
  dofs_.set_extra_dofs(n_);
  dofs_.resolve({});
  auto p = std::make_shared<SparsePattern>();  // dense: joints couple any two bodies
  p->n = n_;
  for (Index c = 0; c <= n_; ++c) p->colptr.push_back(c * n_);
  for (Index c = 0; c < n_; ++c)
    for (Index r = 0; r < n_; ++r) p->rowind.push_back(r);
  pattern_ = p;
}

double RigidSystem::potential(const Eigen::VectorXd& u) const {
  double V = 0.0;
  for (size_t b = 0; b < bodies_.size(); ++b) V -= bodies_[b].mass() * gravity_.dot(q0_.segment<3>(12 * b) + u.segment<3>(12 * b));
  return V;
}

State RigidSystem::initial_state() const {
  State s;
  s.u = Eigen::VectorXd::Zero(n_);
  s.v = v0_;
  s.a = Eigen::VectorXd::Zero(n_);
  return s;
}

double RigidSystem::internal(const Eigen::VectorXd& u, const std::vector<DirectorChart>&, double* F, SparseMatrix* K) const {
  // Uniform gravity as the potential V = −Σ m g·φ (linear: its gradient is its discrete gradient, and K + V is
  // the conserved energy with no external work); the bodies have no strain.
  if (F) {
    std::fill(F, F + n_, 0.0);
    for (size_t b = 0; b < bodies_.size(); ++b)
      for (int k = 0; k < 3; ++k) F[12 * b + k] = -bodies_[b].mass() * gravity_[k];
  }
  if (K) K->set_zero();
  return potential(u);
}

void RigidSystem::mass(const Eigen::VectorXd&, const std::vector<DirectorChart>&, SparseMatrix& M) const {
  M.set_zero();
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const Vec12 d = bodies_[b].mass_diagonal();
    for (int i = 0; i < 12; ++i) {
      const Index k = 12 * static_cast<Index>(b) + i;
      M.values[static_cast<size_t>(k * n_ + k)] = d[i];
    }
  }
}

void RigidSystem::inertial(const Eigen::VectorXd&, const Eigen::VectorXd&, const std::vector<DirectorChart>&, double* Fm) const {
  std::fill(Fm, Fm + n_, 0.0);  // constant mass matrix: no convective term
}

void RigidSystem::external(double, const Eigen::VectorXd&, const std::vector<DirectorChart>&, double* F) const {
  std::fill(F, F + n_, 0.0);  // gravity is in internal() as a potential
}

Invariants RigidSystem::invariants(const State& s) const {
  Invariants inv;
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const Vec12 q = q0_.segment<12>(12 * b) + s.u.segment<12>(12 * b), v = s.v.segment<12>(12 * b);
    inv.kinetic += bodies_[b].kinetic_energy(v);
    inv.L += bodies_[b].linear_momentum(v);
    inv.J += bodies_[b].angular_momentum(q, v);
  }
  inv.strain = potential(s.u);  // gravity's potential (internal())
  return inv;
}

std::vector<SemiDiscreteSystem::ConstraintBlock> RigidSystem::constraint_blocks() const {
  std::vector<ConstraintBlock> out;
  for (int i = 0; i < set_.size(); ++i) out.push_back({set_[i].type(), set_[i].name(), set_.offset(i), set_[i].size()});
  return out;
}

SemiDiscreteSystem::ConstraintMatrix RigidSystem::convert(const Eigen::SparseMatrix<double>& A) {
  ConstraintMatrix G(A.rows(), A.cols());
  std::vector<Eigen::Triplet<double, Index>> t;
  for (int k = 0; k < A.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, k); it; ++it) t.emplace_back(it.row(), it.col(), it.value());
  G.setFromTriplets(t.begin(), t.end());
  return G;
}

void RigidSystem::add_dense(const Eigen::SparseMatrix<double>& A, double c, SparseMatrix& K) const {
  for (int k = 0; k < A.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, k); it; ++it)
      K.values[static_cast<size_t>(it.col() * n_ + it.row())] += c * it.value();
}

void RigidSystem::constraint_values(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>&, Eigen::VectorXd& g) const {
  g = set_.g(q0_ + u, t);
}
void RigidSystem::constraint_jacobian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>&, ConstraintMatrix& G) const {
  G = convert(set_.G(q0_ + u, t));
}
void RigidSystem::constraint_time_derivative(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>&,
                                             Eigen::VectorXd& g_t) const {
  g_t = set_.dg_dt(q0_ + u, t);
}
void RigidSystem::constraint_discrete_gradient(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                               const std::vector<DirectorChart>&, ConstraintMatrix& G_bar,
                                               Eigen::VectorXd& tau) const {
  if (endpoint_) {
    G_bar = convert(set_.G(q0_ + u1, t1));
    tau.setZero(set_.rows());
    return;
  }
  G_bar = convert(set_.Gbar(q0_ + u0, t0, q0_ + u1, t1, tau));
}
void RigidSystem::add_constraint_hessian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>&,
                                         const Eigen::VectorXd& lambda, double c, SparseMatrix& K) const {
  add_dense(set_.hessian_contraction(q0_ + u, t, lambda), c, K);
}
void RigidSystem::add_constraint_discrete_tangent(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                                  const std::vector<DirectorChart>&, const Eigen::VectorXd& lambda, double c,
                                                  SparseMatrix& K) const {
  if (endpoint_)
    add_dense(set_.hessian_contraction(q0_ + u1, t1, lambda), c, K);
  else
    add_dense(set_.discrete_tangent(q0_ + u0, t0, q0_ + u1, t1, lambda), c, K);
}

ExactEnergySystem::RigidBlock RigidSystem::rigid_block(int b) const {
  RigidBlock r;
  r.first_dof = 12 * b;
  r.mass = bodies_[static_cast<size_t>(b)].mass();
  r.E = bodies_[static_cast<size_t>(b)].euler_tensor();
  return r;
}

}  // namespace shelldyn::multibody::testing
