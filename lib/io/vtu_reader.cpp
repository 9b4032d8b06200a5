#include "lib/io/vtu_reader.hpp"
#include "lib/io/result_folder.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw std::runtime_error(path + ": " + reason);
}

std::string read_all(const std::string& path, const char* what) {
  require_regular_file(path, what);  // a FIFO would block the open forever (lib/io/result_folder.hpp)
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open the ") + what + ": " + std::strerror(errno) + " (check the path)");
  std::ostringstream os;
  os << in.rdbuf();
  if (in.bad()) fail(path, std::string("cannot read the ") + what);
  return os.str();
}

std::string xml_unescape(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '&') {
      out += s[i];
      continue;
    }
    static const std::pair<const char*, char> kEntities[] = {
        {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
    bool done = false;
    for (const auto& [ent, c] : kEntities)
      if (s.compare(i, std::strlen(ent), ent) == 0) {
        out += c;
        i += std::strlen(ent) - 1;
        done = true;
        break;
      }
    if (!done) out += s[i];
  }
  return out;
}

// The value of attribute `key` in the tag text `tag` ("<DataArray type=... Name=...>"), or `dflt`.
std::string attribute(const std::string& tag, const std::string& key, const std::string& dflt = "") {
  const std::string pat = key + "=\"";
  for (size_t pos = tag.find(pat); pos != std::string::npos; pos = tag.find(pat, pos + 1)) {
    if (pos == 0 || !std::isspace(static_cast<unsigned char>(tag[pos - 1]))) continue;
    const size_t begin = pos + pat.size(), end = tag.find('"', begin);
    if (end == std::string::npos) return dflt;
    return xml_unescape(tag.substr(begin, end - begin));
  }
  return dflt;
}

long long count_attribute(const std::string& path, const std::string& tag, const std::string& key) {
  const std::string v = attribute(tag, key);
  char* end = nullptr;
  errno = 0;
  const long long n = std::strtoll(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || errno != 0 || n < 0) fail(path, "<Piece> has no valid " + key + " (not a VTU file written by shelldyn?)");
  return n;
}

struct DataArray {
  std::string name, format;
  int components = 1;
  std::vector<double> values;
};

// Parses the <DataArray ...>values</DataArray> whose tag starts at `pos`; returns the position after it.
size_t parse_data_array(const std::string& path, const std::string& text, size_t pos, size_t limit, DataArray& a) {
  const size_t tag_end = text.find('>', pos);
  if (tag_end == std::string::npos || tag_end > limit) fail(path, "unterminated <DataArray> tag");
  const std::string tag = text.substr(pos, tag_end - pos);
  a.name = attribute(tag, "Name");
  a.format = attribute(tag, "format", "ascii");
  const std::string nc = attribute(tag, "NumberOfComponents", "1");
  a.components = std::atoi(nc.c_str());
  const std::string label = a.name.empty() ? std::string("the points") : "array '" + a.name + "'";
  if (a.components < 1) fail(path, label + ": NumberOfComponents '" + nc + "' is not a positive integer");
  if (a.format != "ascii")
    fail(path, label + " is '" + a.format + "': only ASCII VTU can be read (ParaView: Data Mode Ascii)");
  if (tag.back() == '/') return tag_end + 1;  // <DataArray .../>: no values
  const size_t close = text.find("</DataArray>", tag_end);
  if (close == std::string::npos || close > limit) fail(path, label + ": no closing </DataArray> (a truncated file?)");
  const char* p = text.c_str() + tag_end + 1;
  const char* stop = text.c_str() + close;
  while (true) {
    while (p < stop && std::isspace(static_cast<unsigned char>(*p))) ++p;
    if (p >= stop) break;
    char* end = nullptr;
    const double x = std::strtod(p, &end);
    if (end == p || end > stop)
      fail(path, label + ": value " + std::to_string(a.values.size() + 1) + " is not a number ('" +
                     std::string(p, std::min<size_t>(20, static_cast<size_t>(stop - p))) + "')");
    a.values.push_back(x);
    p = end;
  }
  return close + std::strlen("</DataArray>");
}

}  // namespace

std::vector<Vec3> VtuPointData::vectors(const std::string& name) const {
  const auto it = arrays.find(name);
  if (it == arrays.end()) {
    std::string have;
    for (const auto& [n, a] : arrays) have += (have.empty() ? "" : ", ") + n;
    fail(path, "no point data array '" + name + "' (use a VTU written by shelldyn)\npoint data in the file: " +
                   (have.empty() ? std::string("none") : have));
  }
  if (it->second.components != 3)
    fail(path, "point data '" + name + "' has " + std::to_string(it->second.components) + " components, expected 3");
  std::vector<Vec3> out(num_points);
  for (size_t i = 0; i < num_points; ++i) {
    out[i] = Vec3(it->second.values[3 * i], it->second.values[3 * i + 1], it->second.values[3 * i + 2]);
    if (!out[i].allFinite())
      fail(path, "point data '" + name + "' is not finite at point " + std::to_string(i) + " (a field of a failed run?)");
  }
  return out;
}

VtuPointData read_vtu(const std::string& path) {
  const std::string text = read_all(path, "VTU file");
  VtuPointData out;
  out.path = path;
  if (text.find("<VTKFile") == std::string::npos || text.find("UnstructuredGrid") == std::string::npos)
    fail(path, "not a VTK UnstructuredGrid (.vtu) file (give a fields/step_NNNNNN.vtu written by shelldyn)");
  if (text.find("<AppendedData") != std::string::npos)
    fail(path, "appended (binary) VTK data cannot be read; only ASCII VTU files (shelldyn writes them)");
  const size_t piece = text.find("<Piece");
  if (piece == std::string::npos) fail(path, "no <Piece> element (an empty or truncated file?)");
  if (text.find("<Piece", piece + 1) != std::string::npos) fail(path, "more than one <Piece>: only single-piece VTU files can be read");
  const size_t piece_tag_end = text.find('>', piece);
  if (piece_tag_end == std::string::npos) fail(path, "unterminated <Piece> tag");
  const std::string piece_tag = text.substr(piece, piece_tag_end - piece);
  out.num_points = static_cast<size_t>(count_attribute(path, piece_tag, "NumberOfPoints"));
  out.num_cells = static_cast<size_t>(count_attribute(path, piece_tag, "NumberOfCells"));

  const size_t points = text.find("<Points>", piece_tag_end), points_end = text.find("</Points>", piece_tag_end);
  if (points == std::string::npos || points_end == std::string::npos) fail(path, "no <Points> section (a truncated file?)");
  const size_t pa = text.find("<DataArray", points);
  if (pa == std::string::npos || pa > points_end) fail(path, "<Points> holds no <DataArray>");
  DataArray pts;
  parse_data_array(path, text, pa, points_end, pts);
  if (pts.components != 3 || pts.values.size() != 3 * out.num_points)
    fail(path, "<Points> holds " + std::to_string(pts.values.size()) + " values, expected 3 × " +
                   std::to_string(out.num_points) + " (a truncated file?)");
  out.points.resize(out.num_points);
  for (size_t i = 0; i < out.num_points; ++i) out.points[i] = Vec3(pts.values[3 * i], pts.values[3 * i + 1], pts.values[3 * i + 2]);

  const size_t pd = text.find("<PointData", piece_tag_end);
  if (pd != std::string::npos) {
    const size_t pd_end = text.find("</PointData>", pd);
    if (pd_end == std::string::npos) fail(path, "no closing </PointData> (a truncated file?)");
    for (size_t pos = text.find("<DataArray", pd); pos != std::string::npos && pos < pd_end;
         pos = text.find("<DataArray", pos)) {
      DataArray a;
      pos = parse_data_array(path, text, pos, pd_end, a);
      if (a.name.empty()) fail(path, "a point data array has no Name");
      if (a.values.size() != static_cast<size_t>(a.components) * out.num_points)
        fail(path, "point data '" + a.name + "' has " + std::to_string(a.values.size()) + " values, expected " +
                       std::to_string(a.components) + " × " + std::to_string(out.num_points) + " (a truncated file?)");
      if (out.arrays.count(a.name)) fail(path, "point data '" + a.name + "' appears twice");
      out.arrays[a.name] = VtuPointData::Array{a.components, std::move(a.values)};
    }
  }
  for (size_t i = 0; i < out.num_points; ++i)
    if (!out.points[i].allFinite()) fail(path, "point " + std::to_string(i) + " has a non-finite coordinate (a field of a failed run?)");
  return out;
}

bool vtu_time_from_pvd(const std::string& vtu_path, double* time) {
  std::error_code ec;
  const fs::path vtu = fs::weakly_canonical(fs::path(vtu_path), ec);
  if (ec) return false;
  // DIR/fields/step_N.vtu is listed as "fields/step_N.vtu" in DIR/fields.pvd.
  const fs::path run_dir = vtu.parent_path().parent_path();
  const fs::path pvd = run_dir / "fields.pvd";
  if (!fs::exists(pvd, ec)) return false;
  require_regular_file(pvd, "fields.pvd");
  std::ifstream in(pvd);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("<DataSet") == std::string::npos) continue;
    const std::string file = attribute(line, "file"), t = attribute(line, "timestep");
    if (file.empty() || t.empty()) continue;
    const fs::path listed = fs::weakly_canonical(run_dir / file, ec);
    if (ec || listed != vtu) continue;
    char* end = nullptr;
    const double value = std::strtod(t.c_str(), &end);
    if (*end != '\0' || !std::isfinite(value)) return false;
    *time = value;
    return true;
  }
  return false;
}

void check_vtu_matches_mesh(const VtuPointData& vtu, const std::vector<Vec3>& X) {
  if (vtu.num_points != X.size())
    fail(vtu.path, "has " + std::to_string(vtu.num_points) + " points, the case's mesh " + std::to_string(X.size()) +
                       " nodes (a field of another mesh?)");
  if (X.empty()) return;
  Vec3 lo = X.front(), hi = X.front();
  for (const Vec3& x : X) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  const double tol = 1e-9 * std::max((hi - lo).norm(), 1e-300);
  const std::vector<Vec3> d = vtu.has("displacement") ? vtu.vectors("displacement") : std::vector<Vec3>(X.size(), Vec3::Zero());
  for (size_t i = 0; i < X.size(); ++i) {
    const Vec3 ref = vtu.points[i] - d[i];
    if ((ref - X[i]).norm() > tol) {
      std::ostringstream os;
      os.precision(10);
      os << "point " << i << " is at (" << ref.x() << ", " << ref.y() << ", " << ref.z()
         << ") in the reference configuration, the case's node " << i << " at (" << X[i].x() << ", " << X[i].y() << ", "
         << X[i].z() << ") (a field of another mesh or node numbering?)";
      fail(vtu.path, os.str());
    }
  }
}

}  // namespace shelldyn
