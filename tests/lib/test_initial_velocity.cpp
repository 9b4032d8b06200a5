// Initial velocity fields on sets and from CSV files (docs/manual.md §2.6).
#include "lib/model/discretization.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

namespace shelldyn {
namespace {

const std::string kHead = "mesh: {generator: rectangle, a: 2, b: 1, nx: 2, ny: 1}\n"
                          "material: {E: 1.0e6, nu: 0.3, rho: 1, thickness: 0.1}\n"
                          "integrator: {name: em-galpha}\ntime: {dt: 0.1, t_end: 1}\n";

Vec3 v_of(const Discretization& d, int node) { return d.initial_velocity.segment<3>(DofMap::dof(node, 0)); }

TEST(InitialVelocity, ListEntriesOnSetsOverrideInOrder) {
  const Discretization d = build_discretization(load_case_from_string(
      kHead + "initial_velocity: [{translation: [1, 0, 0]}, {set: right, translation: [0, 0, 2]}]\n", "iv.yaml"));
  const auto& right = d.mesh.node_sets.at("right");
  for (int i = 0; i < d.mesh.num_nodes(); ++i) {
    const bool in_right = std::find(right.begin(), right.end(), i) != right.end();
    EXPECT_EQ(v_of(d, i), in_right ? Vec3(0, 0, 2) : Vec3(1, 0, 0)) << "node " << i;
  }
}

TEST(InitialVelocity, RigidRotationOfASetIsAboutItsCentroid) {
  const Discretization d = build_discretization(
      load_case_from_string(kHead + "initial_velocity: {set: right, angular: [1, 0, 0]}\n", "iv.yaml"));
  const auto& right = d.mesh.node_sets.at("right");  // x = 2, y in [0, 1]: centroid (2, 0.5, 0)
  for (int i : right) {
    const Vec3 X = d.mesh.X[static_cast<size_t>(i)];
    EXPECT_NEAR((v_of(d, i) - Vec3(1, 0, 0).cross(X - Vec3(2, 0.5, 0))).norm(), 0.0, 1e-14);
  }
  EXPECT_EQ(v_of(d, d.mesh.node_sets.at("corner_ll")[0]), Vec3::Zero());
}

TEST(InitialVelocity, CsvFieldWithDirectorRates) {
  const std::string path = testing::TempDir() + "/iv_field.csv";
  {
    std::ofstream f(path);
    f << "node,vx,vy,vz,pdx,pdy,pdz\n0,0,0,3,0.5,0,7\n4,1,2,3,0,0,0\n";
  }
  const Discretization d = build_discretization(
      load_case_from_string(kHead + "initial_velocity: {field: " + path + "}\n", "iv.yaml"));
  EXPECT_EQ(v_of(d, 0), Vec3(0, 0, 3));
  EXPECT_EQ(v_of(d, 4), Vec3(1, 2, 3));
  EXPECT_EQ(v_of(d, 1), Vec3::Zero());
  // p = +Z on the flat plate: the normal component 7 of the director rate is removed, 0.5 along X kept.
  const Vec3 pdot = director_A1(Eigen::Vector2d(0, 0), d.charts[0]) * d.initial_velocity.segment<2>(DofMap::dof(0, 3));
  EXPECT_NEAR((pdot - Vec3(0.5, 0, 0)).norm(), 0.0, 1e-14);
  {
    std::ofstream f(path);
    f << "node,vx,vy,vz\n99,0,0,3\n";
  }
  try {
    build_discretization(load_case_from_string(kHead + "initial_velocity: {field: " + path + "}\n", "iv.yaml"));
    FAIL() << "no error for a node outside the mesh";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("iv_field.csv:2: expected a node index"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

// initial_velocity: {mode: FILE, index, amplitude}: v = A φ_k from a mode_shapes.csv (docs/manual.md §2.6);
// the director change δp is converted to the node's chart unknowns. Errors name the case line and the key.
TEST(InitialVelocity, ModeShapeFileScaledByTheAmplitude) {
  const std::string path = testing::TempDir() + "/iv_modes.csv";
  auto write = [&](const std::string& header, int modes, int nodes) {
    std::ofstream f(path);
    f << header << "\n";
    for (int k = 1; k <= modes; ++k)
      for (int i = 0; i < nodes; ++i) f << k << "," << i << ",0,0," << k * 0.1 * i << "," << 0.01 * k << ",0,0\n";
  };
  write("mode,node,ux,uy,uz,pdx,pdy,pdz", 2, 15);  // the 2 × 1 mesh has 15 nodes
  const Discretization d = build_discretization(
      load_case_from_string(kHead + "initial_velocity: {mode: " + path + ", index: 2, amplitude: 3}\n", "iv.yaml"));
  for (int i = 0; i < 15; ++i) {
    EXPECT_NEAR((v_of(d, i) - Vec3(0, 0, 3 * 0.2 * i)).norm(), 0.0, 1e-14) << "node " << i;
    const Vec3 pdot = director_A1(Eigen::Vector2d(0, 0), d.charts[static_cast<size_t>(i)]) *
                      d.initial_velocity.segment<2>(DofMap::dof(i, 3));
    EXPECT_NEAR((pdot - Vec3(0.06, 0, 0)).norm(), 0.0, 1e-14) << "node " << i;
  }
  auto error = [&](const std::string& entry) {
    try {
      build_discretization(load_case_from_string(kHead + "initial_velocity: " + entry + "\n", "iv.yaml"));
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  auto has = [](const std::string& msg, const std::string& part) { return msg.find(part) != std::string::npos; };
  std::string m = error("{mode: " + path + ", index: 3, amplitude: 1}");
  EXPECT_TRUE(has(m, "iv.yaml:5: initial_velocity.index: mode 3 is not in") && has(m, "modes 1..2")) << m;
  m = error("{mode: " + path + ", amplitude: 1}");
  EXPECT_TRUE(has(m, "iv.yaml:5: initial_velocity.index: missing required key 'index'")) << m;
  m = error("{mode: " + path + ", index: 1, amplitude: 1, translation: [1, 0, 0]}");
  EXPECT_TRUE(has(m, "iv.yaml:5: initial_velocity.translation: give either 'mode'")) << m;
  m = error("{index: 1, amplitude: 1}");
  EXPECT_TRUE(has(m, "iv.yaml:5: initial_velocity.index: 'index' belongs to a mode shape")) << m;
  m = error("{mode: " + path + ", index: 0, amplitude: 1}");
  EXPECT_TRUE(has(m, "iv.yaml:5: initial_velocity.index: must be an integer >= 1")) << m;
  m = error("{mode: no-such-file.csv, index: 1, amplitude: 1}");
  EXPECT_TRUE(has(m, "initial_velocity.mode: cannot open the mode-shape file") && has(m, "shelldyn modes")) << m;
  write("node,vx,vy,vz", 1, 15);
  m = error("{mode: " + path + ", index: 1, amplitude: 1}");
  EXPECT_TRUE(has(m, "iv_modes.csv:1: expected the header 'mode,node,ux,uy,uz,pdx,pdy,pdz'")) << m;
  write("mode,node,ux,uy,uz,pdx,pdy,pdz", 1, 9);  // a smaller mesh's file
  m = error("{mode: " + path + ", index: 1, amplitude: 1}");
  EXPECT_TRUE(has(m, "gives mode 1 at 9 nodes, the mesh has 15")) << m;
  write("mode,node,ux,uy,uz,pdx,pdy,pdz", 1, 25);  // a larger mesh's file
  m = error("{mode: " + path + ", index: 1, amplitude: 1}");
  EXPECT_TRUE(has(m, "iv_modes.csv:17: node 15 is not in the mesh (15 nodes)")) << m;
  // A mode of other boundary conditions moves a DOF this case fixes.
  write("mode,node,ux,uy,uz,pdx,pdy,pdz", 1, 15);
  try {
    build_discretization(load_case_from_string(kHead + "boundary_conditions: [{set: left, fix: [uz]}]\n"
                                                       "initial_velocity: {mode: " + path + ", index: 1, amplitude: 1}\n",
                                               "iv.yaml"));
    ADD_FAILURE() << "no error for a mode moving a fixed DOF";
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(has(e.what(), "iv.yaml:6: initial_velocity: the initial velocity is")) << e.what();
    EXPECT_TRUE(has(e.what(), "which a boundary condition fixes")) << e.what();
  }
  std::remove(path.c_str());
}

}  // namespace
}  // namespace shelldyn
