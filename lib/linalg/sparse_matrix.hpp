// Compressed sparse column storage with 64-bit indices (= SUNDIALS' sunindextype on Debian 12,
// docs/dependencies.md §2.3), so that arrays can be handed to KLU (klu_l_*), CHOLMOD (cholmod_l_*), Eigen
// (StorageIndex = int64_t) and SUNSparseMatrix without copies.
//
// Contract: square, full symmetric storage (both triangles), row indices sorted within each column,
// no duplicates. The pattern is computed once per run and never changes; only values change.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

namespace shelldyn {

using Index = std::int64_t;

struct SparsePattern {
  Index n = 0;
  std::vector<Index> colptr;  // size n + 1
  std::vector<Index> rowind;  // size colptr[n]
  Index nnz() const { return colptr.empty() ? 0 : colptr.back(); }
};

// Non-owning view of a CSC matrix, the currency of the linear-solver back-ends.
struct CscView {
  Index n = 0;
  const Index* colptr = nullptr;
  const Index* rowind = nullptr;
  const double* values = nullptr;
  Index nnz() const { return colptr ? colptr[n] : 0; }
};

// A matrix on a shared, fixed pattern.
struct SparseMatrix {
  std::shared_ptr<const SparsePattern> pattern;
  std::vector<double> values;  // size pattern->nnz()

  CscView view() const {
    return {pattern->n, pattern->colptr.data(), pattern->rowind.data(), values.data()};
  }
  void set_zero() { std::fill(values.begin(), values.end(), 0.0); }
};

}  // namespace shelldyn
