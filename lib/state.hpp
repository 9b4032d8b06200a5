// The state of the semi-discrete shell at one instant (architecture.md §4.1).
//
// u holds, per node, [d_X, d_Y, d_Z, q_1, q_2]: translations from the initial position and the two
// minor components of the unit nodal director in that node's chart (docs/theory.md §2.1); v = u̇ and
// a = ü are the rates of the same unknowns. The charts change only between steps (Model::rechart),
// which rewrites the rotational entries of u, v, a so that p, ṗ, p̈ are unchanged.
#pragma once

#include "elements/director.hpp"

#include <Eigen/Core>
#include <vector>

namespace shelldyn {

struct State {
  double t = 0.0;
  Eigen::VectorXd u, v, a;
  std::vector<DirectorChart> charts;
};

}  // namespace shelldyn
