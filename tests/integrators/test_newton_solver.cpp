// KINSOL-driven NewtonSolver (integrators/nonlinear/newton_solver.hpp) on the 2-D Bratu problem
//   F_i(u) = (4 u_i − Σ_neighbours u_j) / h² − λ e^{u_i} = 0   on an m x m interior grid, u = 0 outside,
// whose Jacobian (5-point Laplacian/h² − λ diag e^u) is sparse and symmetric, and SPD for λ below
// the fold (λ ≈ 6.8).
#include "integrators/nonlinear/newton_solver.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace shelldyn {
namespace {

struct Bratu {
  int m;
  double lambda;
  double h;
  std::shared_ptr<SparsePattern> pattern;

  Bratu(int m_, double lambda_) : m(m_), lambda(lambda_), h(1.0 / (m_ + 1)) {
    pattern = std::make_shared<SparsePattern>();
    pattern->n = Index(m) * m;
    pattern->colptr.push_back(0);
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {  // column of node (i, j); rows sorted: (i,j-1),(i-1,j),(i,j),(i+1,j),(i,j+1)
        if (j > 0) pattern->rowind.push_back(id(i, j - 1));
        if (i > 0) pattern->rowind.push_back(id(i - 1, j));
        pattern->rowind.push_back(id(i, j));
        if (i < m - 1) pattern->rowind.push_back(id(i + 1, j));
        if (j < m - 1) pattern->rowind.push_back(id(i, j + 1));
        pattern->colptr.push_back(static_cast<Index>(pattern->rowind.size()));
      }
  }
  Index id(int i, int j) const { return Index(j) * m + i; }
  Index n() const { return pattern->n; }

  void residual(const double* u, double* f) const {
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const Index k = id(i, j);
        double s = 4.0 * u[k];
        if (i > 0) s -= u[id(i - 1, j)];
        if (i < m - 1) s -= u[id(i + 1, j)];
        if (j > 0) s -= u[id(i, j - 1)];
        if (j < m - 1) s -= u[id(i, j + 1)];
        f[k] = s / (h * h) - lambda * std::exp(u[k]);
      }
  }
  void jacobian(const double* u, SparseMatrix& J) const {
    const auto& P = *pattern;
    for (Index c = 0; c < P.n; ++c)
      for (Index p = P.colptr[c]; p < P.colptr[c + 1]; ++p)
        J.values[p] = P.rowind[p] == c ? 4.0 / (h * h) - lambda * std::exp(u[c]) : -1.0 / (h * h);
  }
  NewtonSolver::Residual F() const {
    return [this](const double* u, double* f) { residual(u, f); };
  }
  NewtonSolver::Jacobian J() const {
    return [this](const double* u, SparseMatrix& Jm) { jacobian(u, Jm); };
  }
  double max_residual(const std::vector<double>& u) const {
    std::vector<double> f(u.size());
    residual(u.data(), f.data());
    double mx = 0;
    for (double v : f) mx = std::max(mx, std::abs(v));
    return mx;
  }
};

double max_abs(const double* v, Index n) {
  double mx = 0;
  for (Index i = 0; i < n; ++i) mx = std::max(mx, std::abs(v[i]));
  return mx;
}

TEST(NewtonSolver, FullNewtonConvergesQuadraticallyWithEveryBackEnd) {
  const Bratu b(24, 6.0);
  std::vector<double> reference;
  for (const auto& name : linear_solver_names()) {
    NewtonOptions o;
    o.linear_solver = name;
    NewtonSolver solver(b.pattern, o);
    std::vector<double> u(b.n(), 0.0);
    std::vector<double> fnorms;  // ‖F(u_{k-1})‖∞ as seen by the hook
    const auto r = solver.solve(u.data(), b.F(), b.J(), nullptr, nullptr,
                                [&](int, const double*, const double*, const double* f) {
                                  fnorms.push_back(max_abs(f, b.n()));
                                });
    ASSERT_TRUE(r.converged) << name << ": " << r.message;
    EXPECT_EQ(r.stop_reason, NewtonSolver::StopReason::fnorm) << name;
    EXPECT_LE(b.max_residual(u), 1e-10) << name;
    EXPECT_NEAR(r.fnorm, b.max_residual(u), 1e-14) << name;
    EXPECT_LE(r.iterations, 8) << name;
    EXPECT_EQ(r.jacobian_evals, r.iterations) << name;  // full Newton: one setup per iteration
    EXPECT_EQ(r.factorizations, r.iterations) << name;
    EXPECT_EQ(r.residual_evals, r.iterations + 1) << name;  // the cache removes KINSOL's re-evaluations
    ASSERT_EQ(static_cast<int>(fnorms.size()), r.iterations);
    fnorms.push_back(r.fnorm);
    // Quadratic convergence: once in the asymptotic range, ‖F_{k+1}‖ ≤ C ‖F_k‖² (log-ratio ≥ 1.8
    // on the last ratios that are above round-off).
    int checked = 0;
    for (size_t k = 1; k + 1 < fnorms.size(); ++k) {
      if (fnorms[k] > 1e-1 || fnorms[k + 1] < 1e-11) continue;
      EXPECT_GE(std::log(fnorms[k + 1]) / std::log(fnorms[k]), 1.8)
          << name << " k=" << k << ": " << fnorms[k] << " -> " << fnorms[k + 1];
      ++checked;
    }
    EXPECT_GE(checked, 1) << name;
    if (reference.empty()) reference = u;
    for (Index i = 0; i < b.n(); ++i) ASSERT_NEAR(u[i], reference[i], 1e-10) << name;
    EXPECT_EQ(solver.linear_solver().stats().analyses, 1);
    if (name == "eigen-ldlt") {
      std::string seq;
      for (double f : fnorms) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.2e ", f);
        seq += buf;
      }
      RecordProperty("fnorm_sequence", seq);
      std::printf("[ info ] full Newton, Bratu 24x24 lambda=6: %d iterations, |F|inf: %s\n", r.iterations,
                  seq.c_str());
    }
  }
}

TEST(NewtonSolver, ModifiedNewtonUsesFewerFactorizationsAndMoreIterations) {
  const Bratu b(24, 6.0);
  NewtonOptions full_o;
  NewtonSolver full(b.pattern, full_o);
  std::vector<double> u_full(b.n(), 0.0);
  const auto rf = full.solve(u_full.data(), b.F(), b.J());
  ASSERT_TRUE(rf.converged) << rf.message;

  NewtonOptions mo;
  mo.modified = true;
  mo.max_setup_calls = 5;
  mo.max_iters = 60;
  NewtonSolver mod(b.pattern, mo);
  std::vector<double> u_mod(b.n(), 0.0);
  const auto rm = mod.solve(u_mod.data(), b.F(), b.J());
  ASSERT_TRUE(rm.converged) << rm.message;
  EXPECT_GT(rm.iterations, rf.iterations);
  EXPECT_LT(rm.factorizations, rf.factorizations);
  EXPECT_EQ(rm.jacobian_evals, (rm.iterations + mo.max_setup_calls - 1) / mo.max_setup_calls);
  EXPECT_LE(b.max_residual(u_mod), 1e-10);
  std::printf("[ info ] Bratu 24x24: full Newton %d iters / %d factorizations, modified (refresh 5) %d / %d\n",
              rf.iterations, rf.factorizations, rm.iterations, rm.factorizations);

  // Across calls: a second solve from the converged state of a nearby problem reuses the
  // factorization (no Jacobian evaluation) until max_setup_calls iterations have accumulated.
  const Bratu b2(24, 6.05);
  const int since = rm.iterations % mo.max_setup_calls;
  const auto rm2 = mod.solve(u_mod.data(), b2.F(), b2.J());
  ASSERT_TRUE(rm2.converged) << rm2.message;
  std::printf("[ info ] modified Newton, second call: %d iterations, %d Jacobian evaluations (%d carried over)\n",
              rm2.iterations, rm2.jacobian_evals, since);
  if (since != 0 && rm2.iterations <= mo.max_setup_calls - since) {
    EXPECT_EQ(rm2.jacobian_evals, 0);
  }
  EXPECT_LE(rm2.jacobian_evals, (rm2.iterations + since + mo.max_setup_calls - 1) / mo.max_setup_calls);
  // invalidate_jacobian() forces a fresh setup at the start of the next solve.
  mod.invalidate_jacobian();
  const auto rm3 = mod.solve(u_mod.data(), b.F(), b.J());
  ASSERT_TRUE(rm3.converged) << rm3.message;
  EXPECT_GE(rm3.jacobian_evals, 1);
  EXPECT_EQ(mod.linear_solver().stats().analyses, 1);
}

TEST(NewtonSolver, ContractionBasedRefreshKeepsAGoodFactorizationAndReplacesAPoorOne) {
  // Bratu from u = 0: the Jacobian at u = 0 is a poor model of the one at the solution (θ ≈ 0.3 - 0.5),
  // so a contraction threshold of 0.1 must refresh it, while a threshold of 0.9 keeps it.
  const Bratu b(24, 6.0);
  auto run = [&](double threshold, NewtonSolver::Result* out) {
    NewtonOptions o;
    o.modified = true;
    o.max_setup_calls = 1000000;  // no refresh by count
    o.refresh_contraction = threshold;
    o.max_iters = 200;
    NewtonSolver solver(b.pattern, o);
    std::vector<double> u(b.n(), 0.0);
    *out = solver.solve(u.data(), b.F(), b.J());
    EXPECT_TRUE(out->converged) << out->message;
    EXPECT_LE(b.max_residual(u), 1e-10);
  };
  NewtonSolver::Result loose, tight;
  run(0.9, &loose);
  run(0.1, &tight);
  std::printf("[ info ] contraction refresh 0.9: %d iterations / %d factorizations (last theta %.2g); 0.1: %d / %d\n",
              loose.iterations, loose.factorizations, loose.contraction, tight.iterations, tight.factorizations);
  EXPECT_EQ(loose.factorizations, 1);           // never refreshed: θ stayed below 0.9
  EXPECT_GT(loose.contraction, 0.1);            // ... but above 0.1, so the tight run must refresh
  EXPECT_GE(tight.factorizations, 2);
  EXPECT_LT(tight.iterations, loose.iterations);
  // With refresh by contraction off and no count, the first factorization is used throughout.
  NewtonSolver::Result off;
  run(0.0, &off);
  EXPECT_EQ(off.factorizations, 1);
  EXPECT_EQ(off.iterations, loose.iterations);
}

TEST(NewtonSolver, LineSearchVariantConverges) {
  const Bratu b(24, 6.0);
  NewtonOptions o;
  o.line_search = true;
  o.linear_solver = "klu";
  NewtonSolver solver(b.pattern, o);
  std::vector<double> u(b.n(), 0.0);
  const auto r = solver.solve(u.data(), b.F(), b.J());
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_LE(b.max_residual(u), 1e-10);
  EXPECT_NEAR(r.fnorm, b.max_residual(u), 1e-14);
  EXPECT_LE(r.iterations, 8);
}

TEST(NewtonSolver, ContinuationKeepsOneAnalysisAcrossSixSolves) {
  const Bratu base(30, 1.0);
  NewtonOptions o;
  o.linear_solver = "cholmod";
  NewtonSolver solver(base.pattern, o);
  std::vector<double> u(base.n(), 0.0);
  int total_jac = 0;
  for (int s = 1; s <= 6; ++s) {
    Bratu b(30, 1.0 * s);
    b.pattern = base.pattern;  // same pattern object
    const auto r = solver.solve(u.data(), b.F(), b.J());
    ASSERT_TRUE(r.converged) << "lambda " << s << ": " << r.message;
    EXPECT_LE(b.max_residual(u), 1e-10);
    total_jac += r.jacobian_evals;
  }
  EXPECT_EQ(solver.linear_solver().stats().analyses, 1);
  EXPECT_EQ(solver.linear_solver().stats().factorizations, total_jac);
  EXPECT_GT(total_jac, 6);
}

TEST(NewtonSolver, ThrowingCallbacksReturnFailureWithTheirMessage) {
  const Bratu b(8, 3.0);
  NewtonSolver solver(b.pattern);
  int calls = 0;
  auto throwing_residual = [&](const double* u, double* f) {
    if (++calls == 3) throw std::runtime_error("director overshoot at node 7");
    b.residual(u, f);
  };
  std::vector<double> u(b.n(), 0.0);
  auto r = solver.solve(u.data(), throwing_residual, b.J());
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.stop_reason, NewtonSolver::StopReason::failure);
  EXPECT_NE(r.message.find("director overshoot at node 7"), std::string::npos) << r.message;
  EXPECT_LT(r.kinsol_flag, 0);

  auto throwing_jacobian = [&](const double*, SparseMatrix&) { throw std::runtime_error("bad tangent"); };
  std::fill(u.begin(), u.end(), 0.0);
  r = solver.solve(u.data(), b.F(), throwing_jacobian);
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.message.find("bad tangent"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("KIN_LSETUP_FAIL"), std::string::npos) << r.message;

  auto nan_residual = [&](const double* u, double* f) {
    b.residual(u, f);
    f[5] = std::nan("");
  };
  std::fill(u.begin(), u.end(), 0.0);
  r = solver.solve(u.data(), nan_residual, b.J());
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.message.find("residual component 5"), std::string::npos) << r.message;

  std::fill(u.begin(), u.end(), 0.0);
  r = solver.solve(u.data(), b.F(), b.J(), nullptr, nullptr,
                   [](int k, const double*, const double*, const double*) {
                     if (k == 2) throw std::runtime_error("hook refused");
                   });
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.message.find("hook refused"), std::string::npos) << r.message;
  EXPECT_EQ(r.iterations, 2);

  // After all these failures the solver still works.
  std::fill(u.begin(), u.end(), 0.0);
  r = solver.solve(u.data(), b.F(), b.J());
  EXPECT_TRUE(r.converged) << r.message;
}

TEST(NewtonSolver, SingularJacobianReportsLinearSolverFailure) {
  const Bratu b(6, 3.0);
  NewtonSolver solver(b.pattern);
  std::vector<double> u(b.n(), 0.0);
  const auto r = solver.solve(u.data(), b.F(), [](const double*, SparseMatrix& J) { J.set_zero(); });
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.message.find("eigen-ldlt: zero pivot"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("KIN_LSETUP_FAIL"), std::string::npos) << r.message;
}

TEST(NewtonSolver, MaxItersReportsKinsolFlagName) {
  const Bratu b(16, 6.0);
  NewtonOptions o;
  o.max_iters = 2;
  NewtonSolver solver(b.pattern, o);
  std::vector<double> u(b.n(), 0.0);
  const auto r = solver.solve(u.data(), b.F(), b.J());
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 2);
  EXPECT_EQ(r.kinsol_flag, -6);  // KIN_MAXITER_REACHED
  EXPECT_EQ(r.stop_reason, NewtonSolver::StopReason::max_iters);
  EXPECT_NE(r.message.find("KIN_MAXITER_REACHED"), std::string::npos) << r.message;
  EXPECT_GT(r.fnorm, 1e-10);
}

TEST(NewtonSolver, EnergyCriterionStopsAtCcBelowTolerance) {
  const Bratu b(24, 6.0);
  NewtonOptions o;
  o.stop = StopTest::energy;
  o.energy_tol = 1e-6;
  NewtonSolver solver(b.pattern, o);
  std::vector<double> u(b.n(), 0.0);
  std::vector<double> E;  // E_{k-1} = |du_k · F(u_{k-1})|, computed independently
  const auto r = solver.solve(u.data(), b.F(), b.J(), nullptr, nullptr,
                              [&](int, const double*, const double* du, const double* f) {
                                double e = 0;
                                for (Index i = 0; i < b.n(); ++i) e += du[i] * f[i];
                                E.push_back(std::abs(e));
                              });
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.stop_reason, NewtonSolver::StopReason::energy);
  ASSERT_GE(E.size(), 2u);
  const double cc = E.back() / E.front();
  EXPECT_NEAR(r.energy_ratio, cc, 1e-12 * std::max(1.0, cc));
  EXPECT_LE(cc, 1e-6);
  const double cc_prev = E[E.size() - 2] / E.front();
  if (E.size() > 2) {
    EXPECT_GT(cc_prev, 1e-6);  // stopped at the first iterate that satisfies it
  }
  std::printf("[ info ] energy criterion: %d iterations, cc = %.3e (previous %.3e), |F|inf = %.3e\n",
              r.iterations, cc, cc_prev, r.fnorm);

  // min_iters is honoured even when the criterion would stop earlier.
  NewtonOptions o2 = o;
  o2.min_iters = static_cast<int>(E.size()) + 2;
  NewtonSolver solver2(b.pattern, o2);
  std::vector<double> u2(b.n(), 0.0);
  const auto r2 = solver2.solve(u2.data(), b.F(), b.J());
  ASSERT_TRUE(r2.converged) << r2.message;
  EXPECT_EQ(r2.iterations, o2.min_iters);

  // fnorm_and_energy needs both; fnorm_or_energy stops at the first.
  NewtonOptions o3 = o;
  o3.stop = StopTest::fnorm_and_energy;
  o3.fnorm_tol = 1e-12;
  NewtonSolver s3(b.pattern, o3);
  std::vector<double> u3(b.n(), 0.0);
  const auto r3 = s3.solve(u3.data(), b.F(), b.J());
  ASSERT_TRUE(r3.converged) << r3.message;
  EXPECT_LE(r3.fnorm, 1e-12);
  EXPECT_LE(r3.energy_ratio, 1e-6);
  EXPECT_GE(r3.iterations, r.iterations);
}

TEST(NewtonSolver, HookCanAcceptAndInitialSolutionIsRecognised) {
  const Bratu b(12, 4.0);
  NewtonSolver solver(b.pattern);
  std::vector<double> u(b.n(), 0.0);
  auto r = solver.solve(u.data(), b.F(), b.J(), nullptr, nullptr,
                        [](int k, const double*, const double*, const double*) { return k == 2; });
  ASSERT_TRUE(r.converged);
  EXPECT_EQ(r.stop_reason, NewtonSolver::StopReason::hook);
  EXPECT_EQ(r.iterations, 2);
  // Continue to the solution, then solve again from it: min_iters = 1 still forces one iteration,
  // which leaves u unchanged to round-off and stops on KINSOL's fnorm test.
  r = solver.solve(u.data(), b.F(), b.J());
  ASSERT_TRUE(r.converged);
  const std::vector<double> u_sol = u;
  r = solver.solve(u.data(), b.F(), b.J());
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.iterations, 1);
  for (Index i = 0; i < b.n(); ++i) EXPECT_NEAR(u[i], u_sol[i], 1e-12);
  // With min_iters = 0 the converged guess is accepted without iterating.
  NewtonOptions o;
  o.min_iters = 0;
  NewtonSolver s0(b.pattern, o);
  r = s0.solve(u.data(), b.F(), b.J());
  ASSERT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(r.stop_reason, NewtonSolver::StopReason::initial_guess);
  EXPECT_EQ(r.jacobian_evals, 0);
}

TEST(NewtonSolver, KeptBasisChangeSolvesInTheNewUnknownsWithoutAFactorization) {
  // docs/theory.md §6.9: a kept factorization of A, seen through δu₀ = T δu, is the matrix Tᵀ A T. For the
  // linear problem F(u) = Tᵀ A T u − Tᵀ c the kept factorization with the change installed is its exact
  // Jacobian: one iteration and no setup; without the change the same kept A needs many iterations.
  const Bratu b(4, 1.0);
  const Index n = b.n();
  SparseMatrix Am{b.pattern, {}};
  Am.values.assign(b.pattern->nnz(), 0.0);
  const std::vector<double> zero(static_cast<size_t>(n), 0.0);
  b.jacobian(zero.data(), Am);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (Index c = 0; c < n; ++c)
    for (Index p = b.pattern->colptr[c]; p < b.pattern->colptr[c + 1]; ++p) A(b.pattern->rowind[p], c) = Am.values[p];
  // T block diagonal: a rotation-like 3 × 3 block at 0, a 2 × 2 block at 5, identity elsewhere.
  Eigen::MatrixXd T = Eigen::MatrixXd::Identity(n, n);
  T.block<3, 3>(0, 0) << 0.8, -0.6, 0.0, 0.6, 0.8, 0.0, 0.0, 0.0, 1.0;
  T.block<2, 2>(5, 5) << 1.2, 0.3, -0.1, 0.9;
  const Eigen::MatrixXd Ti = T.inverse();
  std::vector<NewtonSolver::BasisBlock> blocks(2);
  blocks[0].first = 0;
  blocks[0].size = 3;
  blocks[1].first = 5;
  blocks[1].size = 2;
  for (const int k : {0, 1})
    for (int r = 0; r < blocks[k].size; ++r)
      for (int c = 0; c < blocks[k].size; ++c) blocks[k].inverse[3 * r + c] = Ti(blocks[k].first + r, blocks[k].first + c);
  Eigen::VectorXd c = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0);
  const Eigen::MatrixXd TAT = T.transpose() * A * T;
  const Eigen::VectorXd rhs = T.transpose() * c;
  NewtonSolver::Residual F1 = [&](const double* u, double* f) {
    Eigen::Map<Eigen::VectorXd>(f, n) = A * Eigen::Map<const Eigen::VectorXd>(u, n) - c;
  };
  NewtonSolver::Residual F2 = [&](const double* u, double* f) {
    Eigen::Map<Eigen::VectorXd>(f, n) = TAT * Eigen::Map<const Eigen::VectorXd>(u, n) - rhs;
  };
  NewtonSolver::Jacobian J = [&](const double*, SparseMatrix& Jm) { Jm.values = Am.values; };
  auto run = [&](bool change, NewtonSolver::Result& r1, NewtonSolver::Result& r2, Eigen::VectorXd& u2) {
    NewtonOptions o;
    o.modified = true;
    o.max_setup_calls = 1000;
    o.max_iters = 200;
    o.fnorm_tol = 1e-9;
    o.step_tol = 0.0;
    NewtonSolver s(b.pattern, o);
    std::vector<double> u(static_cast<size_t>(n), 0.0);
    r1 = s.solve(u.data(), F1, J);  // forms and keeps A
    if (change) s.set_kept_basis_change(blocks);
    std::fill(u.begin(), u.end(), 0.0);
    r2 = s.solve(u.data(), F2, J);
    u2 = Eigen::Map<Eigen::VectorXd>(u.data(), n);
    EXPECT_EQ(s.kept_basis_change().size(), change ? 2u : 0u);
    s.invalidate_jacobian();  // a new setup forms the matrix in the current unknowns: the change is cleared
    r1 = s.solve(u.data(), F1, J);
    EXPECT_TRUE(s.kept_basis_change().empty());
  };
  NewtonSolver::Result r1, r2, q1, q2;
  Eigen::VectorXd u2, v2;
  run(true, r1, r2, u2);
  ASSERT_TRUE(r2.converged) << r2.message;
  EXPECT_EQ(r2.jacobian_evals, 0);
  EXPECT_EQ(r2.iterations, 1);
  EXPECT_LE((TAT * u2 - rhs).cwiseAbs().maxCoeff(), 1e-9);
  run(false, q1, q2, v2);
  EXPECT_EQ(q2.jacobian_evals, 0);
  EXPECT_GT(q2.iterations, 5) << "the kept A without the change should be a poor model of Tᵀ A T";

  NewtonSolver s(b.pattern);
  auto bad = blocks;
  bad[1].first = 2;  // overlaps the 3 × 3 block
  EXPECT_THROW(s.set_kept_basis_change(bad), std::invalid_argument);
  bad = blocks;
  bad[1].first = n - 1;  // runs past the end
  EXPECT_THROW(s.set_kept_basis_change(bad), std::invalid_argument);
  bad = blocks;
  bad[0].inverse[4] = std::nan("");
  EXPECT_THROW(s.set_kept_basis_change(bad), std::invalid_argument);
}

TEST(NewtonSolver, RejectsBadOptions) {
  const Bratu b(4, 1.0);
  NewtonOptions o;
  o.linear_solver = "pardiso";
  try {
    NewtonSolver s(b.pattern, o);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("eigen-ldlt"), std::string::npos) << e.what();
  }
  o = NewtonOptions{};
  o.min_iters = 30;
  EXPECT_THROW(NewtonSolver(b.pattern, o), std::invalid_argument);
  o = NewtonOptions{};
  o.max_iters = 0;
  EXPECT_THROW(NewtonSolver(b.pattern, o), std::invalid_argument);
  o = NewtonOptions{};
  o.refresh_contraction = -0.1;
  EXPECT_THROW(NewtonSolver(b.pattern, o), std::invalid_argument);
  EXPECT_THROW(NewtonSolver(nullptr), std::invalid_argument);
  NewtonSolver s(b.pattern);
  std::vector<double> u(b.n(), 0.0), bad_scale(b.n(), 1.0);
  bad_scale[2] = 0.0;
  EXPECT_THROW(s.solve(u.data(), b.F(), b.J(), bad_scale.data()), std::invalid_argument);
}

}  // namespace
}  // namespace shelldyn
