// Initial nodal normals p_i0 and element orientation of a quad9 shell mesh (docs/theory.md §2.4,
// paper eq. 7), plus the mid-surface area.
//
// Scope: smooth shells only (docs/theory.md §2.4). Folded or non-smooth shells need the separate
// treatment of Li et al. 2018/2021 and are rejected by check_orientation().
// All functions are pure functions of the mesh (no global state); errors are exceptions whose
// message names the element (0-based index), the local node (1-based, docs/theory.md §1 numbering)
// and the mesh node (0-based index).
#pragma once

#include "lib/mesh/mesh.hpp"

#include <vector>

namespace shelldyn {

// docs/theory.md §2.4: for each element e and each of its nodes i, n_e,i = X,xi x X,eta at the
// node's natural coordinates (quad9 geometry), normalised; at each mesh node the n_e,i of the adjacent
// elements are summed and normalised again. Returns one unit vector per mesh node.
// Throws std::invalid_argument if an element references a node index out of range, if X,xi x X,eta
// vanishes at a node (degenerate element), if a node belongs to no element, or if the element normals
// at a node cancel (inconsistent orientation: call orient_consistently() first).
std::vector<Vec3> initial_normals(const Mesh& mesh);

// Make the orientations of edge-adjacent elements agree (each shared edge traversed in opposite
// directions by its two elements). Breadth-first search over edge adjacency; the first element (lowest
// index) of each connected component keeps its orientation. Reversing an element maps corners
// (1,2,3,4) -> (1,4,3,2), mid-sides (5,6,7,8) -> (8,7,6,5), centre 9 -> 9 (xi <-> eta swap).
// Node and element indices (hence all sets) are unchanged. Returns the number of reversed elements.
// Throws std::invalid_argument for a non-orientable mesh (e.g. a Moebius strip) or an edge shared by
// more than two elements (non-manifold), naming the elements involved.
int orient_consistently(Mesh& mesh);

// docs/theory.md §2.4 orientation requirement: for every element the initial diagonal triad e_z0
// (§3.1: a = X3 - X1, b = X4 - X2, e_x ∝ â - b̂, e_y ∝ â + b̂, e_z = e_x × e_y) must satisfy
// e_z0 · p_i0 > 0 at all 9 nodes. Throws std::invalid_argument naming the first failing element and
// node (with the value of e_z0 · p_i0), or a degenerate element (zero diagonal, or parallel diagonals).
// `normals` must have one entry per mesh node (as returned by initial_normals()).
void check_orientation(const Mesh& mesh, const std::vector<Vec3>& normals);

// Mid-surface area: sum over elements of the 3x3 Gauss rule applied to |X,xi x X,eta| on the quad9
// geometry (same units^2 as the mesh coordinates).
double surface_area(const Mesh& mesh);

}  // namespace shelldyn
