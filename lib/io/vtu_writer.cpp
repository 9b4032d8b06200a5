#include "lib/io/vtu_writer.hpp"
#include "lib/io/result_folder.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <stdexcept>

namespace shelldyn {

namespace {

constexpr int kVtkBiquadraticQuad = 28;

// XML attribute values: field names come from users (monitor/extra names), so escape them.
std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

class File {
 public:
  // Recorded in the result folder's manifest first (lib/io/result_folder.hpp): --overwrite removes it.
  explicit File(const std::string& path) : path_(path), f_((record_output(path), std::fopen(path.c_str(), "w"))) {
    if (!f_) throw std::runtime_error(path + ": cannot create file: " + std::strerror(errno));
  }
  ~File() {  // not closed: an exception interrupted the write; leave no half-written file behind
    if (f_) {
      std::fclose(f_);
      std::remove(path_.c_str());
    }
  }
  std::FILE* get() const { return f_; }
  void close() {
    errno = 0;
    const bool bad = std::fflush(f_) != 0 || std::ferror(f_) != 0;
    const int err = errno;
    const int rc = std::fclose(f_);
    f_ = nullptr;
    if (bad || rc != 0) {
      const int e = err ? err : errno;
      std::remove(path_.c_str());
      throw std::runtime_error(path_ + ": cannot write: " +
                               (e == ENOSPC ? std::string("the disk is full (free space and rerun)") : std::strerror(e)));
    }
  }

 private:
  std::string path_;
  std::FILE* f_;
};

void check_size(size_t got, size_t want, const std::string& what) {
  if (got != want)
    throw std::invalid_argument("write_vtu: " + what + " has " + std::to_string(got) + " entries, expected " +
                                std::to_string(want));
}

// ComponentName0="X" ... attributes of a DataArray (VTK XML format): ParaView labels the components with them.
std::string component_attributes(int components, const std::vector<std::string>& names) {
  std::vector<std::string> use = names;
  if (use.empty() && components == 3) use = {"X", "Y", "Z"};
  std::string out;
  for (size_t c = 0; c < use.size(); ++c)
    out += " ComponentName" + std::to_string(c) + "=\"" + xml_escape(use[c]) + "\"";
  return out;
}

void write_vectors(std::FILE* f, const char* name, const std::vector<Vec3>& v) {
  std::fprintf(f, "        <DataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"3\"%s format=\"ascii\">\n", name,
               component_attributes(3, {}).c_str());
  for (const Vec3& x : v) std::fprintf(f, "          %.17g %.17g %.17g\n", x.x(), x.y(), x.z());
  std::fprintf(f, "        </DataArray>\n");
}

void write_scalars(std::FILE* f, const ScalarField& s) {
  std::fprintf(f, "        <DataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"%d\"%s format=\"ascii\">\n",
               xml_escape(s.name).c_str(), s.components, component_attributes(s.components, s.component_names).c_str());
  const size_t nc = static_cast<size_t>(s.components);
  for (size_t k = 0; k < s.values.size(); k += nc) {
    std::fprintf(f, "         ");
    for (size_t c = 0; c < nc; ++c) std::fprintf(f, " %.17g", s.values[k + c]);
    std::fprintf(f, "\n");
  }
  std::fprintf(f, "        </DataArray>\n");
}

}  // namespace

std::string vtu_step_file_name(long long output_step) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "step_%06lld.vtu", output_step);
  return buf;
}

void write_vtu(const std::string& path, const Mesh& mesh, const VtuFields& fields) {
  const size_t np = mesh.X.size(), ne = mesh.elements.size();
  check_size(fields.displacement.size(), np, "displacement");
  check_size(fields.velocity.size(), np, "velocity");
  check_size(fields.director.size(), np, "director");
  std::set<std::string> names = {"displacement", "velocity", "director"};
  for (const auto& s : fields.point_scalars) {
    if (s.components < 1) throw std::invalid_argument("write_vtu: field '" + s.name + "' has < 1 component");
    check_size(s.values.size(), np * static_cast<size_t>(s.components), "point field '" + s.name + "'");
    if (!s.component_names.empty()) check_size(s.component_names.size(), static_cast<size_t>(s.components), "point field '" + s.name + "''s component_names");
    if (s.name.empty() || !names.insert(s.name).second)
      throw std::invalid_argument("write_vtu: point field name '" + s.name + "' is empty or repeated");
  }
  std::set<std::string> cell_names;
  for (const auto& s : fields.cell_scalars) {
    if (s.components < 1) throw std::invalid_argument("write_vtu: field '" + s.name + "' has < 1 component");
    check_size(s.values.size(), ne * static_cast<size_t>(s.components), "cell field '" + s.name + "'");
    if (!s.component_names.empty()) check_size(s.component_names.size(), static_cast<size_t>(s.components), "cell field '" + s.name + "''s component_names");
    if (s.name.empty() || !cell_names.insert(s.name).second)
      throw std::invalid_argument("write_vtu: cell field name '" + s.name + "' is empty or repeated");
  }
  for (size_t e = 0; e < ne; ++e)
    for (int a : mesh.elements[e])
      if (a < 0 || static_cast<size_t>(a) >= np)
        throw std::invalid_argument("write_vtu: element " + std::to_string(e) + " refers to node " +
                                    std::to_string(a) + ", but the mesh has " + std::to_string(np) + " nodes");

  File file(path);
  std::FILE* f = file.get();
  std::fprintf(f, "<?xml version=\"1.0\"?>\n");
  std::fprintf(f, "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
  std::fprintf(f, "  <UnstructuredGrid>\n");
  std::fprintf(f, "    <Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n", np, ne);
  std::fprintf(f, "      <Points>\n");
  std::fprintf(f, "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
  for (size_t i = 0; i < np; ++i) {
    const Vec3 x = mesh.X[i] + fields.displacement[i];
    std::fprintf(f, "          %.17g %.17g %.17g\n", x.x(), x.y(), x.z());
  }
  std::fprintf(f, "        </DataArray>\n      </Points>\n");
  std::fprintf(f, "      <Cells>\n");
  std::fprintf(f, "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
  for (const Quad9& el : mesh.elements) {
    std::fprintf(f, "         ");
    for (int a : el) std::fprintf(f, " %d", a);
    std::fprintf(f, "\n");
  }
  std::fprintf(f, "        </DataArray>\n");
  std::fprintf(f, "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
  for (size_t e = 0; e < ne; ++e) std::fprintf(f, "          %zu\n", 9 * (e + 1));
  std::fprintf(f, "        </DataArray>\n");
  std::fprintf(f, "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
  for (size_t e = 0; e < ne; ++e) std::fprintf(f, "          %d\n", kVtkBiquadraticQuad);
  std::fprintf(f, "        </DataArray>\n      </Cells>\n");
  std::fprintf(f, "      <PointData Vectors=\"displacement\">\n");
  write_vectors(f, "displacement", fields.displacement);
  write_vectors(f, "velocity", fields.velocity);
  write_vectors(f, "director", fields.director);
  for (const auto& s : fields.point_scalars) write_scalars(f, s);
  std::fprintf(f, "      </PointData>\n");
  if (!fields.cell_scalars.empty()) {
    std::fprintf(f, "      <CellData>\n");
    for (const auto& s : fields.cell_scalars) write_scalars(f, s);
    std::fprintf(f, "      </CellData>\n");
  }
  std::fprintf(f, "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
  file.close();
}

PvdWriter::PvdWriter(std::string pvd_path) : path_(std::move(pvd_path)) {}

void PvdWriter::add(double time, const std::string& file) {
  entries_.emplace_back(time, file);
  // Write a complete new file and rename it over the old one: a reader never sees a half-written
  // collection, and a killed run leaves the last complete list.
  const std::string tmp = path_ + ".tmp";
  try {
    File out(tmp);
    std::FILE* f = out.get();
    std::fprintf(f, "<?xml version=\"1.0\"?>\n");
    std::fprintf(f, "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
    std::fprintf(f, "  <Collection>\n");
    for (const auto& [t, name] : entries_)
      std::fprintf(f, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"%s\"/>\n", t,
                   xml_escape(name).c_str());
    std::fprintf(f, "  </Collection>\n</VTKFile>\n");
    out.close();
  } catch (const std::runtime_error& e) {  // name the collection, not its temporary (File removed that)
    entries_.pop_back();                    // the file on disk (if any) still lists the earlier entries
    std::string what = e.what();
    if (what.rfind(tmp, 0) == 0) what = path_ + what.substr(tmp.size());
    throw std::runtime_error(what);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path_, ec);
  if (ec) throw std::runtime_error(path_ + ": cannot replace the collection file: " + ec.message());
}

}  // namespace shelldyn
