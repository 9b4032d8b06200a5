// Triangular solves with a float (or double) copy of a supernodal factor: lib/linalg/single_precision_factor.hpp.
#include "lib/linalg/single_precision_factor.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace shelldyn {

template <typename Real>
void SupernodalFactorCopy<Real>::clear() {
  n_ = 0;
  blocks_.clear();
  rows_.clear();
  perm_.clear();
  values_.clear();
}

template <typename Real>
bool SupernodalFactorCopy<Real>::assign(const Arrays& a) {
  clear();
  if (a.n <= 0 || a.nsuper <= 0 || !a.super || !a.pi || !a.px || !a.s || !a.x)
    throw std::invalid_argument("SupernodalFactorCopy: empty or incomplete supernodal factor");
  if (a.super[0] != 0 || a.super[a.nsuper] != a.n)
    throw std::invalid_argument("SupernodalFactorCopy: supernode columns do not cover 0.." + std::to_string(a.n - 1));
  blocks_.reserve(static_cast<size_t>(a.nsuper));
  Index max_rows = 0;
  for (Index k = 0; k < a.nsuper; ++k) {
    const Index ncol = a.super[k + 1] - a.super[k], nrow = a.pi[k + 1] - a.pi[k];
    if (ncol <= 0 || nrow < ncol || a.px[k + 1] - a.px[k] < nrow * ncol)
      throw std::invalid_argument("SupernodalFactorCopy: supernode " + std::to_string(k) + " has an inconsistent shape");
    Block b{a.super[k], ncol, nrow, static_cast<Index>(rows_.size()), static_cast<Index>(values_.size())};
    for (Index p = a.pi[k] + ncol; p < a.pi[k + 1]; ++p) {
      if (a.s[p] < 0 || a.s[p] >= a.n) throw std::invalid_argument("SupernodalFactorCopy: row index out of range");
      rows_.push_back(a.s[p]);
    }
    // The block's ncol columns of nrow entries each (CHOLMOD may pad px; the padding is not copied).
    values_.insert(values_.end(), a.x + a.px[k], a.x + a.px[k] + nrow * ncol);
    for (Index p = b.vals; p < b.vals + nrow * ncol; ++p)
      if (!std::isfinite(values_[static_cast<size_t>(p)])) {
        clear();
        return false;
      }
    for (Index j = 0; j < ncol; ++j)
      if (values_[static_cast<size_t>(b.vals + j * nrow + j)] == Real(0)) {
        clear();
        return false;
      }
    blocks_.push_back(b);
    max_rows = std::max(max_rows, nrow);
  }
  if (a.perm) perm_.assign(a.perm, a.perm + a.n);
  n_ = a.n;
  y_.assign(static_cast<size_t>(n_), 0.0);
  w_.assign(static_cast<size_t>(max_rows), 0.0);
  return true;
}

namespace {
// Σ a_i w_i with four partial sums in a fixed pattern (i mod 4), combined as (s0 + s1) + (s2 + s3): the same
// value whatever the compiler vectorizes, and no serial chain of additions.
template <typename Real>
inline double dot4(const Real* a, const double* w, Index n) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  Index i = 0;
  for (; i + 4 <= n; i += 4) {
    s0 += static_cast<double>(a[i]) * w[i];
    s1 += static_cast<double>(a[i + 1]) * w[i + 1];
    s2 += static_cast<double>(a[i + 2]) * w[i + 2];
    s3 += static_cast<double>(a[i + 3]) * w[i + 3];
  }
  if (i < n) s0 += static_cast<double>(a[i]) * w[i];
  if (i + 1 < n) s1 += static_cast<double>(a[i + 1]) * w[i + 1];
  if (i + 2 < n) s2 += static_cast<double>(a[i + 2]) * w[i + 2];
  return (s0 + s1) + (s2 + s3);
}
}  // namespace

template <typename Real>
void SupernodalFactorCopy<Real>::solve(const double* b, double* x) const {
  double* y = y_.data();
  double* w = w_.data();
  if (perm_.empty())
    std::copy(b, b + n_, y);
  else
    for (Index k = 0; k < n_; ++k) y[k] = b[perm_[k]];

  // A block's entries of y are gathered into w: its own ncol columns, then the rows below the triangle, so that
  // column j of the block (rows j..nrow−1, contiguous in the factor) meets w[j..nrow−1] contiguously.
  auto gather = [&](const Block& bl) {
    std::copy(y + bl.col0, y + bl.col0 + bl.ncol, w);
    const Index* rows = rows_.data() + bl.rows;
    for (Index i = 0, below = bl.nrow - bl.ncol; i < below; ++i) w[bl.ncol + i] = y[rows[i]];
  };

  // Forward, L y = P b, blocks in column order; columns in pairs: divide by the pivots, then one pass over the rows
  // below that subtracts both columns' updates (half the loads and stores of w), so every entry receives its updates
  // in column order, a pair at a time. (Pairing the backward dot products as well measured slower.)
  for (const Block& bl : blocks_) {
    gather(bl);
    const Real* col = values_.data() + bl.vals;
    Index j = 0;
    for (; j + 1 < bl.ncol; j += 2, col += 2 * bl.nrow) {  // two columns per pass over the rows below
      const Real* col1 = col + bl.nrow;
      const double wj = w[j] / static_cast<double>(col[j]);
      w[j] = wj;
      const double wj1 = (w[j + 1] - static_cast<double>(col[j + 1]) * wj) / static_cast<double>(col1[j + 1]);
      w[j + 1] = wj1;
      for (Index i = j + 2; i < bl.nrow; ++i)
        w[i] -= static_cast<double>(col[i]) * wj + static_cast<double>(col1[i]) * wj1;
    }
    if (j < bl.ncol) {
      const double wj = w[j] / static_cast<double>(col[j]);
      w[j] = wj;
      for (Index i = j + 1; i < bl.nrow; ++i) w[i] -= static_cast<double>(col[i]) * wj;
    }
    std::copy(w, w + bl.ncol, y + bl.col0);
    const Index* rows = rows_.data() + bl.rows;
    for (Index i = 0, below = bl.nrow - bl.ncol; i < below; ++i) y[rows[i]] = w[bl.ncol + i];
  }

  // Backward, Lᵀ z = y, blocks in reverse order; column j: one dot product with the rows below it.
  for (auto it = blocks_.rbegin(); it != blocks_.rend(); ++it) {
    const Block& bl = *it;
    gather(bl);
    for (Index j = bl.ncol - 1; j >= 0; --j) {
      const Real* col = values_.data() + bl.vals + j * bl.nrow;
      w[j] = (w[j] - dot4(col + j + 1, w + j + 1, bl.nrow - j - 1)) / static_cast<double>(col[j]);
    }
    std::copy(w, w + bl.ncol, y + bl.col0);
  }

  if (perm_.empty())
    std::copy(y, y + n_, x);
  else
    for (Index k = 0; k < n_; ++k) x[perm_[k]] = y[k];
}

template class SupernodalFactorCopy<float>;
template class SupernodalFactorCopy<double>;

}  // namespace shelldyn
