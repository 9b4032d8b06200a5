// From case to discrete problem (lib/model/discretization.hpp): meshes of the benchmark cases, set
// resolution, load distribution, initial velocity, constraints, monitors and their errors.
#include "lib/model/discretization.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

using namespace shelldyn;

namespace {

std::string case_path(const char* name) { return std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/" + name; }

// A 2 x 1 plate on [0,2]x[0,1] with 2 x 2 elements: nodes on a 5 x 5 grid, spacing 0.5 x 0.25.
const std::string kPlate =
    "name: plate\n"                                                   // 1
    "mesh: {generator: rectangle, a: 2, b: 1, nx: 2, ny: 2}\n"        // 2
    "material: {E: 1.0e6, nu: 0.3, rho: 2, thickness: 0.1}\n"         // 3
    "integrator: {name: em-galpha}\n"                                 // 4
    "time: {dt: 0.01, t_end: 1}\n";                                   // 5

Discretization build(const std::string& extra) {
  return build_discretization(load_case_from_string(kPlate + extra, "plate.yaml"));
}

std::string error_of(const std::string& extra) {
  try {
    build(extra);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

int node_at(const Mesh& m, const Vec3& x) {
  for (int i = 0; i < m.num_nodes(); ++i)
    if ((m.X[static_cast<size_t>(i)] - x).norm() < 1e-9) return i;
  return -1;
}

Vec3 total_load(const Discretization& d) {
  Vec3 sum = Vec3::Zero();
  for (const auto& l : d.loads) sum += l.vector;
  return sum;
}

// --- the three benchmark cases ------------------------------------------------------------------------
TEST(BenchmarkDiscretization, FlyingPlate) {
  const Discretization d = build_discretization(load_case(case_path("flying-plate.yaml")));
  EXPECT_EQ(d.mesh.num_elements(), 30);
  EXPECT_EQ(d.mesh.num_nodes(), 7 * 15 + 6 * 7);  // [0,3]x[0,7] plus [3,6]x[0,3] minus the shared column
  EXPECT_EQ(d.dofs.num_dofs(), 5 * 147);
  EXPECT_EQ(d.dofs.num_constrained(), 0);
  EXPECT_NEAR(d.total_mass, 3.0, 1e-12);  // docs/benchmarks.md §1.1
  ASSERT_EQ(d.loads.size(), 2u);
  EXPECT_EQ(d.loads[0].node, node_at(d.mesh, Vec3(6, 0, 0)));
  EXPECT_EQ(d.loads[0].vector, Vec3(0, 0, 5));
  EXPECT_EQ(d.loads[1].node, node_at(d.mesh, Vec3(0, 7, 0)));
  EXPECT_EQ(d.loads[1].vector, Vec3(5, 0, 0));
  EXPECT_DOUBLE_EQ(d.loads_end, 5.0);
  ASSERT_EQ(d.monitors.size(), 6u);
  EXPECT_EQ(d.monitors[2].node, d.loads[0].node);
  for (const Vec3& p : d.normals) EXPECT_NEAR((p - Vec3::UnitZ()).norm(), 0.0, 1e-14);
  EXPECT_EQ(d.initial_velocity.size(), 5 * 147);
  EXPECT_EQ(d.initial_velocity.norm(), 0.0);
}

TEST(BenchmarkDiscretization, CylindricalPanel) {
  const Discretization d = build_discretization(load_case(case_path("cylindrical-panel.yaml")));
  EXPECT_EQ(d.mesh.num_elements(), 24);
  EXPECT_EQ(d.mesh.num_nodes(), 9 * 13);
  // rho h R theta L; the quadratic elements approximate the arc (relative area error ~1e-8 here).
  EXPECT_NEAR(d.total_mass, 1e-8 * 1.0 * 150.0 * 0.2 * 30.0, 9e-6 * 1e-7);
  ASSERT_EQ(d.loads.size(), 1u);
  const Vec3 corner(0, -150 * std::sin(0.1), 150 * std::cos(0.1) - 150);
  EXPECT_EQ(d.loads[0].node, node_at(d.mesh, corner));
  EXPECT_EQ(d.loads[0].node, d.mesh.node_sets.at("corner_x0_arcmin").at(0));
  EXPECT_EQ(d.loads[0].vector, Vec3(0, 1, 1));
  EXPECT_DOUBLE_EQ(d.loads_end, 0.02);
  // Normals point away from the axis: +Z at the apex line (docs/benchmarks.md §2.3).
  const int apex = node_at(d.mesh, Vec3(0, 0, 0));
  ASSERT_GE(apex, 0);
  EXPECT_GT(d.normals[static_cast<size_t>(apex)].z(), 0.999);
}

TEST(BenchmarkDiscretization, PinchedHemisphere) {
  const Discretization d = build_discretization(load_case(case_path("pinched-hemisphere.yaml")));
  EXPECT_EQ(d.mesh.num_elements(), 256);
  EXPECT_EQ(d.mesh.num_nodes(), 64 * 17);  // 64 nodes per ring (periodic), 17 rings
  const double area = 2.0 * M_PI * 100.0 * std::cos(18.0 * M_PI / 180.0);
  EXPECT_NEAR(d.total_mass, 1000.0 * 0.04 * area, 1e-4 * 1000.0 * 0.04 * area);
  ASSERT_EQ(d.loads.size(), 4u);
  EXPECT_NEAR(total_load(d).norm(), 0.0, 1e-12);  // self-equilibrated pinch (§3.2)
  Vec3 moment = Vec3::Zero();
  for (const auto& l : d.loads) moment += d.mesh.X[static_cast<size_t>(l.node)].cross(l.vector);
  EXPECT_NEAR(moment.norm(), 0.0, 1e-9);
  ASSERT_EQ(d.monitors.size(), 2u);
  EXPECT_EQ(d.monitors[0].node, node_at(d.mesh, Vec3(10, 0, 0)));
  EXPECT_EQ(d.monitors[1].node, d.mesh.node_sets.at("point_ypos").at(0));
  for (size_t i = 0; i < d.normals.size(); ++i)  // outward radial normals
    EXPECT_GT(d.normals[i].dot(d.mesh.X[i].normalized()), 0.99);
}

// --- sets ------------------------------------------------------------------------------------------
TEST(Discretization, CaseSetsAreResolved) {
  const Discretization d = build(
      "sets:\n"
      "  A: {point: [2, 1, 0]}\n"
      "  strip: {box: [[0, 0, -1], [0.5, 1, 1]]}\n"
      "  some: {nodes: [3, 0, 3]}\n"
      "  both: {union: [A, later]}\n"
      "  later: {union: [some, right]}\n");
  const auto& s = d.mesh.node_sets;
  EXPECT_EQ(s.at("A"), std::vector<int>{node_at(d.mesh, Vec3(2, 1, 0))});
  EXPECT_EQ(s.at("strip").size(), 10u);  // columns X = 0 and X = 0.5, five nodes each
  EXPECT_EQ(s.at("some"), (std::vector<int>{0, 3}));
  std::vector<int> expect = s.at("some");
  expect.insert(expect.end(), s.at("right").begin(), s.at("right").end());
  expect.push_back(s.at("A")[0]);
  std::sort(expect.begin(), expect.end());
  expect.erase(std::unique(expect.begin(), expect.end()), expect.end());
  EXPECT_EQ(s.at("both"), expect);
}

struct BadSetup {
  const char* label;
  std::string extra;
  const char* prefix;
  const char* reason;
};

class BadDiscretization : public ::testing::TestWithParam<BadSetup> {};

TEST_P(BadDiscretization, IsRejectedWithKeyAndLine) {
  const auto& c = GetParam();
  const std::string msg = error_of(c.extra);
  EXPECT_EQ(msg.rfind(c.prefix, 0), 0u) << c.label << ": " << msg;
  EXPECT_NE(msg.find(c.reason), std::string::npos) << c.label << ": " << msg;
}

const BadSetup kBad[] = {
    {"unknown set in a load", "loads:\n  - {set: tip, type: force, direction: [0, 0, 1], amplitude: 1}\n",
     "plate.yaml:7: loads[0].set:", "unknown set 'tip'"},
    {"unknown set in a boundary condition", "boundary_conditions:\n  - {set: lft, fix: [ux]}\n",
     "plate.yaml:7: boundary_conditions[0].set:", "unknown set 'lft' (define it under 'sets:' or use one below)\navailable: all, bottom"},
    {"unknown set in a monitor", "monitors:\n  - {name: w, set: B, quantity: uz}\n", "plate.yaml:7: monitors[0].set:",
     "unknown set 'B'"},
    {"unknown set in a union", "sets:\n  U: {union: [left, nowhere]}\n", "plate.yaml:7: sets.U.union:",
     "unknown set 'nowhere'"},
    {"cycle of unions", "sets:\n  U: {union: [left, V]}\n  V: {union: [U]}\n", "plate.yaml:", "cycle"},
    {"point without a node", "sets:\n  P: {point: [0.1, 0, 0]}\n", "plate.yaml:7: sets.P.point:",
     "the nearest is node 0"},
    {"empty box", "sets:\n  E: {box: [[5, 5, 5], [6, 6, 6]]}\n", "plate.yaml:7: sets.E.box:", "empty set"},
    {"node index out of range", "sets:\n  N: {nodes: [25]}\n", "plate.yaml:7: sets.N.nodes:", "out of range"},
    {"set name taken by the generator", "sets:\n  left: {nodes: [0]}\n", "plate.yaml:7: sets.left:",
     "already has a node set"},
    {"monitor on several nodes", "monitors:\n  - {name: w, set: left, quantity: uz}\n",
     "plate.yaml:7: monitors[0].set:", "has 5 nodes"},
    {"edge load without edges", "loads:\n  - {set: corner_ll, type: force, direction: [1, 0, 0], amplitude: 1, "
                                "distribution: edge_total}\n",
     "plate.yaml:7: loads[0].distribution:", "edge_total needs element edges"},
    {"velocity at a fixed DOF",
     "boundary_conditions:\n  - {set: left, fix: [ux]}\ninitial_velocity: {translation: [1, 0, 0]}\n",
     "plate.yaml:8: initial_velocity:", "fixes"},
    {"fixing the dependent director component", "boundary_conditions:\n  - {set: left, fix: [px, pz]}\n",
     "plate.yaml:7: boundary_conditions[0].fix:", "cannot fix pz"},
};

INSTANTIATE_TEST_SUITE_P(Discretization, BadDiscretization,
                         ::testing::ValuesIn(kBad),
                         [](const ::testing::TestParamInfo<BadSetup>& info) {
                           std::string name;
                           for (const char* p = info.param.label; *p; ++p)
                             name += std::isalnum(static_cast<unsigned char>(*p)) ? *p : '_';
                           return name;
                         });

TEST(Discretization, GeneratorErrorsCarryTheMeshLocation) {
  // Overlapping rectangles pass the schema but not the generator.
  const std::string text =
      "mesh: {generator: cell_union, cells: [[0, 0, 2, 2], [1, 1, 3, 3]]}\n"
      "material: {E: 1, nu: 0.3, rho: 1, thickness: 0.1}\nintegrator: {name: x}\ntime: {dt: 1, t_end: 1}\n";
  try {
    build_discretization(load_case_from_string(text, "overlap.yaml"));
    FAIL() << "overlapping cells accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("overlap.yaml:1: mesh: ", 0), 0u) << e.what();
  }
}

// --- loads -----------------------------------------------------------------------------------------
TEST(Discretization, EdgeTotalOnStraightEdgesUsesConsistentWeights) {
  // Right edge X = 2: two quadratic edges of length 0.5 -> weights 1/12, 4/12, 2/12, 4/12, 1/12.
  const Discretization d = build(
      "loads:\n  - {set: right, type: force, direction: [0, 0, 2], amplitude: 3, distribution: edge_total,\n"
      "     function: {type: ramp, t1: 1}}\n");
  ASSERT_EQ(d.loads.size(), 5u);
  std::map<double, double> by_y;
  for (const auto& l : d.loads) by_y[d.mesh.X[static_cast<size_t>(l.node)].y()] = l.vector.z();
  const double total = 6.0;
  EXPECT_NEAR(by_y[0.0], total / 12, 1e-14);
  EXPECT_NEAR(by_y[0.25], total * 4 / 12, 1e-14);
  EXPECT_NEAR(by_y[0.5], total * 2 / 12, 1e-14);
  EXPECT_NEAR(by_y[0.75], total * 4 / 12, 1e-14);
  EXPECT_NEAR(by_y[1.0], total / 12, 1e-14);
  EXPECT_NEAR((total_load(d) - Vec3(0, 0, total)).norm(), 0.0, 1e-13);
  EXPECT_TRUE(std::isinf(d.loads_end));
}

TEST(Discretization, EdgeTotalOnACurvedEdgeSumsToTheTotal) {
  const std::string text =
      "mesh: {generator: cylindrical_panel, radius: 5, angle: 1.5, length: 2, n_arc: 3, n_axial: 1}\n"
      "material: {E: 1, nu: 0.3, rho: 1, thickness: 0.1}\nintegrator: {name: x}\ntime: {dt: 1, t_end: 1}\n"
      "loads:\n  - {set: x0, type: force, direction: [1, 0, 0], amplitude: 7, distribution: edge_total}\n";
  const Discretization d = build_discretization(load_case_from_string(text, "arc.yaml"));
  ASSERT_EQ(d.loads.size(), 7u);
  EXPECT_NEAR(total_load(d).x(), 7.0, 1e-12);
  // Equal arcs: the two ends carry the same share. Reference for the corner share: the quadratic edge
  // through three points of the arc (angles -h, 0, h, h = 0.25), w_a = ∫ N_a |x'(s)| ds by a dense
  // composite Simpson rule (independent of the Gauss rule in the code), over 3 edges.
  std::vector<double> xs;
  for (const auto& l : d.loads) xs.push_back(l.vector.x());
  std::sort(xs.begin(), xs.end());
  EXPECT_NEAR(xs[0], xs[1], 1e-12);
  const double R = 5.0, h = 0.25;
  const Vec3 Pa(0, -R * std::sin(h), R * std::cos(h)), Pm(0, 0, R), Pb(0, R * std::sin(h), R * std::cos(h));
  const int N = 20000;
  double wa = 0.0, len = 0.0;
  for (int k = 0; k <= N; ++k) {
    const double s = -1.0 + 2.0 * k / N;
    const double c = (k == 0 || k == N) ? 1.0 : (k % 2 ? 4.0 : 2.0);
    const double J = ((s - 0.5) * Pa - 2.0 * s * Pm + (s + 0.5) * Pb).norm();
    wa += c * 0.5 * s * (s - 1.0) * J;
    len += c * J;
  }
  EXPECT_NEAR(xs[0], 7.0 * wa / (3.0 * len), 1e-8);  // 5-point Gauss on a non-polynomial |x'|: ~1e-9
  EXPECT_GT(std::abs(xs[0] - 7.0 / 18.0), 1e-3);  // the curvature matters: not the straight-edge 1/6
}

TEST(Discretization, PerNodeLoadsEveryNodeOfTheSet) {
  const Discretization d = build(
      "loads:\n  - {set: left, type: moment, direction: [0, 1, 0], amplitude: -2,\n"
      "     function: {type: triangle, t_peak: 1, t_end: 3}}\n");
  ASSERT_EQ(d.loads.size(), 5u);
  for (const auto& l : d.loads) {
    EXPECT_EQ(l.type, LoadType::Moment);
    EXPECT_EQ(l.vector, Vec3(0, -2, 0));
    EXPECT_DOUBLE_EQ(l.function(2.0), 0.5);
  }
  EXPECT_DOUBLE_EQ(d.loads_end, 3.0);
}

// --- boundary conditions, initial velocity, monitors ------------------------------------------------
TEST(Discretization, ClampedEdgeConstrainsFiveDofsPerNode) {
  const Discretization d = build("boundary_conditions:\n  - {set: left, fix: [ux, uy, uz, director]}\n"
                                 "  - {set: corner_lr, fix: [uz]}\n");
  EXPECT_EQ(d.dofs.num_constrained(), 5 * 5 + 1);
  EXPECT_EQ(d.dofs.num_free(), d.dofs.num_dofs() - 26);
  const int lr = d.mesh.node_sets.at("corner_lr")[0];
  EXPECT_TRUE(d.dofs.is_constrained(DofMap::dof(lr, 2)));
  EXPECT_FALSE(d.dofs.is_constrained(DofMap::dof(lr, 0)));
}

TEST(Discretization, InitialVelocityIsARigidField) {
  const Discretization d = build("initial_velocity: {translation: [0.1, 0, 0.2], angular: [1, 0, 0.5]}\n");
  const Vec3 centroid(1.0, 0.5, 0.0);
  const Vec3 w(1, 0, 0.5), v0(0.1, 0, 0.2);
  for (int i = 0; i < d.mesh.num_nodes(); ++i) {
    const Eigen::Index b = 5 * i;
    const Vec3 expect = v0 + w.cross(d.mesh.X[static_cast<size_t>(i)] - centroid);
    EXPECT_NEAR((d.initial_velocity.segment<3>(b) - expect).norm(), 0.0, 1e-14) << "node " << i;
    // p = e_Z, chart (n, m) = (X, Y): q̇ = (ṗ_X, ṗ_Y) with ṗ = ω × e_Z = (0, -1, 0).
    EXPECT_NEAR(d.initial_velocity[b + 3], 0.0, 1e-15);
    EXPECT_NEAR(d.initial_velocity[b + 4], -1.0, 1e-15);
  }
}

TEST(Discretization, InitialVelocityAboutAGivenPoint) {
  const Discretization d = build("initial_velocity: {angular: [0, 0, 2], about: [2, 1, 0]}\n");
  const int ur = d.mesh.node_sets.at("corner_ur")[0];
  const int ll = d.mesh.node_sets.at("corner_ll")[0];
  EXPECT_NEAR(d.initial_velocity.segment<3>(5 * ur).norm(), 0.0, 1e-15);
  EXPECT_NEAR((d.initial_velocity.segment<3>(5 * ll) - Vec3(2, -4, 0)).norm(), 0.0, 1e-14);
}

TEST(Discretization, MonitorValues) {
  const Discretization d = build(
      "sets:\n  A: {point: [2, 1, 0]}\n"
      "monitors:\n  - {name: a, set: A, quantity: ur}\n  - {name: b, set: A, quantity: pz}\n"
      "  - {name: c, set: A, quantity: vy}\n  - {name: e, set: A, quantity: uy}\n");
  ASSERT_EQ(d.monitors.size(), 4u);
  const int node = d.monitors[0].node;
  Eigen::VectorXd u = Eigen::VectorXd::Zero(d.dofs.num_dofs()), v = u;
  u.segment<3>(5 * node) = Vec3(1, 2, 3);
  u.segment<2>(5 * node + 3) = Eigen::Vector2d(0.6, 0.0);  // p = (0.6, 0, 0.8) in the (X, Y | Z) chart
  v.segment<3>(5 * node) = Vec3(4, 5, 6);
  EXPECT_NEAR(monitor_value(d.monitors[0], d.mesh, u, v, d.charts), (2.0 + 2.0) / std::sqrt(5.0), 1e-14);
  EXPECT_NEAR(monitor_value(d.monitors[1], d.mesh, u, v, d.charts), 0.8, 1e-14);
  EXPECT_EQ(monitor_value(d.monitors[2], d.mesh, u, v, d.charts), 5.0);
  EXPECT_EQ(monitor_value(d.monitors[3], d.mesh, u, v, d.charts), 2.0);
}

// --- Gmsh file meshes -------------------------------------------------------------------------------
TEST(Discretization, GmshMeshWithPhysicalGroups) {
  const Discretization d = build_discretization(load_case(std::string(SHELLDYN_TEST_DATA) + "/case_gmsh_plate.yaml"));
  EXPECT_EQ(d.mesh.num_elements(), 1);
  EXPECT_EQ(d.mesh.num_nodes(), 9);
  EXPECT_EQ(d.dofs.num_constrained(), 9);  // uz on the physical surface "plate"
  EXPECT_NEAR(d.total_mass, 2.0 * 0.1 * 2.0, 1e-12);
  ASSERT_EQ(d.loads.size(), 3u);  // edge X = 2 carries 1/6, 4/6, 1/6 of 3
  EXPECT_NEAR(total_load(d).x(), 3.0, 1e-14);
  double biggest = 0;
  for (const auto& l : d.loads) biggest = std::max(biggest, l.vector.x());
  EXPECT_NEAR(biggest, 2.0, 1e-14);
}

}  // namespace

namespace {

TEST(Discretization, SymmetryPlanesOnAQuarterHemisphere) {
  const std::string text =
      "mesh: {generator: hemisphere, radius: 10, hole_deg: 18, quarter: true, n: 2}\n"
      "material: {E: 1, nu: 0.3, rho: 1, thickness: 0.04}\nintegrator: {name: x}\ntime: {dt: 1, t_end: 1}\n"
      "boundary_conditions:\n  - {set: sym_y0, fix: [uy, py]}\n  - {set: sym_x0, fix: [ux, px]}\n";
  const Discretization d = build_discretization(load_case_from_string(text, "quarter.yaml"));
  const auto& y0 = d.mesh.node_sets.at("sym_y0");
  const auto& x0 = d.mesh.node_sets.at("sym_x0");
  EXPECT_EQ(y0.size(), 5u);
  EXPECT_EQ(d.dofs.num_constrained(), static_cast<Index>(2 * (y0.size() + x0.size())));
  for (int node : y0) {
    EXPECT_TRUE(d.dofs.is_constrained(DofMap::dof(node, 1)));
    const DirectorChart& ch = d.charts[static_cast<size_t>(node)];
    // p_Y is stored in q_1 if n = Y, else in q_2 (m = Y); that entry must be constrained.
    EXPECT_TRUE(d.dofs.is_constrained(DofMap::dof(node, ch.n == 1 ? 3 : 4)));
  }
}

}  // namespace
