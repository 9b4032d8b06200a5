// Bordered Newton of constrained steps (docs/theory/multibody.md §9; header for the equations).
#include "integrators/newmark/bordered_newton.hpp"
#include "integrators/newmark/consistent_acceleration.hpp"

#include "lib/model/assembler.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace shelldyn {

namespace {

Index find_entry(const SparsePattern& p, Index row, Index col) {  // position of (row, col), −1 if not in the pattern
  const auto b = p.rowind.begin() + p.colptr[static_cast<size_t>(col)], e = p.rowind.begin() + p.colptr[static_cast<size_t>(col) + 1];
  const auto it = std::lower_bound(b, e, row);
  return (it != e && *it == row) ? static_cast<Index>(it - p.rowind.begin()) : -1;
}

}  // namespace

// Augmentation of a singular K̄ (multibody.md §9.2): a flat rigid body has E_i = 0, so its d_i rows of K̄ = c M + …
// are zero and K̄ cannot be factorized, though the bordered matrix is regular (the frame rows fix d_i). Adding
// Gᵀ W G times the constraint rows G δu = −g to the first block row gives the same solution with
// K̃ = K̄ + Gᵀ W G, which is regular on such problems: ρ becomes ρ + Gᵀ W g. Only constraint rows whose column pairs
// all lie on the system's pattern take part (w_i = max_j |K̄_jj| / |G_i|² over their columns, or the largest
// diagonal of K̄ if those are all zero; else 0), and only
// when K̄ has a diagonal entry ≤ 1e-14 of its largest. Returns false (w empty) when K̄ needs no augmentation.
static bool augment(const BorderedNewton::ConstraintMatrix& G, const DofMap& dofs, SparseMatrix& J, Eigen::VectorXd& w) {
  const SparsePattern& p = *J.pattern;
  double dmax = 0.0, dmin = std::numeric_limits<double>::infinity();
  for (Index c = 0; c < p.n; ++c) {
    if (dofs.is_constrained(c)) continue;
    const Index k = find_entry(p, c, c);
    const double d = k >= 0 ? std::abs(J.values[static_cast<size_t>(k)]) : 0.0;
    dmax = std::max(dmax, d);
    dmin = std::min(dmin, d);
  }
  w.resize(0);
  if (!(dmin <= 1e-14 * dmax)) return false;
  w.setZero(G.rows());
  for (Index i = 0; i < G.rows(); ++i) {
    std::vector<std::pair<Index, double>> cols;
    for (BorderedNewton::ConstraintMatrix::InnerIterator it(G, i); it; ++it)
      if (it.value() != 0.0 && !dofs.is_constrained(it.col())) cols.emplace_back(it.col(), it.value());
    bool on_pattern = !cols.empty();
    double scale = 0.0, g2 = 0.0;
    for (const auto& [a, va] : cols) {
      g2 += va * va;
      const Index k = find_entry(p, a, a);
      if (k >= 0) scale = std::max(scale, std::abs(J.values[static_cast<size_t>(k)]));
      for (const auto& bc : cols)
        if (find_entry(p, a, bc.first) < 0) on_pattern = false;
    }
    if (!on_pattern || !(g2 > 0.0)) continue;
    if (!(scale > 1e-14 * dmax)) scale = dmax;  // a row on massless unknowns only (|d3|² of a flat body)
    w[i] = scale / g2;
    for (const auto& [a, va] : cols)
      for (const auto& [b, vb] : cols) J.values[static_cast<size_t>(find_entry(p, a, b))] += w[i] * va * vb;
  }
  return true;
}

BorderedNewton::BorderedNewton(std::shared_ptr<const SparsePattern> pattern, BorderedNewtonOptions options)
    : opt_(std::move(options)), solver_(make_linear_solver(opt_.linear_solver)) {
  J_ = SparseMatrix{pattern, std::vector<double>(static_cast<size_t>(pattern->nnz()), 0.0)};
}

BorderedNewton::Result BorderedNewton::solve(const DofMap& dofs, const Eigen::VectorXd& u_n, Eigen::VectorXd& u,
                                             Eigen::VectorXd& lambda, Index m, const Callbacks& cb) {
  // A callback that cannot evaluate an iterate (e.g. a director chart overshot, std::domain_error) fails the step,
  // as KINSOL's callbacks do in the unconstrained steps: the integrator retries or cuts it.
  Result res;
  try {
    return solve_impl(dofs, u_n, u, lambda, m, cb);
  } catch (const std::exception& e) {
    res.message = e.what();
    return res;
  }
}

BorderedNewton::Result BorderedNewton::solve_impl(const DofMap& dofs, const Eigen::VectorXd& u_n, Eigen::VectorXd& u,
                                                  Eigen::VectorXd& lambda, Index m, const Callbacks& cb) {
  const Index n = u.size();
  if (lambda.size() != m) lambda = Eigen::VectorXd::Zero(m);
  const Eigen::ArrayXd uscale = 1.0 / u_n.array().abs().max(1.0);
  Result res;
  Eigen::VectorXd r(n), rho(n), g(m), y(n), b(n), du(n);
  ConstraintMatrix Gh, G, G_aug;
  Eigen::VectorXd w_aug;  // augmentation weights of a singular K̄ (augment()), empty if none
  Eigen::MatrixXd Z(n, m);
  const double u_max = std::max(1.0, u_n.cwiseAbs().maxCoeff());
  double kbar_row_sum = 0.0;  // max_i Σ_j |K̄_ij| of the last K̄ (the residual's round-off level)
  bool fresh = false;        // K̄ factorized at the current iterate
  bool need_refresh = true;  // first iteration: form K̄
  double prev_norm = 0.0, last_step = std::numeric_limits<double>::infinity(), best = std::numeric_limits<double>::infinity();
  for (int k = 0;; ++k) {
    // ρ = r + Ĝᵀλ and g at the iterate (docs/theory/multibody.md §9.1).
    const double scale = cb.residual(u, r);
    ++res.residual_evals;
    cb.force_matrix(u, Gh);
    rho = r + Gh.transpose() * lambda;
    zero_constrained(dofs, rho.data());
    cb.constraints(u, g, G);
    if (!rho.allFinite() || !g.allFinite()) {
      res.message = "non-finite residual or constraint value";
      return res;
    }
    res.residual = rho.cwiseAbs().maxCoeff() / std::max(scale, std::numeric_limits<double>::min());
    res.g_norm = m > 0 ? g.cwiseAbs().maxCoeff() : 0.0;
    res.iterations = k;
    const bool g_ok = res.g_norm <= opt_.g_tol;
    if (g_ok && (res.residual <= opt_.res_tol || (k > 0 && last_step <= opt_.step_tol))) {
      res.converged = true;
      return res;
    }
    // Round-off floor of the residual (options): it stopped falling with a K̄ formed at the previous iterate.
    const double level = kbar_row_sum * std::numeric_limits<double>::epsilon() * u_max / std::max(scale, 1e-300);
    if (g_ok && k >= 2 && res.residual <= std::max(opt_.stall_tol, level) && res.residual > 0.5 * best) {
      if (fresh) {
        res.converged = true;
        return res;
      }
      need_refresh = true;
    }
    best = std::min(best, res.residual);
    if (k >= opt_.max_iters) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "no convergence in %d iterations, scaled residual %.3g, |g|inf = %.3g", k,
                    res.residual, res.g_norm);
      res.message = buf;
      return res;
    }
    fresh = false;
    if (need_refresh || opt_.refresh <= 0.0) {
      cb.jacobian(u, J_);
      if (m > 0) cb.force_tangent(u, lambda, J_);
      apply_dirichlet(dofs, J_, nullptr);
      if (m > 0 && augment(G, dofs, J_, w_aug)) G_aug = G; else w_aug.resize(0);
      kbar_row_sum = 0.0;  // full symmetric storage: column sums are the row sums
      for (Index c = 0; c < J_.pattern->n; ++c) {
        double sum = 0.0;
        for (Index q = J_.pattern->colptr[static_cast<size_t>(c)]; q < J_.pattern->colptr[static_cast<size_t>(c) + 1]; ++q)
          sum += std::abs(J_.values[static_cast<size_t>(q)]);
        kbar_row_sum = std::max(kbar_row_sum, sum);
      }
      try {
        solver_->factorize(J_.view());
      } catch (const std::exception& e) {
        res.message = e.what();
        return res;
      }
      ++res.factorizations;
      fresh = true;
      need_refresh = false;
    }
    // Schur complement of the bordered matrix (header): Z = K̄⁻¹Ĝᵀ, S = G Z, m × m, LU with full pivoting.
    if (w_aug.size() == m) {  // K̃ = K̄ + G_augᵀ W G_aug (augment()): ρ + G_augᵀ W g
      b = rho + G_aug.transpose() * w_aug.cwiseProduct(g);
      zero_constrained(dofs, b.data());
      solver_->solve(b.data(), y.data());
    } else {
      solver_->solve(rho.data(), y.data());
    }
    if (m > 0) {
      for (Index i = 0; i < m; ++i) {
        b = Gh.row(i).transpose();
        zero_constrained(dofs, b.data());
        solver_->solve(b.data(), Z.col(i).data());
      }
      const Eigen::MatrixXd S = G * Z;
      const Eigen::FullPivLU<Eigen::MatrixXd> lu(S);
      if (lu.rank() < m) {
        res.message = "the constraint Schur complement G K̄⁻¹Ĝᵀ is singular (redundant constraints?)";
        return res;
      }
      const Eigen::VectorXd dl = lu.solve(g - G * y);
      du = -y - Z * dl;
      lambda += dl;
    } else {
      du = -y;
    }
    if (!du.allFinite()) {
      res.message = "non-finite Newton correction";
      return res;
    }
    u += du;
    last_step = (du.array().abs() * uscale).maxCoeff();
    const double norm = du.norm();
    if (k > 0 && prev_norm > 0.0 && norm > opt_.refresh * prev_norm) need_refresh = true;  // slow contraction
    prev_norm = norm;
  }
}

void constrained_acceleration(const SemiDiscreteSystem& sys, const State& s, const std::string& linear_solver,
                              Eigen::VectorXd& a, Eigen::VectorXd* lambda) {
  const Index n = sys.num_dofs(), m = sys.num_constraints();
  SparseMatrix M;
  Eigen::VectorXd rhs;
  acceleration_system(sys, s, M, rhs);
  auto solver = make_linear_solver(linear_solver);
  a.resize(n);
  if (m == 0) {
    solver->factorize(M.view());
    solver->solve(rhs.data(), a.data());
    if (lambda) lambda->resize(0);
    return;
  }
  // c = d/ds [G(u + s v, t + s) v + ∂g/∂t(u + s v, t + s)] at s = 0 by a central difference (exact for quadratic
  // scleronomic g); the acceleration condition is G a + c = 0 (multibody.md §9.3).
  const double vmax = std::max(1.0, s.v.cwiseAbs().maxCoeff());
  const double eps = 1e-4 / vmax;
  auto velocity_level = [&](double sgn) {
    const Eigen::VectorXd us = s.u + sgn * eps * s.v;
    SemiDiscreteSystem::ConstraintMatrix G;
    Eigen::VectorXd gt;
    sys.constraint_jacobian(s.t + sgn * eps, us, s.charts, G);
    sys.constraint_time_derivative(s.t + sgn * eps, us, s.charts, gt);
    Eigen::VectorXd w = G * s.v;
    if (gt.size() == m) w += gt;
    return w;
  };
  const Eigen::VectorXd c = (velocity_level(1.0) - velocity_level(-1.0)) / (2.0 * eps);
  SemiDiscreteSystem::ConstraintMatrix G;
  sys.constraint_jacobian(s.t, s.u, s.charts, G);
  // M + Gᵀ W G when M is singular (a flat rigid body, augment()); the constraint rows G a = −c move −Gᵀ W c to the
  // right-hand side.
  Eigen::VectorXd w;
  if (augment(G, sys.dofs(), M, w)) {
    rhs -= G.transpose() * w.cwiseProduct(c);
    zero_constrained(sys.dofs(), rhs.data());
  }
  try {
    solver->factorize(M.view());
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("initial acceleration with constraints: the mass matrix is singular on the "
                                         "constraints' null space (") + e.what() + ")");
  }
  solver->solve(rhs.data(), a.data());
  Eigen::MatrixXd Z(n, m);
  Eigen::VectorXd b(n);
  for (Index i = 0; i < m; ++i) {
    b = G.row(i).transpose();
    zero_constrained(sys.dofs(), b.data());
    solver->solve(b.data(), Z.col(i).data());
  }
  // M a + Gᵀλ = f, G a = −c  ⇒  (G M⁻¹ Gᵀ) λ = G a_free + c,  a = a_free − M⁻¹Gᵀλ.
  const Eigen::MatrixXd S = G * Z;
  const Eigen::VectorXd l = S.fullPivLu().solve(G * a + c);
  a -= Z * l;
  if (lambda) *lambda = l;
}

}  // namespace shelldyn
