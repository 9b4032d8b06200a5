// Case-file parsing and validation (lib/io/case_file.hpp; architecture.md §5: unknown keys and wrong
// types are errors that name the key and the line).
#include "lib/io/case_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace shelldyn;

namespace {

// Lines 1-5 of every test case: a valid minimal case. Bad variants append or replace lines, so the
// expected line numbers below are easy to read off.
const std::string kMinimal =
    "name: t\n"                                                     // 1
    "mesh: {generator: rectangle, a: 2, b: 1, nx: 2, ny: 1}\n"      // 2
    "material: {E: 1.0e6, nu: 0.3, rho: 1, thickness: 0.1}\n"       // 3
    "integrator: {name: em-galpha, rho_inf: 0.9, xi: 0}\n"          // 4
    "time: {dt: 0.01, t_end: 1}\n";                                 // 5

std::string error_of(const std::string& text) {
  try {
    load_case_from_string(text, "bad.yaml");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

std::string replace_line(std::string text, int line, const std::string& replacement) {
  size_t begin = 0;
  for (int k = 1; k < line; ++k) begin = text.find('\n', begin) + 1;
  const size_t end = text.find('\n', begin);
  return text.replace(begin, end - begin, replacement);
}

struct BadCase {
  const char* label;
  std::string text;
  const char* expected_prefix;  // "bad.yaml:LINE: key.path"
  const char* expected_reason;  // a fragment of the reason
};

class BadCaseFile : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadCaseFile, IsRejectedWithKeyAndLine) {
  const BadCase& c = GetParam();
  const std::string msg = error_of(c.text);
  EXPECT_EQ(msg.rfind(c.expected_prefix, 0), 0u) << c.label << ": " << msg;
  EXPECT_NE(msg.find(c.expected_reason), std::string::npos) << c.label << ": " << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line expected: " << msg;
}

const BadCase kBadCases[] = {
    {"unknown top-level key", kMinimal + "colour: red\n", "bad.yaml:6: colour:", "unknown key 'colour'"},
    {"unknown nested key", replace_line(kMinimal, 3, "material: {E: 1.0e6, nu: 0.3, rho: 1, thickness: 0.1, Ee: 2}"),
     "bad.yaml:3: material.Ee:", "unknown key"},
    {"wrong type", replace_line(kMinimal, 5, "time: {dt: fast, t_end: 1}"), "bad.yaml:5: time.dt:",
     "expected a number"},
    {"quoted number", replace_line(kMinimal, 5, "time: {dt: \"0.01\", t_end: 1}"), "bad.yaml:5: time.dt:",
     "expected a number"},
    {"missing required key", replace_line(kMinimal, 3, "material: {E: 1.0e6, nu: 0.3, thickness: 0.1}"),
     "bad.yaml:3: material.rho:", "missing required key 'rho'"},
    {"missing top-level block", replace_line(kMinimal, 5, "# no time"), "bad.yaml:1: time:",
     "missing required key 'time'"},
    {"negative dt", replace_line(kMinimal, 5, "time: {dt: -0.01, t_end: 1}"), "bad.yaml:5: time.dt:", "must be > 0"},
    {"zero element count", replace_line(kMinimal, 2, "mesh: {generator: rectangle, a: 2, b: 1, nx: 0, ny: 1}"),
     "bad.yaml:2: mesh.nx:", "must be an integer >= 1"},
    {"output interval below dt", replace_line(kMinimal, 5, "time: {dt: 0.01, t_end: 1, output_interval: 0.001}"),
     "bad.yaml:5: time.output_interval:", "must be >= dt"},
    {"empty node list", kMinimal + "sets:\n  S: {nodes: []}\n", "bad.yaml:7: sets.S.nodes:", "empty set"},
    {"empty union", kMinimal + "sets:\n  S: {union: []}\n", "bad.yaml:7: sets.S.union:", "empty set"},
    {"set with two definitions", kMinimal + "sets:\n  S: {nodes: [1], point: [0, 0, 0]}\n", "bad.yaml:7: sets.S:",
     "only one of"},
    {"bad fix name", kMinimal + "sets:\n  S: {nodes: [0]}\nboundary_conditions:\n  - {set: S, fix: [ux, uw]}\n",
     "bad.yaml:9: boundary_conditions[0].fix[1]:", "unknown DOF name 'uw'"},
    {"both generator and file", replace_line(kMinimal, 2, "mesh: {generator: rectangle, file: plate.msh}"),
     "bad.yaml:2: mesh:", "not both"},
    {"mesh file not found", replace_line(kMinimal, 2, "mesh: {file: no-such-mesh.msh}"), "bad.yaml:2: mesh.file:",
     "cannot find"},
    {"unknown generator", replace_line(kMinimal, 2, "mesh: {generator: torus, a: 1}"), "bad.yaml:2: mesh.generator:",
     "unknown value 'torus'"},
    {"bad hat parameter",
     kMinimal + "loads:\n  - {set: all, type: force, direction: [0, 0, 1], amplitude: 1, function: {type: hat, t1: -2}}\n",
     "bad.yaml:7: loads[0].function.t1:", "must be > 0"},
    {"triangle peak after end",
     kMinimal + "loads:\n  - set: all\n    type: force\n    direction: [0, 0, 1]\n    amplitude: 1\n"
                "    function: {type: triangle, t_peak: 0.03, t_end: 0.015}\n",
     "bad.yaml:11: loads[0].function:", "must be greater than t_peak"},
    {"table not increasing",
     kMinimal + "loads:\n  - {set: all, type: force, direction: [0, 0, 1], amplitude: 1,\n"
                "     function: {type: table, points: [[0, 0], [1, 1], [1, 2]]}}\n",
     "bad.yaml:8: loads[0].function:", "times must increase"},
    {"spin_up without a positive T_s",
     kMinimal + "loads:\n  - {set: all, type: force, direction: [0, 0, 1], amplitude: 1, function: {type: spin_up, T_s: 0}}\n",
     "bad.yaml:7: loads[0].function.T_s:", "must be > 0"},
    {"time function with a foreign key",
     kMinimal + "loads:\n  - {set: all, type: force, direction: [0, 0, 1], amplitude: 1, function: {type: ramp, t_peak: 1}}\n",
     "bad.yaml:7: loads[0].function.t_peak:", "unknown key"},
    {"zero load direction", kMinimal + "loads:\n  - {set: all, type: force, direction: [0, 0, 0], amplitude: 1}\n",
     "bad.yaml:7: loads[0].direction:", "zero vector"},
    {"bad load type", kMinimal + "loads:\n  - {set: all, type: torque, direction: [0, 0, 1], amplitude: 1}\n",
     "bad.yaml:7: loads[0].type:", "unknown value 'torque'"},
    {"vector of wrong length", kMinimal + "initial_velocity: {translation: [1, 2]}\n",
     "bad.yaml:6: initial_velocity.translation:", "3 numbers"},
    {"bad monitor quantity", kMinimal + "monitors:\n  - {name: w, set: all, quantity: uw}\n",
     "bad.yaml:7: monitors[0].quantity:", "unknown value 'uw'"},
    {"monitor named like a standard column", kMinimal + "monitors:\n  - {name: kinetic, set: all, quantity: uz}\n",
     "bad.yaml:7: monitors[0].name:", "standard history.csv column"},
    {"duplicate key", kMinimal + "name: u\n", "bad.yaml:6: name:", "duplicate key"},
    {"Poisson ratio out of range", replace_line(kMinimal, 3, "material: {E: 1.0e6, nu: 0.5, rho: 1, thickness: 0.1}"),
     "bad.yaml:3: material.nu:", "(-1, 0.5)"},
    {"nested integrator setting", replace_line(kMinimal, 4, "integrator: {name: em-galpha, newton: {tol: 1}}"),
     "bad.yaml:4: integrator.newton:", "single values"},
    {"bad boolean", kMinimal + "output: {vtu: maybe}\n", "bad.yaml:6: output.vtu:", "expected true or false"},
    {"YAML syntax error", kMinimal + "sets: {A: [1, 2\n", "bad.yaml:", "YAML syntax error"},
    {"path-like case name", replace_line(kMinimal, 1, "name: ../evil"), "bad.yaml:1: name:", "not a valid name"},
    // Rigid bodies and joints (docs/manual.md §2.13); the mesh-dependent checks are in tests/bad_input.
    {"joint on an unknown body",
     kMinimal + "rigid_bodies:\n  hub: {mass: 1, inertia: [1, 1, 1]}\njoints:\n  - {name: p, type: fixed_point, body: wheel, at: [0, 0, 0]}\n",
     "bad.yaml:9: joints[0].body:", "unknown rigid body 'wheel' (defined: hub)"},
    {"joint end on an unknown body",
     kMinimal + "joints:\n  - {name: b, type: spherical, a: {set: all}, b: {body: hub, at: [0, 0, 0]}}\n",
     "bad.yaml:7: joints[0].b.body:", "unknown rigid body 'hub' (define it under rigid_bodies:)"},
    {"non-positive body mass", kMinimal + "rigid_bodies:\n  hub: {mass: -1, inertia: [1, 1, 1]}\n",
     "bad.yaml:7: rigid_bodies.hub.mass:", "must be > 0"},
    {"inertias violating the triangle inequality", kMinimal + "rigid_bodies:\n  hub: {mass: 1, inertia: [3, 1, 1]}\n",
     "bad.yaml:7: rigid_bodies.hub.inertia:", "J1 = 3 exceeds J2 + J3"},
    {"body axes not orthonormal", kMinimal + "rigid_bodies:\n  hub: {mass: 1, inertia: [1, 1, 1], axes: [[1, 0, 0], [1, 1, 0]]}\n",
     "bad.yaml:7: rigid_bodies.hub.axes:", "unit vectors normal to each other"},
    {"duplicate joint name",
     kMinimal + "joints:\n  - {name: p, type: fixed_point, set: all}\n  - {name: p, type: fixed_point, set: all}\n",
     "bad.yaml:8: joints[1].name:", "used twice"},
    {"unknown joint type", kMinimal + "joints:\n  - {name: p, type: weld, set: all}\n", "bad.yaml:7: joints[0].type:",
     "unknown value 'weld'"},
    {"revolute without an axis",
     kMinimal + "joints:\n  - {name: h, type: revolute, a: {set: all}, b: {ground: [0, 0, 0]}}\n", "bad.yaml:7: joints[0].axis:",
     "missing required key 'axis'"},
    {"joint end of two kinds",
     kMinimal + "joints:\n  - {name: b, type: spherical, a: {set: all, ground: [0, 0, 0]}, b: {ground: [0, 0, 0]}}\n",
     "bad.yaml:7: joints[0].a.ground:", "unknown key"},
};

INSTANTIATE_TEST_SUITE_P(CaseFile, BadCaseFile, ::testing::ValuesIn(kBadCases),
                         [](const ::testing::TestParamInfo<BadCase>& info) {
                           std::string name;
                           for (const char* p = info.param.label; *p; ++p)
                             name += std::isalnum(static_cast<unsigned char>(*p)) ? *p : '_';
                           return name;
                         });

TEST(CaseFile, MinimalCaseGetsDefaults) {
  const CaseSpec c = load_case_from_string(kMinimal, "minimal.yaml");
  EXPECT_EQ(c.name, "t");
  ASSERT_TRUE(std::holds_alternative<RectangleMeshSpec>(c.mesh));
  const auto& r = std::get<RectangleMeshSpec>(c.mesh);
  EXPECT_EQ(r.a, 2.0);
  EXPECT_EQ(r.nx, 2);
  EXPECT_EQ(r.x0, 0.0);
  EXPECT_NEAR(c.material.shear_factor, 5.0 / 6.0, 1e-15);
  EXPECT_EQ(c.time.output_interval, c.time.dt);
  EXPECT_EQ(c.time.num_steps(), 100);
  EXPECT_TRUE(c.output.vtu);
  EXPECT_EQ(c.output.vtu_every, 10);
  EXPECT_TRUE(c.output.history);
  EXPECT_FALSE(c.initial_velocity.given);
  // Integrator settings keep file order and the text as written.
  ASSERT_EQ(c.integrator.settings.size(), 2u);
  EXPECT_EQ(c.integrator.name, "em-galpha");
  EXPECT_EQ(c.integrator.settings[0], std::make_pair(std::string("rho_inf"), std::string("0.9")));
  EXPECT_EQ(c.integrator.settings[1].first, "xi");
}

TEST(CaseFile, DefaultNameIsTheFileStem) {
  const CaseSpec c = load_case_from_string(kMinimal.substr(kMinimal.find('\n') + 1), "dir/my-case.yaml");
  EXPECT_EQ(c.name, "my-case");
}

TEST(CaseFile, ParsesEverySection) {
  const std::string text = kMinimal +
                           "sets:\n"
                           "  A: {point: [2, 0, 0], tol: 1e-3}\n"
                           "  strip: {box: [[0, 0, -1], [1, 1, 1]]}\n"
                           "  some: {nodes: [0, 5, 7]}\n"
                           "  both: {union: [A, strip]}\n"
                           "boundary_conditions:\n"
                           "  - {set: strip, fix: [ux, uy, uz, director]}\n"
                           "initial_velocity: {translation: [0.1, 0, 0.2], angular: [0.3, 0.5, 1.0], about: [1, 2, 3]}\n"
                           "loads:\n"
                           "  - {set: A, type: moment, direction: [0, 1, 0], amplitude: -2.5, distribution: edge_total,\n"
                           "     function: {type: table, points: [[0, 0], [1, 1]]}}\n"
                           "output: {vtu: false, vtu_every: 3, history: no}\n"
                           "monitors:\n"
                           "  - {name: wA, set: A, quantity: ur}\n";
  const CaseSpec c = load_case_from_string(text, "full.yaml");
  ASSERT_EQ(c.sets.size(), 4u);
  EXPECT_EQ(c.sets[0].kind, SetSpec::Kind::Point);
  EXPECT_EQ(c.sets[0].tol, 1e-3);
  EXPECT_EQ(c.sets[1].kind, SetSpec::Kind::Box);
  EXPECT_EQ(c.sets[1].box_max.z(), 1.0);
  EXPECT_EQ(c.sets[2].nodes, (std::vector<int>{0, 5, 7}));
  EXPECT_EQ(c.sets[3].members, (std::vector<std::string>{"A", "strip"}));
  EXPECT_EQ(c.sets[3].where, "full.yaml:10: sets.both");
  ASSERT_EQ(c.boundary_conditions.size(), 1u);
  EXPECT_EQ(c.boundary_conditions[0].fix.size(), 4u);
  EXPECT_EQ(c.boundary_conditions[0].fix[3], Fix::Director);
  EXPECT_TRUE(c.initial_velocity.given);
  EXPECT_FALSE(c.initial_velocity.about_centroid);
  EXPECT_EQ(c.initial_velocity.about, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(c.initial_velocity.angular, Eigen::Vector3d(0.3, 0.5, 1.0));
  ASSERT_EQ(c.loads.size(), 1u);
  EXPECT_EQ(c.loads[0].type, LoadType::Moment);
  EXPECT_EQ(c.loads[0].distribution, LoadDistribution::EdgeTotal);
  EXPECT_EQ(c.loads[0].amplitude, -2.5);
  EXPECT_DOUBLE_EQ(c.loads[0].function(0.5), 0.5);
  EXPECT_FALSE(c.output.vtu);
  EXPECT_EQ(c.output.vtu_every, 3);
  EXPECT_FALSE(c.output.history);
  ASSERT_EQ(c.monitors.size(), 1u);
  EXPECT_EQ(c.monitors[0].quantity, MonitorQuantity::Ur);
}

TEST(CaseFile, MissingFileIsAnError) {
  EXPECT_THROW(load_case("/nonexistent/case.yaml"), std::runtime_error);
}

TEST(CaseFile, EmptyDocumentIsAnError) {
  EXPECT_NE(error_of("# nothing\n").find("empty"), std::string::npos);
}

TEST(CaseFile, NumStepsRoundsNearMultiples) {
  TimeSpec t;
  t.dt = 1e-3, t.t_end = 20.0;
  EXPECT_EQ(t.num_steps(), 20000);
  t.dt = 1.25e-4, t.t_end = 1.25;
  EXPECT_EQ(t.num_steps(), 10000);
  t.dt = 0.3, t.t_end = 1.0;
  EXPECT_EQ(t.num_steps(), 4);
}

// --- the shipped benchmark cases -------------------------------------------------------------------
std::string case_path(const char* name) { return std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/" + name; }

TEST(BenchmarkCases, FlyingPlateMatchesFlpProv) {
  const CaseSpec c = load_case(case_path("flying-plate.yaml"));
  EXPECT_EQ(c.name, "flying-plate");
  const auto& m = std::get<CellUnionMeshSpec>(c.mesh);
  ASSERT_EQ(m.cells.size(), 2u);
  EXPECT_EQ(m.cells[0], (std::array<int, 4>{0, 0, 3, 7}));
  EXPECT_EQ(m.cells[1], (std::array<int, 4>{3, 0, 6, 3}));
  EXPECT_EQ(c.material.E, 1.0e6);
  EXPECT_EQ(c.material.thickness, 0.1);
  ASSERT_EQ(c.loads.size(), 2u);
  EXPECT_DOUBLE_EQ(c.loads[0].amplitude * c.loads[0].function(2.5), 5.0);
  EXPECT_DOUBLE_EQ(c.loads[1].function.end_of_support(), 5.0);
  EXPECT_EQ(c.time.num_steps(), 20000);
  EXPECT_TRUE(c.boundary_conditions.empty());
  EXPECT_EQ(c.monitors.size(), 6u);
}

TEST(BenchmarkCases, SpinUpDrivesTheHubByKaneRyanBanerjee) {
  // docs/benchmarks.md §7.4: θ(t) = ω_s f(t), ω_s = 6 rad/s, T_s = 15 s; f(T_s) = T_s/2, f' = 1 after T_s.
  const CaseSpec c = load_case(case_path("spin-up.yaml"));
  ASSERT_EQ(c.joints.size(), 2u);
  const JointSpec& drive = c.joints[1];
  EXPECT_EQ(drive.type, "prescribed_rotation");
  EXPECT_EQ(drive.angle.kind(), TimeFunction::Kind::SpinUp);
  EXPECT_EQ(drive.amplitude, 6.0);
  EXPECT_EQ(drive.axis, Eigen::Vector3d(0, 1, 0));
  EXPECT_NEAR(drive.amplitude * drive.angle(15.0), 45.0, 1e-12);
  EXPECT_DOUBLE_EQ(drive.amplitude * drive.angle.rate(16.0), 6.0);
  // The strip's beam properties: rho A = 1.2 kg/m, EI = E b h³/12 = 14000 N m².
  EXPECT_NEAR(c.material.rho * c.material.thickness * 0.1, 1.2, 1e-12);
  EXPECT_NEAR(c.material.E * 0.1 * std::pow(c.material.thickness, 3) / 12.0, 14000.0, 1e-6);
}

TEST(BenchmarkCases, CylindricalPanelMatchesCypProv) {
  const CaseSpec c = load_case(case_path("cylindrical-panel.yaml"));
  const auto& m = std::get<CylindricalPanelMeshSpec>(c.mesh);
  EXPECT_EQ(m.radius, 150.0);
  EXPECT_EQ(m.angle, 0.2);
  EXPECT_EQ(m.n_arc * m.n_axial, 24);
  EXPECT_EQ(c.material.rho, 1e-8);
  EXPECT_EQ(c.time.dt, 1e-5);
  EXPECT_EQ(c.time.num_steps(), 10000);
  ASSERT_EQ(c.loads.size(), 1u);
  EXPECT_EQ(c.loads[0].direction, Eigen::Vector3d(0, 1, 1));
  EXPECT_DOUBLE_EQ(c.loads[0].function.end_of_support(), 0.02);
  ASSERT_EQ(c.sets.size(), 1u);
  EXPECT_NEAR(c.sets[0].point.y(), -150.0 * std::sin(0.1), 1e-12);
  EXPECT_NEAR(c.sets[0].point.z(), 150.0 * std::cos(0.1) - 150.0, 1e-12);
}

TEST(BenchmarkCases, PinchedHemisphereMatchesSection3) {
  const CaseSpec c = load_case(case_path("pinched-hemisphere.yaml"));
  const auto& m = std::get<HemisphereMeshSpec>(c.mesh);
  EXPECT_FALSE(m.quarter);
  EXPECT_EQ(4 * m.n * m.n, 256);
  EXPECT_EQ(c.material.rho, 1000.0);
  EXPECT_EQ(c.time.num_steps(), 10000);
  ASSERT_EQ(c.loads.size(), 4u);
  Eigen::Vector3d net = Eigen::Vector3d::Zero();
  for (const auto& l : c.loads) {
    EXPECT_DOUBLE_EQ(l.amplitude * l.function(0.015), 100.0);
    net += l.amplitude * l.direction;
  }
  EXPECT_EQ(net.norm(), 0.0);  // self-equilibrated pinch (§3.2)
  ASSERT_EQ(c.monitors.size(), 2u);
  EXPECT_EQ(c.monitors[0].quantity, MonitorQuantity::Ur);
}

}  // namespace

TEST(CaseFile, RigidBodiesJointsAndGravity) {
  const CaseSpec c = load_case_from_string(
      kMinimal + "gravity: [0, 0, -9.81]\n"
                 "rigid_bodies:\n"
                 "  hub: {mass: 2, inertia: [0.1, 0.1, 0.2], position: [1, 2, 3], axes: [[0, 1, 0], [0, 0, 1]],\n"
                 "        velocity: [1, 0, 0], angular_velocity: [0, 0, 3]}\n"
                 "joints:\n"
                 "  - {name: pin, type: fixed_point, body: hub, at: [1, 2, 2]}\n"
                 "  - {name: ball, type: spherical, a: {set: all}, b: {ground: [0, 0, 0]}}\n"
                 "  - {name: hinge, type: revolute, a: {body: hub, at: [1, 2, 3]}, b: {ground: [1, 2, 3]}, axis: [0, 0, 2]}\n"
                 "  - {name: clamp, type: rigid_connection, set: all, body: hub}\n"
                 "  - {name: drive, type: prescribed_rotation, body: hub, point: [1, 2, 3], axis: [0, 0, 1],\n"
                 "     angle: {type: ramp, t1: 2}, amplitude: 3}\n",
      "mb.yaml");
  EXPECT_EQ(c.gravity, Eigen::Vector3d(0, 0, -9.81));
  ASSERT_FALSE(c.loads.empty());  // gravity on the shell: a gravity load on `all`
  EXPECT_EQ(c.loads.back().type, LoadType::Gravity);
  EXPECT_EQ(c.loads.back().set, "all");
  EXPECT_EQ(c.loads.back().amplitude * c.loads.back().direction, Eigen::Vector3d(0, 0, -9.81));
  ASSERT_EQ(c.rigid_bodies.size(), 1u);
  const RigidBodySpec& b = c.rigid_bodies[0];
  EXPECT_EQ(b.name, "hub");
  EXPECT_EQ(b.mass, 2.0);
  EXPECT_EQ(b.position, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(b.axes.col(2), Eigen::Vector3d(1, 0, 0));  // d3 = d1 × d2
  EXPECT_EQ(b.angular_velocity, Eigen::Vector3d(0, 0, 3));
  ASSERT_EQ(c.joints.size(), 5u);
  EXPECT_EQ(c.joints[0].a.kind, JointEndSpec::Kind::body);
  EXPECT_EQ(c.joints[0].a.at, Eigen::Vector3d(1, 2, 2));
  EXPECT_EQ(c.joints[1].a.kind, JointEndSpec::Kind::set);
  EXPECT_EQ(c.joints[1].b.kind, JointEndSpec::Kind::ground);
  EXPECT_EQ(c.joints[2].axis, Eigen::Vector3d(0, 0, 2));
  EXPECT_EQ(c.joints[3].set, "all");
  EXPECT_EQ(c.joints[3].body, "hub");
  EXPECT_EQ(c.joints[4].amplitude, 3.0);
  EXPECT_DOUBLE_EQ(c.joints[4].amplitude * c.joints[4].angle(1.0), 1.5);
}
