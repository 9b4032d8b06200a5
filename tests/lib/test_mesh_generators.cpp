// Built-in mesh generators (lib/mesh/mesh_generators.hpp): counts, exact geometry, sets, normals, area.
#include "lib/mesh/mesh_generators.hpp"
#include "lib/mesh/nodal_normals.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>

namespace shelldyn {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Structural invariants every generated mesh must satisfy: indices in range, 9 distinct nodes per
// element, every node used, sets sorted/unique/in range, "all" sets present, and no two nodes at the
// same position (coincident nodes must have been merged by construction).
void expect_valid_mesh(const Mesh& m) {
  std::vector<int> used(m.X.size(), 0);
  for (const Quad9& q : m.elements) {
    std::set<int> distinct(q.begin(), q.end());
    EXPECT_EQ(distinct.size(), 9u);
    for (int n : q) {
      ASSERT_GE(n, 0);
      ASSERT_LT(n, m.num_nodes());
      used[static_cast<size_t>(n)] = 1;
    }
  }
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0) << "unused nodes";
  auto check_set = [](const std::vector<int>& s, int n, const std::string& name) {
    EXPECT_TRUE(std::is_sorted(s.begin(), s.end())) << name;
    EXPECT_EQ(std::adjacent_find(s.begin(), s.end()), s.end()) << name;
    for (int i : s) {
      EXPECT_GE(i, 0) << name;
      EXPECT_LT(i, n) << name;
    }
  };
  for (const auto& kv : m.node_sets) check_set(kv.second, m.num_nodes(), "node set " + kv.first);
  for (const auto& kv : m.element_sets) check_set(kv.second, m.num_elements(), "element set " + kv.first);
  ASSERT_TRUE(m.node_sets.count("all"));
  ASSERT_TRUE(m.element_sets.count("all"));
  EXPECT_EQ(m.node_sets.at("all").size(), m.X.size());
  EXPECT_EQ(m.element_sets.at("all").size(), m.elements.size());
  // Coincident nodes: sort coordinates lexicographically and compare neighbours, with a tolerance of
  // 1e-9 of the bounding box (far below any node spacing used in these tests).
  std::vector<std::tuple<double, double, double>> pts;
  double scale = 0;
  for (const Vec3& x : m.X) {
    pts.emplace_back(x.x(), x.y(), x.z());
    scale = std::max(scale, x.cwiseAbs().maxCoeff());
  }
  std::sort(pts.begin(), pts.end());
  int coincident = 0;
  for (size_t i = 0; i < pts.size(); ++i)
    for (size_t j = i + 1; j < pts.size() && std::get<0>(pts[j]) - std::get<0>(pts[i]) < 1e-9 * scale; ++j) {
      const Vec3 a(std::get<0>(pts[i]), std::get<1>(pts[i]), std::get<2>(pts[i]));
      const Vec3 b(std::get<0>(pts[j]), std::get<1>(pts[j]), std::get<2>(pts[j]));
      if ((a - b).norm() < 1e-9 * scale) ++coincident;
    }
  EXPECT_EQ(coincident, 0) << "coincident (unmerged) nodes";
}

template <class F>
void expect_invalid(F f, const std::string& fragment) {
  try {
    f();
    ADD_FAILURE() << "expected std::invalid_argument mentioning '" << fragment << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

// ------------------------------------------------------------------------------------------------

TEST(MakeRectangle, CountsGeometrySetsAndNormals) {
  const Mesh m = make_rectangle(4.0, 2.0, 3, 2, 1.0, -1.0);
  expect_valid_mesh(m);
  EXPECT_EQ(m.num_nodes(), 7 * 5);
  EXPECT_EQ(m.num_elements(), 6);
  EXPECT_EQ(m.node_sets.at("left").size(), 5u);
  EXPECT_EQ(m.node_sets.at("right").size(), 5u);
  EXPECT_EQ(m.node_sets.at("bottom").size(), 7u);
  EXPECT_EQ(m.node_sets.at("top").size(), 7u);
  for (int n : m.node_sets.at("left")) EXPECT_EQ(m.X[n].x(), 1.0);
  for (int n : m.node_sets.at("right")) EXPECT_EQ(m.X[n].x(), 5.0);
  for (int n : m.node_sets.at("bottom")) EXPECT_EQ(m.X[n].y(), -1.0);
  for (int n : m.node_sets.at("top")) EXPECT_EQ(m.X[n].y(), 1.0);
  EXPECT_EQ(m.X[m.node_sets.at("corner_ll")[0]], Vec3(1, -1, 0));
  EXPECT_EQ(m.X[m.node_sets.at("corner_lr")[0]], Vec3(5, -1, 0));
  EXPECT_EQ(m.X[m.node_sets.at("corner_ur")[0]], Vec3(5, 1, 0));
  EXPECT_EQ(m.X[m.node_sets.at("corner_ul")[0]], Vec3(1, 1, 0));
  // Corner 1 of every element is its lower-left corner, node 3 upper right (counter-clockwise, +Z).
  for (const Quad9& q : m.elements) {
    EXPECT_LT(m.X[q[0]].x(), m.X[q[1]].x());
    EXPECT_LT(m.X[q[1]].y(), m.X[q[2]].y());
    EXPECT_NEAR((m.X[q[8]] - 0.25 * (m.X[q[0]] + m.X[q[1]] + m.X[q[2]] + m.X[q[3]])).norm(), 0, 1e-14);
  }
  EXPECT_NEAR(surface_area(m), 8.0, 1e-13);
  const auto p = initial_normals(m);
  for (const Vec3& n : p) EXPECT_NEAR((n - Vec3::UnitZ()).norm(), 0.0, 1e-15);
  EXPECT_NO_THROW(check_orientation(m, p));
}

TEST(MakeRectangle, RejectsBadParameters) {
  expect_invalid([] { make_rectangle(0.0, 1.0, 1, 1); }, "'a'");
  expect_invalid([] { make_rectangle(1.0, -1.0, 1, 1); }, "'b'");
  expect_invalid([] { make_rectangle(1.0, NAN, 1, 1); }, "'b'");
  expect_invalid([] { make_rectangle(1.0, 1.0, 0, 1); }, "'nx'");
  expect_invalid([] { make_rectangle(1.0, 1.0, 1, -3); }, "'ny'");
  expect_invalid([] { make_rectangle(1.0, 1.0, 1, 1, INFINITY); }, "'x0'");
  expect_invalid([] { make_rectangle(1.0, 1.0, 100000, 100000); }, "nodes");
}

// FLP-prov plate of docs/benchmarks.md §1.3: [0,3]x[0,7] u [3,6]x[0,3].
TEST(MakeCellUnion, FlyingLShape) {
  const Mesh m = make_cell_union({{0, 0, 3, 7}, {3, 0, 6, 3}}, 1.0);
  expect_valid_mesh(m);
  EXPECT_EQ(m.num_elements(), 30);
  // Half-cell node grid: long leg 7 x 15 nodes, short leg 7 x 7, sharing the 7 nodes on X = 3.
  EXPECT_EQ(m.num_nodes(), 7 * 15 + 7 * 7 - 7);
  // Perimeter 6 + 3 + 3 + 4 + 3 + 7 = 26 unit edges, 2 node intervals each, closed loop -> 52 nodes.
  EXPECT_EQ(m.node_sets.at("boundary").size(), 52u);
  for (int n : m.node_sets.at("boundary")) {
    const Vec3& x = m.X[n];
    const bool on = x.x() == 0 || x.y() == 0 || x.y() == 7 || x.x() == 6 || (x.y() == 3 && x.x() >= 3) ||
                    (x.x() == 3 && x.y() >= 3);
    EXPECT_TRUE(on) << x.transpose();
  }
  EXPECT_NEAR(surface_area(m), 30.0, 1e-12);
  // Points A = (6,0,0) and B = (0,7,0) of the benchmark exist as nodes.
  int found = 0;
  for (const Vec3& x : m.X) found += (x == Vec3(6, 0, 0)) + (x == Vec3(0, 7, 0));
  EXPECT_EQ(found, 2);
  const auto p = initial_normals(m);
  for (const Vec3& n : p) EXPECT_NEAR((n - Vec3::UnitZ()).norm(), 0.0, 1e-15);
  EXPECT_NO_THROW(check_orientation(m, p));
}

TEST(MakeCellUnion, CellSizeAndNegativeOffsets) {
  const Mesh m = make_cell_union({{-2, -1, 0, 1}}, 0.5);
  expect_valid_mesh(m);
  EXPECT_EQ(m.num_elements(), 4);
  EXPECT_EQ(m.num_nodes(), 25);
  EXPECT_NEAR(surface_area(m), 1.0, 1e-14);
  EXPECT_EQ(m.X.front(), Vec3(-1.0, -0.5, 0.0));
  EXPECT_EQ(m.node_sets.at("boundary").size(), 16u);
}

TEST(MakeCellUnion, RejectsOverlapDisconnectedAndBadInput) {
  expect_invalid([] { make_cell_union({{0, 0, 3, 7}, {2, 0, 6, 3}}); }, "overlap");
  expect_invalid([] { make_cell_union({{0, 0, 1, 1}, {1, 1, 2, 2}}); }, "connected");  // corner contact only
  expect_invalid([] { make_cell_union({{0, 0, 1, 1}, {3, 0, 4, 1}}); }, "connected");
  expect_invalid([] { make_cell_union({}); }, "'rectangles'");
  expect_invalid([] { make_cell_union({{0, 0, 0, 1}}); }, "rectangles[0]");
  expect_invalid([] { make_cell_union({{0, 0, 1, 1}}, 0.0); }, "'cell'");
}

// docs/benchmarks.md §2.3 geometry.
TEST(MakeCylindricalPanel, CountsExactGeometrySetsNormals) {
  const double R = 150, angle = 0.2, L = 30;
  const Mesh m = make_cylindrical_panel(R, angle, L, 6, 4);
  expect_valid_mesh(m);
  EXPECT_EQ(m.num_elements(), 24);
  EXPECT_EQ(m.num_nodes(), 9 * 13);
  EXPECT_EQ(m.node_sets.at("x0").size(), 13u);
  EXPECT_EQ(m.node_sets.at("x1").size(), 13u);
  EXPECT_EQ(m.node_sets.at("arc_min").size(), 9u);
  EXPECT_EQ(m.node_sets.at("arc_max").size(), 9u);
  // Every node (mid-sides and centres included) lies on the cylinder of radius R about (x, 0, -R).
  for (const Vec3& x : m.X) {
    EXPECT_NEAR(std::hypot(x.y(), x.z() + R), R, 1e-12 * R);
    EXPECT_GE(x.x(), 0.0);
    EXPECT_LE(x.x(), L);
  }
  const Vec3 c = m.X[m.node_sets.at("corner_x0_arcmin")[0]];
  EXPECT_EQ(c.x(), 0.0);
  EXPECT_NEAR(c.y(), -R * std::sin(0.1), 1e-12 * R);
  EXPECT_NEAR(c.z(), R * std::cos(0.1) - R, 1e-12 * R);
  EXPECT_EQ(m.X[m.node_sets.at("corner_x1_arcmax")[0]].x(), L);
  EXPECT_EQ(m.X[m.node_sets.at("corner_x1_arcmax")[0]].y(), -c.y());
  EXPECT_EQ(m.X[m.node_sets.at("corner_x0_arcmax")[0]].y(), -c.y());
  EXPECT_EQ(m.X[m.node_sets.at("corner_x1_arcmin")[0]].y(), c.y());
  // Normals: unit and outward radial. Interior nodes are symmetric, hence radial to round-off; the
  // worst deviation (boundary nodes with a one-sided element) is bounded in the convergence test.
  const auto p = initial_normals(m);
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec3 radial = Vec3(0, m.X[i].y(), m.X[i].z() + R) / R;
    EXPECT_NEAR(p[i].norm(), 1.0, 1e-15);
    EXPECT_GT(p[i].dot(radial), std::cos(1e-3));
  }
  EXPECT_NO_THROW(check_orientation(m, p));
}

// Area R*angle*L is approximated by the quad9 interpolation of the arc: the error must fall at
// least like h^4 (ratio >= 12 per halving; measured 15.4 and 15.9: quadratic isoparametric geometry),
// and the angle between nodal normal and true radial like h^3 (ratio >= 6; measured 7.3 and 7.8; the
// worst node is on the free edge, where one element alone defines the normal).
TEST(MakeCylindricalPanel, AreaAndNormalsConvergeUnderRefinement) {
  const double R = 1.0, angle = 2.0, L = 1.5, exact = R * angle * L;
  double prev_area_err = 0, prev_normal_err = 0;
  for (int n : {2, 4, 8}) {
    const Mesh m = make_cylindrical_panel(R, angle, L, n, 1);
    const double area_err = std::fabs(surface_area(m) - exact) / exact;
    const auto p = initial_normals(m);
    double normal_err = 0;
    for (size_t i = 0; i < p.size(); ++i) {
      const Vec3 radial = Vec3(0, m.X[i].y(), m.X[i].z() + R) / R;
      normal_err = std::max(normal_err, std::acos(std::min(1.0, p[i].dot(radial))));
    }
    RecordProperty("area_err_n" + std::to_string(n), std::to_string(area_err));
    RecordProperty("normal_err_n" + std::to_string(n), std::to_string(normal_err));
    // Element arc angle/n; a quadratic chord of arc 2 rad already gives < 1 % area error.
    EXPECT_LT(area_err, 1e-2);
    EXPECT_LT(normal_err, 0.1);
    if (prev_area_err > 0) {
      EXPECT_GT(prev_area_err / area_err, 12.0) << "n = " << n;
      EXPECT_GT(prev_normal_err / normal_err, 6.0) << "n = " << n;
    }
    prev_area_err = area_err;
    prev_normal_err = normal_err;
  }
}

TEST(MakeCylindricalPanel, RejectsBadParameters) {
  expect_invalid([] { make_cylindrical_panel(-1, 0.2, 30, 4, 6); }, "'radius'");
  expect_invalid([] { make_cylindrical_panel(150, 0.0, 30, 4, 6); }, "'angle'");
  expect_invalid([] { make_cylindrical_panel(150, 7.0, 30, 4, 6); }, "'angle'");
  expect_invalid([] { make_cylindrical_panel(150, 4.0, 30, 1, 6); }, "'n_arc'");
  expect_invalid([] { make_cylindrical_panel(150, 0.2, 0, 4, 6); }, "'length'");
  expect_invalid([] { make_cylindrical_panel(150, 0.2, 30, 0, 6); }, "'n_arc'");
  expect_invalid([] { make_cylindrical_panel(150, 0.2, 30, 4, 0); }, "'n_axial'");
}

void expect_on_hemisphere(const Mesh& m, double R, double hole_deg) {
  const double zmax = R * std::cos(hole_deg * kPi / 180);
  for (const Vec3& x : m.X) {
    EXPECT_NEAR(x.norm(), R, 1e-13 * R);
    EXPECT_GE(x.z(), 0.0);
    EXPECT_LE(x.z(), zmax * (1 + 1e-14));
  }
}

// docs/benchmarks.md §§3.2, 4.4 geometry.
TEST(MakeHemisphere, QuarterModel) {
  const double R = 10;
  const int n = 4;
  const Mesh m = make_hemisphere(R, 18.0, true, n);
  expect_valid_mesh(m);
  EXPECT_EQ(m.num_elements(), n * n);
  EXPECT_EQ(m.num_nodes(), (2 * n + 1) * (2 * n + 1));
  expect_on_hemisphere(m, R, 18.0);
  for (const char* s : {"equator", "hole", "sym_y0", "sym_x0"}) EXPECT_EQ(m.node_sets.at(s).size(), 9u) << s;
  for (int i : m.node_sets.at("equator")) EXPECT_EQ(m.X[i].z(), 0.0);
  for (int i : m.node_sets.at("sym_y0")) EXPECT_EQ(m.X[i].y(), 0.0);
  for (int i : m.node_sets.at("sym_x0")) EXPECT_EQ(m.X[i].x(), 0.0);
  for (int i : m.node_sets.at("hole")) EXPECT_NEAR(m.X[i].z(), R * std::cos(18 * kPi / 180), 1e-13 * R);
  EXPECT_EQ(m.X[m.node_sets.at("point_xpos")[0]], Vec3(R, 0, 0));
  EXPECT_EQ(m.X[m.node_sets.at("point_ypos")[0]], Vec3(0, R, 0));
  EXPECT_FALSE(m.node_sets.count("point_xneg"));
  const auto p = initial_normals(m);
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(p[i].norm(), 1.0, 1e-15);
    EXPECT_GT(p[i].dot(m.X[i] / R), std::cos(0.02)) << "node " << i;  // outward, nearly radial
  }
  EXPECT_NO_THROW(check_orientation(m, p));
}

TEST(MakeHemisphere, FullModelWrapsAroundWithoutDuplicates) {
  const double R = 10;
  const int n = 3;
  const Mesh m = make_hemisphere(R, 18.0, false, n);
  expect_valid_mesh(m);  // includes the no-coincident-nodes check at the phi = 0 / 360 seam
  EXPECT_EQ(m.num_elements(), 4 * n * n);
  EXPECT_EQ(m.num_nodes(), (2 * n + 1) * 8 * n);
  expect_on_hemisphere(m, R, 18.0);
  EXPECT_EQ(m.node_sets.at("equator").size(), size_t(8 * n));
  EXPECT_EQ(m.node_sets.at("hole").size(), size_t(8 * n));
  EXPECT_EQ(m.X[m.node_sets.at("point_xpos")[0]], Vec3(R, 0, 0));
  EXPECT_EQ(m.X[m.node_sets.at("point_ypos")[0]], Vec3(0, R, 0));
  EXPECT_EQ(m.X[m.node_sets.at("point_xneg")[0]], Vec3(-R, 0, 0));
  EXPECT_EQ(m.X[m.node_sets.at("point_yneg")[0]], Vec3(0, -R, 0));
  EXPECT_FALSE(m.node_sets.count("sym_x0"));
  const auto p = initial_normals(m);
  for (size_t i = 0; i < p.size(); ++i) EXPECT_GT(p[i].dot(m.X[i] / R), std::cos(0.03)) << "node " << i;
  EXPECT_NO_THROW(check_orientation(m, p));
  // The benchmark mesh (docs/benchmarks.md §3.2): 4 quarters x 8 x 8 = 256 elements.
  EXPECT_EQ(make_hemisphere(R, 18.0, false, 8).num_elements(), 256);
}

// Area 2 pi R^2 cos(hole) (full) and a quarter of it: the relative error must be small and fall at
// least like h^4 (ratio >= 12 per halving of the element size; measured 8.2e-4, 5.2e-5, 3.3e-6 for
// n = 2, 4, 8, i.e. ratios 15.8 and 15.9).
TEST(MakeHemisphere, AreaConvergesToExact) {
  const double R = 10, hole = 18.0;
  const double exact = 2 * kPi * R * R * std::cos(hole * kPi / 180);
  double prev = 0;
  for (int n : {2, 4, 8}) {
    const double err_q = std::fabs(4 * surface_area(make_hemisphere(R, hole, true, n)) - exact) / exact;
    const double err_f = std::fabs(surface_area(make_hemisphere(R, hole, false, n)) - exact) / exact;
    RecordProperty("area_err_n" + std::to_string(n), std::to_string(err_q));
    EXPECT_NEAR(err_q, err_f, 1e-12);  // same elements, just 4 copies
    EXPECT_LT(err_q, 2e-3);
    if (prev > 0) {
      EXPECT_GT(prev / err_q, 12.0) << "n = " << n;
    }
    prev = err_q;
  }
}

TEST(MakeHemisphere, RejectsBadParameters) {
  expect_invalid([] { make_hemisphere(0, 18, true, 4); }, "'radius'");
  expect_invalid([] { make_hemisphere(10, 0, true, 4); }, "'hole_deg'");
  expect_invalid([] { make_hemisphere(10, 90, true, 4); }, "'hole_deg'");
  expect_invalid([] { make_hemisphere(10, -5, false, 4); }, "'hole_deg'");
  expect_invalid([] { make_hemisphere(10, 18, false, 0); }, "'n'");
}

}  // namespace
}  // namespace shelldyn

namespace shelldyn {
namespace {

// Generators for path-following benchmarks (issue 12): geometry, orientation and sets.
TEST(MeshGenerators, CylinderPatchSitsAtItsNaturalHeightWithEdgesOnCoordinatePlanes) {
  const Mesh m = make_cylinder_patch(2540.0, 0.1, 254.0, 4, 3);
  EXPECT_EQ(m.num_nodes(), 9 * 7);
  EXPECT_EQ(m.num_elements(), 12);
  for (const Vec3& x : m.X) EXPECT_NEAR(std::hypot(x.y(), x.z()), 2540.0, 1e-9);
  for (int i : m.node_sets.at("arc0")) EXPECT_EQ(m.X[static_cast<size_t>(i)].y(), 0.0);  // plane Y = 0
  for (int i : m.node_sets.at("x0")) EXPECT_EQ(m.X[static_cast<size_t>(i)].x(), 0.0);    // plane X = 0
  EXPECT_DOUBLE_EQ(m.X[static_cast<size_t>(m.node_sets.at("corner_x0_arc0")[0])].z(), 2540.0);
  EXPECT_THROW(make_cylinder_patch(1.0, 4.0, 1.0, 4, 4), std::invalid_argument);
}

TEST(MeshGenerators, ClosedCylinderMergesTheSeam) {
  const Mesh m = make_closed_cylinder(3.0, 10.0, 8, 4);
  EXPECT_EQ(m.num_nodes(), 16 * 9);  // 2 n_circ nodes per ring, no duplicate seam
  EXPECT_EQ(m.num_elements(), 32);
  for (const Vec3& x : m.X) EXPECT_NEAR(std::hypot(x.y(), x.z()), 3.0, 1e-12);
  EXPECT_EQ(m.node_sets.at("top").size(), 9u);
  EXPECT_EQ(m.node_sets.at("bottom").size(), 9u);
  EXPECT_THROW(make_closed_cylinder(3.0, 10.0, 3, 4), std::invalid_argument);
}

TEST(MeshGenerators, SlitAnnulusKeepsTheSlitOpen) {
  const Mesh m = make_slit_annulus(6.0, 10.0, 2, 8);
  EXPECT_EQ(m.num_nodes(), 5 * 17);  // theta = 0 and 2 pi are distinct nodes
  const Vec3 a = m.X[static_cast<size_t>(m.node_sets.at("point_A")[0])];
  const Vec3 b = m.X[static_cast<size_t>(m.node_sets.at("point_B")[0])];
  EXPECT_EQ(a, Vec3(6.0, 0.0, 0.0));
  EXPECT_EQ(b, Vec3(10.0, 0.0, 0.0));
  const auto& s0 = m.node_sets.at("slit_start");
  const auto& s1 = m.node_sets.at("slit_end");
  for (size_t k = 0; k < s0.size(); ++k) EXPECT_NE(s0[k], s1[k]);
  EXPECT_THROW(make_slit_annulus(10.0, 6.0, 2, 8), std::invalid_argument);
}

}  // namespace
}  // namespace shelldyn
