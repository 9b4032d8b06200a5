// Reaction forces at constrained DOFs (docs/theory.md §9.2).
//
// R = F_int − F_ext (static: the state's t is the load factor) or R = M a + F_m + F_int − F_ext
// (dynamic; F_m includes Rayleigh damping), kept at constrained DOFs and set to zero at free DOFs,
// where it vanishes to solver tolerance anyway. R is the force the supports exert on the shell, so at
// equilibrium Σ R + Σ F_ext = 0 over the translations (internal forces have zero resultant).
#pragma once

#include "lib/model/model.hpp"

#include <Eigen/Core>
#include <vector>

namespace shelldyn {

Eigen::VectorXd reactions(const Model& model, const State& s, bool dynamic);

// Σ of the translational components of a global 5-per-node vector over `nodes` (all nodes if empty).
Vec3 translational_sum(const Eigen::VectorXd& global, const std::vector<int>& nodes, int num_nodes);

}  // namespace shelldyn
