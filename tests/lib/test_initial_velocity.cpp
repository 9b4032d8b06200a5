// Initial velocity fields on sets and from CSV files (docs/manual.md §2.6).
#include "lib/discretization.hpp"

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

}  // namespace
}  // namespace shelldyn
