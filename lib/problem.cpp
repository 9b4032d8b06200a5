#include "lib/problem.hpp"

#include <stdexcept>

namespace shelldyn {

ShellMaterial shell_material(const CaseMaterial& m) {
  ShellMaterial s{m.E, m.nu, m.rho, m.thickness};
  s.shear_factor = m.shear_factor;
  return s;
}

Model make_model(const Discretization& d, const CaseMaterial& material) {
  std::vector<NodalLoad> loads;
  loads.reserve(d.loads.size());
  for (const auto& l : d.loads) {
    NodalLoad nl;
    nl.node = l.node;
    nl.kind = (l.type == LoadType::Moment) ? NodalLoad::Kind::Moment : NodalLoad::Kind::Force;
    nl.vector = l.vector;
    nl.function = l.function;
    loads.push_back(nl);
  }
  Model model(d.mesh, d.normals, shell_material(material), d.dofs, std::move(loads));
  model.set_follower_pressures(d.follower_pressures);
  return model;
}

State Problem::initial_state() const {
  State s = model->initial_state();
  if (disc.initial_velocity.size() == s.v.size()) s.v = disc.initial_velocity;
  return s;
}

Problem make_problem(CaseSpec spec) {
  Problem p;
  p.spec = std::move(spec);
  p.disc = build_discretization(p.spec);
  try {
    p.model = std::make_unique<Model>(make_model(p.disc, p.spec.material));
    p.model->set_rayleigh_damping(p.spec.damping.mass, p.spec.damping.stiffness);
  } catch (const std::exception& e) {
    throw std::runtime_error(p.spec.source + ": " + e.what());
  }
  return p;
}

Problem load_problem(const std::string& case_path) { return make_problem(load_case(case_path)); }

}  // namespace shelldyn
