// Mesh of 9-node quadrilateral shell elements: initial nodal coordinates, connectivity, named sets.
//
// Node order inside an element is Gmsh type 10 = VTK type 28 = docs/theory.md §1:
//
//      4 ---- 7 ---- 3        eta
//      |             |         ^
//      8      9      6         |
//      |             |         +--> xi
//      1 ---- 5 ---- 2
//
// (1-based in the picture; stored 0-based). Corners run counter-clockwise when seen from the side the
// initial shell normal points to (docs/theory.md §2.4 orientation requirement).
//
// Units: whatever consistent unit system the case file uses; the mesh does not scale anything.
// Ownership: a Mesh is a plain value; generators and readers return it by value.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // Vec3::cross is used wherever meshes are
#include <array>
#include <map>
#include <string>
#include <vector>

namespace shelldyn {

using Vec3 = Eigen::Vector3d;
using Quad9 = std::array<int, 9>;  // 0-based node indices, Gmsh type-10 order

struct Mesh {
  std::vector<Vec3> X;          // initial mid-surface coordinates X_i0, one per node
  std::vector<Quad9> elements;  // connectivity
  // Named sets. Node/element indices are sorted and unique. Generators always provide the node set
  // "all" and the element set "all"; other names are listed with each generator.
  std::map<std::string, std::vector<int>> node_sets;
  std::map<std::string, std::vector<int>> element_sets;

  int num_nodes() const { return static_cast<int>(X.size()); }
  int num_elements() const { return static_cast<int>(elements.size()); }
};

}  // namespace shelldyn
