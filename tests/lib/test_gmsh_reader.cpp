// Gmsh MSH 4.1 ASCII reader (lib/mesh/gmsh_reader.hpp): a valid two-element file with physical groups and
// sparse node tags, and malformed files that must be rejected with FILE:LINE: reason.
#include "lib/mesh/gmsh_reader.hpp"
#include "lib/mesh/nodal_normals.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace shelldyn {
namespace {

// Sparse, non-contiguous node tags for the 5 x 3 half-cell grid of the 2 x 1 plate [0,2] x [0,1].
long long tag(int i, int j) {
  return 100 + 7 * (j * 5 + i);
}
constexpr int kDI[9] = {0, 2, 2, 0, 1, 2, 1, 0, 1};
constexpr int kDJ[9] = {0, 0, 2, 2, 0, 1, 2, 1, 1};

// A file laid out as Gmsh writes it: entities with physical tags, a point node block, a parametric
// surface node block, an unused geometry node, an unknown section, point/line3/quad9 element blocks.
std::string valid_msh() {
  std::ostringstream os;
  os << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
     << "$PhysicalNames\n3\n0 1 \"A\"\n1 2 \"left edge\"\n2 3 \"plate_left\"\n$EndPhysicalNames\n"
     << "$Comments\nthis section is unknown to the reader and must be skipped\n$EndComments\n"
     << "$Entities\n2 1 2 0\n"
     << "1 1 0 0 1 1\n"               // point 1 at (1,0,0), physical 1
     << "2 9 9 9 0\n"                 // point 2, no physical group
     << "1 0 0 0 0 1 0 1 2 2 1 -2\n"  // curve 1, physical 2, bounded by points 1, -2
     << "1 0 0 0 1 1 0 1 3 1 1\n"     // surface 1, physical 3
     << "2 1 0 0 2 1 0 1 7 1 1\n"     // surface 2, physical 7 (unnamed)
     << "$EndEntities\n";
  os << "$Nodes\n3 16 5 " << tag(4, 2) << "\n";
  os << "0 1 0 1\n" << tag(2, 0) << "\n1 0 0\n";
  os << "0 2 0 1\n5\n9 9 9\n";
  os << "2 1 1 14\n";
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 5; ++i)
      if (!(i == 2 && j == 0)) os << tag(i, j) << "\n";
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 5; ++i)
      if (!(i == 2 && j == 0)) os << 0.5 * i << " " << 0.5 * j << " 0 " << 0.1 * i << " " << 0.1 * j << "\n";
  os << "$EndNodes\n";
  os << "$Elements\n4 4 1 40\n";
  os << "0 1 15 1\n1 " << tag(2, 0) << "\n";
  os << "1 1 8 1\n2 " << tag(0, 0) << " " << tag(0, 2) << " " << tag(0, 1) << "\n";
  for (int e = 0; e < 2; ++e) {
    os << "2 " << e + 1 << " 10 1\n" << 30 + 10 * e;
    for (int k = 0; k < 9; ++k) os << " " << tag(2 * e + kDI[k], kDJ[k]);
    os << "\n";
  }
  os << "$EndElements\n";
  return os.str();
}

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "shelldyn_" + name + ".msh";
  std::ofstream(path) << text;
  return path;
}

// 1-based line number of the first line containing `needle` in `text`.
int line_of(const std::string& text, const std::string& needle) {
  const size_t pos = text.find(needle);
  EXPECT_NE(pos, std::string::npos) << needle;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(pos), '\n'));
}

std::string replace_once(std::string s, const std::string& from, const std::string& to) {
  const size_t pos = s.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return s.replace(pos, from.size(), to);
}

// Reads `text` from a file and expects a runtime_error "PATH:LINE: ..." containing `reason`.
void expect_rejected(const std::string& name, const std::string& text, int line, const std::string& reason) {
  const std::string path = write_file(name, text);
  try {
    read_gmsh(path);
    ADD_FAILURE() << name << ": accepted a malformed file";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path + ":" + std::to_string(line) + ": ", 0), 0u) << name << ": " << msg;
    EXPECT_NE(msg.find(reason), std::string::npos) << name << ": " << msg;
  }
}

TEST(GmshReader, ReadsTwoQuad9WithPhysicalGroupsAndSparseTags) {
  const Mesh m = read_gmsh(write_file("valid", valid_msh()));
  // The unused geometry node (tag 5) is dropped; the rest are renumbered densely by ascending tag.
  ASSERT_EQ(m.num_nodes(), 15);
  ASSERT_EQ(m.num_elements(), 2);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 5; ++i) EXPECT_EQ(m.X[j * 5 + i], Vec3(0.5 * i, 0.5 * j, 0.0)) << i << "," << j;
  for (int e = 0; e < 2; ++e)
    for (int k = 0; k < 9; ++k) EXPECT_EQ(m.elements[e][k], kDJ[k] * 5 + 2 * e + kDI[k]) << e << "," << k;
  EXPECT_EQ(m.node_sets.at("A"), std::vector<int>({2}));
  EXPECT_EQ(m.node_sets.at("left edge"), std::vector<int>({0, 5, 10}));
  EXPECT_EQ(m.element_sets.at("plate_left"), std::vector<int>({0}));
  EXPECT_EQ(m.node_sets.at("plate_left"), std::vector<int>({0, 1, 2, 5, 6, 7, 10, 11, 12}));
  EXPECT_EQ(m.element_sets.at("physical_7"), std::vector<int>({1}));
  EXPECT_EQ(m.node_sets.at("physical_7"), std::vector<int>({2, 3, 4, 7, 8, 9, 12, 13, 14}));
  EXPECT_EQ(m.node_sets.at("all").size(), 15u);
  EXPECT_EQ(m.element_sets.at("all"), std::vector<int>({0, 1}));
  EXPECT_EQ(m.node_sets.size(), 5u);
  EXPECT_EQ(m.element_sets.size(), 3u);
  EXPECT_NEAR(surface_area(m), 2.0, 1e-14);
  const auto p = initial_normals(m);
  EXPECT_NO_THROW(check_orientation(m, p));
  EXPECT_NEAR((p[7] - Vec3::UnitZ()).norm(), 0.0, 1e-15);
}

TEST(GmshReader, RejectsWrongVersion) {
  const std::string text = replace_once(valid_msh(), "4.1 0 8", "2.2 0 8");
  expect_rejected("version", text, 2, "MSH version 2.2 is not supported");
}

TEST(GmshReader, RejectsBinary) {
  const std::string text = replace_once(valid_msh(), "4.1 0 8", "4.1 1 8");
  expect_rejected("binary", text, 2, "binary MSH files are not supported");
}

TEST(GmshReader, RejectsUnsupportedElementTypesWithHint) {
  const std::string base = valid_msh();
  // Quad4 (type 3) and tri6 (type 9) blocks: the error is at the block header.
  const std::string quad4 = replace_once(base, "2 2 10 1\n", "2 2 3 1\n");
  expect_rejected("quad4", quad4, line_of(quad4, "2 2 3 1\n"),
                  "element type 3 (4-node quadrangle) is not supported");
  expect_rejected("quad4_hint", quad4, line_of(quad4, "2 2 3 1\n"), "gmsh -2 -order 2");
  const std::string tri6 = replace_once(base, "2 1 10 1\n", "2 1 9 1\n");
  expect_rejected("tri6", tri6, line_of(tri6, "2 1 9 1\n"), "only 9-node quadrangles (type 10)");
  expect_rejected("tri6_hint", tri6, line_of(tri6, "2 1 9 1\n"), "Mesh.SecondOrderIncomplete = 0");
}

TEST(GmshReader, RejectsTruncatedSections) {
  const std::string base = valid_msh();
  // Cut in the middle of the surface node coordinates of $Nodes.
  const std::string cut = base.substr(0, base.find("1.5 0.5 0"));
  const int last_line = static_cast<int>(std::count(cut.begin(), cut.end(), '\n'));
  expect_rejected("truncated_nodes", cut, last_line,
                  "unexpected end of file while reading a node coordinate in section $Nodes");
  // Missing $EndNodes: the next section header appears where the end marker is expected.
  const std::string no_end = replace_once(base, "$EndNodes\n", "");
  expect_rejected("no_end_nodes", no_end, line_of(no_end, "$Elements"),
                  "expected '$EndNodes' in section $Nodes, found '$Elements'");
  // Unknown section without its end marker.
  const std::string open_unknown = replace_once(base, "$EndComments\n", "");
  expect_rejected("open_unknown", open_unknown,
                  static_cast<int>(std::count(base.begin(), base.end(), '\n')) - 1,
                  "section $Comments (started at line " + std::to_string(line_of(base, "$Comments")) +
                      ") has no $EndComments");
}

TEST(GmshReader, RejectsUndefinedNodesDuplicatesBadNumbersAndMissingFile) {
  const std::string base = valid_msh();
  const std::string undefined = replace_once(base, "\n30 ", "\n30 99999 ");
  expect_rejected("undefined", undefined, line_of(undefined, "\n30 ") + 1,
                  "element node tag 99999 is not defined");
  const std::string dup = replace_once(base, "0 2 0 1\n5\n", "0 2 0 1\n" + std::to_string(tag(2, 0)) + "\n");
  expect_rejected("duplicate", dup, line_of(dup, "9 9 9\n"), "is defined twice");
  const std::string nan = replace_once(base, "\n1 0 0\n", "\n1 nan 0\n");
  expect_rejected("nan", nan, line_of(nan, "1 nan 0"), "is not finite");
  const std::string word = replace_once(base, "4 4 1 40", "4 four 1 40");
  expect_rejected("word", word, line_of(word, "4 four 1 40"),
                  "expected an integer for the number of elements");
  const std::string reserved = replace_once(base, "\"plate_left\"", "\"all\"");
  expect_rejected("reserved", reserved, line_of(reserved, "\"all\""), "\"all\" is reserved");
  const std::string missing = ::testing::TempDir() + "shelldyn_does_not_exist.msh";
  try {
    read_gmsh(missing);
    ADD_FAILURE() << "opened a missing file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing + ": cannot open"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace shelldyn
