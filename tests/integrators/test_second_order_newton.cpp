// The Schur-complement solve of the baselines' Newton matrix (integrators/baselines/second_order_newton.hpp):
// the solution must satisfy every row of the full block system, on free and constrained dofs, for symmetric
// blocks (Cholesky) and non-symmetric ones (KLU), with m and p each present or absent.
#include "integrators/baselines/second_order_newton.hpp"

#include <gtest/gtest.h>

#include <ostream>
#include <random>
#include <vector>

namespace shelldyn {
namespace {

constexpr int kNodes = 3;  // 15 dofs

std::shared_ptr<SparsePattern> full_pattern(Index n) {
  auto P = std::make_shared<SparsePattern>();
  P->n = n;
  P->colptr.push_back(0);
  for (Index j = 0; j < n; ++j) {
    for (Index i = 0; i < n; ++i) P->rowind.push_back(i);
    P->colptr.push_back(static_cast<Index>(P->rowind.size()));
  }
  return P;
}

// Dense n × n matrix into the full pattern; symmetric = true symmetrises it.
void fill(SparseMatrix& A, std::mt19937& rng, double diagonal, bool symmetric) {
  const Index n = A.pattern->n;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> d(static_cast<size_t>(n * n));
  for (auto& x : d) x = u(rng);
  for (Index j = 0; j < n; ++j)
    for (Index i = 0; i < n; ++i) {
      double v = symmetric ? 0.5 * (d[i + n * j] + d[j + n * i]) : d[i + n * j];
      if (i == j) v += diagonal;
      A.values[static_cast<size_t>(i + n * j)] = v;
    }
}

Eigen::VectorXd times(const SparseMatrix& A, const Eigen::VectorXd& x) {
  const Index n = A.pattern->n;
  Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
  for (Index j = 0; j < n; ++j)
    for (Index i = 0; i < n; ++i) y[i] += A.values[static_cast<size_t>(i + n * j)] * x[j];
  return y;
}

struct Case {
  const char* solver;
  bool symmetric, with_m, with_p, constrained;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.solver << (c.symmetric ? " symmetric" : " non-symmetric") << (c.with_m ? " m" : "") << (c.with_p ? " p" : "")
      << (c.constrained ? " constrained" : " unconstrained");
}

class SecondOrderNewtonRows : public ::testing::TestWithParam<Case> {};

TEST_P(SecondOrderNewtonRows, SolutionSatisfiesEveryRowOfTheBlockSystem) {
  const Case c = GetParam();
  DofMap dofs(kNodes);
  if (c.constrained) {
    dofs.fix(0, Fix::Ux);
    dofs.fix(2, Fix::Uz);
  }
  dofs.resolve(std::vector<DirectorChart>(kNodes));
  const Index n = dofs.num_dofs();
  std::mt19937 rng(7);
  SecondOrderNewton nw(full_pattern(n), dofs, c.solver);
  fill(nw.K, rng, 20.0, c.symmetric);
  fill(nw.M, rng, 30.0, true);
  fill(nw.G, rng, 5.0, c.symmetric);
  const double gamma = 0.3;
  nw.factorize(gamma);

  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd r_q(n), m(n), p(n), xq(n), xv(n);
  for (Index i = 0; i < n; ++i) r_q[i] = u(rng), m[i] = c.with_m ? u(rng) : 0.0, p[i] = c.with_p ? u(rng) : 0.0;
  nw.solve(r_q.data(), c.with_m ? m.data() : nullptr, c.with_p ? p.data() : nullptr, xq.data(), xv.data());

  // Row by row: x_q − γ x_v = r_q everywhere; free momentum rows γ K x_q + (M + γ G) x_v = M m + p;
  // constrained momentum rows x_v,c = m_c + p_c.
  const Eigen::VectorXd mom = gamma * times(nw.K, xq) + times(nw.M, xv) + gamma * times(nw.G, xv);
  const Eigen::VectorXd rhs = times(nw.M, m) + p;
  for (Index i = 0; i < n; ++i) {
    EXPECT_NEAR(xq[i] - gamma * xv[i], r_q[i], 1e-12) << "q row " << i;
    if (dofs.is_constrained(i))
      EXPECT_NEAR(xv[i], m[i] + p[i], 1e-14) << "constrained momentum row " << i;
    else
      EXPECT_NEAR(mom[i], rhs[i], 1e-11) << "momentum row " << i;
  }
  EXPECT_EQ(nw.gamma(), gamma);
  EXPECT_EQ(nw.backend().stats().factorizations, 1);
}

INSTANTIATE_TEST_SUITE_P(
    Blocks, SecondOrderNewtonRows,
    ::testing::Values(Case{"cholmod", true, false, true, true},   // IDA's use: p only
                      Case{"eigen-ldlt", true, true, false, true}, // ARKODE's use: m only
                      Case{"cholmod", true, true, true, false},
                      Case{"klu", false, false, true, true},       // fd-inertia: non-symmetric K and G
                      Case{"klu", false, true, true, true}));

TEST(SecondOrderNewton, RefusesSolveWithoutFactorizationAndNonPositiveGamma) {
  DofMap dofs(1);
  dofs.resolve(std::vector<DirectorChart>(1));
  SecondOrderNewton nw(full_pattern(dofs.num_dofs()), dofs, "klu");
  std::vector<double> b(5, 1.0), x(5), y(5);
  EXPECT_THROW(nw.solve(b.data(), nullptr, nullptr, x.data(), y.data()), std::logic_error);
  EXPECT_THROW(nw.factorize(0.0), std::invalid_argument);
  EXPECT_THROW(nw.factorize(-1.0), std::invalid_argument);
}

}  // namespace
}  // namespace shelldyn
