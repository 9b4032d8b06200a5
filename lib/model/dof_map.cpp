#include "lib/model/dof_map.hpp"

#include <algorithm>
#include <stdexcept>

namespace shelldyn {

Fix parse_fix(const std::string& name) {
  static const std::pair<const char*, Fix> table[] = {{"ux", Fix::Ux}, {"uy", Fix::Uy}, {"uz", Fix::Uz},
                                                      {"px", Fix::Px}, {"py", Fix::Py}, {"pz", Fix::Pz},
                                                      {"director", Fix::Director}};
  for (const auto& [key, value] : table)
    if (name == key) return value;
  throw std::invalid_argument("unknown constraint '" + name +
                              "' (valid: ux, uy, uz, px, py, pz, director)");
}

const char* fix_name(Fix f) {
  switch (f) {
    case Fix::Ux: return "ux";
    case Fix::Uy: return "uy";
    case Fix::Uz: return "uz";
    case Fix::Px: return "px";
    case Fix::Py: return "py";
    case Fix::Pz: return "pz";
    case Fix::Director: return "director";
  }
  return "?";
}

DofMap::DofMap(int num_nodes) : num_nodes_(num_nodes) {
  if (num_nodes < 0) throw std::invalid_argument("DofMap: negative number of nodes");
  resolve({});
}

void DofMap::fix(int node, Fix what) {
  if (node < 0 || node >= num_nodes_)
    throw std::out_of_range("DofMap::fix: node " + std::to_string(node) + " out of range [0, " +
                            std::to_string(num_nodes_) + ")");
  for (const auto& c : constraints_)
    if (c.node == node && c.what == what) return;
  constraints_.push_back({node, what});
}

void DofMap::resolve(const std::vector<DirectorChart>& charts) {
  const auto n = static_cast<size_t>(num_dofs());
  constrained_mask_.assign(n, 0);
  for (const auto& c : constraints_) {
    switch (c.what) {
      case Fix::Ux:
      case Fix::Uy:
      case Fix::Uz:
        constrained_mask_[static_cast<size_t>(dof(c.node, static_cast<int>(c.what)))] = 1;
        break;
      case Fix::Director:  // both minor components fixed => p fixed (docs/theory.md §2.3, clamped)
        constrained_mask_[static_cast<size_t>(dof(c.node, 3))] = 1;
        constrained_mask_[static_cast<size_t>(dof(c.node, 4))] = 1;
        break;
      case Fix::Px:
      case Fix::Py:
      case Fix::Pz: {
        // Symmetry plane with normal e_k: fix the q-entry holding p_k (docs/theory.md §2.3 item 2).
        // The slot depends on the node's chart, hence resolution per chart set.
        if (charts.size() != static_cast<size_t>(num_nodes_))
          throw std::logic_error("DofMap::resolve: director-component constraints need one chart per node");
        const int k = static_cast<int>(c.what) - static_cast<int>(Fix::Px);
        const DirectorChart& ch = charts.at(static_cast<size_t>(c.node));
        int slot = -1;
        if (ch.n == k) slot = 3;
        if (ch.m == k) slot = 4;
        if (slot < 0)
          throw std::runtime_error("node " + std::to_string(c.node) + ": director component " +
                                   fix_name(c.what) +
                                   " is fixed but is the node's dependent (largest) component; a "
                                   "fixed director component must be zero (symmetry plane)");
        constrained_mask_[static_cast<size_t>(dof(c.node, slot))] = 1;
        break;
      }
    }
  }
  constrained_.clear();
  free_index_.assign(n, -1);
  Index next = 0;
  for (size_t i = 0; i < n; ++i) {
    if (constrained_mask_[i])
      constrained_.push_back(static_cast<Index>(i));
    else
      free_index_[i] = next++;
  }
}

}  // namespace shelldyn
