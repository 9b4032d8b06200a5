// Triangular solves with a float (or double) copy of a supernodal factor: lib/linalg/single_precision_factor.hpp.
#include "lib/linalg/single_precision_factor.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <numeric>
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
  split_ = Split{};
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

// A block's entries of y gathered into w: its own ncol columns, then the rows below the triangle, so that column j
// of the block (rows j..nrow−1, contiguous in the factor) meets w[j..nrow−1] contiguously.
template <typename Real>
void SupernodalFactorCopy<Real>::gather(const Block& bl, const double* y, double* w) const {
  const Index* rows = rows_.data() + bl.rows;
  std::copy(y + bl.col0, y + bl.col0 + bl.ncol, w);
  for (Index i = 0, below = bl.nrow - bl.ncol; i < below; ++i) w[bl.ncol + i] = y[rows[i]];
}

// Forward sweep of one block, L y = P b: columns in pairs: divide by the pivots, then one pass over the rows below
// that subtracts both columns' updates (half the loads and stores of w), so every entry receives its updates in
// column order, a pair at a time. (Pairing the backward dot products as well measured slower.)
template <typename Real>
void SupernodalFactorCopy<Real>::forward(const Block& bl, double* y, double* w) const {
  const Index* rows = rows_.data() + bl.rows;
  const Index below = bl.nrow - bl.ncol;
  gather(bl, y, w);
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
  for (Index i = 0; i < below; ++i) y[rows[i]] = w[bl.ncol + i];
}

// Backward sweep of one block, Lᵀ z = y; column j: one dot product with the rows below it.
template <typename Real>
void SupernodalFactorCopy<Real>::backward(const Block& bl, double* y, double* w) const {
  gather(bl, y, w);
  for (Index j = bl.ncol - 1; j >= 0; --j) {
    const Real* col = values_.data() + bl.vals + j * bl.nrow;
    w[j] = (w[j] - dot4(col + j + 1, w + j + 1, bl.nrow - j - 1)) / static_cast<double>(col[j]);
  }
  std::copy(w, w + bl.ncol, y + bl.col0);
}

// The split of the supernodal elimination tree (parent of a block: the block holding its first row below the
// triangle). Starting from the roots, the heaviest candidate subtree is moved to the top part and replaced by its
// children, and the candidates are dealt to the groups heaviest first (to the lightest group); the best estimate
// (heaviest group + top part) over these steps is kept. Needs CHOLMOD's postorder (a subtree is a contiguous block
// range); otherwise, or when the best estimate saves < 10 %, the split is empty (parts = 0).
template <typename Real>
const typename SupernodalFactorCopy<Real>::Split& SupernodalFactorCopy<Real>::split(int parts) const {
  if (split_.parts == parts || parts < 2) return split_;
  Split sp;
  sp.parts = parts;
  const Index nb = static_cast<Index>(blocks_.size());
  std::vector<Index> col_block(static_cast<size_t>(n_)), parent(static_cast<size_t>(nb), -1),
      first(static_cast<size_t>(nb)), count(static_cast<size_t>(nb), 1);
  std::vector<double> own(static_cast<size_t>(nb)), work(static_cast<size_t>(nb));
  std::vector<std::vector<Index>> children(static_cast<size_t>(nb));
  for (Index k = 0; k < nb; ++k)
    for (Index c = 0; c < blocks_[k].ncol; ++c) col_block[static_cast<size_t>(blocks_[k].col0 + c)] = k;
  bool postordered = true;
  for (Index k = 0; k < nb; ++k) {
    const Block& bl = blocks_[static_cast<size_t>(k)];
    own[k] = static_cast<double>(bl.nrow) * static_cast<double>(bl.ncol) + static_cast<double>(bl.nrow);
    work[k] += own[k];
    if (bl.nrow > bl.ncol) {
      Index r = rows_[static_cast<size_t>(bl.rows)];
      for (Index i = 1; i < bl.nrow - bl.ncol; ++i) r = std::min(r, rows_[static_cast<size_t>(bl.rows + i)]);
      const Index p = col_block[static_cast<size_t>(r)];
      if (p <= k) { postordered = false; break; }
      parent[k] = p;
      children[p].push_back(k);
    }
  }
  if (postordered) {  // subtree sizes, work and first block, children before parents
    for (Index k = 0; k < nb; ++k) first[k] = k;
    for (Index k = 0; k < nb; ++k) {
      const Index p = parent[k];
      if (p < 0) continue;
      work[p] += work[k];
      count[p] += count[k];
      first[p] = std::min(first[p], first[k]);
    }
    for (Index k = 0; k < nb && postordered; ++k) postordered = count[k] == k - first[k] + 1;
  }
  const double total = std::accumulate(own.begin(), own.end(), 0.0);
  if (!postordered || nb < 2 || total <= 0) {
    split_ = std::move(sp);
    return split_;
  }
  std::vector<Index> cand;
  for (Index k = 0; k < nb; ++k)
    if (parent[k] < 0) cand.push_back(k);
  double top = 0, best = total;
  std::vector<Index> best_cand;
  std::vector<int> best_group;
  for (Index step = 0; step < nb && top < best; ++step) {
    std::sort(cand.begin(), cand.end(), [&](Index a, Index b) { return work[a] > work[b] || (work[a] == work[b] && a < b); });
    std::vector<double> load(static_cast<size_t>(parts), 0.0);
    std::vector<int> group(cand.size());
    for (size_t c = 0; c < cand.size(); ++c) {
      const int g = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
      group[c] = g;
      load[static_cast<size_t>(g)] += work[cand[c]];
    }
    const double est = top + *std::max_element(load.begin(), load.end());
    if (est < best) {
      best = est;
      best_cand = cand;
      best_group = group;
    }
    const Index h = cand.front();
    if (children[h].empty()) break;
    cand.erase(cand.begin());
    top += own[h];
    cand.insert(cand.end(), children[h].begin(), children[h].end());
  }
  sp.estimate = best / total;
  if (sp.estimate > 0.9 || best_cand.empty()) {
    sp.estimate = 1.0;
    split_ = std::move(sp);
    return split_;
  }
  sp.ranges.assign(static_cast<size_t>(parts), {});
  std::vector<char> in_group(static_cast<size_t>(nb), 0);
  std::vector<std::vector<std::pair<Index, Index>>> r(static_cast<size_t>(parts));
  for (size_t c = 0; c < best_cand.size(); ++c) {
    const Index k = best_cand[c];
    r[static_cast<size_t>(best_group[c])].push_back({first[k], k});
    for (Index q = first[k]; q <= k; ++q) in_group[q] = 1;
  }
  for (int g = 0; g < parts; ++g) {
    std::sort(r[g].begin(), r[g].end());
    for (const auto& pr : r[g]) {
      sp.ranges[g].push_back(pr.first);
      sp.ranges[g].push_back(pr.second);
    }
  }
  for (Index k = 0; k < nb; ++k)
    if (!in_group[k]) sp.top.push_back(k);
  Index max_rows = 0;
  for (const Block& bl : blocks_) max_rows = std::max(max_rows, bl.nrow);
  sp.y.assign(static_cast<size_t>(parts), std::vector<double>());
  for (int g = 1; g < parts; ++g) sp.y[g].assign(static_cast<size_t>(n_), 0.0);
  sp.w.assign(static_cast<size_t>(parts), std::vector<double>(static_cast<size_t>(max_rows), 0.0));
  split_ = std::move(sp);
  return split_;
}

template <typename Real>
double SupernodalFactorCopy<Real>::split_estimate() const {
  if (n_ == 0) return 1.0;
  return split(kSplitGroups).estimate;
}

template <typename Real>
void SupernodalFactorCopy<Real>::solve(const double* b, double* x, bool split_solve) const {
  if (split_solve) {
    const Split& sp = split(kSplitGroups);
    if (!sp.ranges.empty()) {
      solve_split(sp, b, x);
      return;
    }
  }
  double* y = y_.data();
  double* w = w_.data();
  if (perm_.empty())
    std::copy(b, b + n_, y);
  else
    for (Index k = 0; k < n_; ++k) y[k] = b[perm_[k]];
  for (const Block& bl : blocks_) forward(bl, y, w);  // blocks in column order
  for (auto it = blocks_.rbegin(); it != blocks_.rend(); ++it) backward(*it, y, w);  // reverse order
  if (perm_.empty())
    std::copy(y, y + n_, x);
  else
    for (Index k = 0; k < n_; ++k) x[perm_[k]] = y[k];
}

template <typename Real>
void SupernodalFactorCopy<Real>::solve_split(const Split& sp, const double* b, double* x) const {
  double* y = y_.data();
  const int parts = sp.parts;
  auto& ys = const_cast<Split&>(sp).y;
  auto& ws = const_cast<Split&>(sp).w;
  auto load = [&](double* to, Index c0, Index c1) {
    if (perm_.empty())
      std::copy(b + c0, b + c1, to + c0);
    else
      for (Index k = c0; k < c1; ++k) to[k] = b[perm_[k]];
  };
  const int threads = omp_in_parallel() ? 1 : std::min(parts, omp_get_max_threads());
#pragma omp parallel num_threads(threads) if (threads > 1)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    for (int g = t; g < parts; g += nt) {  // the forward sweep of group g (g ≥ nt only with fewer threads)
      double* yg = g == 0 ? y : ys[static_cast<size_t>(g)].data();
      double* w = ws[static_cast<size_t>(g)].data();
      const auto& rg = sp.ranges[static_cast<size_t>(g)];
      for (size_t q = 0; q < rg.size(); q += 2)
        load(yg, blocks_[rg[q]].col0, blocks_[rg[q + 1]].col0 + blocks_[rg[q + 1]].ncol);
      for (Index k : sp.top) {
        const Block& bl = blocks_[static_cast<size_t>(k)];
        if (g == 0)
          load(y, bl.col0, bl.col0 + bl.ncol);
        else
          std::fill(yg + bl.col0, yg + bl.col0 + bl.ncol, 0.0);
      }
      for (size_t q = 0; q < rg.size(); q += 2)
        for (Index k = rg[q]; k <= rg[q + 1]; ++k) forward(blocks_[static_cast<size_t>(k)], yg, w);
      if (g != 0)
        for (size_t q = 0; q < rg.size(); q += 2) {
          const Index c0 = blocks_[rg[q]].col0, c1 = blocks_[rg[q + 1]].col0 + blocks_[rg[q + 1]].ncol;
          std::copy(yg + c0, yg + c1, y + c0);
        }
    }
#pragma omp barrier
#pragma omp single
    {  // the top part: the groups' updates of its rows in group order, then its forward and backward sweeps
      double* w = ws[0].data();
      for (Index k : sp.top) {
        const Block& bl = blocks_[static_cast<size_t>(k)];
        for (int g = 1; g < parts; ++g) {
          const double* yg = ys[static_cast<size_t>(g)].data();
          for (Index c = bl.col0; c < bl.col0 + bl.ncol; ++c) y[c] += yg[c];
        }
      }
      for (Index k : sp.top) forward(blocks_[static_cast<size_t>(k)], y, w);
      for (auto it = sp.top.rbegin(); it != sp.top.rend(); ++it) backward(blocks_[static_cast<size_t>(*it)], y, w);
    }  // implicit barrier
    for (int g = t; g < parts; g += nt) {  // the backward sweep of group g
      double* w = ws[static_cast<size_t>(g)].data();
      const auto& rg = sp.ranges[static_cast<size_t>(g)];
      for (size_t q = rg.size(); q >= 2; q -= 2)
        for (Index k = rg[q - 1]; k >= rg[q - 2]; --k) backward(blocks_[static_cast<size_t>(k)], y, w);
    }
#pragma omp barrier
    if (perm_.empty()) {
#pragma omp for schedule(static)
      for (Index k = 0; k < n_; ++k) x[k] = y[k];
    } else {
#pragma omp for schedule(static)
      for (Index k = 0; k < n_; ++k) x[perm_[k]] = y[k];
    }
  }
}

template class SupernodalFactorCopy<float>;
template class SupernodalFactorCopy<double>;

}  // namespace shelldyn
