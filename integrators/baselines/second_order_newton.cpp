#include "integrators/baselines/second_order_newton.hpp"

#include "lib/model/assembler.hpp"

#include <algorithm>
#include <stdexcept>

namespace shelldyn {

SecondOrderNewton::SecondOrderNewton(std::shared_ptr<const SparsePattern> pattern, const DofMap& dofs,
                                     const std::string& linear_solver)
    : dofs_(dofs), solver_(make_linear_solver(linear_solver)) {
  if (!pattern) throw std::invalid_argument("SecondOrderNewton: null pattern");
  K.pattern = M.pattern = G.pattern = S_.pattern = pattern;
  K.values.assign(static_cast<size_t>(pattern->nnz()), 0.0);
  M.values = G.values = S_.values = K.values;
  const Index n = pattern->n;
  z_.resize(n);
  xc_.resize(n);
  rhs_.resize(n);
  tmp_.resize(n);
}

void SecondOrderNewton::factorize(double gamma) {
  if (!(gamma > 0.0)) throw std::invalid_argument("SecondOrderNewton: step factor gamma must be > 0");
  const double g2 = gamma * gamma;
  for (size_t k = 0; k < S_.values.size(); ++k) S_.values[k] = M.values[k] + gamma * G.values[k] + g2 * K.values[k];
  apply_dirichlet(dofs_, S_, nullptr, 1.0);
  // An undamped model with the approximate Jacobian has G = 0: skip its product in every solve.
  g_zero_ = std::all_of(G.values.begin(), G.values.end(), [](double v) { return v == 0.0; });
  gamma_ = 0.0;
  solver_->factorize(S_.view());
  gamma_ = gamma;
}

void SecondOrderNewton::solve(const double* r_q, const double* m, const double* p, double* x_q, double* x_v) {
  if (!(gamma_ > 0.0)) throw std::logic_error("SecondOrderNewton::solve without a valid factorization");
  const Index n = static_cast<Index>(z_.size());
  const double g = gamma_;
  // z = r_q (free) / −γ x_v,c (constrained); x_c = x_q,c on constrained dofs, 0 elsewhere.
  xc_.setZero();
  for (Index i = 0; i < n; ++i) z_[i] = r_q[i];
  for (Index c : dofs_.constrained_dofs()) {
    x_v[c] = (m ? m[c] : 0.0) + (p ? p[c] : 0.0);
    xc_[c] = r_q[c] + g * x_v[c];
    z_[c] = -g * x_v[c];
  }
  // rhs = M (z + γ m) + γ G z + γ p − γ² K x_c
  if (m)
    for (Index i = 0; i < n; ++i) tmp_[i] = z_[i] + g * m[i];
  else
    tmp_ = z_;
  multiply(M.view(), tmp_.data(), rhs_.data());
  if (!g_zero_) {
    multiply(G.view(), z_.data(), tmp_.data());
    rhs_ += g * tmp_;
  }
  if (p) rhs_ += g * Eigen::Map<const Eigen::VectorXd>(p, n);
  if (dofs_.num_constrained() > 0) {
    multiply(K.view(), xc_.data(), tmp_.data());
    rhs_ -= (g * g) * tmp_;
  }
  for (Index c : dofs_.constrained_dofs()) rhs_[c] = xc_[c];
  solver_->solve(rhs_.data(), x_q);
  for (Index i = 0; i < n; ++i)
    if (!dofs_.is_constrained(i)) x_v[i] = (x_q[i] - r_q[i]) / g;
}

}  // namespace shelldyn
