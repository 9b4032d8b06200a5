#include "lib/state_output.hpp"

#include <filesystem>
#include <fstream>
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
  for (ScalarField* s : {&Nf, &Mf, &Qf, &ef, &kf, &gf, &uf}) f.cell_scalars.push_back(std::move(*s));
  return f;
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

}  // namespace shelldyn
