// Test matrices with the sparsity of a 9-node shell mesh, for the linear-solver tests (tests/lib).
#pragma once

#include "lib/linalg/sparse_matrix.hpp"

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

namespace shelldyn::test {

// ne × ne mesh of 9-node elements, 5 DOFs per node, per element a random SPD block B Bᵀ/45 + 0.01 I, plus
// diagonal_shift on the diagonal; full symmetric CSC storage (sorted, no duplicates).
inline SparseMatrix shell_like_matrix(int ne, unsigned seed, double diagonal_shift = 0.0) {
  const int nn = 2 * ne + 1;
  const Index n = Index(nn) * nn * 5;
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Triplet<double, Index>> trip;
  for (int ey = 0; ey < ne; ++ey)
    for (int ex = 0; ex < ne; ++ex) {
      std::vector<Index> dofs;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          for (int c = 0; c < 5; ++c) dofs.push_back((Index(2 * ey + a) * nn + (2 * ex + b)) * 5 + c);
      Eigen::MatrixXd B(45, 45);
      for (int i = 0; i < 45; ++i)
        for (int j = 0; j < 45; ++j) B(i, j) = normal(rng);
      const Eigen::MatrixXd Ke = B * B.transpose() / 45.0 + 0.01 * Eigen::MatrixXd::Identity(45, 45);
      for (int i = 0; i < 45; ++i)
        for (int j = 0; j < 45; ++j) trip.emplace_back(dofs[i], dofs[j], Ke(i, j));
    }
  if (diagonal_shift != 0.0)
    for (Index i = 0; i < n; ++i) trip.emplace_back(i, i, diagonal_shift);
  Eigen::SparseMatrix<double, Eigen::ColMajor, Index> A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  A.makeCompressed();
  auto pattern = std::make_shared<SparsePattern>();
  pattern->n = n;
  pattern->colptr.assign(A.outerIndexPtr(), A.outerIndexPtr() + n + 1);
  pattern->rowind.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
  SparseMatrix M;
  M.pattern = pattern;
  M.values.assign(A.valuePtr(), A.valuePtr() + A.nonZeros());
  return M;
}

// ‖A x − b‖₂ / ‖b‖₂ using the full storage.
inline double relative_residual(const CscView& A, const std::vector<double>& x, const std::vector<double>& b) {
  std::vector<double> r(b.begin(), b.end());
  for (Index j = 0; j < A.n; ++j)
    for (Index p = A.colptr[j]; p < A.colptr[j + 1]; ++p) r[A.rowind[p]] -= A.values[p] * x[j];
  double rr = 0, bb = 0;
  for (size_t i = 0; i < b.size(); ++i) rr += r[i] * r[i], bb += b[i] * b[i];
  return std::sqrt(rr / bb);
}

}  // namespace shelldyn::test
