// A single-precision copy of a supernodal Cholesky factor, and the triangular solves with it
// (docs/dependencies.md §5.5).
//
// Why: with modified Newton the factorization of K̄ is kept for many steps (the pinched hemisphere's 10 000
// steps use one), so the triangular solves dominate the linear algebra, and they are bound by memory
// traffic, not arithmetic: the hemisphere's factor holds 0.61 million entries (4.9 MB), which the element
// loops between two solves push out of the caches. Stored in float it is half the bytes. The solve is then
// x̂ = (L̂ L̂ᵀ)⁻¹ b with L̂ = fl32(L): a perturbation of relative size ~6e-8 of a matrix that modified Newton
// already uses stale, so it changes the correction, not the converged iterate (the iteration stops on its own
// residual, computed in double). The arithmetic is double throughout; only the factor's entries are rounded.
//
// Layout: CHOLMOD's supernodal one (cholmod_core.h: super, pi, px, s, x) with its fill-reducing permutation
// (A = Pᵀ L Lᵀ P), copied from the arrays, so this header needs no CHOLMOD. Supernode s holds columns
// super[s] .. super[s+1]−1 as a dense column-major block whose rows are s[pi[s] .. pi[s+1]−1] (the first
// ncol of them are the block's own columns: the dense triangle L1, the rest the rectangle L2 below it),
// leading dimension pi[s+1] − pi[s], starting at x[px[s]].
//
// Threads (docs/dependencies.md §5.7): solve() splits the supernodal elimination tree once per factor into two groups of
// independent subtrees of balanced work and a top part (the ancestors: separators and the roots). The forward sweep
// runs each group on its own thread (the second group accumulates its updates of top-part rows in a private vector,
// added afterwards), then the top part's forward and backward sweeps run on one thread, then each group's backward
// sweep on its own thread (it reads only its own and top-part entries). The split depends on the factor's structure
// only, and the arithmetic does not depend on how many threads run it: one thread (--threads 1, or a call inside a
// parallel region) runs both groups in turn and gets the same bits as two. Compared with the plain sequential
// sweeps (solve(b, x, false), used when no split saves ≥ 10 % of the estimated work) only the top-part rows of the
// forward sweep are summed in another order: the results agree to round-off.
// Not thread-safe: solve() uses internal work buffers.
#pragma once

#include "lib/linalg/sparse_matrix.hpp"

#include <vector>

namespace shelldyn {

struct SupernodalArrays {  // views of a supernodal LLᵀ factor (CHOLMOD's names)
  Index n = 0, nsuper = 0;
  const Index* super = nullptr;  // nsuper + 1 column starts
  const Index* pi = nullptr;     // nsuper + 1 starts in s
  const Index* px = nullptr;     // nsuper + 1 starts in x
  const Index* s = nullptr;      // row indices
  const double* x = nullptr;     // values
  const Index* perm = nullptr;   // fill-reducing permutation (row k of L is row perm[k] of A); null: identity
};

// Real = float: the single-precision copy described above. Real = double: the same solves on an exact copy of the
// factor, used for solve_precision = double (docs/dependencies.md §5.5): on a small factor (the flying plate's,
// 735 unknowns) CHOLMOD's supernodal solve spends much of its time in per-supernode BLAS calls.
template <typename Real>
class SupernodalFactorCopy {
 public:
  using Arrays = SupernodalArrays;

  // Copies the structure and the values (rounded to Real). Returns false (and stays empty) if a value does not fit:
  // beyond Real's range (float: ~3.4e38), not finite, or a pivot that rounds to zero; the caller then keeps
  // CHOLMOD's own solves. Throws std::invalid_argument on inconsistent arrays.
  bool assign(const Arrays& a);
  bool empty() const { return n_ == 0; }
  void clear();

  // x = (P ᵀ L̂ L̂ᵀ P)⁻¹ b. x may alias b. split = false: the plain sequential sweeps (for comparisons).
  void solve(const double* b, double* x, bool split = true) const;

  // Estimated time of the split solve on two threads over the sequential one (work = factor entries touched;
  // 1 = no split), for benchmarks and tests.
  double split_estimate() const;
  static constexpr int kSplitGroups = 2;

 private:
  struct Block {
    Index col0, ncol, nrow;  // first column, columns, rows (ncol of them in the triangle)
    Index rows, vals;        // offsets into rows_ (of the nrow − ncol rows below the triangle) and values_
  };
  struct Split {  // one P-group split of the elimination tree (see above)
    int parts = 0;
    double estimate = 1.0;                       // max group work + top work, over the total
    std::vector<std::vector<Index>> ranges;      // per group: [first, last] block ranges (subtrees), ascending
    std::vector<Index> top;                      // top-part blocks, ascending
    std::vector<std::vector<double>> y, w;       // per group: private right-hand side (groups ≥ 1), block rows
  };
  const Split& split(int parts) const;
  void gather(const Block& bl, const double* y, double* w) const;
  void forward(const Block& bl, double* y, double* w) const;
  void backward(const Block& bl, double* y, double* w) const;
  void solve_split(const Split& sp, const double* b, double* x) const;

  Index n_ = 0;
  mutable Split split_;  // made at the first solve (parts = kSplitGroups)
  std::vector<Block> blocks_;
  std::vector<Index> rows_, perm_;
  std::vector<Real> values_;
  mutable std::vector<double> y_, w_;  // permuted right-hand side; one block's rows gathered
};

using SinglePrecisionFactor = SupernodalFactorCopy<float>;
using DoublePrecisionFactor = SupernodalFactorCopy<double>;

extern template class SupernodalFactorCopy<float>;
extern template class SupernodalFactorCopy<double>;

// Factors A (full CSC storage, symmetric positive definite) with CHOLMOD's supernodal LLᵀ as the "cholmod" back-end
// does (upper triangle, AMD, postordered) and copies the factor into out (lib/linalg/linear_solver.cpp). Returns false
// if A is not positive definite or a value does not fit Real. For tests and benchmarks of the solves.
template <typename Real>
bool copy_cholmod_factor(const CscView& A, SupernodalFactorCopy<Real>& out);

}  // namespace shelldyn
