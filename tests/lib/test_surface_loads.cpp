// Distributed loads (lib/model/surface_loads, docs/theory.md §8.2–8.4): resultants of the consistent nodal
// forces, the follower-pressure tangent against finite differences, and the case-file path.
#include "lib/model/surface_loads.hpp"

#include "elements/shape_functions.hpp"
#include "lib/model/assembler.hpp"
#include "lib/mesh/mesh_generators.hpp"
#include "lib/model/problem.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

namespace shelldyn {
namespace {

Vec3 total(const std::map<int, Vec3>& f) {
  Vec3 s = Vec3::Zero();
  for (const auto& [node, v] : f) s += v;
  return s;
}

TEST(SurfaceLoads, DeadPressureOnAPlateSumsToPressureTimesArea) {
  const Mesh m = make_rectangle(2.0, 1.0, 4, 2, 0.0, 0.0);
  const auto f = dead_pressure_forces(m, m.element_sets.at("all"), 3.0);
  EXPECT_NEAR((total(f) - Vec3(0, 0, 6.0)).norm(), 0.0, 1e-12);
  // Consistent (not lumped) forces: a corner node of the biquadratic element gets p·A_e/36.
  const double Ae = 0.25;
  EXPECT_NEAR(f.at(m.node_sets.at("corner_ll")[0]).z(), 3.0 * Ae / 36.0, 1e-14);
}

TEST(SurfaceLoads, PressureOnACylinderPanelIsRadial) {
  // Panel of the cylinder of radius 150 about the line (x, 0, -150), opening 0.2 rad: the resultant of an
  // outward pressure is p·L·2R·sin(0.1) along +Z (the chord projection), exactly up to quadrature.
  const double R = 150, L = 30, p = 2.0;
  const Mesh m = make_cylindrical_panel(R, 0.2, L, 4, 3);
  const Vec3 F = total(dead_pressure_forces(m, m.element_sets.at("all"), p));
  const double expected = p * L * 2 * R * std::sin(0.1);
  EXPECT_NEAR(F.z(), expected, 2e-6 * expected);
  EXPECT_NEAR(F.x(), 0.0, 1e-9 * expected);
  EXPECT_NEAR(F.y(), 0.0, 1e-9 * expected);
}

TEST(SurfaceLoads, BodyForceAndEdgeLoadResultants) {
  const Mesh m = make_rectangle(2.0, 1.0, 4, 2, 0.0, 0.0);
  const Vec3 b(0, 0, -9.81);
  EXPECT_NEAR((total(body_forces(m, m.element_sets.at("all"), b, 0.1)) - 2.0 * 0.1 * b).norm(), 0.0, 1e-13);
  const Vec3 t(0, 0, 5.0);  // force per length on the edge x = 2 (length 1)
  const auto f = edge_line_forces(m, m.node_sets.at("right"), t);
  EXPECT_NEAR((total(f) - t).norm(), 0.0, 1e-13);
  EXPECT_EQ(f.size(), 5u);
  EXPECT_TRUE(edge_line_forces(m, m.node_sets.at("corner_ll"), t).empty());
}

// ∂f/∂x of a follower pressure on a curved, distorted element vs central differences of f.
TEST(SurfaceLoads, FollowerPressureTangentMatchesFiniteDifferences) {
  std::array<Vec3, 9> x;
  for (int a = 0; a < 9; ++a) {
    const double xi = kNodeXi[static_cast<size_t>(a)], eta = kNodeEta[static_cast<size_t>(a)];
    x[static_cast<size_t>(a)] = Vec3(1.2 * xi + 0.1 * eta * eta, 0.8 * eta + 0.15 * xi * eta, 0.3 * xi * xi - 0.2 * eta);
  }
  Eigen::Matrix<double, 27, 1> f, fp, fm;
  Eigen::Matrix<double, 27, 27> K, Kfd;
  element_pressure(x, 1.7, f, &K);
  const double h = 1e-6;
  for (int j = 0; j < 27; ++j) {
    auto xp = x, xm = x;
    xp[static_cast<size_t>(j / 3)][j % 3] += h;
    xm[static_cast<size_t>(j / 3)][j % 3] -= h;
    element_pressure(xp, 1.7, fp);
    element_pressure(xm, 1.7, fm);
    Kfd.col(j) = (fp - fm) / (2 * h);
  }
  EXPECT_LT((K - Kfd).norm() / K.norm(), 1e-8);
  EXPECT_GT((K - K.transpose()).norm() / K.norm(), 1e-3);  // a follower load is not symmetric
}

constexpr const char* kPlateCase = R"(
mesh: {generator: rectangle, a: 1, b: 1, nx: 2, ny: 2}
material: {E: 1.0e6, nu: 0.3, rho: 2.0, thickness: 0.05}
sets:
  half: {box: [[0, 0, -1], [0.5, 1, 1]]}
loads:
  - {set: half, type: pressure, amplitude: 4}
  - {type: gravity, direction: [0, 0, -1], amplitude: 10}
  - {set: right, type: force, direction: [0, 0, 3], amplitude: 1, distribution: per_length}
  - {set: all, type: follower_pressure, amplitude: 1.5, function: {type: ramp, t1: 2}}
damping: {mass: 0.5, stiffness: 1e-4}
integrator: {name: em-galpha}
time: {dt: 0.1, t_end: 1}
)";

TEST(SurfaceLoads, CaseFileLoadsBecomeConsistentForces) {
  Problem p = make_problem(load_case_from_string(kPlateCase, "loads.yaml"));
  Vec3 dead = Vec3::Zero();
  for (const auto& l : p.disc.loads) dead += l.vector;
  // pressure 4 on half the plate (0.5), gravity rho*h*g*A = 2*0.05*10, edge load 3 on length 1.
  EXPECT_NEAR((dead - Vec3(0, 0, 4 * 0.5 - 1.0 + 3.0)).norm(), 0.0, 1e-12);
  ASSERT_EQ(p.disc.follower_pressures.size(), 1u);
  EXPECT_EQ(p.disc.follower_pressures[0].elements.size(), 4u);
  EXPECT_TRUE(std::isinf(p.disc.loads_end) || p.disc.loads_end > 1e300);  // constant loads never end
  // Follower part at t = 1 (ramp: half of 1.5) on the flat plate: 0.75 along +Z.
  const Model& model = *p.model;
  const State s = model.initial_state();
  Eigen::VectorXd F(model.num_dofs());
  model.external(1.0, s.u, s.charts, F.data());
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < model.mesh().num_nodes(); ++i) sum += F.segment<3>(DofMap::dof(i, 0));
  EXPECT_NEAR((sum - Vec3(0, 0, 4 * 0.5 - 1.0 + 3.0 + 0.75)).norm(), 0.0, 1e-12);
  EXPECT_TRUE(model.has_damping());
}

TEST(SurfaceLoads, CaseFileRejectsBadDistributedLoads) {
  auto err = [](const std::string& text) {
    try {
      make_problem(load_case_from_string(text, "bad.yaml"));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string head = "mesh: {generator: rectangle, a: 1, b: 1, nx: 2, ny: 2}\n"
                           "material: {E: 1.0e6, nu: 0.3, rho: 2.0, thickness: 0.05}\n"
                           "integrator: {name: em-galpha}\ntime: {dt: 0.1, t_end: 1}\n";
  EXPECT_NE(err(head + "loads: [{type: pressure, amplitude: 1, direction: [0, 0, 1]}]").find("unknown key 'direction'"),
            std::string::npos);
  EXPECT_NE(err(head + "loads: [{set: corner_ll, type: pressure, amplitude: 1}]").find("no element has all its 9 nodes"),
            std::string::npos);
  EXPECT_NE(err(head + "loads: [{set: corner_ll, type: force, direction: [0,0,1], amplitude: 1, distribution: per_length}]")
                .find("per_length needs element edges"),
            std::string::npos);
  EXPECT_NE(err(head + "damping: {mass: -1}").find("damping.mass: must be >= 0"), std::string::npos);
}

}  // namespace
}  // namespace shelldyn
