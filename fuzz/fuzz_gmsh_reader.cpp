// libFuzzer target: the Gmsh MSH 4.1 reader (lib/mesh/gmsh_reader.hpp), then the orientation pass every
// file mesh goes through (lib/mesh/nodal_normals.hpp).
//
// Contract under test: any byte string either yields a Mesh or throws std::runtime_error /
// std::invalid_argument with a message; anything else is a finding. Run with scripts/fuzz.sh.
#include "lib/mesh/gmsh_reader.hpp"
#include "lib/mesh/nodal_normals.hpp"

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    shelldyn::Mesh mesh = shelldyn::read_gmsh(in, "fuzz.msh");
    if (mesh.num_elements() <= 64) {
      shelldyn::orient_consistently(mesh);
      shelldyn::check_orientation(mesh, shelldyn::initial_normals(mesh));
    }
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
