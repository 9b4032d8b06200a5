#include "lib/model/assembler.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace shelldyn {

Assembler::Assembler(const std::vector<Quad9>& elements, int num_nodes, Index extra_dofs,
                     const std::vector<std::vector<Index>>& couplings) {
  const Index n_shell = static_cast<Index>(num_nodes) * kDofsPerNode;
  const Index n = n_shell + extra_dofs;
  dofs_.resize(elements.size());
  for (size_t e = 0; e < elements.size(); ++e) {
    for (int a = 0; a < 9; ++a) {
      const int node = elements[e][static_cast<size_t>(a)];
      if (node < 0 || node >= num_nodes)
        throw std::invalid_argument("Assembler: element " + std::to_string(e) + " references node " +
                                    std::to_string(node) + ", outside [0, " + std::to_string(num_nodes) + ")");
      for (int c = 0; c < kDofsPerNode; ++c)
        dofs_[e][static_cast<size_t>(a * kDofsPerNode + c)] = DofMap::dof(node, c);
    }
  }

  // Node-level adjacency (nodes sharing an element), then expand to 5×5 DOF blocks. Building at node
  // level keeps the sort cost 25× smaller than sorting DOF pairs.
  std::vector<std::vector<int>> node_adj(static_cast<size_t>(num_nodes));
  for (const auto& el : elements)
    for (int a : el)
      for (int b : el) node_adj[static_cast<size_t>(a)].push_back(b);
  for (auto& adj : node_adj) {
    std::sort(adj.begin(), adj.end());
    adj.erase(std::unique(adj.begin(), adj.end()), adj.end());
  }

  pattern_ = std::make_shared<SparsePattern>();
  pattern_->n = n;
  pattern_->colptr.assign(static_cast<size_t>(n) + 1, 0);
  for (int node = 0; node < num_nodes; ++node) {
    const Index col_len = static_cast<Index>(node_adj[static_cast<size_t>(node)].size()) * kDofsPerNode;
    for (int c = 0; c < kDofsPerNode; ++c) {
      const Index col = DofMap::dof(node, c);
      pattern_->colptr[static_cast<size_t>(col) + 1] = pattern_->colptr[static_cast<size_t>(col)] + col_len;
    }
  }
  for (Index col = n_shell; col < n; ++col) pattern_->colptr[static_cast<size_t>(col) + 1] = pattern_->colptr[static_cast<size_t>(col)];
  pattern_->rowind.resize(static_cast<size_t>(pattern_->colptr.back()));
  for (int node = 0; node < num_nodes; ++node) {
    for (int c = 0; c < kDofsPerNode; ++c) {
      Index pos = pattern_->colptr[static_cast<size_t>(DofMap::dof(node, c))];
      for (int other : node_adj[static_cast<size_t>(node)])
        for (int r = 0; r < kDofsPerNode; ++r) pattern_->rowind[static_cast<size_t>(pos++)] = DofMap::dof(other, r);
    }
  }

  if (!couplings.empty()) {  // merge the coupling groups' entries column by column
    std::vector<std::vector<Index>> extra(static_cast<size_t>(n));
    for (const auto& g : couplings)
      for (Index c : g) {
        if (c < 0 || c >= n) throw std::invalid_argument("Assembler: coupling on DOF " + std::to_string(c) + " outside the system");
        for (Index r : g) extra[static_cast<size_t>(c)].push_back(r);
      }
    auto merged = std::make_shared<SparsePattern>();
    merged->n = n;
    merged->colptr.assign(static_cast<size_t>(n) + 1, 0);
    std::vector<Index> rows;
    for (Index col = 0; col < n; ++col) {
      rows.assign(pattern_->rowind.begin() + pattern_->colptr[static_cast<size_t>(col)],
                  pattern_->rowind.begin() + pattern_->colptr[static_cast<size_t>(col) + 1]);
      rows.insert(rows.end(), extra[static_cast<size_t>(col)].begin(), extra[static_cast<size_t>(col)].end());
      std::sort(rows.begin(), rows.end());
      rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
      merged->rowind.insert(merged->rowind.end(), rows.begin(), rows.end());
      merged->colptr[static_cast<size_t>(col) + 1] = static_cast<Index>(merged->rowind.size());
    }
    pattern_ = std::move(merged);
  }

  // Scatter maps: position of (row a, col b) of every element block, stored column-major.
  scatter_.resize(elements.size() * kElementDofs * kElementDofs);
  for (size_t e = 0; e < elements.size(); ++e) {
    Index* out = &scatter_[e * kElementDofs * kElementDofs];
    for (int b = 0; b < kElementDofs; ++b)
      for (int a = 0; a < kElementDofs; ++a) out[b * kElementDofs + a] = find(dofs_[e][a], dofs_[e][b]);
  }

  // Greedy colouring: an element takes the first colour none of whose elements shares a node with it.
  std::vector<std::vector<int>> node_colours(static_cast<size_t>(num_nodes));
  for (size_t e = 0; e < elements.size(); ++e) {
    int colour = 0;
    for (;; ++colour) {
      bool clash = false;
      for (int node : elements[e]) {
        const auto& used = node_colours[static_cast<size_t>(node)];
        if (std::find(used.begin(), used.end(), colour) != used.end()) { clash = true; break; }
      }
      if (!clash) break;
    }
    if (colour >= static_cast<int>(colours_.size())) colours_.resize(static_cast<size_t>(colour) + 1);
    colours_[static_cast<size_t>(colour)].push_back(static_cast<int>(e));
    for (int node : elements[e]) node_colours[static_cast<size_t>(node)].push_back(colour);
  }
}

Index Assembler::find(Index row, Index col) const {
  if (row < 0 || col < 0 || row >= pattern_->n || col >= pattern_->n) return -1;
  const auto first = pattern_->rowind.begin() + pattern_->colptr[static_cast<size_t>(col)];
  const auto last = pattern_->rowind.begin() + pattern_->colptr[static_cast<size_t>(col) + 1];
  const auto it = std::lower_bound(first, last, row);
  return (it != last && *it == row) ? static_cast<Index>(it - pattern_->rowind.begin()) : -1;
}

void Assembler::add_matrix(int e, const ElementMatrix& Ke, double* values) const {
  const Index* pos = &scatter_[static_cast<size_t>(e) * kElementDofs * kElementDofs];
  const double* k = Ke.data();  // column-major, same order as the scatter map
  for (int i = 0; i < kElementDofs * kElementDofs; ++i) values[pos[i]] += k[i];
}

void Assembler::add_vector(int e, const ElementVector& fe, double* global) const {
  const auto& d = dofs_[static_cast<size_t>(e)];
  for (int a = 0; a < kElementDofs; ++a) global[d[static_cast<size_t>(a)]] += fe[a];
}

void Assembler::gather(int e, const double* global, ElementVector& ue) const {
  const auto& d = dofs_[static_cast<size_t>(e)];
  for (int a = 0; a < kElementDofs; ++a) ue[a] = global[d[static_cast<size_t>(a)]];
}

void apply_dirichlet(const DofMap& dofs, SparseMatrix& A, double* rhs, double diagonal) {
  const SparsePattern& p = *A.pattern;
  for (Index col = 0; col < p.n; ++col) {
    const bool col_fixed = dofs.is_constrained(col);
    for (Index k = p.colptr[static_cast<size_t>(col)]; k < p.colptr[static_cast<size_t>(col) + 1]; ++k) {
      const Index row = p.rowind[static_cast<size_t>(k)];
      if (col_fixed || dofs.is_constrained(row)) A.values[static_cast<size_t>(k)] = (row == col) ? diagonal : 0.0;
    }
  }
  if (rhs) zero_constrained(dofs, rhs);
}

void zero_constrained(const DofMap& dofs, double* v) {
  for (Index d : dofs.constrained_dofs()) v[d] = 0.0;
}

void multiply(const CscView& A, const double* x, double* y) {
  std::fill(y, y + A.n, 0.0);
  for (Index col = 0; col < A.n; ++col)
    for (Index k = A.colptr[col]; k < A.colptr[col + 1]; ++k) y[A.rowind[k]] += A.values[k] * x[col];
}

}  // namespace shelldyn
