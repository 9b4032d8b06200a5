// Case files (YAML): the user-facing description of one simulation (architecture.md §5).
//
// load_case() parses and validates a case file into a CaseSpec, a plain value that holds what the
// file says, resolved only as far as possible without building the mesh (paths made absolute,
// defaults filled in). Everything that needs the mesh (set look-up, load distribution, initial
// velocity) happens in build_discretization() (lib/model/discretization.hpp), which reports errors with
// the same "FILE:LINE: key.path" prefix kept in the `where` fields below.
//
// Schema (every key is checked; unknown keys, wrong types, missing required keys, non-positive sizes,
// empty lists and bad names are errors):
//
//   name: flying-plate                 optional, default = file stem
//   description: "..."                 optional
//   mesh:                              exactly one of `generator` / `file`
//     generator: rectangle             a, b, nx, ny, [x0, y0]
//              | cell_union            cells: [[i0,j0,i1,j1], ...], [cell]
//              | cylindrical_panel     radius, angle, length, n_arc, n_axial
//              | hemisphere            radius, hole_deg, quarter, n
//              | cylinder_patch        radius, angle, length, n_arc, n_axial   (axis X through the origin)
//              | closed_cylinder       radius, length, n_circ, n_axial
//              | slit_annulus          r_inner, r_outer, n_radial, n_circ
//     file: plate.msh                  Gmsh 4.1 (quad9); relative to the case file's folder
//   material: {E, nu, rho, thickness, [shear_factor = 5/6]}
//   sets:                              optional extra node sets, each exactly one of
//     NAME: {point: [x,y,z], [tol]} | {box: [[xmin,ymin,zmin],[xmax,ymax,zmax]]}
//         | {nodes: [i, ...]}  (0-based) | {union: [NAME, ...]}
//   boundary_conditions: [{set, fix: [ux|uy|uz|px|py|pz|director, ...]}, ...]          optional
//   initial_velocity: {[set = all], [translation], [angular], [about: centroid | [x,y,z]] | [field: v.csv | fields/step_N.vtu]
//                      | [mode: mode_shapes.csv, index: k, amplitude: A]}
//                     or a list of such entries (later ones override earlier ones)         optional
//   initial_displacement: {field: fields/step_N.vtu | u.csv}  (displacement and director of a run)  optional
//   loads: [{set, type: force|moment, direction, amplitude, [distribution: per_node|edge_total|per_length],
//            [function: {type: constant|ramp|hat|triangle|table|spin_up, ...}]}
//          | {[set = all], type: pressure|follower_pressure, amplitude, [function]}
//          | {[set = all], type: body_force|gravity, direction, amplitude, [function]}, ...]   optional
//   prescribed_displacements: [{set, dofs: [ux|uy|uz, ...], value, [function]}, ...]  optional
//   damping: {[mass = 0], [stiffness = 0]}                                             optional
//   gravity: [gx, gy, gz]              uniform gravity on the shell and the rigid bodies         optional
//   rigid_bodies: {NAME: {mass, inertia: [J1,J2,J3], [position], [axes: [d1, d2]], [velocity], [angular_velocity]}}
//   joints: [{name, type: fixed_point|spherical|revolute|rigid_connection|prescribed_rotation, ...}]  optional
// The full reference with types, defaults and units is docs/manual.md.
//   integrator: {name, ...settings}    settings kept as ordered (key, scalar text) pairs
//   time: {dt, t_end, [output_interval = dt]}
//   output: {[vtu = true], [vtu_every = 10], [history = true]}                           optional
//   monitors: [{name, set, quantity: ux|uy|uz|ur|px|py|pz|vx|vy|vz|rx|ry|rz, [reduce: none|sum|mean|max|min],
//               [axis: {point, direction}]}, ...]                                         optional
//
// Errors: std::runtime_error with one line "FILE:LINE: key.path: reason (how to fix)".
// Units: whatever consistent system the file uses; nothing is scaled.
#pragma once

#include "lib/model/dof_map.hpp"
#include "lib/model/time_function.hpp"

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace shelldyn {

// --- mesh ----------------------------------------------------------------------------------------
// Parameter names are those of lib/mesh/mesh_generators.hpp.
struct RectangleMeshSpec {
  double a = 0, b = 0;
  int nx = 0, ny = 0;
  double x0 = 0, y0 = 0;
};
struct CellUnionMeshSpec {
  std::vector<std::array<int, 4>> cells;
  double cell = 1.0;
};
struct CylindricalPanelMeshSpec {
  double radius = 0, angle = 0, length = 0;
  int n_arc = 0, n_axial = 0;
};
struct HemisphereMeshSpec {
  double radius = 0, hole_deg = 0;
  bool quarter = false;
  int n = 0;
};
struct CylinderPatchMeshSpec {
  double radius = 0, angle = 0, length = 0;
  int n_arc = 0, n_axial = 0;
};
struct ClosedCylinderMeshSpec {
  double radius = 0, length = 0;
  int n_circ = 0, n_axial = 0;
};
struct SlitAnnulusMeshSpec {
  double r_inner = 0, r_outer = 0;
  int n_radial = 0, n_circ = 0;
};
struct MeshFileSpec {
  std::string path;  // absolute (resolved against the case file's folder)
  // mesh.coincident_nodes: warn (default) | error — distinct nodes at one position (lib/model/discretization.cpp).
  bool coincident_nodes_error = false;
};
using MeshSpec = std::variant<RectangleMeshSpec, CellUnionMeshSpec, CylindricalPanelMeshSpec, HemisphereMeshSpec,
                              MeshFileSpec, CylinderPatchMeshSpec, ClosedCylinderMeshSpec, SlitAnnulusMeshSpec>;

// "rectangle", "cell_union", "cylindrical_panel", "hemisphere", "file", "cylinder_patch",
// "closed_cylinder" or "slit_annulus".
const char* mesh_kind_name(const MeshSpec& mesh);

// --- material ------------------------------------------------------------------------------------
// Kept separate from the element's material type on purpose: the case file is the user's vocabulary.
struct CaseMaterial {
  double E = 0;             // Young's modulus
  double nu = 0;            // Poisson ratio, -1 < nu < 0.5
  double rho = 0;           // mass density per volume
  double thickness = 0;     // shell thickness h
  double shear_factor = 5.0 / 6.0;
};

// --- node sets defined in the case file ----------------------------------------------------------
struct SetSpec {
  enum class Kind { Point, Box, Nodes, Union };
  std::string name;
  Kind kind = Kind::Nodes;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // Point
  double tol = -1.0;                                 // Point; < 0: default 1e-6 * mesh size
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero(), box_max = Eigen::Vector3d::Zero();  // Box
  std::vector<int> nodes;                            // Nodes (0-based, as written)
  std::vector<std::string> members;                  // Union
  std::string where;                                 // "FILE:LINE: sets.NAME" for later errors
};

struct BoundaryConditionSpec {
  std::string set;
  std::vector<Fix> fix;
  std::string where;  // "FILE:LINE: boundary_conditions[k]"
};

// Rigid field v = translation + ω × (X − about), ṗ = ω × p on the nodes of `set`, or (with `field`) the
// velocities of a CSV file "node,vx,vy,vz[,pdx,pdy,pdz]" (0-based nodes; director rates optional, projected
// on the tangent plane of p). Later entries of a list override earlier ones on shared nodes.
struct InitialVelocitySpec {
  bool given = false;  // false: the body starts at rest
  std::string set = "all";
  std::string field;   // absolute path of a CSV velocity field; empty: rigid field
  // Mode shape of `shelldyn modes` (mode_shapes.csv): v = amplitude · φ_index (φ mass-normalised, so the
  // initial kinetic energy is ½ amplitude² when the set is `all`). Empty: no mode.
  std::string mode_file;
  int mode_index = 0;        // 1-based, the `mode` column of modes.csv / mode_shapes.csv
  double mode_amplitude = 0.0;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();
  bool about_centroid = true;  // true: about = centroid of the set's nodes
  Eigen::Vector3d about = Eigen::Vector3d::Zero();
  std::string where;
};

// force, moment: on the nodes of a node set. pressure (dead), follower_pressure: force per area on the
// elements of an element set (or of the elements whose 9 nodes are in a node set), along the normal.
// body_force: force per volume; gravity: acceleration (body force rho*g). docs/theory.md §8.
enum class LoadType { Force, Moment, Pressure, FollowerPressure, BodyForce, Gravity };
// per_node: the vector on every node; edge_total: the vector is the total, spread consistently over the
// set's element edges; per_length: the vector is a force per unit length on those edges.
enum class LoadDistribution { PerNode, EdgeTotal, PerLength };
const char* load_type_name(LoadType t);
const char* load_distribution_name(LoadDistribution d);

struct LoadSpec {
  std::string set;
  LoadType type = LoadType::Force;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // not normalised: the load is amplitude * direction
  double amplitude = 0;
  LoadDistribution distribution = LoadDistribution::PerNode;
  TimeFunction function;  // default constant
  std::string where;      // "FILE:LINE: loads[k]"
};

// Prescribed displacement history (docs/manual.md §2.12, docs/theory.md §8.6): each listed translation of every
// node of `set` follows u(t) = value * function(t), measured from the reference configuration. Director DOFs
// cannot follow a history (they can be held with boundary_conditions). The DOFs become constrained DOFs:
// their reactions are reported, and the work the prescribed motion does is a term of the energy balance.
struct PrescribedDisplacementSpec {
  std::string set;
  std::vector<int> components;  // 0, 1, 2 for ux, uy, uz (no repeats)
  double value = 0.0;           // length
  TimeFunction function;        // default constant
  std::string where;            // "FILE:LINE: prescribed_displacements[k]"
};

// Rayleigh damping C = mass * M_0 + stiffness * K_0 (docs/theory.md §8.5); both 0: none.
struct DampingSpec {
  double mass = 0.0;       // a_M [1/time]
  double stiffness = 0.0;  // a_K [time]
  std::string where;
};

struct IntegratorSpec {
  std::string name;
  std::vector<std::pair<std::string, std::string>> settings;  // in file order, values as written
  // "FILE:LINE" of the block and of each setting (parallel to `settings`), for errors that the
  // integrator raises later (integrators/runs/case_integrator.hpp); empty for specs not read from a file.
  std::string where;
  std::vector<std::string> setting_where;
};

struct TimeSpec {
  double dt = 0;
  double t_end = 0;
  double output_interval = 0;
  // Number of steps to reach t_end: round(t_end/dt) if t_end is a multiple of dt up to 1e-9
  // relative, else ceil(t_end/dt) (the last step is then shortened by the caller or overshoots).
  long long num_steps() const;
};

struct OutputSpec {
  bool vtu = true;
  int vtu_every = 10;  // write a VTU every this many output steps
  bool history = true;
};

// Rx, Ry, Rz: reaction forces at constrained DOFs (docs/theory.md §9.2).
enum class MonitorQuantity { Ux, Uy, Uz, Ur, Px, Py, Pz, Vx, Vy, Vz, Rx, Ry, Rz };
const char* monitor_quantity_name(MonitorQuantity q);
// None: the set must hold exactly one node; otherwise a reduction over the set's nodes.
enum class MonitorReduce { None, Sum, Mean, Max, Min };
const char* monitor_reduce_name(MonitorReduce r);

struct MonitorSpec {
  std::string name;
  std::string set;
  MonitorQuantity quantity = MonitorQuantity::Ux;
  MonitorReduce reduce = MonitorReduce::None;
  bool has_axis = false;  // ur about the axis through axis_point along axis_direction (else: from the origin)
  Eigen::Vector3d axis_point = Eigen::Vector3d::Zero(), axis_direction = Eigen::Vector3d::UnitZ();
  std::string where;
};

// Rigid bodies and joints (docs/manual.md "Rigid bodies and joints"; docs/theory/multibody.md §3, §4).
struct RigidBodySpec {
  std::string name;
  double mass = 0.0;
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero();  // principal inertias about the centre of mass
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // centre of mass at t = 0
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns d1, d2, d3 = d1 × d2 at t = 0
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero(), angular_velocity = Eigen::Vector3d::Zero();
  std::string where;
};
// One end of a joint: {set: S} (a one-node set), {body: B, at: [x,y,z]} (the body's point at x at t = 0) or
// {ground: [x,y,z]}.
struct JointEndSpec {
  enum class Kind { none, set, body, ground };
  Kind kind = Kind::none;
  std::string set, body;
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
  std::string where;
};
struct JointSpec {
  std::string name;
  std::string type;  // fixed_point, spherical, revolute, rigid_connection, prescribed_rotation
  JointEndSpec a, b;  // fixed_point: a; spherical, revolute: a and b
  std::string set;    // rigid_connection: every node of the set
  std::string body;   // rigid_connection, prescribed_rotation
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   // revolute, prescribed_rotation (space, t = 0)
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // prescribed_rotation
  TimeFunction angle;                                 // prescribed_rotation: θ(t) = amplitude · angle(t) [rad]
  double amplitude = 1.0;
  std::string where;
};

struct CaseSpec {
  std::string name;
  std::string description;
  std::string source;    // the case file path as given (or the label passed to load_case_from_string)
  std::string base_dir;  // folder that relative paths in the file are resolved against
  MeshSpec mesh;
  std::string mesh_where;
  CaseMaterial material;
  std::vector<SetSpec> sets;
  std::vector<BoundaryConditionSpec> boundary_conditions;
  InitialVelocitySpec initial_velocity;                 // the mapping form, or the first entry of the list form
  std::vector<InitialVelocitySpec> initial_velocity_more;  // further entries of the list form
  // initial_displacement: {field: FILE.vtu | FILE.csv}: the displacements and directors of a VTU written by
  // shelldyn, or a CSV "node,ux,uy,uz[,px,py,pz]" (docs/manual.md §2.6); empty: the reference configuration.
  std::string initial_displacement;
  std::string initial_displacement_where;
  std::vector<LoadSpec> loads;
  std::vector<PrescribedDisplacementSpec> prescribed_displacements;
  DampingSpec damping;
  IntegratorSpec integrator;
  TimeSpec time;
  OutputSpec output;
  std::vector<MonitorSpec> monitors;
  // gravity: [gx, gy, gz]: uniform gravity on the shell (a gravity load on `all`, added to `loads`) and on the
  // rigid bodies (m g). Zero if absent.
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  std::vector<RigidBodySpec> rigid_bodies;
  std::vector<JointSpec> joints;
  // plugins: [PATH.so, ...]: shared libraries that register integrators, loaded before the integrator is made
  // (integrators/runs/plugin.hpp); relative paths are resolved against base_dir. plugins_where: "FILE:LINE: plugins".
  std::vector<std::string> plugins;
  std::string plugins_where;
};

// Reads and validates a case file. Throws std::runtime_error ("FILE:LINE: key.path: reason") on
// any problem, including an unreadable file or YAML syntax errors.
CaseSpec load_case(const std::string& path);

// Same from text (tests, embedded cases). `source` labels error messages and gives the default name
// (its stem); relative mesh paths are resolved against `base_dir`.
CaseSpec load_case_from_string(const std::string& text, const std::string& source,
                               const std::string& base_dir = ".");

}  // namespace shelldyn
