// From a validated case (lib/io/case_file.hpp) to the discrete problem: mesh, initial normals and
// director charts, node sets, constraints, initial velocity, nodal loads, monitors, mass.
//
// This is the mesh-dependent half of reading a case: set look-ups, load distribution and the initial
// velocity field need the nodes. Errors are std::runtime_error carrying the case file's
// "FILE:LINE: key.path" of the offending entry, e.g.
//   "plate.yaml:31: loads[0].set: unknown set 'tip' (available: all, boundary, A, B)".
// Units are those of the case file.
#pragma once

#include "elements/director.hpp"
#include "lib/io/case_file.hpp"
#include "lib/model/dof_map.hpp"
#include "lib/mesh/mesh.hpp"
#include "lib/model/surface_loads.hpp"
#include "lib/model/time_function.hpp"

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

namespace shelldyn {

// A dead nodal load after distribution: the load vector (force, or moment vector) is
// `vector * function(t)`, where `vector` already includes the amplitude and the distribution weight.
struct DiscreteLoad {
  int node = 0;
  LoadType type = LoadType::Force;
  Vec3 vector = Vec3::Zero();
  TimeFunction function;
};

// A prescribed displacement history on one translation DOF (docs/theory.md §8.6): u = value · function(t).
struct DiscretePrescribed {
  int node = 0;
  int component = 0;  // 0, 1, 2: ux, uy, uz
  double value = 0.0;
  TimeFunction function;
};

struct Monitor {
  std::string name;
  int node = 0;             // the first (for reduce = none: the only) node of the set
  std::vector<int> nodes;   // all nodes of the set
  MonitorQuantity quantity = MonitorQuantity::Ux;
  MonitorReduce reduce = MonitorReduce::None;
  bool has_axis = false;    // ur about an axis
  Vec3 axis_point = Vec3::Zero(), axis_direction = Vec3::UnitZ();
};

struct Discretization {
  // The mesh, consistently oriented (orient_consistently), with the case's sets added to
  // mesh.node_sets next to the generator's / Gmsh's own sets.
  Mesh mesh;
  std::vector<Vec3> normals;          // initial unit nodal normals p_i0 (docs/theory.md §2.4)
  std::vector<DirectorChart> charts;  // select_chart(p_i0) per node (docs/theory.md §2.3)
  DofMap dofs{0};                     // boundary conditions recorded and resolved for `charts`
  // 5 per node: [v_X, v_Y, v_Z, q̇_1, q̇_2] with v = translation + ω × (X − about), q̇ = S (ω × p_i0)
  // (S = 2x3 selector of the chart's minor components n, m). Zero if the case has no initial velocity.
  Eigen::VectorXd initial_velocity;
  // The director rate ṗ of each node as given (3 per node, before the projection normal to p_i0): with an
  // initial_displacement it is re-expressed for the displaced directors (Problem::initial_state).
  std::vector<Vec3> initial_director_rate;
  std::vector<DiscreteLoad> loads;    // nodal forces/moments, incl. dead pressure, body force, edge loads
  std::vector<FollowerPressure> follower_pressures;  // evaluated on the current geometry by the Model
  // Prescribed displacement histories, one per DOF (also recorded as constraints in `dofs`); the initial
  // velocity of those DOFs is their history's rate at t = 0.
  std::vector<DiscretePrescribed> prescribed;
  // initial_displacement from a CSV file (docs/manual.md §2.6): node -> (u, p) for the nodes listed (p = the
  // unit director if the file has director columns, else unused); empty for a VTU (Problem::initial_state).
  bool initial_displacement_from_csv = false;
  std::map<int, Eigen::Matrix<double, 6, 1>> initial_displacement_field;
  bool initial_displacement_directors = false;
  // all loads vanish and prescribed displacements stop moving for t >= loads_end (+inf if some never do; 0 if none)
  double loads_end = 0.0;
  std::vector<Monitor> monitors;
  double surface_area = 0.0;
  double total_mass = 0.0;            // rho * thickness * surface_area
  double mesh_size = 0.0;             // diagonal of the bounding box of the nodes
};

Discretization build_discretization(const CaseSpec& spec);

// The mesh of a case alone (generated or read), before orientation; errors carry the mesh's location.
Mesh build_mesh(const CaseSpec& spec);

// Value of a monitor at a state given by the global vectors u = [d, q] and v = u̇ (5 per node) and
// the current charts: ux..uz = d, ur = d·e_r (e_r: unit vector from the axis, perpendicular to it, or
// X0/|X0| without an axis), px..pz = p(q), vx..vz = ḋ, rx..rz = reactions (lib/model/reactions.hpp; NaN if
// `reactions` is null), reduced over the set's nodes by m.reduce.
double monitor_value(const Monitor& m, const Mesh& mesh, const Eigen::VectorXd& u, const Eigen::VectorXd& v,
                     const std::vector<DirectorChart>& charts, const Eigen::VectorXd* reactions = nullptr);
// True if some monitor needs reaction forces.
bool monitors_need_reactions(const std::vector<Monitor>& monitors);

}  // namespace shelldyn
