// Bordered Newton of constrained steps (docs/theory/multibody.md §9; header for the equations).
#include "integrators/newmark/bordered_newton.hpp"

#include "lib/model/assembler.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace shelldyn {

BorderedNewton::BorderedNewton(std::shared_ptr<const SparsePattern> pattern, BorderedNewtonOptions options)
    : opt_(std::move(options)), solver_(make_linear_solver(opt_.linear_solver)) {
  J_ = SparseMatrix{pattern, std::vector<double>(static_cast<size_t>(pattern->nnz()), 0.0)};
}

BorderedNewton::Result BorderedNewton::solve(const DofMap& dofs, const Eigen::VectorXd& u_n, Eigen::VectorXd& u,
                                             Eigen::VectorXd& lambda, Index m, const Callbacks& cb) {
  const Index n = u.size();
  if (lambda.size() != m) lambda = Eigen::VectorXd::Zero(m);
  const Eigen::ArrayXd uscale = 1.0 / u_n.array().abs().max(1.0);
  Result res;
  Eigen::VectorXd r(n), rho(n), g(m), y(n), b(n), du(n);
  ConstraintMatrix Gh, G;
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
    solver_->solve(rho.data(), y.data());
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
  SparseMatrix M{sys.pattern(), std::vector<double>(static_cast<size_t>(sys.pattern()->nnz()), 0.0)};
  Eigen::VectorXd fint = Eigen::VectorXd::Zero(n), fm = Eigen::VectorXd::Zero(n), fext = Eigen::VectorXd::Zero(n);
  sys.mass(s.u, s.charts, M);
  sys.internal(s.u, s.charts, fint.data(), nullptr);
  sys.inertial(s.u, s.v, s.charts, fm.data());
  sys.external(s.t, s.u, s.charts, fext.data());
  Eigen::VectorXd rhs = fext - fint - fm;
  apply_dirichlet(sys.dofs(), M, rhs.data());
  auto solver = make_linear_solver(linear_solver);
  solver->factorize(M.view());
  a.resize(n);
  solver->solve(rhs.data(), a.data());
  if (m == 0) {
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
