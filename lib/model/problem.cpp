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
      if (disc.initial_velocity.size() >= k + 3) s.v.segment<3>(k) = disc.initial_velocity.segment<3>(k);
      const Vec3 p = model->director(s, i);
      const Vec3 w = si < disc.initial_director_rate.size() ? disc.initial_director_rate[si] : Vec3::Zero();
      s.v.segment<2>(k + 3) = chart_coordinates(w - w.dot(p) * p, s.charts[si]);
    }
    return with_prescribed_start(*model, std::move(s));
  }
  // The shell's initial velocity (5 per node); bodies keep theirs from Model::initial_state().
  if (disc.initial_velocity.size() == 5 * static_cast<Index>(model->mesh().num_nodes()))
    s.v.head(disc.initial_velocity.size()) = disc.initial_velocity;
  return with_prescribed_start(*model, std::move(s));
}

namespace {

// rigid_bodies and joints of the case (docs/manual.md "Rigid bodies and joints") → the Model's definitions.
void add_multibody(Model& model, const CaseSpec& spec, const Discretization& d) {
  if (spec.rigid_bodies.empty() && spec.joints.empty()) return;
  std::vector<RigidBodyDef> bodies;
  for (const auto& b : spec.rigid_bodies)
    bodies.push_back({b.name, b.mass, b.inertia, b.position, b.axes, b.velocity, b.angular_velocity});
  auto body_index = [&](const std::string& name) {
    for (size_t k = 0; k < spec.rigid_bodies.size(); ++k)
      if (spec.rigid_bodies[k].name == name) return static_cast<int>(k);
    return -1;  // the parser has checked the names
  };
  auto nodes_of = [&](const std::string& set, const std::string& where) -> const std::vector<int>& {
    const auto it = d.mesh.node_sets.find(set);
    if (it == d.mesh.node_sets.end()) {
      std::string names;
      for (const auto& [k, v] : d.mesh.node_sets) names += (names.empty() ? "" : ", ") + k;
      throw std::runtime_error(where + ": unknown set '" + set + "' (define it under 'sets:' or use one below)\navailable: " + names);
    }
    if (it->second.empty()) throw std::runtime_error(where + ": set '" + set + "' has no nodes");
    return it->second;
  };
  auto end = [&](const JointEndSpec& e, const std::string& joint) {
    JointEnd out;
    switch (e.kind) {
      case JointEndSpec::Kind::set: {
        const std::vector<int>& nodes = nodes_of(e.set, e.where);
        if (nodes.size() != 1)
          throw std::runtime_error(e.where + ": joint '" + joint + "': set '" + e.set + "' has " + std::to_string(nodes.size()) +
                                   " nodes, a joint end needs one (a {point} set)");
        out.kind = JointEnd::Kind::node;
        out.node = nodes[0];
        break;
      }
      case JointEndSpec::Kind::body:
        out.kind = JointEnd::Kind::body;
        out.body = body_index(e.body);
        out.at = e.at;
        break;
      case JointEndSpec::Kind::ground:
        out.kind = JointEnd::Kind::ground;
        out.at = e.at;
        break;
      case JointEndSpec::Kind::none: break;
    }
    return out;
  };
  std::vector<JointDef> joints;
  for (const auto& j : spec.joints) {
    JointDef def;
    def.name = j.name;
    def.a = end(j.a, j.name);
    def.b = end(j.b, j.name);
    def.axis = j.axis;
    def.point = j.point;
    def.angle = j.angle;
    def.angle_scale = j.amplitude;
    if (j.type == "fixed_point") def.type = JointDef::Type::fixed_point;
    else if (j.type == "spherical") def.type = JointDef::Type::spherical;
    else if (j.type == "revolute") def.type = JointDef::Type::revolute;
    else if (j.type == "rigid_connection") {
      def.type = JointDef::Type::rigid_connection;
      def.nodes = nodes_of(j.set, j.where + ".set");
    } else def.type = JointDef::Type::prescribed_rotation;
    if (!j.body.empty()) def.body = body_index(j.body);
    joints.push_back(std::move(def));
  }
  try {
    model.set_multibody(std::move(bodies), std::move(joints), spec.gravity);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(spec.source + ": " + e.what());
  }
}

}  // namespace

Problem make_problem(CaseSpec spec) {
  Problem p;
  p.spec = std::move(spec);
  p.disc = build_discretization(p.spec);
  try {
    p.model = std::make_unique<Model>(make_model(p.disc, p.spec.material));
  } catch (const std::exception& e) {
    throw std::runtime_error(p.spec.source + ": " + e.what());
  }
  add_multibody(*p.model, p.spec, p.disc);  // errors carry the joint's FILE:LINE
  try {
    p.model->set_rayleigh_damping(p.spec.damping.mass, p.spec.damping.stiffness);
  } catch (const std::exception& e) {
    throw std::runtime_error(p.spec.source + ": " + e.what());
  }
  if (!p.spec.initial_displacement.empty()) (void)p.initial_state();  // a bad VTU is a case error, found now
  if (p.model->num_constraints() > 0) {  // redundant joints, joints on supports, initial violation
    // An initial field sets the shell's nodes only (a VTU or CSV holds no rigid-body states): a joint it breaks
    // says so in place of the generic advice.
    const bool field = !p.spec.initial_displacement.empty() && p.model->num_rigid_bodies() > 0;
    try {
      p.model->check_constraints(p.initial_state(), field ? "initial fields move the shell, not the bodies" : "");
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(p.spec.source + ": joints: " + e.what());
    }
  }
  return p;
}

Problem load_problem(const std::string& case_path) { return make_problem(load_case(case_path)); }

}  // namespace shelldyn
