#include "lib/state_output.hpp"

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace shelldyn {

VtuFields state_fields(const Model& model, const State& state) {
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
