#include "lib/run_info.hpp"

#include <Eigen/Core>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#ifndef SHELLDYN_VERSION
#define SHELLDYN_VERSION "unknown"
#endif

namespace shelldyn {

std::string shelldyn_version() { return SHELLDYN_VERSION; }

std::string eigen_version() {
  return std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) + "." +
         std::to_string(EIGEN_MINOR_VERSION);
}

std::string json_quote(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);  // UTF-8 passes through unchanged
        }
    }
  }
  return out + "\"";
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

void JsonFields::set_encoded(const std::string& key, std::string json) {
  for (auto& e : entries_)
    if (e.first == key) {
      e.second = std::move(json);
      return;
    }
  entries_.emplace_back(key, std::move(json));
}
void JsonFields::set(const std::string& key, const std::string& value) { set_encoded(key, json_quote(value)); }
void JsonFields::set(const std::string& key, double value) { set_encoded(key, json_number(value)); }
void JsonFields::set(const std::string& key, long long value) { set_encoded(key, std::to_string(value)); }
void JsonFields::set(const std::string& key, bool value) { set_encoded(key, value ? "true" : "false"); }

namespace {

// Minimal pretty printer: objects and arrays are opened/closed explicitly; commas are tracked per level.
class JsonOut {
 public:
  std::string str() const { return os_.str(); }

  void open_object(const std::string& key = "") { open(key, '{'); }
  void open_array(const std::string& key = "") { open(key, '['); }
  void close_object() { close('}'); }
  void close_array() { close(']'); }
  // A member (inside an object, key non-empty) or an element (inside an array, key empty).
  void value(const std::string& key, const std::string& encoded) {
    item(key);
    os_ << encoded;
  }
  void str(const std::string& key, const std::string& s) { value(key, json_quote(s)); }
  void num(const std::string& key, double v) { value(key, json_number(v)); }
  void integer(const std::string& key, long long v) { value(key, std::to_string(v)); }
  void boolean(const std::string& key, bool v) { value(key, v ? "true" : "false"); }
  void vec3(const std::string& key, const Eigen::Vector3d& v) {
    value(key, "[" + json_number(v.x()) + ", " + json_number(v.y()) + ", " + json_number(v.z()) + "]");
  }
  void fields(const std::string& key, const JsonFields& f) {
    open_object(key);
    for (const auto& [k, v] : f.entries()) value(k, v);
    close_object();
  }

 private:
  void item(const std::string& key) {
    if (!first_.empty()) {
      if (!first_.back()) os_ << ",";
      first_.back() = false;
      os_ << "\n" << std::string(2 * first_.size(), ' ');
    }
    if (!key.empty()) os_ << json_quote(key) << ": ";
  }
  void open(const std::string& key, char bracket) {
    item(key);
    os_ << bracket;
    first_.push_back(true);
  }
  void close(char bracket) {
    const bool was_empty = first_.back();
    first_.pop_back();
    if (!was_empty) os_ << "\n" << std::string(2 * first_.size(), ' ');
    os_ << bracket;
  }
  std::ostringstream os_;
  std::vector<bool> first_;
};

const char* set_kind_name(SetSpec::Kind k) {
  switch (k) {
    case SetSpec::Kind::Point: return "point";
    case SetSpec::Kind::Box: return "box";
    case SetSpec::Kind::Nodes: return "nodes";
    case SetSpec::Kind::Union: return "union";
  }
  return "?";
}

void write_mesh(JsonOut& j, const MeshSpec& mesh) {
  j.open_object("mesh");
  if (const auto* m = std::get_if<MeshFileSpec>(&mesh)) {
    j.str("file", m->path);
  } else {
    j.str("generator", mesh_kind_name(mesh));
    if (const auto* r = std::get_if<RectangleMeshSpec>(&mesh)) {
      j.num("a", r->a), j.num("b", r->b), j.integer("nx", r->nx), j.integer("ny", r->ny);
      j.num("x0", r->x0), j.num("y0", r->y0);
    } else if (const auto* c = std::get_if<CellUnionMeshSpec>(&mesh)) {
      j.open_array("cells");
      for (const auto& r : c->cells)
        j.value("", "[" + std::to_string(r[0]) + ", " + std::to_string(r[1]) + ", " + std::to_string(r[2]) + ", " +
                        std::to_string(r[3]) + "]");
      j.close_array();
      j.num("cell", c->cell);
    } else if (const auto* p = std::get_if<CylindricalPanelMeshSpec>(&mesh)) {
      j.num("radius", p->radius), j.num("angle", p->angle), j.num("length", p->length);
      j.integer("n_arc", p->n_arc), j.integer("n_axial", p->n_axial);
    } else if (const auto* h = std::get_if<HemisphereMeshSpec>(&mesh)) {
      j.num("radius", h->radius), j.num("hole_deg", h->hole_deg), j.boolean("quarter", h->quarter);
      j.integer("n", h->n);
    }
  }
  j.close_object();
}

std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace

std::string run_json(const CaseSpec& c, const RunInfo& info) {
  JsonOut j;
  j.open_object();
  j.str("status", info.status);
  j.str("created_utc", utc_now());
  if (!info.command.empty()) j.str("command", info.command);
  j.open_object("versions");
  j.str("shelldyn", shelldyn_version());
  j.str("sundials", info.sundials_version.empty() ? "not used" : info.sundials_version);
  j.str("eigen", eigen_version());
#ifdef __VERSION__
  j.str("compiler", __VERSION__);
#endif
  j.close_object();

  j.open_object("case");
  j.str("name", c.name);
  j.str("description", c.description);
  j.str("source", c.source.empty() ? "" : std::filesystem::absolute(c.source).lexically_normal().string());
  write_mesh(j, c.mesh);
  j.open_object("material");
  j.num("E", c.material.E), j.num("nu", c.material.nu), j.num("rho", c.material.rho);
  j.num("thickness", c.material.thickness), j.num("shear_factor", c.material.shear_factor);
  j.close_object();
  j.open_object("sets");
  for (const auto& s : c.sets) {
    j.open_object(s.name);
    j.str("kind", set_kind_name(s.kind));
    switch (s.kind) {
      case SetSpec::Kind::Point:
        j.vec3("point", s.point);
        if (s.tol >= 0) j.num("tol", s.tol);
        break;
      case SetSpec::Kind::Box:
        j.vec3("min", s.box_min), j.vec3("max", s.box_max);
        break;
      case SetSpec::Kind::Nodes:
        j.open_array("nodes");
        for (int n : s.nodes) j.integer("", n);
        j.close_array();
        break;
      case SetSpec::Kind::Union:
        j.open_array("union");
        for (const auto& m : s.members) j.str("", m);
        j.close_array();
        break;
    }
    j.close_object();
  }
  j.close_object();
  j.open_array("boundary_conditions");
  for (const auto& bc : c.boundary_conditions) {
    j.open_object();
    j.str("set", bc.set);
    j.open_array("fix");
    for (Fix f : bc.fix) j.str("", fix_name(f));
    j.close_array();
    j.close_object();
  }
  j.close_array();
  j.open_object("initial_velocity");
  j.str("set", c.initial_velocity.set);
  if (!c.initial_velocity.field.empty()) j.str("field", c.initial_velocity.field);
  if (!c.initial_velocity_more.empty()) j.integer("further_entries", static_cast<long long>(c.initial_velocity_more.size()));
  j.vec3("translation", c.initial_velocity.translation);
  j.vec3("angular", c.initial_velocity.angular);
  if (c.initial_velocity.about_centroid)
    j.str("about", "centroid");
  else
    j.vec3("about", c.initial_velocity.about);
  j.close_object();
  j.open_array("loads");
  for (const auto& l : c.loads) {
    j.open_object();
    j.str("set", l.set), j.str("type", load_type_name(l.type)), j.vec3("direction", l.direction);
    j.num("amplitude", l.amplitude), j.str("distribution", load_distribution_name(l.distribution));
    j.open_object("function");
    j.str("type", l.function.kind_name());
    for (const auto& [k, v] : l.function.parameters()) j.num(k, v);
    if (l.function.kind() == TimeFunction::Kind::Table) {
      j.open_array("points");
      for (const auto& [t, f] : l.function.table_points()) j.value("", "[" + json_number(t) + ", " + json_number(f) + "]");
      j.close_array();
    }
    j.close_object();
    j.close_object();
  }
  j.close_array();
  j.open_object("damping");
  j.num("mass", c.damping.mass), j.num("stiffness", c.damping.stiffness);
  j.close_object();
  j.open_object("integrator");
  j.str("name", c.integrator.name);
  for (const auto& [k, v] : c.integrator.settings) j.str(k, v);
  j.close_object();
  j.open_object("time");
  j.num("dt", c.time.dt), j.num("t_end", c.time.t_end), j.num("output_interval", c.time.output_interval);
  j.integer("num_steps", c.time.num_steps());
  j.close_object();
  j.open_object("output");
  j.boolean("vtu", c.output.vtu), j.integer("vtu_every", c.output.vtu_every), j.boolean("history", c.output.history);
  j.close_object();
  j.open_array("monitors");
  for (const auto& m : c.monitors) {
    j.open_object();
    j.str("name", m.name), j.str("set", m.set), j.str("quantity", monitor_quantity_name(m.quantity));
    j.str("reduce", monitor_reduce_name(m.reduce));
    if (m.has_axis) {
      j.open_object("axis");
      j.vec3("point", m.axis_point), j.vec3("direction", m.axis_direction);
      j.close_object();
    }
    j.close_object();
  }
  j.close_array();
  j.close_object();  // case

  j.fields("discretization", info.discretization);
  j.fields("summary", info.summary);
  j.close_object();
  return j.str() + "\n";
}

void write_run_json(const std::string& path, const CaseSpec& spec, const RunInfo& info) {
  const std::string text = run_json(spec, info);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot create run.json (check the output folder)");
    out << text;
    out.close();
    if (!out) throw std::runtime_error(path + ": write error");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error(path + ": cannot replace run.json: " + ec.message());
}

}  // namespace shelldyn
