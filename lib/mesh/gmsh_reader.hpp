// Reader for Gmsh MSH 4.1 ASCII files of 9-node quadrilateral shell meshes.
//
// Accepted: $MeshFormat 4.1 with file-type 0 (ASCII); $PhysicalNames; $Entities (physical tags of
// points, curves, surfaces; volumes are parsed and ignored); $Nodes (entity blocks, optional
// parametric coordinates, sparse node tags); $Elements with types 10 (quad9: the shell mesh), and
// 15 (point), 1 (line2), 8 (line3) which only serve physical groups. Other sections are skipped.
// Gmsh's type-10 node order is the order of lib/mesh/mesh.hpp (docs/theory.md §1), so connectivity is
// copied as is.
//
// Result:
// - Nodes: only nodes of quad9 elements are kept (geometry-only nodes would have no stiffness),
//   renumbered 0-based and dense in ascending Gmsh node-tag order.
// - Elements: the quad9 elements in file order.
// - Physical groups of dimension 0 and 1 become node sets (all nodes of their elements); groups of
//   dimension 2 become element sets and node sets (the nodes of their elements). A set is named by
//   the physical name, or "physical_<tag>" if the group has no name; groups of different dimension
//   with the same name are merged (union). Every mesh also gets the node set and element set "all"
//   (so a physical group may not be called "all").
// - Orientation is NOT changed: call orient_consistently() and check_orientation()
//   (lib/mesh/nodal_normals.hpp) before building a model.
//
// Rejected (std::runtime_error "FILE:LINE: reason"): other MSH versions, binary files, element types
// other than 1, 8, 10, 15 (with a hint how to produce quad9 meshes), truncated or malformed sections,
// undefined or duplicate node tags, non-finite coordinates, a file without quad9 elements, nodes of a
// point/curve group that belong to no quad9 element. A file that cannot be opened gives
// "FILE: cannot open ...".
#pragma once

#include "lib/mesh/mesh.hpp"

#include <istream>
#include <string>

namespace shelldyn {

Mesh read_gmsh(const std::string& path);
// The same from a stream; `path` only labels error messages (used by fuzz/fuzz_gmsh_reader.cpp).
Mesh read_gmsh(std::istream& in, const std::string& path);

}  // namespace shelldyn
