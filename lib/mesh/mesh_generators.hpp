// Built-in structured meshes of 9-node quadrilaterals with named node and element sets, matching the
// geometry conventions of docs/benchmarks.md. Every generator returns consistently oriented elements
// (counter-clockwise seen from the documented outward normal side) and the sets "all" (nodes) and
// "all" (elements). Invalid parameters (non-positive sizes or counts, hole angle out of range, ...)
// throw std::invalid_argument naming the parameter and the accepted range.
#pragma once

#include "lib/mesh/mesh.hpp"

#include <array>
#include <vector>

namespace shelldyn {

// Rectangle [x0, x0+a] x [y0, y0+b] in the plane Z = 0, nx x ny elements, normal +Z.
// Node sets: "left" (X = x0), "right" (X = x0+a), "bottom" (Y = y0), "top" (Y = y0+b),
// "corner_ll", "corner_lr", "corner_ur", "corner_ul" (one node each).
Mesh make_rectangle(double a, double b, int nx, int ny, double x0 = 0.0, double y0 = 0.0);

// Union of axis-aligned rectangles on a grid of square cells of side `cell` in the plane Z = 0,
// normal +Z (for the flying L-shaped plate, docs/benchmarks.md §1.3: cells {0,0,3,7} and {3,0,6,3}
// with cell = 1). Each rectangle is {i0, j0, i1, j1} in cell units (i1 > i0, j1 > j0); rectangles
// must not overlap and must form one edge-connected region. One element per cell; shared nodes merged.
// Node sets: "boundary" (all nodes on the outer boundary).
Mesh make_cell_union(const std::vector<std::array<int, 4>>& rectangles, double cell = 1.0);

// Cylindrical panel (docs/benchmarks.md §2.3): axis along X, X in [0, length],
// Y = R sin(psi), Z = R cos(psi) - R, psi in [-angle/2, +angle/2]; n_arc elements along psi,
// n_axial along X; normal points away from the axis (+Z at the apex line).
// Node sets: "x0" (X = 0), "x1" (X = length), "arc_min" (psi = -angle/2), "arc_max" (psi = +angle/2),
// "corner_x0_arcmin", "corner_x0_arcmax", "corner_x1_arcmin", "corner_x1_arcmax".
Mesh make_cylindrical_panel(double radius, double angle, double length, int n_arc, int n_axial);

// Hemisphere with a polar hole (docs/benchmarks.md §§3, 4.4): pole on +Z,
// X = R sin(chi) cos(phi), Y = R sin(chi) sin(phi), Z = R cos(chi), chi in [hole, 90 deg].
// quarter = true: phi in [0, 90 deg], n x n elements; quarter = false: phi in [0, 360 deg), 4n x n
// elements (n per quarter in each direction). Normal points outward (radial).
// Node sets: "equator" (chi = 90 deg), "hole" (chi = hole), "point_xpos" (R,0,0), "point_ypos" (0,R,0);
// full model also "point_xneg", "point_yneg"; quarter model also "sym_y0" (phi = 0, plane Y = 0) and
// "sym_x0" (phi = 90 deg, plane X = 0).
Mesh make_hemisphere(double radius, double hole_deg, bool quarter, int n);

// Cylindrical patch for quarter / octant models, axis along X through the origin (the shell sits at its
// natural height): X in [0, length], Y = R sin(psi), Z = R cos(psi), psi in [0, angle] (0 < angle <= pi);
// the straight edge psi = 0 lies in the plane Y = 0 and the arc X = 0 in the plane X = 0. n_arc elements
// along psi, n_axial along X; normal outward (away from the axis).
// Node sets: "x0" (X = 0), "x1" (X = length), "arc0" (psi = 0, plane Y = 0), "arc1" (psi = angle),
// "corner_x0_arc0", "corner_x0_arc1", "corner_x1_arc0", "corner_x1_arc1".
Mesh make_cylinder_patch(double radius, double angle, double length, int n_arc, int n_axial);

// Closed cylinder, axis along X: X in [0, length], Y = R sin(theta), Z = R cos(theta), theta in [0, 2 pi)
// with the seam merged; n_circ >= 4 elements around, n_axial along; normal outward.
// Node sets: "x0", "x1" (the end rings), "top" (theta = 0: Y = 0, Z = R), "bottom" (theta = pi).
Mesh make_closed_cylinder(double radius, double length, int n_circ, int n_axial);

// Slit annular plate in the plane Z = 0 (Sze, Liu & Lo 2004 §3.3), r in [r_inner, r_outer], theta in
// [0, 2 pi] with the slit along +X: the nodes at theta = 0 and theta = 2 pi are distinct. n_radial
// elements across, n_circ >= 3 around; normal +Z.
// Node sets: "slit_start" (theta = 0), "slit_end" (theta = 2 pi), "inner", "outer", "point_A"
// (r_inner on slit_end), "point_B" (r_outer on slit_end).
Mesh make_slit_annulus(double r_inner, double r_outer, int n_radial, int n_circ);

}  // namespace shelldyn
