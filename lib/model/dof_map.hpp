// Degrees of freedom: 5 per node, node-major, [d_X, d_Y, d_Z, q_1, q_2] (docs/theory.md §2.1),
// and Dirichlet constraints (docs/theory.md §2.3 item 2).
//
// Constraints are stored by meaning and resolved to DOF indices for the current director charts:
// fixing the director component p_k means fixing the q-entry that holds p_k, which moves when a chart
// switches (symmetry planes). All solvers work on the full system with constrained rows/columns
// replaced by identity, so the sparsity pattern never depends on the constraints.
#pragma once

#include "elements/director.hpp"
#include "lib/linalg/sparse_matrix.hpp"

#include <string>
#include <vector>

namespace shelldyn {

constexpr int kDofsPerNode = 5;

// What a constraint fixes at a node.
enum class Fix {
  Ux, Uy, Uz,     // one translation component
  Px, Py, Pz,     // one director component (must stay a minor component: symmetry planes, p_k = 0)
  Director        // both director unknowns (clamped edge: p fixed)
};

// Parses "ux", "uy", "uz", "px", "py", "pz", "director"; throws std::invalid_argument otherwise.
Fix parse_fix(const std::string& name);
const char* fix_name(Fix f);

class DofMap {
 public:
  explicit DofMap(int num_nodes);

  int num_nodes() const { return num_nodes_; }
  // 5 per node, then `extra` free unknowns (rigid bodies, lib/model/model_multibody.hpp) that no support fixes.
  Index num_dofs() const { return static_cast<Index>(num_nodes_) * kDofsPerNode + extra_; }
  Index num_extra() const { return extra_; }
  // Sets the number of extra unknowns; takes effect at the next resolve().
  void set_extra_dofs(Index extra) { extra_ = extra; }
  static Index dof(int node, int component) { return static_cast<Index>(node) * kDofsPerNode + component; }

  // Records a constraint; duplicates are ignored. Takes effect at the next resolve().
  void fix(int node, Fix what);

  // Maps the recorded constraints to DOF indices for these charts (one per node). Throws
  // std::runtime_error naming the node if a fixed director component is the chart's dependent one.
  void resolve(const std::vector<DirectorChart>& charts);

  bool is_constrained(Index dof) const { return constrained_mask_[static_cast<size_t>(dof)] != 0; }
  const std::vector<Index>& constrained_dofs() const { return constrained_; }  // sorted
  Index num_constrained() const { return static_cast<Index>(constrained_.size()); }
  Index num_free() const { return num_dofs() - num_constrained(); }
  // Position of a DOF in the numbering of free DOFs, or -1 if constrained.
  Index free_index(Index dof) const { return free_index_[static_cast<size_t>(dof)]; }

 private:
  struct Constraint {
    int node;
    Fix what;
  };
  int num_nodes_;
  Index extra_ = 0;
  std::vector<Constraint> constraints_;
  std::vector<char> constrained_mask_;
  std::vector<Index> constrained_;
  std::vector<Index> free_index_;
};

}  // namespace shelldyn
