#include "lib/mesh/mesh_generators.hpp"
#include "lib/mesh/nodal_normals.hpp"
#include "lib/model/model.hpp"
#include <cstdio>
int main() {
  auto mesh = shelldyn::make_rectangle(1, 1, 2, 2);
  auto normals = shelldyn::initial_normals(mesh);
  shelldyn::DofMap dofs(mesh.num_nodes());
  shelldyn::Model m(mesh, normals, shelldyn::ShellMaterial{1e6, 0.3, 1, 0.1}, dofs);
  std::printf("consumer: %d elements, %lld dofs\n", m.mesh().num_elements(), (long long)m.num_dofs());
}
