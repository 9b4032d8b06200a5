// The state of the semi-discrete shell at one instant (architecture.md §4.1).
//
// u holds, per node, [d_X, d_Y, d_Z, q_1, q_2]: translations from the initial position and the two
// minor components of the unit nodal director in that node's chart (docs/theory.md §2.1); v = u̇ and
// a = ü are the rates of the same unknowns. The charts change only between steps (Model::rechart),
// which rewrites the rotational entries of u, v, a so that p, ṗ, p̈ are unchanged.
//
// pdot (empty unless the integrator uses embedded director velocities, e.g. em-exact): one 3-vector w_i per
// node, the director velocity in ℝ³ of docs/theory/exact-energy-momentum.md §2. It is not tied to q̇ (it may
// have a component along p_i) and is unchanged by chart switches. When present, Model::invariants() takes
// the kinetic energy and the momenta from (v_d, pdot) instead of (v_d, A1 q̇), so that the reported K, L, J
// are the quantities the scheme conserves.
#pragma once

#include "elements/director.hpp"

#include <Eigen/Core>
#include <vector>

namespace shelldyn {

struct State {
  double t = 0.0;
  Eigen::VectorXd u, v, a;
  Eigen::VectorXd pdot;  // embedded director velocities (3 per node) or empty
  std::vector<DirectorChart> charts;
};

}  // namespace shelldyn
