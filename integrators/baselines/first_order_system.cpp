#include "integrators/baselines/first_order_system.hpp"

#include "lib/model/assembler.hpp"
#include "lib/model/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

FirstOrderSystem::FirstOrderSystem(SemiDiscreteSystem& system, const std::string& mass_solver, bool mass_reuse)
    : system_(&system), n_(system.num_dofs()), mass_reuse_(mass_reuse) {
  // M is SPD: a one-triangle Cholesky/LDLᵀ back-end is both valid and the fastest (docs/dependencies.md §5.4).
  if (mass_solver != "eigen-ldlt" && mass_solver != "cholmod")
    throw std::invalid_argument("mass_solver: '" + mass_solver +
                                "' is not valid (the mass matrix is SPD: use eigen-ldlt or cholmod)");
  mass_solver_ = make_linear_solver(mass_solver);
  M_.pattern = system.pattern();
  M_.values.assign(static_cast<size_t>(M_.pattern->nnz()), 0.0);
  f_int_.resize(n_);
  f_m_.resize(n_);
  f_ext_.resize(n_);
  rhs_.resize(n_);
  res_.resize(n_);
  corr_.resize(n_);
}

void FirstOrderSystem::pack(const State& s, double w, double d, double* y) const {
  std::copy(s.u.data(), s.u.data() + n_, y);
  std::copy(s.v.data(), s.v.data() + n_, y + n_);
  y[work_index()] = w;
  y[damping_index()] = d;
}

double FirstOrderSystem::damping_power(const Eigen::VectorXd& v) {
  if (!system_->has_damping()) return 0.0;
  cv_.resize(n_);
  system_->damping_force(v, cv_.data());  // C v (docs/theory.md §8.5)
  return v.dot(cv_);
}

void FirstOrderSystem::unpack(const double* y, State& s) const {
  s.u = Eigen::Map<const Eigen::VectorXd>(y, n_);
  s.v = Eigen::Map<const Eigen::VectorXd>(y + n_, n_);
}

FirstOrderSystem::Powers FirstOrderSystem::acceleration(double t, const State& s, Eigen::VectorXd& a) {
  if (!all_finite(s.u.data(), n_) || !all_finite(s.v.data(), n_)) {
    std::ostringstream os;
    os << "non-finite state at t = " << t;
    throw std::domain_error(os.str());
  }
  const SemiDiscreteSystem& sys = *system_;
  sys.internal(s.u, s.charts, f_int_.data(), nullptr);
  sys.inertial(s.u, s.v, s.charts, f_m_.data());
  sys.external(t, s.u, s.charts, f_ext_.data());
  sys.mass(s.u, s.charts, M_);
  rhs_ = f_ext_ - f_int_ - f_m_;
  // Rows and columns of constrained DOFs become identity with a zero right-hand side: a_c = 0, and
  // since a_c = 0 the dropped columns M_fc a_c contribute nothing (exact, not an approximation).
  apply_dirichlet(sys.dofs(), M_, rhs_.data(), 1.0);
  solve_mass(a);
  return {f_ext_.dot(s.v), damping_power(s.v)};
}

void FirstOrderSystem::solve_mass(Eigen::VectorXd& a) {
  a.resize(n_);
  if (mass_reuse_ && mass_solver_->factorized()) {
    const double target = 1e-12 * rhs_.cwiseAbs().maxCoeff() + 1e-300;
    mass_solver_->solve(rhs_.data(), a.data());
    double previous = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= 4; ++k) {
      multiply(M_.view(), a.data(), res_.data());
      res_ = rhs_ - res_;
      const double r = res_.cwiseAbs().maxCoeff();
      if (r <= target) return;
      if (k == 4 || !(r < 0.25 * previous)) break;  // too slow: M(q) moved away from M₀
      previous = r;
      mass_solver_->solve(res_.data(), corr_.data());
      a += corr_;
      ++refinements_;
    }
  }
  mass_solver_->factorize(M_.view());
  mass_solver_->solve(rhs_.data(), a.data());
}

FirstOrderSystem::Powers FirstOrderSystem::momentum_residual(double t, const State& s, const Eigen::VectorXd& a,
                                                             Eigen::VectorXd& r) {
  const SemiDiscreteSystem& sys = *system_;
  sys.internal(s.u, s.charts, f_int_.data(), nullptr);
  sys.inertial(s.u, s.v, s.charts, f_m_.data());
  sys.external(t, s.u, s.charts, f_ext_.data());
  sys.mass(s.u, s.charts, M_);
  r.resize(n_);
  multiply(M_.view(), a.data(), r.data());
  r += f_m_ + f_int_ - f_ext_;
  for (Index c : sys.dofs().constrained_dofs()) r[c] = a[c];  // v̇_c = 0 replaces the momentum row
  return {f_ext_.dot(s.v), damping_power(s.v)};
}

FirstOrderSystem::ToleranceScales FirstOrderSystem::tolerance_scales(const State& s0, double length_scale,
                                                                     double time_scale) {
  ToleranceScales sc;
  sc.length = length_scale;
  sc.shell = dynamic_cast<const Model*>(system_) != nullptr;
  if (!(sc.length > 0.0)) {
    sc.length = 1.0;
    if (const auto* model = dynamic_cast<const Model*>(system_)) {
      sc.shell = true;
      const auto& X = model->mesh().X;
      if (!X.empty()) {
        Eigen::Vector3d lo = X[0], hi = X[0];
        for (const auto& x : X) {
          lo = lo.cwiseMin(x);
          hi = hi.cwiseMax(x);
        }
        if ((hi - lo).norm() > 0.0) sc.length = (hi - lo).norm();
      }
    }
  }
  sc.time = time_scale > 0.0 ? time_scale : 1.0;
  sc.velocity = sc.length / sc.time;
  system_->mass(s0.u, s0.charts, M_);
  double mass = 0.0;  // eᵀ M e for rigid unit translations e along X, Y, Z, averaged: the total mass
  const SparsePattern& P = *M_.pattern;
  for (Index j = 0; j < n_; ++j) {
    const Index cj = sc.shell ? j % kDofsPerNode : 0;
    if (cj >= 3) continue;
    for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k) {
      const Index i = P.rowind[k];
      if ((sc.shell ? i % kDofsPerNode : 0) == cj) mass += M_.values[static_cast<size_t>(k)];
    }
  }
  if (sc.shell) mass /= 3.0;
  const Invariants inv = system_->invariants(s0);
  // Not m (L/τ)²: a body that starts at rest may move far less than L/τ suggests (hemisphere at ρ = 1000),
  // and a loose tolerance on W_ext shows directly in the energy balance.
  (void)mass;
  sc.energy = std::max(1.0, inv.kinetic + std::abs(inv.strain));
  if (!(sc.energy > 0.0)) sc.energy = 1.0;
  return sc;
}

void FirstOrderSystem::absolute_tolerances(const ToleranceScales& sc, double atol, double* out) const {
  for (Index i = 0; i < n_; ++i) {
    const bool translation = !sc.shell || i % kDofsPerNode < 3;
    out[i] = atol * (translation ? sc.length : 1.0);
    out[n_ + i] = atol * (translation ? sc.velocity : 1.0 / sc.time);
  }
  out[work_index()] = atol * sc.energy;
  out[damping_index()] = atol * sc.energy;  // W_damp is bounded by the energy put in, like W_ext
}

bool all_finite(const double* x, Index n) {
  for (Index i = 0; i < n; ++i)
    if (!std::isfinite(x[i])) return false;
  return true;
}

void check_tolerances(const std::string& who, double rtol, double atol) {
  if (!(rtol > 0.0 && rtol < 1.0)) {
    std::ostringstream os;
    os << who << ": rtol must be in (0, 1), got " << rtol;
    throw std::invalid_argument(os.str());
  }
  if (!(atol > 0.0 && std::isfinite(atol))) {
    std::ostringstream os;
    os << who << ": atol must be positive and finite, got " << atol;
    throw std::invalid_argument(os.str());
  }
}

bool state_in_sync(const State& s, double t, const State& held, const double* y, Index n) {
  if (s.t != t || s.u.size() != n || s.charts.size() != held.charts.size()) return false;
  for (size_t i = 0; i < s.charts.size(); ++i)
    if (s.charts[i].l != held.charts[i].l || s.charts[i].n != held.charts[i].n || s.charts[i].s != held.charts[i].s)
      return false;
  return s.u == Eigen::Map<const Eigen::VectorXd>(y, n) && s.v == Eigen::Map<const Eigen::VectorXd>(y + n, n);
}

}  // namespace shelldyn
