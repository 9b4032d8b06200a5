// Gmsh MSH 4.1 ASCII reader (format reference: Gmsh manual, "MSH file format", version 4.1).
#include "lib/mesh/gmsh_reader.hpp"
#include "lib/io/result_folder.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace shelldyn {
namespace {

// Whitespace tokenizer that remembers line numbers, so every error can say FILE:LINE.
class Lexer {
 public:
  Lexer(std::istream& in, std::string file) : in_(in), file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& reason, int line = -1) const {
    throw std::runtime_error(file_ + ":" + std::to_string(line < 0 ? line_no_ : line) + ": " + reason);
  }

  int line() const { return line_no_; }

  // Next token, or false at the end of the file.
  bool try_next(std::string& token) {
    while (true) {
      while (pos_ < cur_.size() && std::isspace(static_cast<unsigned char>(cur_[pos_]))) ++pos_;
      if (pos_ < cur_.size()) break;
      if (!read_line()) return false;
    }
    const size_t start = pos_;
    while (pos_ < cur_.size() && !std::isspace(static_cast<unsigned char>(cur_[pos_]))) ++pos_;
    token = cur_.substr(start, pos_ - start);
    return true;
  }

  // Next whitespace-separated token; `what` describes what was expected (for the EOF message).
  std::string next(const std::string& what) {
    std::string t;
    if (!try_next(t))
      fail("unexpected end of file while reading " + what + context() + "; the file is truncated");
    return t;
  }

  long long next_int(const std::string& what) {
    const std::string t = next(what);
    errno = 0;
    char* end = nullptr;
    const long long v = std::strtoll(t.c_str(), &end, 10);
    if (t.empty() || *end != '\0' || errno == ERANGE)
      fail("expected an integer for " + what + context() + ", found '" + t + "'");
    return v;
  }

  int next_small_int(const std::string& what) {
    const long long v = next_int(what);
    if (v < INT32_MIN || v > INT32_MAX)
      fail(what + " = " + std::to_string(v) + " is out of range" + context());
    return static_cast<int>(v);
  }

  long long next_count(const std::string& what) {
    const long long v = next_int(what);
    if (v < 0) fail(what + " must be >= 0, found " + std::to_string(v) + context());
    return v;
  }

  double next_double(const std::string& what) {
    const std::string t = next(what);
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (t.empty() || *end != '\0') fail("expected a number for " + what + context() + ", found '" + t + "'");
    if (!std::isfinite(v)) fail(what + " is not finite ('" + t + "')" + context());
    return v;
  }

  // Remaining text of the current line (trimmed); moves to the end of the line.
  std::string rest_of_line() {
    std::string r = cur_.substr(std::min(pos_, cur_.size()));
    pos_ = cur_.size();
    const auto b = r.find_first_not_of(" \t\r");
    const auto e = r.find_last_not_of(" \t\r");
    return b == std::string::npos ? std::string() : r.substr(b, e - b + 1);
  }

  void expect(const std::string& token) {
    const std::string t = next(token);
    if (t != token) fail("expected '" + token + "'" + context() + ", found '" + t + "'");
  }

  // Skips whole lines up to and including the line "$End<name>" (unknown sections).
  void skip_section(const std::string& name) {
    const std::string end = "$End" + name;
    const int start = line_no_;
    pos_ = cur_.size();
    while (read_line()) {
      if (rest_of_line() == end) return;
    }
    fail("unexpected end of file: section $" + name + " (started at line " + std::to_string(start) +
         ") has no " + end + "; the file is truncated");
  }

  void set_section(const std::string& s) { section_ = s; }

 private:
  bool read_line() {
    if (!std::getline(in_, cur_)) return false;
    ++line_no_;
    pos_ = 0;
    return true;
  }
  std::string context() const { return section_.empty() ? std::string() : " in section $" + section_; }

  std::istream& in_;
  std::string file_;
  std::string cur_;
  size_t pos_ = 0;
  int line_no_ = 0;
  std::string section_;
};

// Node count per supported element type, 0 if unsupported.
int nodes_per_element(int type) {
  switch (type) {
    case 1:
      return 2;  // 2-node line
    case 8:
      return 3;  // 3-node line
    case 10:
      return 9;  // 9-node quadrangle (the shell element)
    case 15:
      return 1;  // point
    default:
      return 0;
  }
}

std::string type_name(int type) {
  static const std::map<int, std::string> names = {
      {2, "3-node triangle"},    {3, "4-node quadrangle"},    {4, "4-node tetrahedron"},
      {5, "8-node hexahedron"},  {6, "6-node prism"},         {7, "5-node pyramid"},
      {9, "6-node triangle"},    {11, "10-node tetrahedron"}, {12, "27-node hexahedron"},
      {16, "8-node quadrangle"}, {17, "20-node hexahedron"},  {21, "10-node triangle"},
      {26, "4-node line"},       {36, "16-node quadrangle"}};
  const auto it = names.find(type);
  return it == names.end() ? "unknown type" : it->second;
}

using EntityKey = std::pair<int, int>;  // (dimension, entity tag)

struct ElementBlock {
  int dim = 0, entity = 0, type = 0, line = 0;
  std::vector<long long> node_tags;  // nodes_per_element(type) per element
  std::vector<int> lines;            // line of each element (for errors)
};

}  // namespace

Mesh read_gmsh(const std::string& path) {
  require_regular_file(path, "mesh file");  // a FIFO would block the open forever (lib/io/result_folder.hpp)
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the file for reading (check the path)");
  return read_gmsh(in, path);
}

Mesh read_gmsh(std::istream& in, const std::string& path) {
  Lexer lex(in, path);

  bool have_format = false, have_nodes = false, have_elements = false;
  std::map<EntityKey, std::string> physical_names;
  std::map<EntityKey, std::vector<int>> entity_physicals;
  std::unordered_map<long long, Vec3> node_xyz;
  std::vector<ElementBlock> blocks;

  while (true) {
    // Top level: section headers only.
    std::string header;
    lex.set_section("");
    if (!lex.try_next(header)) break;  // end of file between sections: normal end
    if (header.size() < 2 || header[0] != '$')
      lex.fail("expected a section header such as $Nodes, found '" + header + "'");
    const std::string name = header.substr(1);
    lex.set_section(name);

    if (name == "MeshFormat") {
      const std::string version = lex.next("the MSH version");
      const long long file_type = lex.next_int("the file type");
      lex.next_int("the data size");
      if (version != "4.1")
        lex.fail("MSH version " + version +
                 " is not supported: export MSH 4.1 ASCII (gmsh -format msh41)");
      if (file_type != 0)
        lex.fail("binary MSH files are not supported; save as ASCII (Mesh.Binary = 0, no '-bin')");
      lex.expect("$EndMeshFormat");
      have_format = true;
      continue;
    }
    if (!have_format) lex.fail("section $" + name + " before $MeshFormat; this is not an MSH 4.1 file");

    if (name == "PhysicalNames") {
      const long long n = lex.next_count("the number of physical names");
      for (long long i = 0; i < n; ++i) {
        const int dim = lex.next_small_int("the physical group dimension");
        const int tag = lex.next_small_int("the physical tag");
        const std::string q = lex.rest_of_line();
        if (q.size() < 2 || q.front() != '"' || q.back() != '"')
          lex.fail("expected a quoted physical name, found '" + q + "'");
        const std::string pname = q.substr(1, q.size() - 2);
        if (pname == "all")
          lex.fail(
              "the physical group name \"all\" is reserved (the reader defines the sets \"all\" for "
              "the whole mesh); rename the group");
        if (pname.empty()) lex.fail("empty physical name for tag " + std::to_string(tag));
        physical_names[{dim, tag}] = pname;
      }
      lex.expect("$EndPhysicalNames");
    } else if (name == "Entities") {
      long long counts[4];
      for (int d = 0; d < 4; ++d)
        counts[d] = lex.next_count("the number of entities of dimension " + std::to_string(d));
      for (int d = 0; d < 4; ++d)
        for (long long i = 0; i < counts[d]; ++i) {
          const int tag = lex.next_small_int("an entity tag");
          const int n_coords = d == 0 ? 3 : 6;  // points: X Y Z; others: bounding box
          for (int c = 0; c < n_coords; ++c) lex.next_double("an entity coordinate");
          const long long n_phys = lex.next_count("the number of physical tags");
          auto& phys = entity_physicals[{d, tag}];
          for (long long k = 0; k < n_phys; ++k) phys.push_back(lex.next_small_int("a physical tag"));
          if (d > 0) {
            const long long n_bound = lex.next_count("the number of bounding entities");
            for (long long k = 0; k < n_bound; ++k) lex.next_int("a bounding entity tag");
          }
        }
      lex.expect("$EndEntities");
    } else if (name == "Nodes") {
      const long long n_blocks = lex.next_count("the number of node blocks");
      const long long n_nodes = lex.next_count("the number of nodes");
      lex.next_int("the minimum node tag");
      lex.next_int("the maximum node tag");
      long long seen = 0;
      std::vector<long long> tags;
      for (long long b = 0; b < n_blocks; ++b) {
        const int dim = lex.next_small_int("the entity dimension of a node block");
        lex.next_int("the entity tag of a node block");
        const long long parametric = lex.next_int("the parametric flag");
        const long long n = lex.next_count("the number of nodes in a block");
        if (dim < 0 || dim > 3)
          lex.fail("node block entity dimension " + std::to_string(dim) + " is not 0..3");
        if (parametric != 0 && parametric != 1)
          lex.fail("the parametric flag must be 0 or 1, found " + std::to_string(parametric));
        tags.clear();
        for (long long i = 0; i < n; ++i) tags.push_back(lex.next_int("a node tag"));
        for (long long i = 0; i < n; ++i) {
          Vec3 x;
          for (int c = 0; c < 3; ++c) x[c] = lex.next_double("a node coordinate");
          if (parametric)
            for (int c = 0; c < dim; ++c) lex.next_double("a parametric node coordinate");
          if (!node_xyz.emplace(tags[static_cast<size_t>(i)], x).second)
            lex.fail("node tag " + std::to_string(tags[static_cast<size_t>(i)]) + " is defined twice");
        }
        seen += n;
      }
      if (seen != n_nodes)
        lex.fail("the $Nodes header announces " + std::to_string(n_nodes) + " nodes but the blocks hold " +
                 std::to_string(seen));
      lex.expect("$EndNodes");
      have_nodes = true;
    } else if (name == "Elements") {
      if (!have_nodes) lex.fail("section $Elements before $Nodes; node tags cannot be resolved");
      const long long n_blocks = lex.next_count("the number of element blocks");
      const long long n_elements = lex.next_count("the number of elements");
      lex.next_int("the minimum element tag");
      lex.next_int("the maximum element tag");
      long long seen = 0;
      for (long long b = 0; b < n_blocks; ++b) {
        ElementBlock blk;
        blk.dim = lex.next_small_int("the entity dimension of an element block");
        blk.entity = lex.next_small_int("the entity tag of an element block");
        blk.type = lex.next_small_int("the element type");
        blk.line = lex.line();
        const long long n = lex.next_count("the number of elements in a block");
        const int npe = nodes_per_element(blk.type);
        if (npe == 0)
          lex.fail("element type " + std::to_string(blk.type) + " (" + type_name(blk.type) +
                   ") is not supported: only 9-node quadrangles (type 10) are\n"
                   "gmsh -2 -order 2 with Mesh.RecombineAll = 1 and Mesh.SecondOrderIncomplete = 0");
        if (blk.type == 10 && blk.dim != 2)
          lex.fail("quad9 elements (type 10) must belong to a surface (entity dimension 2), found " +
                   std::to_string(blk.dim));
        // Bounded reserve: a corrupt count must produce a truncation error, not a huge allocation.
        blk.node_tags.reserve(static_cast<size_t>(std::min<long long>(n, 1 << 20) * npe));
        for (long long i = 0; i < n; ++i) {
          lex.next_int("an element tag");
          blk.lines.push_back(lex.line());
          for (int k = 0; k < npe; ++k) {
            const long long t = lex.next_int("an element node tag");
            if (!node_xyz.count(t))
              lex.fail("element node tag " + std::to_string(t) + " is not defined in $Nodes");
            blk.node_tags.push_back(t);
          }
        }
        seen += n;
        blocks.push_back(std::move(blk));
      }
      if (seen != n_elements)
        lex.fail("the $Elements header announces " + std::to_string(n_elements) +
                 " elements but the blocks hold " + std::to_string(seen));
      lex.expect("$EndElements");
      have_elements = true;
    } else {
      lex.skip_section(name);  // unknown or irrelevant section ($NodeData, $Periodic, ...)
    }
  }

  if (!have_format) lex.fail("no $MeshFormat section; this is not a Gmsh MSH file");
  if (!have_nodes || !have_elements) lex.fail("the file has no $Nodes or no $Elements section");

  // Dense renumbering of quad9 nodes in ascending tag order.
  std::vector<long long> used;
  for (const auto& blk : blocks)
    if (blk.type == 10) used.insert(used.end(), blk.node_tags.begin(), blk.node_tags.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  if (used.empty())
    lex.fail(
        "no 9-node quadrangles (type 10) in the file (how to make them below)\n"
        "gmsh -2 -order 2 with Mesh.RecombineAll = 1 and Mesh.SecondOrderIncomplete = 0");
  std::unordered_map<long long, int> index;
  Mesh mesh;
  for (long long t : used) {
    index.emplace(t, mesh.num_nodes());
    mesh.X.push_back(node_xyz.at(t));
  }

  std::map<std::string, std::set<int>> node_sets, element_sets;
  auto group_name = [&](int dim, int ptag) {
    const auto it = physical_names.find({dim, ptag});
    return it != physical_names.end() ? it->second : "physical_" + std::to_string(ptag);
  };
  for (const auto& blk : blocks) {
    const int npe = nodes_per_element(blk.type);
    const auto eit = entity_physicals.find({blk.dim, blk.entity});
    static const std::vector<int> kNone;
    const std::vector<int>& phys = eit == entity_physicals.end() ? kNone : eit->second;
    const int first_element = mesh.num_elements();
    const size_t n = blk.lines.size();
    if (blk.type == 10)
      for (size_t i = 0; i < n; ++i) {
        Quad9 q;
        for (int k = 0; k < 9; ++k) q[k] = index.at(blk.node_tags[i * 9 + k]);  // Gmsh order = ours
        mesh.elements.push_back(q);
      }
    for (int ptag : phys) {
      const std::string gname = group_name(blk.dim, ptag);
      auto& ns = node_sets[gname];
      for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < npe; ++k) {
          const long long t = blk.node_tags[i * npe + k];
          const auto it = index.find(t);
          if (it == index.end())
            lex.fail("physical group \"" + gname + "\" contains node tag " + std::to_string(t) +
                         ", which belongs to no 9-node quadrangle; sets must lie on the shell mesh",
                     blk.lines[i]);
          ns.insert(it->second);
        }
      if (blk.dim == 2) {
        auto& es = element_sets[gname];
        for (size_t i = 0; i < n; ++i) es.insert(first_element + static_cast<int>(i));
      }
    }
  }
  for (auto& kv : node_sets) mesh.node_sets[kv.first].assign(kv.second.begin(), kv.second.end());
  for (auto& kv : element_sets) mesh.element_sets[kv.first].assign(kv.second.begin(), kv.second.end());
  std::vector<int>& all_n = mesh.node_sets["all"];
  all_n.resize(mesh.X.size());
  for (int i = 0; i < mesh.num_nodes(); ++i) all_n[static_cast<size_t>(i)] = i;
  std::vector<int>& all_e = mesh.element_sets["all"];
  all_e.resize(mesh.elements.size());
  for (int i = 0; i < mesh.num_elements(); ++i) all_e[static_cast<size_t>(i)] = i;
  return mesh;
}

}  // namespace shelldyn
