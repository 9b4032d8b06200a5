// Case-file parser (see lib/io/case_file.hpp for the schema). Every error goes through Parser::fail so
// that messages share the form "FILE:LINE: key.path: reason (how to fix)".
#include "lib/io/case_file.hpp"
#include "lib/io/result_folder.hpp"

#include "lib/io/history_writer.hpp"

#include "lib/io/yaml_checks.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace shelldyn {

namespace {

using yaml_checks::join;
using yaml_checks::node_kind;

// Names used as file/directory names and CSV columns: no separators, quotes or path tricks.
bool is_plain_name(const std::string& s) {
  if (s.empty() || s[0] == '.' || s[0] == '-') return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
           c == '.';
  });
}

class Parser {
 public:
  explicit Parser(std::string source) : source_(std::move(source)) {}

  std::string where(const YAML::Node& at, const std::string& path) const {
    std::ostringstream os;
    os << source_;
    const YAML::Mark m = at.Mark();
    if (!m.is_null()) os << ":" << m.line + 1;
    if (!path.empty()) os << ": " << path;
    return os.str();
  }

  [[noreturn]] void fail(const YAML::Node& at, const std::string& path, const std::string& reason) const {
    throw std::runtime_error(where(at, path) + ": " + reason);
  }

  // Checks that `map` is a mapping whose keys are all allowed, unique, and include all required keys.
  void check_keys(const YAML::Node& map, const std::string& path, const std::vector<std::string>& allowed,
                  const std::vector<std::string>& required) const {
    yaml_checks::check_keys(map, path, allowed, required,
                            [this](const YAML::Node& at, const std::string& p, const std::string& r) { fail(at, p, r); });
  }

  double number(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar() || n.Tag() == "!") fail(n, path, "expected a number, got a " + node_kind(n));
    double v = 0.0;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      fail(n, path, "expected a number, got '" + n.Scalar() + "'");
    }
    if (!std::isfinite(v)) fail(n, path, "expected a finite number, got '" + n.Scalar() + "'");
    return v;
  }

  double positive(const YAML::Node& n, const std::string& path) const {
    const double v = number(n, path);
    if (!(v > 0.0)) fail(n, path, "must be > 0, got " + n.Scalar());
    return v;
  }

  long long integer(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar() || n.Tag() == "!") fail(n, path, "expected an integer, got a " + node_kind(n));
    try {
      return n.as<long long>();
    } catch (const YAML::Exception&) {
      fail(n, path, "expected an integer, got '" + n.Scalar() + "'");
    }
  }

  int count(const YAML::Node& n, const std::string& path, long long min_value = 1) const {
    const long long v = integer(n, path);
    if (v < min_value || v > 100000000)
      fail(n, path, "must be an integer >= " + std::to_string(min_value) + ", got " + n.Scalar());
    return static_cast<int>(v);
  }

  bool boolean(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar() || n.Tag() == "!") fail(n, path, "expected true or false, got a " + node_kind(n));
    try {
      return n.as<bool>();
    } catch (const YAML::Exception&) {
      fail(n, path, "expected true or false, got '" + n.Scalar() + "'");
    }
  }

  std::string string(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar()) fail(n, path, "expected a text value, got a " + node_kind(n));
    return n.Scalar();
  }

  std::string name(const YAML::Node& n, const std::string& path) const {
    const std::string s = string(n, path);
    if (!is_plain_name(s))
      fail(n, path, "'" + s + "' is not a valid name (use letters, digits, '_', '-', '.'; not starting with '.' or '-')");
    return s;
  }

  // One of `choices`; returns its index.
  size_t choice(const YAML::Node& n, const std::string& path, const std::vector<std::string>& choices) const {
    const std::string s = string(n, path);
    for (size_t k = 0; k < choices.size(); ++k)
      if (s == choices[k]) return k;
    fail(n, path, "unknown value '" + s + "' (expected one of: " + join(choices) + ")");
  }

  void require_sequence(const YAML::Node& n, const std::string& path, const char* what) const {
    if (!n.IsSequence()) fail(n, path, std::string("expected a list of ") + what + ", got a " + node_kind(n));
  }

  Eigen::Vector3d vec3(const YAML::Node& n, const std::string& path) const {
    if (!n.IsSequence() || n.size() != 3)
      fail(n, path, "expected a list of 3 numbers [x, y, z], got a " + node_kind(n) +
                        (n.IsSequence() ? " of " + std::to_string(n.size()) + " entries" : ""));
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) v[k] = number(n[k], path + "[" + std::to_string(k) + "]");
    return v;
  }

  const std::string& source() const { return source_; }

 private:
  std::string source_;
};

// ---------------------------------------------------------------------------------------------------
MeshSpec parse_mesh(const Parser& p, const YAML::Node& n, const std::string& base_dir) {
  if (!n.IsMap()) p.fail(n, "mesh", "expected a mapping with 'generator' or 'file', got a " + node_kind(n));
  const bool has_gen = n["generator"].IsDefined(), has_file = n["file"].IsDefined();
  if (has_gen == has_file)
    p.fail(n, "mesh", has_gen ? "give either 'generator' or 'file', not both (remove one)"
                              : "missing 'generator' or 'file' (add one of them)");
  if (has_file) {
    p.check_keys(n, "mesh", {"file", "coincident_nodes"}, {"file"});
    const std::string file = p.string(n["file"], "mesh.file");
    fs::path path(file);
    if (path.is_relative()) path = fs::path(base_dir) / path;
    std::error_code ec;
    if (fs::exists(path, ec) && !fs::is_regular_file(path, ec))
      p.fail(n["file"], "mesh.file", "'" + path.string() + "' is not a regular file (a FIFO, device or folder); give the mesh file itself");
    if (!fs::is_regular_file(path, ec))
      p.fail(n["file"], "mesh.file", "cannot find '" + path.string() + "' (paths are relative to the case file)");
    MeshFileSpec m{fs::absolute(path).lexically_normal().string()};
    if (n["coincident_nodes"].IsDefined())
      m.coincident_nodes_error = p.choice(n["coincident_nodes"], "mesh.coincident_nodes", {"warn", "error"}) == 1;
    return m;
  }
  const YAML::Node gen = n["generator"];
  const size_t kind = p.choice(gen, "mesh.generator", {"rectangle", "cell_union", "cylindrical_panel", "hemisphere",
                                                       "cylinder_patch", "closed_cylinder", "slit_annulus"});
  switch (kind) {
    case 0: {
      p.check_keys(n, "mesh", {"generator", "a", "b", "nx", "ny", "x0", "y0"}, {"a", "b", "nx", "ny"});
      RectangleMeshSpec s;
      s.a = p.positive(n["a"], "mesh.a");
      s.b = p.positive(n["b"], "mesh.b");
      s.nx = p.count(n["nx"], "mesh.nx");
      s.ny = p.count(n["ny"], "mesh.ny");
      if (n["x0"]) s.x0 = p.number(n["x0"], "mesh.x0");
      if (n["y0"]) s.y0 = p.number(n["y0"], "mesh.y0");
      return s;
    }
    case 1: {
      p.check_keys(n, "mesh", {"generator", "cells", "cell"}, {"cells"});
      CellUnionMeshSpec s;
      const YAML::Node cells = n["cells"];
      p.require_sequence(cells, "mesh.cells", "[i0, j0, i1, j1] rectangles");
      if (cells.size() == 0) p.fail(cells, "mesh.cells", "empty list (give at least one rectangle [i0, j0, i1, j1])");
      for (size_t k = 0; k < cells.size(); ++k) {
        const std::string path = "mesh.cells[" + std::to_string(k) + "]";
        const YAML::Node c = cells[k];
        if (!c.IsSequence() || c.size() != 4)
          p.fail(c, path, "expected 4 integers [i0, j0, i1, j1], got a " + node_kind(c));
        std::array<int, 4> r{};
        for (int j = 0; j < 4; ++j) r[j] = static_cast<int>(p.integer(c[j], path + "[" + std::to_string(j) + "]"));
        if (r[2] <= r[0] || r[3] <= r[1]) p.fail(c, path, "needs i1 > i0 and j1 > j0 (cell units)");
        s.cells.push_back(r);
      }
      if (n["cell"]) s.cell = p.positive(n["cell"], "mesh.cell");
      return s;
    }
    case 2: {
      p.check_keys(n, "mesh", {"generator", "radius", "angle", "length", "n_arc", "n_axial"},
                   {"radius", "angle", "length", "n_arc", "n_axial"});
      CylindricalPanelMeshSpec s;
      s.radius = p.positive(n["radius"], "mesh.radius");
      s.angle = p.positive(n["angle"], "mesh.angle");
      if (s.angle >= 6.283185307179586) p.fail(n["angle"], "mesh.angle", "must be < 2 pi (total opening angle in radians)");
      s.length = p.positive(n["length"], "mesh.length");
      s.n_arc = p.count(n["n_arc"], "mesh.n_arc");
      s.n_axial = p.count(n["n_axial"], "mesh.n_axial");
      return s;
    }
    case 4: {
      p.check_keys(n, "mesh", {"generator", "radius", "angle", "length", "n_arc", "n_axial"},
                   {"radius", "angle", "length", "n_arc", "n_axial"});
      CylinderPatchMeshSpec s;
      s.radius = p.positive(n["radius"], "mesh.radius");
      s.angle = p.positive(n["angle"], "mesh.angle");
      if (s.angle > 3.141592653589793) p.fail(n["angle"], "mesh.angle", "must be <= pi (opening angle in radians from the plane Y = 0)");
      s.length = p.positive(n["length"], "mesh.length");
      s.n_arc = p.count(n["n_arc"], "mesh.n_arc");
      s.n_axial = p.count(n["n_axial"], "mesh.n_axial");
      return s;
    }
    case 5: {
      p.check_keys(n, "mesh", {"generator", "radius", "length", "n_circ", "n_axial"}, {"radius", "length", "n_circ", "n_axial"});
      ClosedCylinderMeshSpec s;
      s.radius = p.positive(n["radius"], "mesh.radius");
      s.length = p.positive(n["length"], "mesh.length");
      s.n_circ = p.count(n["n_circ"], "mesh.n_circ");
      s.n_axial = p.count(n["n_axial"], "mesh.n_axial");
      return s;
    }
    case 6: {
      p.check_keys(n, "mesh", {"generator", "r_inner", "r_outer", "n_radial", "n_circ"}, {"r_inner", "r_outer", "n_radial", "n_circ"});
      SlitAnnulusMeshSpec s;
      s.r_inner = p.positive(n["r_inner"], "mesh.r_inner");
      s.r_outer = p.positive(n["r_outer"], "mesh.r_outer");
      if (!(s.r_outer > s.r_inner)) p.fail(n["r_outer"], "mesh.r_outer", "must be > r_inner");
      s.n_radial = p.count(n["n_radial"], "mesh.n_radial");
      s.n_circ = p.count(n["n_circ"], "mesh.n_circ");
      return s;
    }
    default: {
      p.check_keys(n, "mesh", {"generator", "radius", "hole_deg", "quarter", "n"}, {"radius", "hole_deg", "n"});
      HemisphereMeshSpec s;
      s.radius = p.positive(n["radius"], "mesh.radius");
      s.hole_deg = p.number(n["hole_deg"], "mesh.hole_deg");
      if (s.hole_deg < 0.0 || s.hole_deg >= 90.0)
        p.fail(n["hole_deg"], "mesh.hole_deg", "must be in [0, 90) degrees (polar hole half-angle)");
      if (n["quarter"]) s.quarter = p.boolean(n["quarter"], "mesh.quarter");
      s.n = p.count(n["n"], "mesh.n");
      return s;
    }
  }
}

CaseMaterial parse_material(const Parser& p, const YAML::Node& n) {
  p.check_keys(n, "material", {"E", "nu", "rho", "thickness", "shear_factor"}, {"E", "nu", "rho", "thickness"});
  CaseMaterial m;
  m.E = p.positive(n["E"], "material.E");
  m.nu = p.number(n["nu"], "material.nu");
  if (!(m.nu > -1.0 && m.nu < 0.5)) p.fail(n["nu"], "material.nu", "Poisson ratio must be in (-1, 0.5)");
  m.rho = p.positive(n["rho"], "material.rho");
  m.thickness = p.positive(n["thickness"], "material.thickness");
  if (n["shear_factor"]) m.shear_factor = p.positive(n["shear_factor"], "material.shear_factor");
  return m;
}

std::vector<SetSpec> parse_sets(const Parser& p, const YAML::Node& n) {
  if (!n.IsMap()) p.fail(n, "sets", "expected a mapping NAME: {point|box|nodes|union: ...}, got a " + node_kind(n));
  std::vector<SetSpec> sets;
  std::set<std::string> names;
  for (auto it = n.begin(); it != n.end(); ++it) {
    SetSpec s;
    s.name = p.name(it->first, "sets");
    const std::string path = "sets." + s.name;
    if (!names.insert(s.name).second) p.fail(it->first, path, "set '" + s.name + "' is defined twice");
    const YAML::Node def = it->second;
    s.where = p.where(it->first, path);
    if (!def.IsMap()) p.fail(def, path, "expected a mapping with one of point, box, nodes, union; got a " + node_kind(def));
    const char* kinds[] = {"point", "box", "nodes", "union"};
    int found = 0;
    for (const char* k : kinds) found += def[k].IsDefined() ? 1 : 0;
    if (found != 1)
      p.fail(def, path, found == 0 ? "needs one of point, box, nodes, union" : "give only one of point, box, nodes, union");
    if (def["point"]) {
      p.check_keys(def, path, {"point", "tol"}, {"point"});
      s.kind = SetSpec::Kind::Point;
      s.point = p.vec3(def["point"], path + ".point");
      if (def["tol"]) s.tol = p.positive(def["tol"], path + ".tol");
    } else if (def["box"]) {
      p.check_keys(def, path, {"box"}, {"box"});
      s.kind = SetSpec::Kind::Box;
      const YAML::Node box = def["box"];
      if (!box.IsSequence() || box.size() != 2)
        p.fail(box, path + ".box", "expected [[xmin, ymin, zmin], [xmax, ymax, zmax]], got a " + node_kind(box));
      s.box_min = p.vec3(box[0], path + ".box[0]");
      s.box_max = p.vec3(box[1], path + ".box[1]");
      if ((s.box_max - s.box_min).minCoeff() < 0.0)
        p.fail(box, path + ".box", "the second corner must be >= the first in every component (swap them)");
    } else if (def["nodes"]) {
      p.check_keys(def, path, {"nodes"}, {"nodes"});
      s.kind = SetSpec::Kind::Nodes;
      const YAML::Node list = def["nodes"];
      p.require_sequence(list, path + ".nodes", "0-based node indices");
      if (list.size() == 0) p.fail(list, path + ".nodes", "empty set (list at least one node index)");
      for (size_t k = 0; k < list.size(); ++k) {
        const std::string ip = path + ".nodes[" + std::to_string(k) + "]";
        s.nodes.push_back(p.count(list[k], ip, 0));
      }
    } else {
      p.check_keys(def, path, {"union"}, {"union"});
      s.kind = SetSpec::Kind::Union;
      const YAML::Node list = def["union"];
      p.require_sequence(list, path + ".union", "set names");
      if (list.size() == 0) p.fail(list, path + ".union", "empty set (list at least one set name)");
      for (size_t k = 0; k < list.size(); ++k)
        s.members.push_back(p.name(list[k], path + ".union[" + std::to_string(k) + "]"));
    }
    sets.push_back(std::move(s));
  }
  return sets;
}

std::vector<BoundaryConditionSpec> parse_bcs(const Parser& p, const YAML::Node& n) {
  p.require_sequence(n, "boundary_conditions", "{set, fix} entries");
  std::vector<BoundaryConditionSpec> bcs;
  for (size_t k = 0; k < n.size(); ++k) {
    const std::string path = "boundary_conditions[" + std::to_string(k) + "]";
    const YAML::Node e = n[k];
    p.check_keys(e, path, {"set", "fix"}, {"set", "fix"});
    BoundaryConditionSpec bc;
    bc.where = p.where(e, path);
    bc.set = p.name(e["set"], path + ".set");
    const YAML::Node fix = e["fix"];
    p.require_sequence(fix, path + ".fix", "names (ux, uy, uz, px, py, pz, director)");
    if (fix.size() == 0) p.fail(fix, path + ".fix", "empty list (name at least one of ux, uy, uz, px, py, pz, director)");
    for (size_t j = 0; j < fix.size(); ++j) {
      const std::string fp = path + ".fix[" + std::to_string(j) + "]";
      const std::string s = p.string(fix[j], fp);
      try {
        bc.fix.push_back(parse_fix(s));
      } catch (const std::invalid_argument&) {
        p.fail(fix[j], fp, "unknown DOF name '" + s + "' (expected one of: ux, uy, uz, px, py, pz, director)");
      }
    }
    bcs.push_back(std::move(bc));
  }
  return bcs;
}

InitialVelocitySpec parse_initial_velocity(const Parser& p, const YAML::Node& n, const std::string& path,
                                           const std::string& base_dir) {
  p.check_keys(n, path, {"set", "translation", "angular", "about", "field", "mode", "index", "amplitude"}, {});
  InitialVelocitySpec v;
  v.given = true;
  v.where = p.where(n, path);
  if (n["set"]) v.set = p.name(n["set"], path + ".set");
  if (n["mode"]) {  // a mode shape of `shelldyn modes` (docs/manual.md §2.6)
    for (const char* k : {"translation", "angular", "about", "field"})
      if (n[k]) p.fail(n[k], path + "." + k, "give either 'mode' (with index, amplitude) or '" + std::string(k) + "', not both");
    for (const char* k : {"index", "amplitude"})
      if (!n[k]) p.fail(n, path + "." + k, std::string("missing required key '") + k + "' (a mode needs 'index' and 'amplitude')");
    fs::path file(p.string(n["mode"], path + ".mode"));
    if (file.is_relative()) file = fs::path(base_dir) / file;
    v.mode_file = file.lexically_normal().string();
    v.mode_index = p.count(n["index"], path + ".index", 1);
    v.mode_amplitude = p.number(n["amplitude"], path + ".amplitude");
    return v;
  }
  for (const char* k : {"index", "amplitude"})
    if (n[k]) p.fail(n[k], path + "." + k, "'" + std::string(k) + "' belongs to a mode shape: add 'mode: mode_shapes.csv' (written by shelldyn modes)");
  if (n["field"]) {
    for (const char* k : {"translation", "angular", "about"})
      if (n[k]) p.fail(n[k], path + "." + k, "give either 'field' or a rigid motion (translation/angular/about), not both");
    fs::path file(p.string(n["field"], path + ".field"));
    if (file.is_relative()) file = fs::path(base_dir) / file;
    v.field = file.lexically_normal().string();
    return v;
  }
  if (n["translation"]) v.translation = p.vec3(n["translation"], path + ".translation");
  if (n["angular"]) v.angular = p.vec3(n["angular"], path + ".angular");
  if (n["about"]) {
    const YAML::Node a = n["about"];
    if (a.IsScalar()) {
      if (a.Scalar() != "centroid")
        p.fail(a, path + ".about", "expected 'centroid' or a point [x, y, z], got '" + a.Scalar() + "'");
    } else {
      v.about_centroid = false;
      v.about = p.vec3(a, path + ".about");
    }
  }
  return v;
}

TimeFunction parse_function(const Parser& p, const YAML::Node& n, const std::string& path) {
  if (!n.IsMap()) p.fail(n, path, "expected a mapping {type: constant|ramp|hat|triangle|table|spin_up, ...}, got a " + node_kind(n));
  if (!n["type"]) p.fail(n, path + ".type", "missing required key 'type' (constant, ramp, hat, triangle, table or spin_up)");
  const size_t kind = p.choice(n["type"], path + ".type", {"constant", "ramp", "hat", "triangle", "table", "spin_up"});
  try {
    switch (kind) {
      case 0:
        p.check_keys(n, path, {"type"}, {"type"});
        return TimeFunction::constant();
      case 1:
        p.check_keys(n, path, {"type", "t1"}, {"type", "t1"});
        return TimeFunction::ramp(p.positive(n["t1"], path + ".t1"));
      case 2:
        p.check_keys(n, path, {"type", "t1"}, {"type", "t1"});
        return TimeFunction::hat(p.positive(n["t1"], path + ".t1"));
      case 3:
        p.check_keys(n, path, {"type", "t_peak", "t_end"}, {"type", "t_peak", "t_end"});
        return TimeFunction::triangle(p.positive(n["t_peak"], path + ".t_peak"),
                                      p.positive(n["t_end"], path + ".t_end"));
      case 5:
        p.check_keys(n, path, {"type", "T_s"}, {"type", "T_s"});
        return TimeFunction::spin_up(p.positive(n["T_s"], path + ".T_s"));
      default: {
        p.check_keys(n, path, {"type", "points"}, {"type", "points"});
        const YAML::Node pts = n["points"];
        p.require_sequence(pts, path + ".points", "[t, f] pairs");
        std::vector<std::pair<double, double>> points;
        for (size_t k = 0; k < pts.size(); ++k) {
          const std::string pp = path + ".points[" + std::to_string(k) + "]";
          if (!pts[k].IsSequence() || pts[k].size() != 2) p.fail(pts[k], pp, "expected a pair [t, f], got a " + node_kind(pts[k]));
          points.emplace_back(p.number(pts[k][0], pp + "[0]"), p.number(pts[k][1], pp + "[1]"));
        }
        return TimeFunction::table(std::move(points));
      }
    }
  } catch (const std::invalid_argument& e) {
    p.fail(n, path, std::string(e.what()) + " (fix the parameters)");
  }
}

std::vector<LoadSpec> parse_loads(const Parser& p, const YAML::Node& n) {
  p.require_sequence(n, "loads", "load entries");
  std::vector<LoadSpec> loads;
  for (size_t k = 0; k < n.size(); ++k) {
    const std::string path = "loads[" + std::to_string(k) + "]";
    const YAML::Node e = n[k];
    if (!e.IsMap()) p.fail(e, path, "expected a mapping {set, type, ...}, got a " + node_kind(e));
    if (!e["type"]) p.fail(e, path + ".type", "missing required key 'type' (force, moment, pressure, follower_pressure, body_force or gravity)");
    LoadSpec l;
    l.type = static_cast<LoadType>(p.choice(
        e["type"], path + ".type", {"force", "moment", "pressure", "follower_pressure", "body_force", "gravity"}));
    const bool nodal = l.type == LoadType::Force || l.type == LoadType::Moment;
    const bool pressure = l.type == LoadType::Pressure || l.type == LoadType::FollowerPressure;
    if (nodal)
      p.check_keys(e, path, {"set", "type", "direction", "amplitude", "distribution", "function"},
                   {"set", "type", "direction", "amplitude"});
    else if (pressure)
      p.check_keys(e, path, {"set", "type", "amplitude", "function"}, {"type", "amplitude"});
    else
      p.check_keys(e, path, {"set", "type", "direction", "amplitude", "function"}, {"type", "direction", "amplitude"});
    l.where = p.where(e, path);
    l.set = e["set"] ? p.name(e["set"], path + ".set") : std::string("all");
    if (!pressure) {
      l.direction = p.vec3(e["direction"], path + ".direction");
      if (l.direction.norm() == 0.0) p.fail(e["direction"], path + ".direction", "must not be the zero vector");
    }
    l.amplitude = p.number(e["amplitude"], path + ".amplitude");
    if (e["distribution"])
      l.distribution = static_cast<LoadDistribution>(
          p.choice(e["distribution"], path + ".distribution", {"per_node", "edge_total", "per_length"}));
    if (l.type == LoadType::Moment && l.distribution == LoadDistribution::PerLength)
      p.fail(e["distribution"], path + ".distribution", "per_length applies to forces only (use per_node or edge_total)");
    if (e["function"]) l.function = parse_function(p, e["function"], path + ".function");
    loads.push_back(std::move(l));
  }
  return loads;
}

// prescribed_displacements (docs/manual.md §2.12).
std::vector<PrescribedDisplacementSpec> parse_prescribed(const Parser& p, const YAML::Node& n) {
  p.require_sequence(n, "prescribed_displacements", "{set, dofs, value, [function]} entries");
  std::vector<PrescribedDisplacementSpec> out;
  for (size_t k = 0; k < n.size(); ++k) {
    const std::string path = "prescribed_displacements[" + std::to_string(k) + "]";
    const YAML::Node e = n[k];
    p.check_keys(e, path, {"set", "dofs", "value", "function"}, {"set", "dofs", "value"});
    PrescribedDisplacementSpec d;
    d.where = p.where(e, path);
    d.set = p.name(e["set"], path + ".set");
    const YAML::Node dofs = e["dofs"];
    p.require_sequence(dofs, path + ".dofs", "DOF names (ux, uy, uz)");
    if (dofs.size() == 0) p.fail(dofs, path + ".dofs", "empty list (name at least one of ux, uy, uz)");
    for (size_t j = 0; j < dofs.size(); ++j) {
      const std::string dp = path + ".dofs[" + std::to_string(j) + "]";
      const std::string name = p.string(dofs[j], dp);
      int c = -1;
      if (name == "ux") c = 0;
      else if (name == "uy") c = 1;
      else if (name == "uz") c = 2;
      else if (name == "px" || name == "py" || name == "pz" || name == "director")
        p.fail(dofs[j], dp, "director DOF '" + name + "' cannot follow a history: only ux, uy, uz can (hold the director "
                            "with boundary_conditions: [{set: " + d.set + ", fix: [director]}])");
      else
        p.fail(dofs[j], dp, "unknown DOF name '" + name + "' (expected one of: ux, uy, uz)");
      if (std::find(d.components.begin(), d.components.end(), c) != d.components.end())
        p.fail(dofs[j], dp, "'" + name + "' is listed twice (keep only one)");
      d.components.push_back(c);
    }
    d.value = p.number(e["value"], path + ".value");
    if (e["function"]) d.function = parse_function(p, e["function"], path + ".function");
    out.push_back(std::move(d));
  }
  return out;
}

DampingSpec parse_damping(const Parser& p, const YAML::Node& n) {
  p.check_keys(n, "damping", {"mass", "stiffness"}, {});
  DampingSpec d;
  d.where = p.where(n, "damping");
  for (const char* key : {"mass", "stiffness"}) {
    if (!n[key]) continue;
    const double v = p.number(n[key], std::string("damping.") + key);
    if (v < 0.0) p.fail(n[key], std::string("damping.") + key, "must be >= 0 (a negative coefficient would add energy)");
    (std::string(key) == "mass" ? d.mass : d.stiffness) = v;
  }
  return d;
}

IntegratorSpec parse_integrator(const Parser& p, const YAML::Node& n) {
  if (!n.IsMap()) p.fail(n, "integrator", "expected a mapping {name: ..., settings...}, got a " + node_kind(n));
  if (!n["name"]) p.fail(n, "integrator.name", "missing required key 'name' (e.g. name: em-galpha)");
  IntegratorSpec s;
  s.name = p.name(n["name"], "integrator.name");
  s.where = p.where(n["name"], "");
  std::set<std::string> seen;
  for (auto it = n.begin(); it != n.end(); ++it) {
    const std::string key = p.string(it->first, "integrator");
    const std::string path = "integrator." + key;
    if (!seen.insert(key).second) p.fail(it->first, path, "duplicate key '" + key + "' (keep only one)");
    if (key == "name") continue;
    if (!it->second.IsScalar())
      p.fail(it->second, path, "integrator settings must be single values, got a " + node_kind(it->second));
    s.settings.emplace_back(key, it->second.Scalar());
    s.setting_where.push_back(p.where(it->first, ""));
  }
  return s;
}

TimeSpec parse_time(const Parser& p, const YAML::Node& n) {
  p.check_keys(n, "time", {"dt", "t_end", "output_interval"}, {"dt", "t_end"});
  TimeSpec t;
  t.dt = p.positive(n["dt"], "time.dt");
  t.t_end = p.positive(n["t_end"], "time.t_end");
  if (t.dt > t.t_end) p.fail(n["dt"], "time.dt", "dt must not exceed t_end");
  // A step count that no run can reach (and that would overflow the step counters) is a typo.
  if (t.t_end / t.dt > 1e10)
    p.fail(n["t_end"], "time.t_end", "t_end/dt is more than 1e10 steps; check t_end and dt");
  t.output_interval = t.dt;
  if (n["output_interval"]) {
    t.output_interval = p.positive(n["output_interval"], "time.output_interval");
    if (t.output_interval < t.dt * (1.0 - 1e-12))
      p.fail(n["output_interval"], "time.output_interval", "must be >= dt (or omit it to output every step)");
  }
  return t;
}

OutputSpec parse_output(const Parser& p, const YAML::Node& n) {
  p.check_keys(n, "output", {"vtu", "vtu_every", "history"}, {});
  OutputSpec o;
  if (n["vtu"]) o.vtu = p.boolean(n["vtu"], "output.vtu");
  if (n["vtu_every"]) o.vtu_every = p.count(n["vtu_every"], "output.vtu_every");
  if (n["history"]) o.history = p.boolean(n["history"], "output.history");
  return o;
}

std::vector<MonitorSpec> parse_monitors(const Parser& p, const YAML::Node& n) {
  p.require_sequence(n, "monitors", "{name, set, quantity} entries");
  const auto& reserved = history_standard_columns();
  std::vector<MonitorSpec> monitors;
  std::set<std::string> names;
  for (size_t k = 0; k < n.size(); ++k) {
    const std::string path = "monitors[" + std::to_string(k) + "]";
    const YAML::Node e = n[k];
    p.check_keys(e, path, {"name", "set", "quantity", "reduce", "axis"}, {"name", "set", "quantity"});
    MonitorSpec m;
    m.where = p.where(e, path);
    m.name = p.name(e["name"], path + ".name");
    if (std::find(reserved.begin(), reserved.end(), m.name) != reserved.end())
      p.fail(e["name"], path + ".name", "'" + m.name + "' is a standard history.csv column (choose another name)");
    if (!names.insert(m.name).second) p.fail(e["name"], path + ".name", "monitor '" + m.name + "' is defined twice");
    m.set = p.name(e["set"], path + ".set");
    m.quantity = static_cast<MonitorQuantity>(
        p.choice(e["quantity"], path + ".quantity",
                 {"ux", "uy", "uz", "ur", "px", "py", "pz", "vx", "vy", "vz", "rx", "ry", "rz"}));
    if (e["reduce"])
      m.reduce = static_cast<MonitorReduce>(
          p.choice(e["reduce"], path + ".reduce", {"none", "sum", "mean", "max", "min"}));
    if (e["axis"]) {
      const YAML::Node a = e["axis"];
      if (m.quantity != MonitorQuantity::Ur)
        p.fail(a, path + ".axis", "only quantity ur has an axis (remove 'axis' or use quantity: ur)");
      p.check_keys(a, path + ".axis", {"point", "direction"}, {"point", "direction"});
      m.has_axis = true;
      m.axis_point = p.vec3(a["point"], path + ".axis.point");
      m.axis_direction = p.vec3(a["direction"], path + ".axis.direction");
      if (m.axis_direction.norm() == 0.0) p.fail(a["direction"], path + ".axis.direction", "must not be the zero vector");
      m.axis_direction.normalize();
    }
    monitors.push_back(std::move(m));
  }
  return monitors;
}

// ---- rigid bodies and joints (docs/manual.md "Rigid bodies and joints") ----------------------------------
std::vector<RigidBodySpec> parse_rigid_bodies(const Parser& p, const YAML::Node& n) {
  if (!n.IsMap() || n.size() == 0)
    p.fail(n, "rigid_bodies", "expected a mapping NAME: {mass, inertia, ...} with at least one body, got a " + node_kind(n));
  std::vector<RigidBodySpec> out;
  for (const auto& kv : n) {
    const std::string path = "rigid_bodies." + kv.first.Scalar();
    RigidBodySpec b;
    b.name = p.name(kv.first, path);
    const YAML::Node m = kv.second;
    if (!m.IsMap()) p.fail(m, path, "expected a mapping {mass, inertia, [position], [axes], [velocity], [angular_velocity]}");
    p.check_keys(m, path, {"mass", "inertia", "position", "axes", "velocity", "angular_velocity"}, {"mass", "inertia"});
    b.where = p.where(m, path);
    b.mass = p.number(m["mass"], path + ".mass");
    if (!(b.mass > 0.0)) p.fail(m["mass"], path + ".mass", "must be > 0, got " + m["mass"].Scalar() + " (a body needs a mass)");
    b.inertia = p.vec3(m["inertia"], path + ".inertia");
    for (int k = 0; k < 3; ++k)
      if (!(b.inertia[k] > 0.0))
        p.fail(m["inertia"], path + ".inertia", "principal inertias must be > 0 (give J1, J2, J3 about the centre of mass)");
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      if (b.inertia[i] > b.inertia[j] + b.inertia[k])
        p.fail(m["inertia"], path + ".inertia",
               "J" + std::to_string(i + 1) + " = " + m["inertia"][i].Scalar() + " exceeds J" + std::to_string(j + 1) + " + J" +
                   std::to_string(k + 1) + ": no body has these principal inertias (triangle inequality)");
    }
    if (m["position"]) b.position = p.vec3(m["position"], path + ".position");
    if (m["velocity"]) b.velocity = p.vec3(m["velocity"], path + ".velocity");
    if (m["angular_velocity"]) b.angular_velocity = p.vec3(m["angular_velocity"], path + ".angular_velocity");
    if (m["axes"]) {
      const YAML::Node a = m["axes"];
      if (!a.IsSequence() || a.size() != 2) p.fail(a, path + ".axes", "expected [d1, d2], two orthonormal 3-vectors");
      const Eigen::Vector3d d1 = p.vec3(a[0], path + ".axes[0]"), d2 = p.vec3(a[1], path + ".axes[1]");
      if (std::abs(d1.norm() - 1.0) > 1e-6 || std::abs(d2.norm() - 1.0) > 1e-6 || std::abs(d1.dot(d2)) > 1e-6)
        p.fail(a, path + ".axes", "d1 and d2 must be unit vectors normal to each other (to 1e-6)");
      // Orthonormalized to round-off, so the frame constraints hold at t = 0 (multibody.md (3.3)).
      const Eigen::Vector3d e1 = d1.normalized(), e2 = (d2 - d2.dot(e1) * e1).normalized();
      b.axes.col(0) = e1;
      b.axes.col(1) = e2;
      b.axes.col(2) = e1.cross(e2);
    }
    out.push_back(std::move(b));
  }
  return out;
}

JointEndSpec parse_joint_end(const Parser& p, const YAML::Node& n, const std::string& path,
                             const std::vector<RigidBodySpec>& bodies) {
  JointEndSpec e;
  e.where = p.where(n, path);
  if (!n.IsMap()) p.fail(n, path, "expected {set: S} | {body: B, at: [x,y,z]} | {ground: [x,y,z]}, got a " + node_kind(n));
  if (n["set"]) {
    p.check_keys(n, path, {"set"}, {"set"});
    e.kind = JointEndSpec::Kind::set;
    e.set = p.string(n["set"], path + ".set");
  } else if (n["body"]) {
    p.check_keys(n, path, {"body", "at"}, {"body", "at"});
    e.kind = JointEndSpec::Kind::body;
    e.body = p.string(n["body"], path + ".body");
    e.at = p.vec3(n["at"], path + ".at");
  } else if (n["ground"]) {
    p.check_keys(n, path, {"ground"}, {"ground"});
    e.kind = JointEndSpec::Kind::ground;
    e.at = p.vec3(n["ground"], path + ".ground");
  } else {
    p.fail(n, path, "expected one of {set: S}, {body: B, at: [x,y,z]} or {ground: [x,y,z]}");
  }
  if (e.kind == JointEndSpec::Kind::body) {
    std::vector<std::string> names;
    for (const auto& b : bodies) names.push_back(b.name);
    if (std::find(names.begin(), names.end(), e.body) == names.end())
      p.fail(n["body"], path + ".body",
             "unknown rigid body '" + e.body + "' (" + (names.empty() ? std::string("define it under rigid_bodies:") : "defined: " + join(names)) + ")");
  }
  return e;
}

std::vector<JointSpec> parse_joints(const Parser& p, const YAML::Node& n, const std::vector<RigidBodySpec>& bodies) {
  p.require_sequence(n, "joints", "joint entries");
  std::vector<JointSpec> out;
  std::vector<std::string> body_names;
  for (const auto& b : bodies) body_names.push_back(b.name);
  auto body_ref = [&](const YAML::Node& at, const std::string& path) {
    const std::string b = p.string(at, path);
    if (std::find(body_names.begin(), body_names.end(), b) == body_names.end())
      p.fail(at, path, "unknown rigid body '" + b + "' (" +
                           (body_names.empty() ? std::string("define it under rigid_bodies:") : "defined: " + join(body_names)) + ")");
    return b;
  };
  for (size_t k = 0; k < n.size(); ++k) {
    const std::string path = "joints[" + std::to_string(k) + "]";
    const YAML::Node j = n[k];
    if (!j.IsMap()) p.fail(j, path, "expected a mapping {name, type, ...}, got a " + node_kind(j));
    if (!j["type"])
      p.fail(j, path + ".type", "missing required key 'type' (fixed_point, spherical, revolute, rigid_connection or prescribed_rotation)");
    JointSpec s;
    s.where = p.where(j, path);
    const std::vector<std::string> types = {"fixed_point", "spherical", "revolute", "rigid_connection", "prescribed_rotation"};
    s.type = types[p.choice(j["type"], path + ".type", types)];
    if (s.type == "fixed_point") {
      p.check_keys(j, path, {"name", "type", "set", "body", "at"}, {"name", "type"});
      if (j["set"] && !j["body"] && !j["at"]) {
        s.a.kind = JointEndSpec::Kind::set;
        s.a.set = p.string(j["set"], path + ".set");
      } else if (j["body"] && j["at"] && !j["set"]) {
        s.a.kind = JointEndSpec::Kind::body;
        s.a.body = body_ref(j["body"], path + ".body");
        s.a.at = p.vec3(j["at"], path + ".at");
      } else {
        p.fail(j, path, "a fixed_point needs either `set` (a one-node set) or `body` and `at`");
      }
      s.a.where = s.where;
    } else if (s.type == "spherical" || s.type == "revolute") {
      if (s.type == "spherical") p.check_keys(j, path, {"name", "type", "a", "b"}, {"name", "type", "a", "b"});
      else p.check_keys(j, path, {"name", "type", "a", "b", "axis"}, {"name", "type", "a", "b", "axis"});
      s.a = parse_joint_end(p, j["a"], path + ".a", bodies);
      s.b = parse_joint_end(p, j["b"], path + ".b", bodies);
      if (s.type == "revolute") {
        s.axis = p.vec3(j["axis"], path + ".axis");
        if (!(s.axis.norm() > 0.0)) p.fail(j["axis"], path + ".axis", "must not be the zero vector");
      }
    } else if (s.type == "rigid_connection") {
      p.check_keys(j, path, {"name", "type", "set", "body"}, {"name", "type", "set", "body"});
      s.set = p.string(j["set"], path + ".set");
      s.body = body_ref(j["body"], path + ".body");
    } else {
      p.check_keys(j, path, {"name", "type", "body", "point", "axis", "angle", "amplitude"},
                   {"name", "type", "body", "point", "axis", "angle"});
      s.body = body_ref(j["body"], path + ".body");
      s.point = p.vec3(j["point"], path + ".point");
      s.axis = p.vec3(j["axis"], path + ".axis");
      if (!(s.axis.norm() > 0.0)) p.fail(j["axis"], path + ".axis", "must not be the zero vector");
      s.angle = parse_function(p, j["angle"], path + ".angle");
      if (j["amplitude"]) s.amplitude = p.number(j["amplitude"], path + ".amplitude");
    }
    s.name = p.name(j["name"], path + ".name");
    for (const auto& o : out)
      if (o.name == s.name) p.fail(j["name"], path + ".name", "joint name '" + s.name + "' is used twice (names must be unique)");
    out.push_back(std::move(s));
  }
  return out;
}

CaseSpec parse_document(const Parser& p, const YAML::Node& root, const std::string& base_dir) {
  if (!root.IsDefined() || root.IsNull()) p.fail(root, "", "the case file is empty (see apps/cases/ for examples)");
  p.check_keys(root, "",
               {"name", "description", "mesh", "material", "sets", "boundary_conditions", "initial_velocity", "initial_displacement", "loads",
                "prescribed_displacements", "damping", "integrator", "time", "output", "monitors", "plugins",
                "gravity", "rigid_bodies", "joints"},
               {"mesh", "material", "integrator", "time"});
  CaseSpec c;
  c.source = p.source();
  c.base_dir = base_dir;
  if (root["name"]) {
    c.name = p.name(root["name"], "name");
  } else {
    c.name = fs::path(p.source()).stem().string();
    if (!is_plain_name(c.name))
      p.fail(root, "name", "the file name '" + c.name + "' is not a valid case name (add a 'name:' key)");
  }
  if (root["description"]) c.description = p.string(root["description"], "description");
  c.mesh_where = p.where(root["mesh"], "mesh");
  c.mesh = parse_mesh(p, root["mesh"], base_dir);
  c.material = parse_material(p, root["material"]);
  if (root["sets"]) c.sets = parse_sets(p, root["sets"]);
  if (root["boundary_conditions"]) c.boundary_conditions = parse_bcs(p, root["boundary_conditions"]);
  if (root["initial_velocity"]) {
    const YAML::Node iv = root["initial_velocity"];
    if (iv.IsSequence()) {
      if (iv.size() == 0) p.fail(iv, "initial_velocity", "empty list (omit the key to start at rest)");
      for (size_t k = 0; k < iv.size(); ++k) {
        InitialVelocitySpec e = parse_initial_velocity(p, iv[k], "initial_velocity[" + std::to_string(k) + "]", base_dir);
        if (k == 0) c.initial_velocity = std::move(e);
        else c.initial_velocity_more.push_back(std::move(e));
      }
    } else {
      c.initial_velocity = parse_initial_velocity(p, iv, "initial_velocity", base_dir);
    }
  }
  if (root["initial_displacement"]) {  // docs/manual.md §2.6
    const YAML::Node id = root["initial_displacement"];
    if (!id.IsMap()) p.fail(id, "initial_displacement", "expected a mapping {field: FILE.vtu | FILE.csv}, got a " + node_kind(id));
    p.check_keys(id, "initial_displacement", {"field"}, {"field"});
    fs::path file(p.string(id["field"], "initial_displacement.field"));
    std::string ext = file.extension().string();
    for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (ext != ".vtu" && ext != ".csv")
      p.fail(id["field"], "initial_displacement.field",
             "'" + file.string() + "' is neither a .vtu nor a .csv file: give a fields/step_NNNNNN.vtu written by shelldyn "
             "or a CSV node,ux,uy,uz[,px,py,pz]");
    if (file.is_relative()) file = fs::path(base_dir) / file;
    c.initial_displacement = file.lexically_normal().string();
    c.initial_displacement_where = p.where(id, "initial_displacement.field");
    const auto rigid_or_mode = [](const InitialVelocitySpec& v) { return v.given && v.field.empty(); };
    bool bad = rigid_or_mode(c.initial_velocity);
    for (const auto& e : c.initial_velocity_more) bad = bad || rigid_or_mode(e);
    if (bad)
      p.fail(id, "initial_displacement",
             "the initial velocity must then be a field (e.g. the same VTU), not a rigid motion or mode");
  }
  if (root["loads"]) c.loads = parse_loads(p, root["loads"]);
  if (root["gravity"]) {  // uniform gravity: a gravity load on the whole shell, m g on the bodies
    c.gravity = p.vec3(root["gravity"], "gravity");
    if (c.gravity.norm() > 0.0) {
      LoadSpec g;
      g.set = "all";
      g.type = LoadType::Gravity;
      g.direction = c.gravity;
      g.amplitude = 1.0;
      g.where = p.where(root["gravity"], "gravity");
      c.loads.push_back(std::move(g));
    }
  }
  if (root["rigid_bodies"]) c.rigid_bodies = parse_rigid_bodies(p, root["rigid_bodies"]);
  if (root["joints"]) c.joints = parse_joints(p, root["joints"], c.rigid_bodies);
  if (root["prescribed_displacements"]) c.prescribed_displacements = parse_prescribed(p, root["prescribed_displacements"]);
  if (root["damping"]) c.damping = parse_damping(p, root["damping"]);
  c.integrator = parse_integrator(p, root["integrator"]);
  c.time = parse_time(p, root["time"]);
  if (root["output"]) c.output = parse_output(p, root["output"]);
  if (root["monitors"]) c.monitors = parse_monitors(p, root["monitors"]);
  if (root["plugins"]) {  // shared libraries that register integrators (docs/tutorials/05-your-own-integrator.md)
    const YAML::Node pl = root["plugins"];
    p.require_sequence(pl, "plugins", "paths of plugin shared libraries (.so)");
    c.plugins_where = p.where(pl, "plugins");
    for (size_t k = 0; k < pl.size(); ++k) {
      fs::path file(p.string(pl[k], "plugins[" + std::to_string(k) + "]"));
      if (file.is_relative()) file = fs::path(base_dir) / file;
      c.plugins.push_back(file.lexically_normal().string());
    }
  }
  return c;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
const char* mesh_kind_name(const MeshSpec& mesh) {
  static const char* names[] = {"rectangle",      "cell_union",      "cylindrical_panel", "hemisphere",
                                "file",           "cylinder_patch",  "closed_cylinder",   "slit_annulus"};
  return names[mesh.index()];
}

const char* load_type_name(LoadType t) {
  static const char* names[] = {"force", "moment", "pressure", "follower_pressure", "body_force", "gravity"};
  return names[static_cast<int>(t)];
}

const char* load_distribution_name(LoadDistribution d) {
  static const char* names[] = {"per_node", "edge_total", "per_length"};
  return names[static_cast<int>(d)];
}

const char* monitor_quantity_name(MonitorQuantity q) {
  static const char* names[] = {"ux", "uy", "uz", "ur", "px", "py", "pz", "vx", "vy", "vz", "rx", "ry", "rz"};
  return names[static_cast<int>(q)];
}

const char* monitor_reduce_name(MonitorReduce r) {
  static const char* names[] = {"none", "sum", "mean", "max", "min"};
  return names[static_cast<int>(r)];
}

long long TimeSpec::num_steps() const {
  const double r = t_end / dt;
  const double nearest = std::round(r);
  if (std::abs(r - nearest) <= 1e-9 * std::max(1.0, nearest)) return static_cast<long long>(nearest);
  return static_cast<long long>(std::ceil(r));
}

CaseSpec load_case_from_string(const std::string& text, const std::string& source, const std::string& base_dir) {
  const Parser p(source);
  // Control characters (a NUL byte, binary data): yaml-cpp would report them as, e.g., "unknown escape character".
  for (size_t k = 0, line = 1; k < text.size(); ++k) {
    const unsigned char c = static_cast<unsigned char>(text[k]);
    if (c == '\n') ++line;
    if (c < 0x20 && c != '\n' && c != '\r' && c != '\t') {
      char code[8];
      std::snprintf(code, sizeof code, "0x%02x", c);
      throw std::runtime_error(source + ":" + std::to_string(line) + ": " + (c == 0 ? std::string("a NUL byte") : "control character " + std::string(code)) +
                               " at byte " + std::to_string(k + 1) + "; a case file is text (is this a binary or damaged file?)");
    }
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::ostringstream os;
    os << source;
    if (!e.mark.is_null()) os << ":" << e.mark.line + 1;
    os << ": YAML syntax error: " << e.msg << " (check indentation, brackets and quotes)";
    throw std::runtime_error(os.str());
  }
  try {
    return parse_document(p, root, base_dir);
  } catch (const YAML::Exception& e) {
    // Safety net: a yaml-cpp access error we did not anticipate still gets the file name and line.
    std::ostringstream os;
    os << source;
    if (!e.mark.is_null()) os << ":" << e.mark.line + 1;
    os << ": " << e.msg;
    throw std::runtime_error(os.str());
  }
}

CaseSpec load_case(const std::string& path) {
  require_regular_file(path, "case file");  // a FIFO would block the open forever (lib/io/result_folder.hpp)
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open the case file (check the path)");
  std::ostringstream text;
  text << in.rdbuf();
  const fs::path dir = fs::absolute(fs::path(path)).parent_path();
  return load_case_from_string(text.str(), path, dir.string());
}

}  // namespace shelldyn
