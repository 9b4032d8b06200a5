#include "lib/model/discretization.hpp"
#include "lib/io/result_folder.hpp"

#include "lib/model/surface_loads.hpp"

#include "lib/mesh/gmsh_reader.hpp"
#include "lib/mesh/mesh_generators.hpp"
#include "lib/mesh/nodal_normals.hpp"
#include "lib/io/vtu_reader.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iostream>
#include <mutex>
#include <array>
#include <functional>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <variant>

namespace shelldyn {

namespace {

[[noreturn]] void fail(const std::string& where, const std::string& reason) {
  throw std::runtime_error(where + ": " + reason);
}

std::string fmt(const Vec3& x) {
  std::ostringstream os;
  os.precision(10);
  os << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
  return os.str();
}

// The lower-case extension of a path (".vtu", ".csv", or "").
std::string fs_extension(const std::string& path) {
  const size_t slash = path.find_last_of('/'), dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string available_sets(const Mesh& mesh) {
  std::string out;
  for (const auto& [name, nodes] : mesh.node_sets) out += (out.empty() ? "" : ", ") + name;
  return out;
}

const std::vector<int>& find_set(const Mesh& mesh, const std::string& name, const std::string& where) {
  auto it = mesh.node_sets.find(name);
  if (it == mesh.node_sets.end())
    fail(where, "unknown set '" + name + "' (define it under 'sets:' or use one below)\navailable: " +
                    available_sets(mesh));
  return it->second;
}

// A CSV of nodal 3- or 6-vectors with the header "node,<cols3>[,<cols6>]", 0-based node indices, any subset of
// the nodes (docs/manual.md §2.6): the velocity fields of initial_velocity (vx,vy,vz[,pdx,pdy,pdz]) and the
// displacement fields of initial_displacement (ux,uy,uz[,px,py,pz]). `what` names the file in messages;
// *with6 (if given) tells whether the file has the last three columns (they are 0 otherwise).
std::map<int, Eigen::Matrix<double, 6, 1>> read_node_csv(const std::string& path, int num_nodes, const std::string& where,
                                                         const std::string& what, const std::string& cols3,
                                                         const std::string& cols6, bool* with6) {
  try {
    require_regular_file(path, what);  // a FIFO would block the open forever (lib/io/result_folder.hpp)
  } catch (const std::exception& e) {
    fail(where, e.what());
  }
  std::ifstream in(path);
  if (!in) fail(where, "cannot open the " + what + " '" + path + "' (check the path; relative to the case file)");
  std::string line;
  std::getline(in, line);
  const bool with_director = std::count(line.begin(), line.end(), ',') >= 6;
  if (line.rfind("node", 0) != 0)
    fail(where, path + ":1: expected the header 'node," + cols3 + "' or 'node," + cols3 + "," + cols6 + "'");
  if (with6) *with6 = with_director;
  std::map<int, Eigen::Matrix<double, 6, 1>> out;
  for (int lineno = 2; std::getline(in, line); ++lineno) {
    if (line.empty()) continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream is(line);
    long long node = -1;
    Eigen::Matrix<double, 6, 1> v = Eigen::Matrix<double, 6, 1>::Zero();
    is >> node >> v[0] >> v[1] >> v[2];
    if (with_director) is >> v[3] >> v[4] >> v[5];
    if (!is || node < 0 || node >= num_nodes || !v.allFinite())
      fail(where, path + ":" + std::to_string(lineno) + ": expected a node index in [0, " + std::to_string(num_nodes) +
                      ") and " + (with_director ? "6" : "3") + " finite numbers");
    out[static_cast<int>(node)] = v;
  }
  return out;
}

// A velocity field (docs/manual.md §2.6): node -> (v, ṗ). Either a VTU written by shelldyn (point data
// `velocity` and, if present, `director_rate`; every node; its reference positions must be the mesh's) or a CSV
// "node,vx,vy,vz[,pdx,pdy,pdz]" (header line, 0-based node indices, any subset of the nodes).
std::map<int, Eigen::Matrix<double, 6, 1>> read_velocity_field(const std::string& path, const Mesh& mesh,
                                                               const std::string& where) {
  const int num_nodes = mesh.num_nodes();
  std::string ext = fs_extension(path);
  if (ext == ".vtu") {
    std::map<int, Eigen::Matrix<double, 6, 1>> out;
    try {
      const VtuPointData vtu = read_vtu(path);
      check_vtu_matches_mesh(vtu, mesh.X);
      const std::vector<Vec3> v = vtu.vectors("velocity");
      const std::vector<Vec3> pdot =
          vtu.has("director_rate") ? vtu.vectors("director_rate") : std::vector<Vec3>(v.size(), Vec3::Zero());
      for (int i = 0; i < num_nodes; ++i) {
        Eigen::Matrix<double, 6, 1> x;
        x << v[static_cast<size_t>(i)], pdot[static_cast<size_t>(i)];
        out[i] = x;
      }
    } catch (const std::runtime_error& e) {
      fail(where, e.what());
    }
    return out;
  }
  if (ext != ".csv")
    fail(where, "the velocity field '" + path + "' must be a .vtu or a .csv file (docs/manual.md §2.6)");
  return read_node_csv(path, num_nodes, where, "velocity field", "vx,vy,vz", "pdx,pdy,pdz", nullptr);
}

// Mode `index` (1-based) of a mode-shape file written by `shelldyn modes` (mode_shapes.csv:
// mode,node,ux,uy,uz,pdx,pdy,pdz; lib/analysis/modal_analysis.hpp), as a velocity field amplitude · φ in the format of
// read_velocity_field. Every node of the mesh must be in the file for that mode.
std::map<int, Eigen::Matrix<double, 6, 1>> read_mode_field(const std::string& path, int index, double amplitude,
                                                           int num_nodes, const std::string& where) {
  try {
    require_regular_file(path, "mode-shape file");
  } catch (const std::exception& e) {
    fail(where + ".mode", e.what());
  }
  std::ifstream in(path);
  if (!in)
    fail(where + ".mode", "cannot open the mode-shape file '" + path +
                              "' (write it with: shelldyn modes CASE -o DIR -> DIR/mode_shapes.csv; relative to the case file)");
  const std::string header = "mode,node,ux,uy,uz,pdx,pdy,pdz";
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != header)
    fail(where + ".mode", path + ":1: expected the header '" + header + "' (the mode_shapes.csv of shelldyn modes)");
  std::map<int, Eigen::Matrix<double, 6, 1>> out;
  long long max_mode = 0;
  for (int lineno = 2; std::getline(in, line); ++lineno) {
    if (line.empty() || line == "\r") continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream is(line);
    long long mode = -1, node = -1;
    Eigen::Matrix<double, 6, 1> v;
    is >> mode >> node >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5];
    if (!is || mode < 1 || node < 0 || !v.allFinite())
      fail(where + ".mode", path + ":" + std::to_string(lineno) + ": expected a mode number >= 1, a node index and 6 finite numbers");
    if (node >= num_nodes)
      fail(where + ".mode", path + ":" + std::to_string(lineno) + ": node " + std::to_string(node) + " is not in the mesh (" +
                                std::to_string(num_nodes) + " nodes): mode shapes of another mesh?");
    max_mode = std::max(max_mode, mode);
    if (mode != index) continue;
    if (out.count(static_cast<int>(node)))
      fail(where + ".mode", path + ":" + std::to_string(lineno) + ": node " + std::to_string(node) + " repeated for mode " +
                                std::to_string(index));
    out[static_cast<int>(node)] = amplitude * v;
  }
  if (out.empty())
    fail(where + ".index", "mode " + std::to_string(index) + " is not in " + path + " (it holds modes 1.." +
                               std::to_string(max_mode) + "; compute more with shelldyn modes -n)");
  if (static_cast<int>(out.size()) != num_nodes)
    fail(where + ".mode", path + " gives mode " + std::to_string(index) + " at " + std::to_string(out.size()) + " nodes, the mesh has " +
                              std::to_string(num_nodes) + " (mode shapes of another mesh?)");
  return out;
}

// Elements a distributed load acts on: the element set `name`, else the elements whose nine nodes all
// belong to the node set `name`.
std::vector<int> find_elements(const Mesh& mesh, const std::string& name, const std::string& where) {
  auto it = mesh.element_sets.find(name);
  if (it != mesh.element_sets.end()) return it->second;
  std::vector<int> elements = elements_within(mesh, find_set(mesh, name, where));
  if (elements.empty())
    fail(where, "no element has all its 9 nodes in set '" + name +
                    "' (a pressure or body force needs a set covering whole elements, e.g. 'all' or a box)");
  return elements;
}

// Adds the case's sets to mesh.node_sets. Unions may refer to sets defined later in the file, so sets
// are resolved on demand with a depth-first walk that reports cycles.
void resolve_case_sets(const CaseSpec& spec, Mesh& mesh, double mesh_size) {
  std::map<std::string, const SetSpec*> pending;
  for (const SetSpec& s : spec.sets) {
    if (mesh.node_sets.count(s.name))
      fail(s.where, "the mesh already has a node set '" + s.name + "' (choose another name)");
    pending[s.name] = &s;
  }
  std::set<std::string> in_progress;
  const int n = mesh.num_nodes();

  std::function<void(const SetSpec&)> resolve = [&](const SetSpec& s) {
    std::vector<int> nodes;
    switch (s.kind) {
      case SetSpec::Kind::Point: {
        const double tol = s.tol >= 0.0 ? s.tol : 1e-6 * mesh_size;
        int best = -1;
        double best_d = std::numeric_limits<double>::infinity();
        for (int i = 0; i < n; ++i) {
          const double d = (mesh.X[static_cast<size_t>(i)] - s.point).norm();
          if (d < best_d) best_d = d, best = i;
        }
        if (best < 0 || best_d > tol) {
          std::ostringstream os;
          os << "no node within tol = " << tol << " of the point " << fmt(s.point) << " (correct the point or set 'tol')";
          if (best >= 0)
            os << "\nthe nearest is node " << best << " at " << fmt(mesh.X[static_cast<size_t>(best)])
               << ", distance " << best_d;
          fail(s.where + ".point", os.str());
        }
        nodes.push_back(best);
        break;
      }
      case SetSpec::Kind::Box: {
        // Round-off tolerance, so that a box drawn exactly through a row of nodes catches it.
        const double eps = 1e-9 * mesh_size;
        for (int i = 0; i < n; ++i) {
          const Vec3& x = mesh.X[static_cast<size_t>(i)];
          if (((x - s.box_min).array() >= -eps).all() && ((s.box_max - x).array() >= -eps).all()) nodes.push_back(i);
        }
        if (nodes.empty())
          fail(s.where + ".box", "empty set: no node lies inside the box " + fmt(s.box_min) + " - " + fmt(s.box_max) +
                                     " (enlarge the box)");
        break;
      }
      case SetSpec::Kind::Nodes:
        for (int i : s.nodes) {
          if (i >= n)
            fail(s.where + ".nodes", "node index " + std::to_string(i) + " is out of range (the mesh has " +
                                         std::to_string(n) + " nodes, indices are 0-based)");
          nodes.push_back(i);
        }
        break;
      case SetSpec::Kind::Union:
        for (const std::string& member : s.members) {
          if (!mesh.node_sets.count(member)) {
            auto it = pending.find(member);
            if (it == pending.end()) find_set(mesh, member, s.where + ".union");  // throws: unknown set
            if (in_progress.count(member))
              fail(s.where + ".union", "set '" + member + "' is part of a cycle of unions (break the cycle)");
            in_progress.insert(member);
            resolve(*it->second);
            in_progress.erase(member);
          }
          const auto& m = mesh.node_sets.at(member);
          nodes.insert(nodes.end(), m.begin(), m.end());
        }
        break;
    }
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    mesh.node_sets[s.name] = std::move(nodes);
  };

  for (const SetSpec& s : spec.sets) {
    if (mesh.node_sets.count(s.name)) continue;  // already resolved as a member of a union
    in_progress.insert(s.name);
    resolve(s);
    in_progress.erase(s.name);
  }
}

// Consistent nodal weights of a uniform line load on the quadratic edges that lie entirely in
// `nodes` (docs/theory.md §4.1 shape functions restricted to an edge): w_k = ∫ N_k |dX/ds| ds, normalised
// to sum 1. A straight edge with a centred mid-node gets 1/6, 4/6, 1/6 of its length share.
std::map<int, double> edge_weights(const Mesh& mesh, const std::vector<int>& nodes, const std::string& where) {
  static const int kEdges[4][3] = {{0, 4, 1}, {1, 5, 2}, {2, 6, 3}, {3, 7, 0}};  // corner, mid, corner
  // 5-point Gauss–Legendre: exact for straight edges (polynomial degree 2) and accurate for curved ones.
  static const double gs[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                               0.9061798459386640};
  static const double gw[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                               0.2369268850561891};
  const std::set<int> in(nodes.begin(), nodes.end());
  std::set<std::array<int, 3>> done;
  std::map<int, double> w;
  double total = 0.0;
  for (const Quad9& el : mesh.elements) {
    for (const auto& e : kEdges) {
      const int a = el[static_cast<size_t>(e[0])], m = el[static_cast<size_t>(e[1])], b = el[static_cast<size_t>(e[2])];
      if (!in.count(a) || !in.count(m) || !in.count(b)) continue;
      if (!done.insert({std::min(a, b), m, std::max(a, b)}).second) continue;  // shared edge: count once
      const Vec3 &Xa = mesh.X[static_cast<size_t>(a)], &Xm = mesh.X[static_cast<size_t>(m)],
                 &Xb = mesh.X[static_cast<size_t>(b)];
      for (int g = 0; g < 5; ++g) {
        const double s = gs[g];
        const double Na = 0.5 * s * (s - 1.0), Nm = 1.0 - s * s, Nb = 0.5 * s * (s + 1.0);
        const Vec3 dX = (s - 0.5) * Xa - 2.0 * s * Xm + (s + 0.5) * Xb;
        const double jw = dX.norm() * gw[g];
        w[a] += Na * jw, w[m] += Nm * jw, w[b] += Nb * jw;
        total += jw;
      }
    }
  }
  if (w.empty() || !(total > 0.0))
    fail(where, "distribution edge_total needs element edges whose 3 nodes all belong to the set; there are none "
                "(use a set along an edge, or distribution: per_node)");
  for (auto& [node, value] : w) value /= total;
  return w;
}

}  // namespace

Mesh build_mesh(const CaseSpec& spec) {
  try {
    return std::visit(
        [](const auto& m) -> Mesh {
          using T = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<T, RectangleMeshSpec>)
            return make_rectangle(m.a, m.b, m.nx, m.ny, m.x0, m.y0);
          else if constexpr (std::is_same_v<T, CellUnionMeshSpec>)
            return make_cell_union(m.cells, m.cell);
          else if constexpr (std::is_same_v<T, CylindricalPanelMeshSpec>)
            return make_cylindrical_panel(m.radius, m.angle, m.length, m.n_arc, m.n_axial);
          else if constexpr (std::is_same_v<T, HemisphereMeshSpec>)
            return make_hemisphere(m.radius, m.hole_deg, m.quarter, m.n);
          else if constexpr (std::is_same_v<T, CylinderPatchMeshSpec>)
            return make_cylinder_patch(m.radius, m.angle, m.length, m.n_arc, m.n_axial);
          else if constexpr (std::is_same_v<T, ClosedCylinderMeshSpec>)
            return make_closed_cylinder(m.radius, m.length, m.n_circ, m.n_axial);
          else if constexpr (std::is_same_v<T, SlitAnnulusMeshSpec>)
            return make_slit_annulus(m.r_inner, m.r_outer, m.n_radial, m.n_circ);
          else
            return read_gmsh(m.path);
        },
        spec.mesh);
  } catch (const std::exception& e) {
    fail(spec.mesh_where, e.what());
  }
}

// Distinct nodes at one position (within 1e-9 of the mesh size), e.g. two meshed parts that the mesher did not
// merge: they share no DOF, so the parts are not connected. Pairs (a, b), a < b, sorted; found by sorting along x.
std::vector<std::pair<int, int>> coincident_node_pairs(const Mesh& mesh, double size) {
  const double tol = 1e-9 * std::max(size, 1e-300);
  std::vector<int> order(mesh.X.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return mesh.X[static_cast<size_t>(a)].x() < mesh.X[static_cast<size_t>(b)].x(); });
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < order.size(); ++i)
    for (size_t j = i + 1; j < order.size(); ++j) {
      const Vec3& a = mesh.X[static_cast<size_t>(order[i])];
      const Vec3& b = mesh.X[static_cast<size_t>(order[j])];
      if (b.x() - a.x() > tol) break;
      if ((a - b).norm() <= tol) pairs.emplace_back(std::min(order[i], order[j]), std::max(order[i], order[j]));
    }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

Discretization build_discretization(const CaseSpec& spec) {
  Discretization d;
  d.mesh = build_mesh(spec);
  Mesh& mesh = d.mesh;
  const int n = mesh.num_nodes();
  // Before the matrices are allocated: a model that cannot fit is refused with the estimate (lib/io/result_folder.hpp).
  try {
    check_memory_estimate(n, mesh.num_elements(), "",
                          "use a coarser mesh or raise --max-memory");
  } catch (const std::exception& e) {
    fail(spec.mesh_where, e.what());
  }
  try {
    orient_consistently(mesh);
    d.normals = initial_normals(mesh);
    check_orientation(mesh, d.normals);
    d.surface_area = surface_area(mesh);
  } catch (const std::exception& e) {
    fail(spec.mesh_where, e.what());
  }
  d.charts.reserve(static_cast<size_t>(n));
  for (const Vec3& p : d.normals) d.charts.push_back(select_chart(p));

  Vec3 lo = mesh.X.front(), hi = mesh.X.front();
  for (const Vec3& x : mesh.X) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  d.mesh_size = (hi - lo).norm();
  d.total_mass = spec.material.rho * spec.material.thickness * d.surface_area;

  // Coincident unmerged nodes (docs/guide/result-folders.md "Inputs"): a warning naming them, an error with
  // mesh.coincident_nodes: error.
  if (const auto pairs = coincident_node_pairs(mesh, d.mesh_size); !pairs.empty()) {
    std::string list;
    for (size_t k = 0; k < pairs.size() && k < 3; ++k)
      list += (k ? ", " : "") + std::to_string(pairs[k].first) + " & " + std::to_string(pairs[k].second);
    if (pairs.size() > 3) list += ", ...";
    const Vec3& x = mesh.X[static_cast<size_t>(pairs.front().first)];
    std::ostringstream at;
    at << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
    // Node numbers 0-based, as the point ids of the VTU output (Gmsh files: in ascending node-tag order).
    const std::string msg = std::to_string(pairs.size()) + " coincident node pairs not merged (" + list + ", first at " + at.str() +
                            "); merge them (Gmsh: Coherence Mesh)";
    const auto* file = std::get_if<MeshFileSpec>(&spec.mesh);
    if (file && file->coincident_nodes_error) fail(spec.mesh_where, msg);
    static std::mutex m;
    static std::set<std::string> warned;  // once per case and process (check builds the model twice)
    std::lock_guard<std::mutex> g(m);
    if (warned.insert(spec.mesh_where + msg).second)
      std::cerr << "warning: " << spec.mesh_where << ": " << msg << ": the parts are not connected (mesh.coincident_nodes: error refuses such meshes)" << std::endl;
  }

  resolve_case_sets(spec, mesh, d.mesh_size);

  // Boundary conditions (docs/theory.md §2.3 item 2): recorded by meaning, resolved for the initial charts.
  d.dofs = DofMap(n);
  for (const auto& bc : spec.boundary_conditions)
    for (int node : find_set(mesh, bc.set, bc.where + ".set"))
      for (Fix f : bc.fix) {
        // A fixed director component must be a minor one (a symmetry plane has p_k = 0); checked
        // here as well as in DofMap::resolve so that the message can point at the case-file entry.
        const int k = f == Fix::Px ? 0 : f == Fix::Py ? 1 : f == Fix::Pz ? 2 : -1;
        if (k >= 0 && d.charts[static_cast<size_t>(node)].l == k)
          fail(bc.where + ".fix", std::string("cannot fix ") + fix_name(f) + " at node " + std::to_string(node) +
                                      ": it is the largest director component there (p = " +
                                      fmt(d.normals[static_cast<size_t>(node)]) +
                                      "); only components that are 0 on a symmetry plane can be fixed (use 'director' to clamp)");
        d.dofs.fix(node, f);
      }
  // Prescribed displacement histories (docs/manual.md §2.12, docs/theory.md §8.6): constrained translations that
  // follow value · f(t). A DOF is held by one condition only: fixed, or prescribed once.
  static const char* const kTranslation[] = {"ux", "uy", "uz"};
  std::map<Index, size_t> prescribed_by;  // DOF -> prescribed_displacements entry
  for (size_t k = 0; k < spec.prescribed_displacements.size(); ++k) {
    const PrescribedDisplacementSpec& ps = spec.prescribed_displacements[k];
    for (int node : find_set(mesh, ps.set, ps.where + ".set"))
      for (int c : ps.components) {
        const Index dof = DofMap::dof(node, c);
        for (size_t b = 0; b < spec.boundary_conditions.size(); ++b) {
          const BoundaryConditionSpec& bc = spec.boundary_conditions[b];
          const Fix f = c == 0 ? Fix::Ux : c == 1 ? Fix::Uy : Fix::Uz;
          if (std::find(bc.fix.begin(), bc.fix.end(), f) == bc.fix.end()) continue;
          const std::vector<int>& held = find_set(mesh, bc.set, bc.where + ".set");
          if (std::find(held.begin(), held.end(), node) != held.end())
            fail(ps.where + ".dofs", std::string(kTranslation[c]) + " of node " + std::to_string(node) +
                                         " is also fixed by boundary_conditions[" + std::to_string(b) + "] (keep one of the two)");
        }
        const auto [it, fresh] = prescribed_by.emplace(dof, k);
        if (!fresh)
          fail(ps.where + ".dofs", std::string(kTranslation[c]) + " of node " + std::to_string(node) +
                                       " is also prescribed by prescribed_displacements[" + std::to_string(it->second) +
                                       "] (prescribe it once)");
        d.dofs.fix(node, c == 0 ? Fix::Ux : c == 1 ? Fix::Uy : Fix::Uz);
        d.prescribed.push_back({node, c, ps.value, ps.function});
      }
  }
  try {
    d.dofs.resolve(d.charts);
  } catch (const std::exception& e) {
    fail(spec.boundary_conditions.empty() ? spec.source : spec.boundary_conditions.front().where, e.what());
  }
  // ġ(0⁺) of each prescribed DOF: its initial velocity.
  std::map<Index, double> prescribed_rate;
  for (const DiscretePrescribed& pd : d.prescribed)
    prescribed_rate[DofMap::dof(pd.node, pd.component)] = pd.value * pd.function.rate(0.0);

  // Initial velocity (docs/manual.md §2.6): rigid-body fields v = v0 + ω × (X − about), ṗ = ω × p
  // (docs/benchmarks.md §6) on sets, or nodal values from a CSV file; later entries override earlier ones.
  d.initial_velocity = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n) * kDofsPerNode);
  d.initial_director_rate.assign(static_cast<size_t>(n), Vec3::Zero());
  std::vector<const InitialVelocitySpec*> parts;
  if (spec.initial_velocity.given) parts.push_back(&spec.initial_velocity);
  for (const auto& e : spec.initial_velocity_more) parts.push_back(&e);
  for (const InitialVelocitySpec* ivp : parts) {
    const InitialVelocitySpec& iv = *ivp;
    const std::vector<int>& nodes = find_set(mesh, iv.set, iv.where + ".set");
    double scale = 0.0;
    if (!iv.field.empty() || !iv.mode_file.empty()) {
      // A CSV field, or a mode shape of `shelldyn modes` scaled by the amplitude (same format once read).
      const auto field = iv.mode_file.empty()
                             ? read_velocity_field(iv.field, mesh, iv.where + ".field")
                             : read_mode_field(iv.mode_file, iv.mode_index, iv.mode_amplitude, n, iv.where);
      for (const auto& [node, vel] : field) {
        if (!std::binary_search(nodes.begin(), nodes.end(), node)) continue;
        const size_t si = static_cast<size_t>(node);
        const Eigen::Index base = static_cast<Eigen::Index>(DofMap::dof(node, 0));
        const Vec3 pdot = vel.tail<3>() - vel.tail<3>().dot(d.normals[si]) * d.normals[si];  // tangent to p
        d.initial_velocity.segment<3>(base) = vel.head<3>();
        d.initial_velocity.segment<2>(base + 3) = chart_coordinates(pdot, d.charts[si]);
        d.initial_director_rate[si] = vel.tail<3>();
        scale = std::max(scale, vel.norm());
      }
    } else {
      Vec3 about = iv.about;
      if (iv.about_centroid) {
        about.setZero();
        for (int i : nodes) about += mesh.X[static_cast<size_t>(i)];
        about /= static_cast<double>(nodes.size());
      }
      scale = iv.translation.norm() + iv.angular.norm() * std::max(d.mesh_size, 1.0);
      for (int i : nodes) {
        const size_t si = static_cast<size_t>(i);
        const Vec3 v = iv.translation + iv.angular.cross(mesh.X[si] - about);
        const Eigen::Vector2d qdot = chart_coordinates(iv.angular.cross(d.normals[si]), d.charts[si]);
        const Eigen::Index base = static_cast<Eigen::Index>(DofMap::dof(i, 0));
        d.initial_velocity.segment<3>(base) = v;
        d.initial_velocity.segment<2>(base + 3) = qdot;
        d.initial_director_rate[si] = iv.angular.cross(d.normals[si]);
      }
    }
    // A fixed DOF cannot start moving, and a prescribed one starts with its history's rate: refuse a different
    // value instead of silently overwriting the user's field.
    for (Index dof : d.dofs.constrained_dofs()) {
      const double value = d.initial_velocity[static_cast<Eigen::Index>(dof)];
      const auto pr = prescribed_rate.find(dof);
      const double expected = pr == prescribed_rate.end() ? 0.0 : pr->second;
      if (std::abs(value) > 1e-12 * scale && std::abs(value - expected) > 1e-12 * std::max(scale, std::abs(expected))) {
        std::ostringstream os;
        os << "the initial velocity is " << value << " at DOF " << dof % kDofsPerNode << " of node " << dof / kDofsPerNode;
        if (pr == prescribed_rate.end())
          os << ", which a boundary condition fixes (remove the condition or change the velocity)";
        else
          os << ", whose prescribed displacement starts with the rate " << expected
             << " (a prescribed DOF takes its history's rate: leave it out of the initial velocity)";
        fail(iv.where, os.str());
      }
    }
  }
  for (const auto& [dof, rate] : prescribed_rate) d.initial_velocity[static_cast<Eigen::Index>(dof)] = rate;

  // initial_displacement from a CSV (docs/manual.md §2.6; a VTU is read by Problem::initial_state): the listed
  // nodes' displacements and, with director columns, their unit directors. Fixed DOFs must keep their values.
  if (fs_extension(spec.initial_displacement) == ".csv") {
    const std::string& where = spec.initial_displacement_where;
    d.initial_displacement_from_csv = true;
    d.initial_displacement_field = read_node_csv(spec.initial_displacement, n, where, "displacement field", "ux,uy,uz",
                                                 "px,py,pz", &d.initial_displacement_directors);
    const double tol = 1e-12 * std::max(d.mesh_size, 1.0);
    for (auto& [node, x] : d.initial_displacement_field) {
      const size_t sn = static_cast<size_t>(node);
      for (int c = 0; c < 3; ++c) {
        const Index dof = DofMap::dof(node, c);
        if (d.dofs.is_constrained(dof) && !prescribed_rate.count(dof) && std::abs(x[c]) > tol)
          fail(where, spec.initial_displacement + ": node " + std::to_string(node) + " has " + kTranslation[c] + " = " +
                          std::to_string(x[c]) + ", which a boundary condition fixes at 0 (remove the condition or the value)");
      }
      if (!d.initial_displacement_directors) continue;
      const Vec3 p(x[3], x[4], x[5]);
      if (std::abs(p.norm() - 1.0) > 1e-6)
        fail(where, spec.initial_displacement + ": the director (px, py, pz) of node " + std::to_string(node) +
                        " has length " + std::to_string(p.norm()) + ", not 1 (give unit directors)");
      x.tail<3>() = p.normalized();
      const bool held = d.dofs.is_constrained(DofMap::dof(node, 3)) || d.dofs.is_constrained(DofMap::dof(node, 4));
      if (held && (x.tail<3>() - d.normals[sn]).norm() > 1e-9)
        fail(where, spec.initial_displacement + ": node " + std::to_string(node) +
                        " has a director other than its reference one, which a boundary condition holds (remove the "
                        "condition or give p = " + fmt(d.normals[sn]) + ")");
    }
  }

  // Loads.
  d.loads_end = 0.0;
  for (const LoadSpec& l : spec.loads) {
    const Vec3 vec = l.amplitude * l.direction;
    d.loads_end = std::max(d.loads_end, l.function.end_of_support());
    if (l.type != LoadType::Force && l.type != LoadType::Moment) {  // distributed loads (docs/theory.md §8.2–8.4)
      const std::vector<int> elements = find_elements(mesh, l.set, l.where + ".set");
      if (l.type == LoadType::FollowerPressure) {
        d.follower_pressures.push_back({elements, l.amplitude, l.function});
        continue;
      }
      const std::map<int, Vec3> f =
          l.type == LoadType::Pressure ? dead_pressure_forces(mesh, elements, l.amplitude)
          : l.type == LoadType::BodyForce
              ? body_forces(mesh, elements, vec, spec.material.thickness)
              : body_forces(mesh, elements, spec.material.rho * vec, spec.material.thickness);
      for (const auto& [node, force] : f) d.loads.push_back({node, LoadType::Force, force, l.function});
      continue;
    }
    const std::vector<int>& nodes = find_set(mesh, l.set, l.where + ".set");
    if (l.type == LoadType::Force)  // a prescribed DOF takes its reaction, not a load (docs/manual.md §2.12)
      for (int node : nodes)
        for (int c = 0; c < 3; ++c) {
          const auto it = prescribed_by.find(DofMap::dof(node, c));
          if (it != prescribed_by.end() && vec[c] != 0.0)
            fail(l.where + ".set", "force along " + std::string(kTranslation[c]) + " on node " + std::to_string(node) +
                                       ", which prescribed_displacements[" + std::to_string(it->second) +
                                       "] prescribes (drop one of the two)");
        }
    if (l.distribution == LoadDistribution::PerLength) {
      const std::map<int, Vec3> f = edge_line_forces(mesh, nodes, vec);
      if (f.empty())
        fail(l.where + ".distribution", "distribution per_length needs element edges whose 3 nodes all belong to "
                                        "the set; there are none (use a set along an edge)");
      for (const auto& [node, force] : f) d.loads.push_back({node, LoadType::Force, force, l.function});
    } else if (l.distribution == LoadDistribution::PerNode) {
      for (int node : nodes) d.loads.push_back({node, l.type, vec, l.function});
    } else {
      for (const auto& [node, w] : edge_weights(mesh, nodes, l.where + ".distribution"))
        d.loads.push_back({node, l.type, w * vec, l.function});
    }
  }

  for (const DiscretePrescribed& pd : d.prescribed) d.loads_end = std::max(d.loads_end, pd.function.end_of_variation());

  // Monitors.
  for (const MonitorSpec& m : spec.monitors) {
    const std::vector<int>& nodes = find_set(mesh, m.set, m.where + ".set");
    if (m.reduce == MonitorReduce::None && nodes.size() != 1)
      fail(m.where + ".set", "set '" + m.set + "' has " + std::to_string(nodes.size()) +
                                 " nodes, a monitor needs exactly one (define a set with 'point:', or add reduce: sum|mean|max|min)");
    for (int node : nodes) {
      const Vec3& X = mesh.X[static_cast<size_t>(node)];
      const Vec3 r = m.has_axis ? Vec3((X - m.axis_point) - (X - m.axis_point).dot(m.axis_direction) * m.axis_direction) : X;
      if (m.quantity == MonitorQuantity::Ur && r.norm() <= 1e-12 * std::max(d.mesh_size, 1.0))
        fail(m.where + ".quantity", std::string("ur is undefined at node ") + std::to_string(node) +
                                        (m.has_axis ? ", which lies on the axis" : " at the origin (give an axis, or use ux, uy or uz)"));
    }
    Monitor mon;
    mon.name = m.name;
    mon.node = nodes[0];
    mon.nodes = nodes;
    mon.quantity = m.quantity;
    mon.reduce = m.reduce;
    mon.has_axis = m.has_axis;
    mon.axis_point = m.axis_point;
    mon.axis_direction = m.axis_direction;
    d.monitors.push_back(std::move(mon));
  }
  return d;
}

namespace {

double node_value(const Monitor& m, int node, const Mesh& mesh, const Eigen::VectorXd& u, const Eigen::VectorXd& v,
                  const std::vector<DirectorChart>& charts, const Eigen::VectorXd* reactions) {
  const Eigen::Index base = static_cast<Eigen::Index>(DofMap::dof(node, 0));
  const int q = static_cast<int>(m.quantity);
  switch (m.quantity) {
    case MonitorQuantity::Ux:
    case MonitorQuantity::Uy:
    case MonitorQuantity::Uz:
      return u[base + q - static_cast<int>(MonitorQuantity::Ux)];
    case MonitorQuantity::Ur: {
      const Vec3& X = mesh.X[static_cast<size_t>(node)];
      const Vec3 r = m.has_axis ? Vec3((X - m.axis_point) - (X - m.axis_point).dot(m.axis_direction) * m.axis_direction) : X;
      return u.segment<3>(base).dot(r) / r.norm();
    }
    case MonitorQuantity::Px:
    case MonitorQuantity::Py:
    case MonitorQuantity::Pz: {
      const Eigen::Vector2d qn = u.segment<2>(base + 3);
      return director(qn, charts[static_cast<size_t>(node)])[q - static_cast<int>(MonitorQuantity::Px)];
    }
    case MonitorQuantity::Vx:
    case MonitorQuantity::Vy:
    case MonitorQuantity::Vz:
      return v[base + q - static_cast<int>(MonitorQuantity::Vx)];
    case MonitorQuantity::Rx:
    case MonitorQuantity::Ry:
    case MonitorQuantity::Rz:
      return reactions ? (*reactions)[base + q - static_cast<int>(MonitorQuantity::Rx)]
                       : std::numeric_limits<double>::quiet_NaN();
  }
  return 0.0;
}

}  // namespace

double monitor_value(const Monitor& m, const Mesh& mesh, const Eigen::VectorXd& u, const Eigen::VectorXd& v,
                     const std::vector<DirectorChart>& charts, const Eigen::VectorXd* reactions) {
  if (m.reduce == MonitorReduce::None || m.nodes.empty()) return node_value(m, m.node, mesh, u, v, charts, reactions);
  double acc = m.reduce == MonitorReduce::Max ? -std::numeric_limits<double>::infinity()
               : m.reduce == MonitorReduce::Min ? std::numeric_limits<double>::infinity()
                                                : 0.0;
  for (int node : m.nodes) {
    const double x = node_value(m, node, mesh, u, v, charts, reactions);
    if (m.reduce == MonitorReduce::Max) acc = std::max(acc, x);
    else if (m.reduce == MonitorReduce::Min) acc = std::min(acc, x);
    else acc += x;
  }
  return m.reduce == MonitorReduce::Mean ? acc / double(m.nodes.size()) : acc;
}

bool monitors_need_reactions(const std::vector<Monitor>& monitors) {
  for (const auto& m : monitors)
    if (m.quantity == MonitorQuantity::Rx || m.quantity == MonitorQuantity::Ry || m.quantity == MonitorQuantity::Rz)
      return true;
  return false;
}

}  // namespace shelldyn
