// Sparse assembly against a dense reference (issue: foundation, item 6).
#include "lib/model/assembler.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <set>

namespace shelldyn {
namespace {

// nx × ny structured quad9 connectivity on a (2nx+1) × (2ny+1) node grid, Gmsh-10 order.
std::vector<Quad9> grid(int nx, int ny, int* num_nodes) {
  const int cols = 2 * nx + 1;
  *num_nodes = cols * (2 * ny + 1);
  std::vector<Quad9> els;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      auto id = [&](int di, int dj) { return (2 * j + dj) * cols + 2 * i + di; };
      els.push_back({id(0, 0), id(2, 0), id(2, 2), id(0, 2), id(1, 0), id(2, 1), id(1, 2), id(0, 1), id(1, 1)});
    }
  return els;
}

TEST(Assembler, PatternIsSortedUniqueAndSymmetric) {
  int nn = 0;
  const auto els = grid(3, 2, &nn);
  const Assembler asm_(els, nn);
  const auto& p = *asm_.pattern();
  ASSERT_EQ(p.n, nn * 5);
  for (Index c = 0; c < p.n; ++c) {
    for (Index k = p.colptr[c] + 1; k < p.colptr[c + 1]; ++k) EXPECT_LT(p.rowind[k - 1], p.rowind[k]);
    for (Index k = p.colptr[c]; k < p.colptr[c + 1]; ++k) EXPECT_GE(asm_.find(c, p.rowind[k]), 0);
  }
  // Corner node of the grid couples with the 9 nodes of its only element: 45 rows per column.
  EXPECT_EQ(p.colptr[1] - p.colptr[0], 45);
  // A node shared by two elements along an edge (mid-column edge node) couples with 15 nodes.
  EXPECT_EQ(p.colptr[5 * 2 + 1] - p.colptr[5 * 2], 15 * 5);
}

TEST(Assembler, MatchesDenseReferenceAssembly) {
  int nn = 0;
  const auto els = grid(3, 2, &nn);
  const Assembler asm_(els, nn);
  std::mt19937 gen(42);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const Index n = asm_.num_dofs();
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd fdense = Eigen::VectorXd::Zero(n);
  std::vector<double> values(static_cast<size_t>(asm_.pattern()->nnz()), 0.0);
  std::vector<double> f(static_cast<size_t>(n), 0.0);
  for (int e = 0; e < asm_.num_elements(); ++e) {
    ElementMatrix Ke;
    ElementVector fe;
    for (int i = 0; i < kElementDofs * kElementDofs; ++i) Ke.data()[i] = U(gen);
    for (int i = 0; i < kElementDofs; ++i) fe[i] = U(gen);
    asm_.add_matrix(e, Ke, values.data());
    asm_.add_vector(e, fe, f.data());
    const auto& d = asm_.element_dofs(e);
    for (int a = 0; a < kElementDofs; ++a) {
      fdense[d[a]] += fe[a];
      for (int b = 0; b < kElementDofs; ++b) dense(d[a], d[b]) += Ke(a, b);
    }
  }
  Eigen::MatrixXd from_sparse = Eigen::MatrixXd::Zero(n, n);
  const auto& p = *asm_.pattern();
  for (Index c = 0; c < n; ++c)
    for (Index k = p.colptr[c]; k < p.colptr[c + 1]; ++k) from_sparse(p.rowind[k], c) = values[k];
  EXPECT_LT((from_sparse - dense).norm(), 1e-13 * dense.norm());
  EXPECT_LT((Eigen::Map<Eigen::VectorXd>(f.data(), n) - fdense).norm(), 1e-14 * fdense.norm());

  // Matrix-vector product agrees with the dense one.
  Eigen::VectorXd x = Eigen::VectorXd::Random(n), y(n);
  multiply({p.n, p.colptr.data(), p.rowind.data(), values.data()}, x.data(), y.data());
  EXPECT_LT((y - dense * x).norm(), 1e-12 * (dense * x).norm());
}

TEST(Assembler, ColoursShareNoNodeAndCoverEveryElementOnce) {
  int nn = 0;
  const auto els = grid(4, 4, &nn);
  const Assembler asm_(els, nn);
  std::vector<int> seen(els.size(), 0);
  for (const auto& colour : asm_.colours()) {
    std::set<int> nodes;
    for (int e : colour) {
      ++seen[static_cast<size_t>(e)];
      for (int node : els[static_cast<size_t>(e)]) EXPECT_TRUE(nodes.insert(node).second) << "node " << node;
    }
  }
  for (int s : seen) EXPECT_EQ(s, 1);
  EXPECT_LE(asm_.colours().size(), 4u);  // a structured grid needs exactly 4 colours
}

TEST(Assembler, RejectsConnectivityOutsideTheNodeRange) {
  std::vector<Quad9> els = {{0, 1, 2, 3, 4, 5, 6, 7, 9}};
  EXPECT_THROW(Assembler(els, 9), std::invalid_argument);
}

TEST(Dirichlet, IdentityRowsKeepSymmetryAndPattern) {
  int nn = 0;
  const auto els = grid(2, 1, &nn);
  const Assembler asm_(els, nn);
  SparseMatrix A{asm_.pattern(), std::vector<double>(static_cast<size_t>(asm_.pattern()->nnz()), 0.0)};
  for (int e = 0; e < asm_.num_elements(); ++e) {
    ElementMatrix Ke = ElementMatrix::Random();
    Ke = (Ke + Ke.transpose()).eval();
    asm_.add_matrix(e, Ke, A.values.data());
  }
  DofMap dofs(nn);
  dofs.fix(0, Fix::Ux);
  dofs.fix(3, Fix::Director);
  dofs.resolve(std::vector<DirectorChart>(static_cast<size_t>(nn)));
  std::vector<double> rhs(static_cast<size_t>(asm_.num_dofs()), 1.0);
  apply_dirichlet(dofs, A, rhs.data());
  const auto& p = *A.pattern;
  for (Index c = 0; c < p.n; ++c)
    for (Index k = p.colptr[c]; k < p.colptr[c + 1]; ++k) {
      const Index r = p.rowind[k];
      const bool fixed = dofs.is_constrained(r) || dofs.is_constrained(c);
      if (fixed) {
        EXPECT_EQ(A.values[k], r == c ? 1.0 : 0.0);
      }
      EXPECT_EQ(A.values[k], A.values[asm_.find(c, r)]);  // still symmetric
    }
  EXPECT_EQ(rhs[0], 0.0);
  EXPECT_EQ(rhs[DofMap::dof(3, 3)], 0.0);
  EXPECT_EQ(rhs[DofMap::dof(3, 4)], 0.0);
  EXPECT_EQ(rhs[1], 1.0);
}

}  // namespace
}  // namespace shelldyn
