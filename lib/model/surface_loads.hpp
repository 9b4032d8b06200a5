// Distributed loads of a shell mesh as consistent nodal forces (docs/theory.md §8.2–8.4):
// pressure on elements (dead: on the reference geometry; follower: on the current geometry, with its
// load stiffness), force per unit volume (body force, gravity) and force per unit length on edges.
//
// Pressure sign: positive pressure pushes along the element normal x,ξ × x,η, which points to the side
// of the initial nodal normals (meshes are oriented so, docs/theory.md §2.4).
// Units: those of the case file (pressure = force/area, body force = force/volume, edge load = force/length).
#pragma once

#include "lib/mesh/mesh.hpp"
#include "lib/linalg/sparse_matrix.hpp"
#include "lib/model/time_function.hpp"

#include <Eigen/Core>
#include <array>
#include <map>
#include <vector>

namespace shelldyn {

class Assembler;

// A follower pressure on a list of elements: p(t) = pressure * function(t).
struct FollowerPressure {
  std::vector<int> elements;
  double pressure = 0.0;
  TimeFunction function;
};

// Consistent nodal forces of a pressure p on one element whose nine mid-surface nodes are at x:
// f_a = p Σ_gp w N_a (x,ξ × x,η) (27 entries, node-major). If K is given, it receives ∂f/∂x (27×27,
// not symmetric): ∂f_a/∂x_b = p Σ_gp w N_a (N_b,η [x,ξ]× − N_b,ξ [x,η]×).
void element_pressure(const std::array<Vec3, 9>& x, double p, Eigen::Matrix<double, 27, 1>& f,
                      Eigen::Matrix<double, 27, 27>* K = nullptr);

// Dead pressure p on the reference geometry of `elements`: nodal force per node (summed over elements).
std::map<int, Vec3> dead_pressure_forces(const Mesh& mesh, const std::vector<int>& elements, double p);

// Force per unit volume b on `elements` of thickness h: f_i = ∫ N_i b h dA on the reference geometry.
std::map<int, Vec3> body_forces(const Mesh& mesh, const std::vector<int>& elements, const Vec3& b, double h);

// Force per unit length t on the element edges whose three nodes all belong to `nodes`:
// f_i = ∫ N_i t ds (5-point Gauss on the quadratic edge). Empty if there is no such edge.
std::map<int, Vec3> edge_line_forces(const Mesh& mesh, const std::vector<int>& nodes, const Vec3& t);

// Elements whose nine nodes all belong to `nodes` (sorted).
std::vector<int> elements_within(const Mesh& mesh, const std::vector<int>& nodes);

// Follower pressures at time t and displacement u (5 DOF per node): F += f (translations only), and,
// if K is given, K −= ∂f/∂d, either in full (symmetric = false) or its symmetric part.
void add_follower_pressures(const std::vector<FollowerPressure>& loads, const Mesh& mesh, const Assembler& assembler,
                            double t, const Eigen::VectorXd& u, double* F, SparseMatrix* K, bool symmetric);

}  // namespace shelldyn
