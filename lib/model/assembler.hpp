// Sparse assembly on one fixed CSC pattern (architecture.md §4.2, §6).
//
// The pattern (all 5 DOFs of all nodes that share an element couple) is computed once from the
// connectivity; for every element a scatter map stores where each of its 45×45 entries lands in the
// values array, so assembly is a gather/scatter with no search and no allocation. Elements are also
// grouped into colours (no two elements of a colour share a node), so a colour can be assembled in
// parallel without write conflicts.
//
// Owns: the pattern (shared, immutable), the scatter maps and the colouring. Does not own values.
#pragma once

#include "lib/model/dof_map.hpp"
#include "lib/mesh/mesh.hpp"
#include "lib/linalg/sparse_matrix.hpp"

#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

namespace shelldyn {

constexpr int kElementDofs = 9 * kDofsPerNode;  // 45
using ElementVector = Eigen::Matrix<double, kElementDofs, 1>;
using ElementMatrix = Eigen::Matrix<double, kElementDofs, kElementDofs>;

class Assembler {
 public:
  // extra_dofs unknowns follow the 5 per node (rigid bodies); `couplings` are groups of DOFs whose entries all
  // couple (constraint tangents, body mass blocks: lib/model/model_multibody.hpp). Without either, the pattern is
  // the element pattern alone.
  Assembler(const std::vector<Quad9>& elements, int num_nodes, Index extra_dofs = 0,
            const std::vector<std::vector<Index>>& couplings = {});

  std::shared_ptr<const SparsePattern> pattern() const { return pattern_; }
  Index num_dofs() const { return pattern_->n; }
  int num_elements() const { return static_cast<int>(dofs_.size()); }

  // Global DOF indices of element e, node-major (docs/theory.md §1 DOF order).
  const std::array<Index, kElementDofs>& element_dofs(int e) const { return dofs_[static_cast<size_t>(e)]; }

  // values[...] += Ke at the pattern positions of element e (values has pattern()->nnz() entries).
  void add_matrix(int e, const ElementMatrix& Ke, double* values) const;
  // global[dof] += fe.
  void add_vector(int e, const ElementVector& fe, double* global) const;
  // ue = global[element dofs].
  void gather(int e, const double* global, ElementVector& ue) const;

  // Element colours: every colour is a list of elements that share no node.
  const std::vector<std::vector<int>>& colours() const { return colours_; }

  // Position of entry (row, col) in the values array, or -1 if outside the pattern.
  Index find(Index row, Index col) const;

 private:
  std::shared_ptr<SparsePattern> pattern_;
  std::vector<std::array<Index, kElementDofs>> dofs_;
  std::vector<Index> scatter_;  // kElementDofs² positions per element, column-major like Eigen
  std::vector<std::vector<int>> colours_;
};

// Replaces constrained rows and columns by those of the identity (diagonal = `diagonal`), keeping the
// pattern and the symmetry; the matching right-hand-side entries are set to zero when rhs != nullptr.
void apply_dirichlet(const DofMap& dofs, SparseMatrix& A, double* rhs, double diagonal = 1.0);
// Sets the constrained entries of a global vector to zero.
void zero_constrained(const DofMap& dofs, double* v);

// y = A x for a full-storage CSC matrix.
void multiply(const CscView& A, const double* x, double* y);

}  // namespace shelldyn
