#include "lib/model/problem.hpp"

#include "lib/io/state_output.hpp"

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
  std::vector<PrescribedMotion> motion;
  for (const auto& pd : d.prescribed) motion.push_back({DofMap::dof(pd.node, pd.component), pd.value, pd.function});
  model.set_prescribed_motion(std::move(motion));
  return model;
}

namespace {

// The displaced state of an initial_displacement CSV (read and checked by build_discretization): the listed
// nodes' translations and, if given, directors (charts selected for them); the others as in the reference state.
State state_from_displacement_field(const Model& model, const Discretization& disc) {
  State s = model.initial_state();
  for (const auto& [node, x] : disc.initial_displacement_field) {
    s.u.segment<3>(DofMap::dof(node, 0)) = x.head<3>();
    if (!disc.initial_displacement_directors) continue;
    const Vec3 p = x.tail<3>();
    const size_t sn = static_cast<size_t>(node);
    s.charts[sn] = select_chart(p);
    s.u.segment<2>(DofMap::dof(node, 3)) = chart_coordinates(p, s.charts[sn]);
  }
  return s;
}

// Prescribed displacement histories (docs/theory.md §8.6) start at g(0) with the rate ġ(0⁺).
State with_prescribed_start(const Model& model, State s) {
  model.prescribed_displacement(s.t, s.u.data());
  model.prescribed_velocity(s.t, s.v.data());
  return s;
}

}  // namespace

State Problem::initial_state() const {
  State s = model->initial_state();
  if (!spec.initial_displacement.empty()) {
    // initial_displacement (docs/manual.md §2.6): d and p of a VTU (or of a CSV), charts selected for those
    // directors and adopted by the model (its director constraints follow the charts); t = 0 whatever the
    // VTU's time.
    bool has_time = false;
    State d;
    try {
      d = disc.initial_displacement_from_csv ? state_from_displacement_field(*model, disc)
                                             : state_from_vtu(*model, spec.initial_displacement, &has_time);
    } catch (const std::exception& e) {
      throw std::runtime_error(spec.initial_displacement_where + ": " + e.what());
    }
    s.u = d.u;
    s.charts = d.charts;
    model->adopt_charts(s.charts);
    // The initial velocity: translations as given; director rates made normal to the displaced directors and
    // expressed in their charts (only fields are allowed with an initial displacement: case_file.cpp).
    for (int i = 0; i < model->mesh().num_nodes(); ++i) {
      const size_t si = static_cast<size_t>(i);
      const Eigen::Index k = static_cast<Eigen::Index>(DofMap::dof(i, 0));
      if (disc.initial_velocity.size() == s.v.size()) s.v.segment<3>(k) = disc.initial_velocity.segment<3>(k);
      const Vec3 p = model->director(s, i);
      const Vec3 w = si < disc.initial_director_rate.size() ? disc.initial_director_rate[si] : Vec3::Zero();
      s.v.segment<2>(k + 3) = chart_coordinates(w - w.dot(p) * p, s.charts[si]);
    }
    return with_prescribed_start(*model, std::move(s));
  }
  if (disc.initial_velocity.size() == s.v.size()) s.v = disc.initial_velocity;
  return with_prescribed_start(*model, std::move(s));
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
  if (!p.spec.initial_displacement.empty()) (void)p.initial_state();  // a bad VTU is a case error, found now
  return p;
}

Problem load_problem(const std::string& case_path) { return make_problem(load_case(case_path)); }

}  // namespace shelldyn
