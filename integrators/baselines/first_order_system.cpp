#include "integrators/baselines/first_order_system.hpp"

#include "lib/assembler.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

FirstOrderSystem::FirstOrderSystem(SemiDiscreteSystem& system, const std::string& mass_solver)
    : system_(&system), n_(system.num_dofs()) {
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
}

void FirstOrderSystem::pack(const State& s, double w, double* y) const {
  std::copy(s.u.data(), s.u.data() + n_, y);
  std::copy(s.v.data(), s.v.data() + n_, y + n_);
  y[2 * n_] = w;
}

void FirstOrderSystem::unpack(const double* y, State& s) const {
  s.u = Eigen::Map<const Eigen::VectorXd>(y, n_);
  s.v = Eigen::Map<const Eigen::VectorXd>(y + n_, n_);
}

double FirstOrderSystem::acceleration(double t, const State& s, Eigen::VectorXd& a) {
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
  mass_solver_->factorize(M_.view());
  a.resize(n_);
  mass_solver_->solve(rhs_.data(), a.data());
  return f_ext_.dot(s.v);
}

double FirstOrderSystem::momentum_residual(double t, const State& s, const Eigen::VectorXd& a,
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
  return f_ext_.dot(s.v);
}

void FirstOrderSystem::absolute_tolerances(const State& s0, double atol, double* out) const {
  const double vscale = std::max(1.0, s0.v.size() ? s0.v.cwiseAbs().maxCoeff() : 0.0);
  const Invariants inv = system_->invariants(s0);
  const double escale = std::max(1.0, inv.kinetic + std::abs(inv.strain));
  std::fill(out, out + n_, atol);
  std::fill(out + n_, out + 2 * n_, atol * vscale);
  out[2 * n_] = atol * escale;
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
