#include "lib/io/state_output.hpp"

#include "lib/io/vtu_reader.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

VtuFields state_fields(const Model& model, const State& state, const Eigen::VectorXd* reactions) {
  VtuFields f;
  const int n = model.mesh().num_nodes();
  f.displacement.resize(static_cast<size_t>(n));
  f.velocity.resize(static_cast<size_t>(n));
  f.director.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    f.displacement[static_cast<size_t>(i)] = state.u.segment<3>(DofMap::dof(i, 0));
    f.velocity[static_cast<size_t>(i)] = state.v.segment<3>(DofMap::dof(i, 0));
    f.director[static_cast<size_t>(i)] = model.director(state, i);
  }
  // Director rate ṗ (3 components): with it a VTU holds the whole velocity state, so a run can start from it
  // (initial_velocity: {field: FILE.vtu}, docs/manual.md §2.6).
  ScalarField pdot{"director_rate", std::vector<double>(static_cast<size_t>(3 * n)), 3};
  for (int i = 0; i < n; ++i) {
    const size_t si = static_cast<size_t>(i);
    const Vec3 w = state.pdot.size() == 3 * static_cast<Eigen::Index>(n)
                       ? Vec3(state.pdot.segment<3>(3 * static_cast<Eigen::Index>(i)))
                       : Vec3(director_A1(state.u.segment<2>(DofMap::dof(i, 3)), state.charts[si]) *
                              state.v.segment<2>(DofMap::dof(i, 3)));
    for (int c = 0; c < 3; ++c) pdot.values[3 * si + static_cast<size_t>(c)] = w[c];
  }
  f.point_scalars.push_back(std::move(pdot));
  if (reactions) {
    ScalarField r{"reaction", std::vector<double>(static_cast<size_t>(3 * n)), 3};
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) r.values[static_cast<size_t>(3 * i + c)] = (*reactions)[DofMap::dof(i, c)];
    f.point_scalars.push_back(std::move(r));
  }
  // Element averages of strains and stress resultants (docs/theory.md §9.1).
  const int ne = model.mesh().num_elements();
  ScalarField Nf{"membrane_force", {}, 3}, Mf{"bending_moment", {}, 3}, Qf{"shear_force", {}, 2},
      ef{"membrane_strain", {}, 3}, kf{"curvature", {}, 3}, gf{"shear_strain", {}, 2}, uf{"strain_energy_density", {}, 1};
  for (ScalarField* s : {&Nf, &Mf, &ef, &kf}) s->values.reserve(static_cast<size_t>(3 * ne));
  CR9Shell::Vec45 ue;
  CR9Shell::Charts ch;
  for (int e = 0; e < ne; ++e) {
    const auto& nodes = model.mesh().elements[static_cast<size_t>(e)];
    for (size_t a = 0; a < 9; ++a) {
      ue.segment<5>(static_cast<Eigen::Index>(5 * a)) = state.u.segment<5>(DofMap::dof(nodes[a], 0));
      ch[a] = state.charts[static_cast<size_t>(nodes[a])];
    }
    const CR9Shell::Resultants r = model.element(e).resultants(ue, ch);
    auto put = [](ScalarField& s, const auto& v) {
      for (Eigen::Index c = 0; c < v.size(); ++c) s.values.push_back(v[c]);
    };
    put(Nf, r.membrane_force), put(Mf, r.bending_moment), put(Qf, r.shear_force);
    put(ef, r.membrane_strain), put(kf, r.curvature), put(gf, r.shear_strain);
    uf.values.push_back(r.energy_density);
  }
  // Components in the element's local frame (elements/cr9_shell.hpp Resultants; docs/manual.md §4).
  for (ScalarField* s : {&Nf, &Mf, &ef, &kf}) s->component_names = {"11", "22", "12"};
  for (ScalarField* s : {&Qf, &gf}) s->component_names = {"1", "2"};
  for (ScalarField* s : {&Nf, &Mf, &Qf, &ef, &kf, &gf, &uf}) f.cell_scalars.push_back(std::move(*s));
  return f;
}

State state_from_vtu(const Model& model, const std::string& path, bool* has_time) {
  const VtuPointData vtu = read_vtu(path);
  const Mesh& mesh = model.mesh();
  check_vtu_matches_mesh(vtu, mesh.X);
  const std::vector<Vec3> d = vtu.vectors("displacement"), p = vtu.vectors("director"), v = vtu.vectors("velocity");
  const std::vector<Vec3> pdot = vtu.has("director_rate") ? vtu.vectors("director_rate") : std::vector<Vec3>(v.size(), Vec3::Zero());
  State s = model.initial_state();
  *has_time = vtu_time_from_pvd(path, &s.t);
  if (!*has_time) s.t = 0.0;
  const int n = mesh.num_nodes();
  for (int i = 0; i < n; ++i) {
    const size_t si = static_cast<size_t>(i);
    if (std::abs(p[si].norm() - 1.0) > 1e-8)
      throw std::runtime_error(path + ": the director at point " + std::to_string(i) + " has length " +
                               std::to_string(p[si].norm()) + ", not 1 (not a shelldyn state?)");
    const Vec3 pi = p[si].normalized();
    s.charts[si] = select_chart(pi);
    s.u.segment<3>(DofMap::dof(i, 0)) = d[si];
    s.u.segment<2>(DofMap::dof(i, 3)) = chart_coordinates(pi, s.charts[si]);
    s.v.segment<3>(DofMap::dof(i, 0)) = v[si];
    s.v.segment<2>(DofMap::dof(i, 3)) = chart_coordinates(pdot[si] - pdot[si].dot(pi) * pi, s.charts[si]);
  }
  // Fixed DOFs must hold their prescribed values: zero displacement, the reference director's fixed parts.
  double size = 0.0;
  for (const Vec3& x : mesh.X) size = std::max(size, (x - mesh.X.front()).norm());
  const std::vector<Vec3>& p0 = model.normals();
  DofMap dofs = model.dofs();  // the constraints resolved for the state's charts
  try {
    dofs.resolve(s.charts);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what() + " (a state of other boundary conditions?)");
  }
  const std::vector<Index>& prescribed = model.prescribed_dofs();
  for (Index dof : dofs.constrained_dofs()) {
    // A prescribed DOF (docs/theory.md §8.6) is displaced; the run replaces its value by g(0) anyway.
    if (std::binary_search(prescribed.begin(), prescribed.end(), dof)) continue;
    const int node = static_cast<int>(dof / kDofsPerNode), c = static_cast<int>(dof % kDofsPerNode);
    const size_t sn = static_cast<size_t>(node);
    const double bad = c < 3 ? std::abs(d[sn][c]) / std::max(size, 1e-300)
                             : std::abs(s.u[dof] - chart_coordinates(p0[sn], s.charts[sn])[c - 3]);
    if (bad > 1e-9) {
      std::ostringstream os;
      os << path << ": node " << node << " has " << (c < 3 ? "displacement " : "director ") << "component " << c
         << " away from the value its boundary condition fixes (a state of other boundary conditions?)";
      throw std::runtime_error(os.str());
    }
  }
  return s;
}

void prepare_output_folder(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "fields", ec);
  if (ec) throw std::runtime_error("cannot create output folder '" + dir + "': " + ec.message());
  const fs::path probe = fs::path(dir) / ".write-test";
  {
    std::ofstream out(probe);
    if (!out) throw std::runtime_error("output folder '" + dir + "' is not writable");
  }
  fs::remove(probe, ec);
}

std::pair<double, double> constraint_drift(const SemiDiscreteSystem& system, const State& state) {
  if (system.num_constraints() == 0) return {0.0, 0.0};
  Eigen::VectorXd g, gt;
  SemiDiscreteSystem::ConstraintMatrix G;
  system.constraint_values(state.t, state.u, state.charts, g);
  system.constraint_jacobian(state.t, state.u, state.charts, G);
  system.constraint_time_derivative(state.t, state.u, state.charts, gt);
  const Eigen::VectorXd gdot = G * state.v + gt;
  return {g.size() ? g.cwiseAbs().maxCoeff() : 0.0, gdot.size() ? gdot.cwiseAbs().maxCoeff() : 0.0};
}

std::string body_state_header() {
  return "t,body,phi_x,phi_y,phi_z,d1_x,d1_y,d1_z,d2_x,d2_y,d2_z,d3_x,d3_y,d3_z,v_x,v_y,v_z,omega_x,omega_y,omega_z";
}

std::string body_state_rows(const Model& model, const State& state) {
  const ModelMultibody* mb = model.multibody();
  std::string out;
  if (!mb) return out;
  char buf[64];
  auto put = [&](double x) {
    std::snprintf(buf, sizeof buf, ",%.17g", x);
    out += buf;
  };
  for (int b = 0; b < mb->num_bodies(); ++b) {
    const multibody::Vec12 q = mb->body_q(b, state.u);
    const multibody::Vec12 qd = state.v.segment<12>(mb->body_first_dof(b));
    std::snprintf(buf, sizeof buf, "%.17g", state.t);
    out += buf;
    out += "," + mb->body_def(b).name;
    for (int k = 0; k < 12; ++k) put(q[k]);
    for (int k = 0; k < 3; ++k) put(qd[k]);
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) w += 0.5 * Eigen::Vector3d(q.segment<3>(3 + 3 * i)).cross(Eigen::Vector3d(qd.segment<3>(3 + 3 * i)));
    for (int k = 0; k < 3; ++k) put(w[k]);
    out += "\n";
  }
  return out;
}

}  // namespace shelldyn
