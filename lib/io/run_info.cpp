#include "lib/io/run_info.hpp"

#include "lib/linalg/linear_solver.hpp"
#include "lib/io/result_folder.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
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
  // error_handler replace: invalid UTF-8 becomes U+FFFD instead of an exception (a case file or a
  // command line may hold any bytes).
  return nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  return nlohmann::json(v).dump();  // shortest representation that reads back to the same double
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

using Json = nlohmann::ordered_json;  // keys in insertion order: the document reads top-down

Json number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json vec3(const Eigen::Vector3d& v) { return Json::array({number(v.x()), number(v.y()), number(v.z())}); }
Json fields(const JsonFields& f) {
  Json j = Json::object();
  for (const auto& [k, v] : f.entries()) j[k] = Json::parse(v);
  return j;
}

const char* set_kind_name(SetSpec::Kind k) {
  switch (k) {
    case SetSpec::Kind::Point: return "point";
    case SetSpec::Kind::Box: return "box";
    case SetSpec::Kind::Nodes: return "nodes";
    case SetSpec::Kind::Union: return "union";
  }
  return "?";
}

Json mesh_json(const MeshSpec& mesh) {
  Json j = Json::object();
  if (const auto* m = std::get_if<MeshFileSpec>(&mesh)) {
    j["file"] = m->path;
    return j;
  }
  j["generator"] = mesh_kind_name(mesh);
  if (const auto* r = std::get_if<RectangleMeshSpec>(&mesh)) {
    j["a"] = number(r->a), j["b"] = number(r->b), j["nx"] = r->nx, j["ny"] = r->ny;
    j["x0"] = number(r->x0), j["y0"] = number(r->y0);
  } else if (const auto* c = std::get_if<CellUnionMeshSpec>(&mesh)) {
    j["cells"] = Json::array();
    for (const auto& r : c->cells) j["cells"].push_back(Json::array({r[0], r[1], r[2], r[3]}));
    j["cell"] = number(c->cell);
  } else if (const auto* p = std::get_if<CylindricalPanelMeshSpec>(&mesh)) {
    j["radius"] = number(p->radius), j["angle"] = number(p->angle), j["length"] = number(p->length);
    j["n_arc"] = p->n_arc, j["n_axial"] = p->n_axial;
  } else if (const auto* h = std::get_if<HemisphereMeshSpec>(&mesh)) {
    j["radius"] = number(h->radius), j["hole_deg"] = number(h->hole_deg), j["quarter"] = h->quarter;
    j["n"] = h->n;
  } else if (const auto* q = std::get_if<CylinderPatchMeshSpec>(&mesh)) {
    j["radius"] = number(q->radius), j["angle"] = number(q->angle), j["length"] = number(q->length);
    j["n_arc"] = q->n_arc, j["n_axial"] = q->n_axial;
  } else if (const auto* c2 = std::get_if<ClosedCylinderMeshSpec>(&mesh)) {
    j["radius"] = number(c2->radius), j["length"] = number(c2->length), j["n_circ"] = c2->n_circ, j["n_axial"] = c2->n_axial;
  } else if (const auto* a = std::get_if<SlitAnnulusMeshSpec>(&mesh)) {
    j["r_inner"] = number(a->r_inner), j["r_outer"] = number(a->r_outer), j["n_radial"] = a->n_radial, j["n_circ"] = a->n_circ;
  }
  return j;
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
  Json j = Json::object();
  j["status"] = info.status;
  j["created_utc"] = utc_now();
  if (!info.command.empty()) j["command"] = info.command;
  Json& v = j["versions"];
  v["shelldyn"] = shelldyn_version();
  if (!shelldyn_git_commit().empty()) v["git_commit"] = shelldyn_git_commit();
  v["sundials"] = info.sundials_version.empty() ? "not used" : info.sundials_version;
  v["eigen"] = eigen_version();
  v["nlohmann_json"] = std::to_string(NLOHMANN_JSON_VERSION_MAJOR) + "." + std::to_string(NLOHMANN_JSON_VERSION_MINOR) +
                       "." + std::to_string(NLOHMANN_JSON_VERSION_PATCH);
  v["blas"] = blas_description();  // its kernels set the round-off of the factorizations (docs/dependencies.md §5.6)
#ifdef __VERSION__
  v["compiler"] = __VERSION__;
#endif
  if (!info.overrides.empty()) j["command_line_overrides"] = fields(info.overrides);
  if (!info.integrator_origin.empty()) j["integrator_origin"] = info.integrator_origin;
  if (!info.plugins.empty()) {
    Json& pl = j["plugins"] = Json::array();
    for (const auto& p : info.plugins) pl.push_back(fields(p));
  }

  Json& cs = j["case"];
  cs["name"] = c.name;
  cs["description"] = c.description;
  cs["source"] = c.source.empty() ? "" : std::filesystem::absolute(c.source).lexically_normal().string();
  cs["mesh"] = mesh_json(c.mesh);
  cs["material"] = {{"E", number(c.material.E)}, {"nu", number(c.material.nu)}, {"rho", number(c.material.rho)},
                    {"thickness", number(c.material.thickness)}, {"shear_factor", number(c.material.shear_factor)}};
  Json& sets = cs["sets"] = Json::object();
  for (const auto& s : c.sets) {
    Json e = {{"kind", set_kind_name(s.kind)}};
    switch (s.kind) {
      case SetSpec::Kind::Point:
        e["point"] = vec3(s.point);
        if (s.tol >= 0) e["tol"] = number(s.tol);
        break;
      case SetSpec::Kind::Box:
        e["min"] = vec3(s.box_min), e["max"] = vec3(s.box_max);
        break;
      case SetSpec::Kind::Nodes:
        e["nodes"] = s.nodes;
        break;
      case SetSpec::Kind::Union:
        e["union"] = s.members;
        break;
    }
    sets[s.name] = std::move(e);
  }
  Json& bcs = cs["boundary_conditions"] = Json::array();
  for (const auto& bc : c.boundary_conditions) {
    Json fix = Json::array();
    for (Fix f : bc.fix) fix.push_back(fix_name(f));
    bcs.push_back({{"set", bc.set}, {"fix", std::move(fix)}});
  }
  Json& iv = cs["initial_velocity"];
  iv["set"] = c.initial_velocity.set;
  if (!c.initial_velocity.field.empty()) iv["field"] = c.initial_velocity.field;
  if (!c.initial_velocity.mode_file.empty()) {
    iv["mode"] = c.initial_velocity.mode_file;
    iv["index"] = c.initial_velocity.mode_index;
    iv["amplitude"] = number(c.initial_velocity.mode_amplitude);
  }
  if (!c.initial_velocity_more.empty()) iv["further_entries"] = c.initial_velocity_more.size();
  iv["translation"] = vec3(c.initial_velocity.translation);
  iv["angular"] = vec3(c.initial_velocity.angular);
  iv["about"] = c.initial_velocity.about_centroid ? Json("centroid") : vec3(c.initial_velocity.about);
  if (!c.initial_displacement.empty()) cs["initial_displacement"] = {{"field", c.initial_displacement}};
  Json& loads = cs["loads"] = Json::array();
  for (const auto& l : c.loads) {
    Json f = {{"type", l.function.kind_name()}};
    for (const auto& [k, x] : l.function.parameters()) f[k] = number(x);
    if (l.function.kind() == TimeFunction::Kind::Table) {
      Json pts = Json::array();
      for (const auto& [t, x] : l.function.table_points()) pts.push_back(Json::array({number(t), number(x)}));
      f["points"] = std::move(pts);
    }
    loads.push_back({{"set", l.set}, {"type", load_type_name(l.type)}, {"direction", vec3(l.direction)},
                     {"amplitude", number(l.amplitude)}, {"distribution", load_distribution_name(l.distribution)},
                     {"function", std::move(f)}});
  }
  cs["damping"] = {{"mass", number(c.damping.mass)}, {"stiffness", number(c.damping.stiffness)}};
  Json& integ = cs["integrator"];
  integ["name"] = c.integrator.name;
  for (const auto& [k, x] : c.integrator.settings) integ[k] = x;
  cs["time"] = {{"dt", number(c.time.dt)}, {"t_end", number(c.time.t_end)},
                {"output_interval", number(c.time.output_interval)}, {"num_steps", c.time.num_steps()}};
  cs["output"] = {{"vtu", c.output.vtu}, {"vtu_every", c.output.vtu_every}, {"history", c.output.history}};
  Json& mons = cs["monitors"] = Json::array();
  for (const auto& m : c.monitors) {
    Json e = {{"name", m.name}, {"set", m.set}, {"quantity", monitor_quantity_name(m.quantity)},
              {"reduce", monitor_reduce_name(m.reduce)}};
    if (m.has_axis) e["axis"] = {{"point", vec3(m.axis_point)}, {"direction", vec3(m.axis_direction)}};
    mons.push_back(std::move(e));
  }

  j["discretization"] = fields(info.discretization);
  j["summary"] = fields(info.summary);
  if (!info.checkpoint.empty()) j["checkpoint"] = fields(info.checkpoint);
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

void write_text_atomically(const std::string& path, const std::string& text, const std::string& what) {
  const std::string tmp = path + ".tmp";
  auto fail = [&](const std::string& step, int err) {
    std::remove(tmp.c_str());  // never leave a stale .tmp behind
    const std::string reason = err == ENOSPC ? "the disk is full (free space and rerun)"
                               : err == EDQUOT ? "the disk quota is exceeded"
                               : err == EROFS  ? "the file system is read-only"
                               : err == EACCES ? "permission denied (choose a writable folder)"
                                               : std::string(std::strerror(err));
    throw std::runtime_error(path + ": cannot " + step + " " + what + ": " + reason);
  };
  record_output(path);  // the result folder's manifest (lib/io/result_folder.hpp): --overwrite removes it
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) fail("create", errno);
  errno = 0;
  const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size() && std::fflush(f) == 0 &&
                       fsync(fileno(f)) == 0;
  const int err = errno ? errno : EIO;
  if (std::fclose(f) != 0 || !written) fail("write", written ? (errno ? errno : EIO) : err);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) fail("replace", errno);
}

DiskReserve::DiskReserve(const std::string& path, long long bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return;
  // posix_fallocate really allocates the blocks (glibc writes them where the file system cannot).
  const bool ok = posix_fallocate(fd, 0, static_cast<off_t>(bytes)) == 0 && fsync(fd) == 0;
  ::close(fd);
  if (ok) path_ = path;
  else std::remove(path.c_str());
}

void DiskReserve::release() {
  if (path_.empty()) return;
  std::remove(path_.c_str());
  path_.clear();
}

void write_run_json(const std::string& path, const CaseSpec& spec, const RunInfo& info) {
  write_text_atomically(path, run_json(spec, info), "run.json");
}

}  // namespace shelldyn
