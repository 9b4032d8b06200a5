// Reactions at constrained DOFs (docs/theory.md §9.2); see lib/model/reactions.hpp.
#include "lib/model/reactions.hpp"

namespace shelldyn {

Eigen::VectorXd reactions(const Model& model, const State& s, bool dynamic) {
  const Index n = model.num_dofs();
  Eigen::VectorXd r(n), f(n);
  model.internal(s.u, s.charts, r.data(), nullptr);
  model.external(s.t, s.u, s.charts, f.data());
  r -= f;
  if (dynamic) {
    model.inertia_force(s.u, s.v, s.a, s.charts, f.data());
    r += f;
  }
  Eigen::VectorXd out = Eigen::VectorXd::Zero(n);
  for (Index dof : model.dofs().constrained_dofs()) out[dof] = r[dof];
  return out;
}

Vec3 translational_sum(const Eigen::VectorXd& global, const std::vector<int>& nodes, int num_nodes) {
  Vec3 s = Vec3::Zero();
  if (nodes.empty()) {
    for (int i = 0; i < num_nodes; ++i) s += global.segment<3>(DofMap::dof(i, 0));
  } else {
    for (int i : nodes) s += global.segment<3>(DofMap::dof(i, 0));
  }
  return s;
}

}  // namespace shelldyn
