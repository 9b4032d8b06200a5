// Reading back shelldyn's VTU files (lib/io/vtu_reader.hpp): the velocity field of initial_velocity: {field:
// FILE.vtu} (docs/manual.md §2.6) and the saved state of --state FILE.vtu (docs/manual.md §1), with the
// errors a wrong file must give.
#include "lib/model/problem.hpp"
#include "lib/io/state_output.hpp"
#include "lib/io/vtu_reader.hpp"
#include "lib/io/vtu_writer.hpp"
#include "tests/support/test_files.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace shelldyn;
namespace fs = std::filesystem;

namespace {

using shelldyn::testing::error_of;
using shelldyn::testing::read_text;
using shelldyn::testing::write_text;

fs::path scratch_dir(const std::string& name) { return shelldyn::testing::scratch_dir("vtu_reader_" + name, {"fields"}); }

// A curved mesh, so that director rates and charts are not trivial.
const std::string kPanel = "mesh: {generator: cylindrical_panel, radius: 1.0, angle: 1.2, length: 1.5, n_arc: 2, n_axial: 2}\n"
                           "material: {E: 1.0e6, nu: 0.3, rho: 2, thickness: 0.05}\n"
                           "integrator: {name: em-galpha}\ntime: {dt: 0.1, t_end: 1}\n";

Problem panel(const std::string& extra = "") { return make_problem(load_case_from_string(kPanel + extra, "panel.yaml")); }


// A deformed, moving state of the panel: translations, rotated directors (same charts), velocities.
State moving_state(const Model& model) {
  State s = model.initial_state();
  const Mesh& mesh = model.mesh();
  for (int i = 0; i < mesh.num_nodes(); ++i) {
    const Vec3 X = mesh.X[static_cast<size_t>(i)];
    s.u.segment<3>(DofMap::dof(i, 0)) = Vec3(0.01 * X.y(), -0.02 * X.x() * X.z(), 0.03 * X.x() * X.x());
    const Vec3 p0 = model.normals()[static_cast<size_t>(i)];
    const Vec3 p = (p0 + Vec3(0.05 * X.x(), -0.03, 0.02 * X.y())).normalized();
    s.u.segment<2>(DofMap::dof(i, 3)) = chart_coordinates(p, s.charts[static_cast<size_t>(i)]);
    s.v.segment<3>(DofMap::dof(i, 0)) = Vec3(1.0 + X.x(), -2.0 * X.y(), 0.5 * X.z());
    s.v.segment<2>(DofMap::dof(i, 3)) = Eigen::Vector2d(0.3 * X.x(), -0.7 + X.y());
  }
  return s;
}

}  // namespace

TEST(VtuReader, ReadsBackWhatTheWriterWrote) {
  Problem pb = panel();
  const Model& model = *pb.model;
  const State s = moving_state(model);
  const fs::path dir = scratch_dir("roundtrip");
  const VtuFields f = state_fields(model, s);
  write_vtu((dir / "a.vtu").string(), model.mesh(), f);
  const VtuPointData r = read_vtu((dir / "a.vtu").string());
  ASSERT_EQ(r.num_points, static_cast<size_t>(model.mesh().num_nodes()));
  EXPECT_EQ(r.num_cells, static_cast<size_t>(model.mesh().num_elements()));
  const auto d = r.vectors("displacement"), v = r.vectors("velocity"), p = r.vectors("director");
  for (size_t i = 0; i < r.num_points; ++i) {  // %.17g: exact
    EXPECT_EQ(d[i], f.displacement[i]);
    EXPECT_EQ(v[i], f.velocity[i]);
    EXPECT_EQ(p[i], f.director[i]);
    EXPECT_EQ(r.points[i], Vec3(model.mesh().X[i] + f.displacement[i]));
  }
  ASSERT_TRUE(r.has("director_rate"));
  EXPECT_EQ(r.arrays.at("director_rate").values, f.point_scalars.front().values);
  EXPECT_NO_THROW(check_vtu_matches_mesh(r, model.mesh().X));
}

// initial_velocity: {field: FILE.vtu}: the velocity a run wrote becomes the initial velocity of another,
// director rates included (the written ṗ = A1 q̇ goes back to the same chart rates q̇).
TEST(VtuReader, InitialVelocityFromAVtuRoundTrips) {
  const std::string rigid = "initial_velocity: {translation: [1, -2, 0.5], angular: [0.3, -0.2, 0.5], about: [0.2, 0.1, 0]}\n";
  Problem a = panel(rigid);
  const fs::path dir = scratch_dir("iv");
  const std::string vtu = (dir / "fields" / "step_000000.vtu").string();
  write_vtu(vtu, a.model->mesh(), state_fields(*a.model, a.initial_state()));
  Problem b = panel("initial_velocity: {field: " + vtu + "}\n");
  const double scale = a.disc.initial_velocity.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.5);
  EXPECT_LE((b.disc.initial_velocity - a.disc.initial_velocity).cwiseAbs().maxCoeff(), 1e-15 * scale);
  // The director rates are there (not silently zero): the kinetic energies agree.
  const double Ka = a.model->invariants(a.initial_state()).kinetic, Kb = b.model->invariants(b.initial_state()).kinetic;
  EXPECT_NEAR(Kb, Ka, 1e-14 * Ka);
  // Without director_rate in the file, ṗ = 0: a measurably smaller kinetic energy (so the test above can fail).
  std::string text = read_text(vtu);
  const size_t at = text.find("Name=\"director_rate\"");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 20, "Name=\"something_else\"");
  write_text(dir / "fields" / "no_rates.vtu", text);
  Problem c = panel("initial_velocity: {field: " + (dir / "fields" / "no_rates.vtu").string() + "}\n");
  const double Kc = c.model->invariants(c.initial_state()).kinetic;
  EXPECT_LT(Kc, Ka * (1 - 1e-6));
  // Only the nodes of `set` take the field.
  Problem d = panel("initial_velocity: {set: x0, field: " + vtu + "}\n");
  const auto& x0 = d.disc.mesh.node_sets.at("x0");
  for (int i = 0; i < d.disc.mesh.num_nodes(); ++i) {
    const bool in = std::find(x0.begin(), x0.end(), i) != x0.end();
    const Eigen::Index k = DofMap::dof(i, 0);
    using Vec5 = Eigen::Matrix<double, 5, 1>;
    const Vec5 want = in ? Vec5(a.disc.initial_velocity.segment<5>(k)) : Vec5(Vec5::Zero());
    EXPECT_LE((Vec5(d.disc.initial_velocity.segment<5>(k)) - want).cwiseAbs().maxCoeff(), 1e-15 * scale) << "node " << i;
  }
}

TEST(VtuReader, InitialVelocityFieldErrorsNameTheFileAndTheProblem) {
  Problem a = panel("initial_velocity: {translation: [1, 0, 0]}\n");
  const fs::path dir = scratch_dir("errors");
  const fs::path good = dir / "good.vtu";
  write_vtu(good.string(), a.model->mesh(), state_fields(*a.model, a.initial_state()));
  const std::string text = read_text(good);
  auto with = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string t = text;
    EXPECT_NE(t.find(from), std::string::npos) << from;
    for (size_t at = t.find(from); at != std::string::npos; at = t.find(from, at + to.size())) t.replace(at, from.size(), to);
    write_text(dir / name, t);
    return (dir / name).string();
  };
  auto error = [&](const std::string& file) {
    return error_of([&] { panel("initial_velocity: {field: " + file + "}\n"); });
  };
  EXPECT_NE(error((dir / "missing.vtu").string()).find("missing.vtu: cannot open the VTU file"), std::string::npos);
  write_text(dir / "truncated.vtu", text.substr(0, text.size() * 3 / 5));
  EXPECT_NE(error((dir / "truncated.vtu").string()).find("truncated"), std::string::npos) << error((dir / "truncated.vtu").string());
  const size_t vel = text.find("Name=\"velocity\"");
  const size_t first_value = text.find('\n', vel) + 1;
  std::string nan_text = text;
  nan_text.replace(first_value, text.find('\n', first_value) - first_value, "          nan 0 0");
  write_text(dir / "nan.vtu", nan_text);
  EXPECT_NE(error((dir / "nan.vtu").string()).find("point data 'velocity' is not finite at point 0"), std::string::npos)
      << error((dir / "nan.vtu").string());
  EXPECT_NE(error(with("noarray.vtu", "Name=\"velocity\"", "Name=\"speed\"")).find("no point data array 'velocity'"),
            std::string::npos);
  // The writer names the components (ComponentName0..2) between NumberOfComponents and format.
  const std::string velocity_tag = "Name=\"velocity\" NumberOfComponents=\"3\" ComponentName0=\"X\" "
                                   "ComponentName1=\"Y\" ComponentName2=\"Z\" format=";
  EXPECT_NE(error(with("binary.vtu", velocity_tag + "\"ascii\"", velocity_tag + "\"binary\""))
                .find("only ASCII VTU can be read"),
            std::string::npos);
  EXPECT_NE(error(with("notvtu.vtu", "UnstructuredGrid", "PolyData")).find("not a VTK UnstructuredGrid"), std::string::npos);
  // The case line is named first.
  EXPECT_EQ(error((dir / "missing.vtu").string()).rfind("panel.yaml:", 0), 0u) << error((dir / "missing.vtu").string());
  // A field of another mesh: other node count, or the same count elsewhere.
  Problem big = make_problem(load_case_from_string(
      "mesh: {generator: cylindrical_panel, radius: 1.0, angle: 1.2, length: 1.5, n_arc: 3, n_axial: 2}\n"
      "material: {E: 1.0e6, nu: 0.3, rho: 2, thickness: 0.05}\nintegrator: {name: em-galpha}\ntime: {dt: 0.1, t_end: 1}\n",
      "big.yaml"));
  write_vtu((dir / "big.vtu").string(), big.model->mesh(), state_fields(*big.model, big.initial_state()));
  EXPECT_NE(error((dir / "big.vtu").string()).find("has 35 points, the case's mesh 25 nodes"), std::string::npos)
      << error((dir / "big.vtu").string());
  Problem wide = make_problem(load_case_from_string(
      "mesh: {generator: cylindrical_panel, radius: 1.0, angle: 1.3, length: 1.5, n_arc: 2, n_axial: 2}\n"
      "material: {E: 1.0e6, nu: 0.3, rho: 2, thickness: 0.05}\nintegrator: {name: em-galpha}\ntime: {dt: 0.1, t_end: 1}\n",
      "wide.yaml"));
  write_vtu((dir / "wide.vtu").string(), wide.model->mesh(), state_fields(*wide.model, wide.initial_state()));
  EXPECT_NE(error((dir / "wide.vtu").string()).find("in the reference configuration, the case's node"), std::string::npos)
      << error((dir / "wide.vtu").string());
  EXPECT_NE(error((dir / "v.txt").string()).find("must be a .vtu or a .csv file"), std::string::npos);
}

// --state FILE.vtu: the configuration, velocity and time of a run's VTU (time from its fields.pvd).
TEST(VtuReader, StateFromAVtuOfARun) {
  Problem pb = panel();
  Model& model = *pb.model;
  const State s = moving_state(model);
  const fs::path dir = scratch_dir("state");
  const std::string vtu = (dir / "fields" / "step_000003.vtu").string();
  write_vtu(vtu, model.mesh(), state_fields(model, s));
  bool has_time = true;
  State r = state_from_vtu(model, vtu, &has_time);
  EXPECT_FALSE(has_time);  // no fields.pvd yet
  PvdWriter pvd((dir / "fields.pvd").string());
  pvd.add(0.0, "fields/step_000000.vtu");
  pvd.add(0.375, "fields/step_000003.vtu");
  r = state_from_vtu(model, vtu, &has_time);
  EXPECT_TRUE(has_time);
  EXPECT_EQ(r.t, 0.375);
  ASSERT_EQ(r.charts.size(), s.charts.size());
  for (size_t i = 0; i < s.charts.size(); ++i) EXPECT_EQ(r.charts[i].l, s.charts[i].l);
  EXPECT_LE((r.u - s.u).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LE((r.v - s.v).cwiseAbs().maxCoeff(), 1e-14);
  const Invariants a = model.invariants(s), b = model.invariants(r);
  EXPECT_NEAR(b.kinetic, a.kinetic, 1e-13 * a.kinetic);
  EXPECT_NEAR(b.strain, a.strain, 1e-12 * a.strain);
  ASSERT_GT(a.strain, 0.0);
  // A state that violates this case's boundary conditions is refused.
  Problem fixed = panel("boundary_conditions: [{set: x0, fix: [ux, uy, uz]}]\n");
  EXPECT_NE(error_of([&] { state_from_vtu(*fixed.model, vtu, &has_time); }).find("away from the value its boundary condition fixes"),
            std::string::npos);
  // The static continuation of the unconstrained panel is still accepted (only the translations differ).
  EXPECT_NO_THROW(state_from_vtu(model, vtu, &has_time));
}

// initial_displacement: {field: FILE.vtu} (docs/manual.md §2.6): the run starts from the VTU's displacements
// and directors; with initial_velocity: {field: same.vtu} the whole state of the VTU comes back, so K, V, L,
// J are those of the written state. Only velocity fields go with it; a bad VTU is a case error.
TEST(VtuReader, InitialDisplacementAndVelocityFromAVtu) {
  Problem pb = panel();
  const State s = moving_state(*pb.model);
  const fs::path dir = scratch_dir("initial_displacement");
  const std::string vtu = (dir / "fields" / "step_000002.vtu").string();
  write_vtu(vtu, pb.model->mesh(), state_fields(*pb.model, s));
  Problem b = panel("initial_displacement: {field: " + vtu + "}\ninitial_velocity: {field: " + vtu + "}\n");
  const State r = b.initial_state();
  EXPECT_EQ(r.t, 0.0);
  EXPECT_LE((r.u - s.u).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LE((r.v - s.v).cwiseAbs().maxCoeff(), 1e-14);
  const Invariants a = pb.model->invariants(s), c = b.model->invariants(r);
  ASSERT_GT(a.strain, 0.0);
  EXPECT_NEAR(c.kinetic, a.kinetic, 1e-13 * a.kinetic);
  EXPECT_NEAR(c.strain, a.strain, 1e-12 * a.strain);
  EXPECT_LE((c.L - a.L).norm(), 1e-13 * a.L.norm());
  EXPECT_LE((c.J - a.J).norm(), 1e-13 * a.J.norm());
  // Displacement only: at rest in the displaced configuration.
  Problem only = panel("initial_displacement: {field: " + vtu + "}\n");
  EXPECT_EQ(only.initial_state().v.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NEAR(only.model->invariants(only.initial_state()).strain, a.strain, 1e-12 * a.strain);
  // Errors: a rigid initial velocity with it, not a VTU, a VTU of another mesh (named with the case line).
  EXPECT_NE(error_of([&] { panel("initial_displacement: {field: " + vtu + "}\ninitial_velocity: {translation: [1, 0, 0]}\n"); })
                .find("initial_displacement: the initial velocity must then be a field"),
            std::string::npos);
  EXPECT_NE(error_of([&] { panel("initial_displacement: {field: d.txt}\n"); }).find("is neither a .vtu nor a .csv file"), std::string::npos);
  Problem big = make_problem(load_case_from_string(
      "mesh: {generator: cylindrical_panel, radius: 1.0, angle: 1.2, length: 1.5, n_arc: 3, n_axial: 2}\n"
      "material: {E: 1.0e6, nu: 0.3, rho: 2, thickness: 0.05}\nintegrator: {name: em-galpha}\ntime: {dt: 0.1, t_end: 1}\n",
      "big.yaml"));
  write_vtu((dir / "big.vtu").string(), big.model->mesh(), state_fields(*big.model, big.initial_state()));
  const std::string e = error_of([&] { panel("initial_displacement: {field: " + (dir / "big.vtu").string() + "}\n"); });
  EXPECT_EQ(e.rfind("panel.yaml:", 0), 0u) << e;
  EXPECT_NE(e.find("initial_displacement.field: " + (dir / "big.vtu").string() + ": has 35 points"), std::string::npos) << e;
}

namespace shelldyn {
namespace {

// initial_displacement: {field: FILE.csv} (docs/manual.md §2.6): the same displaced state as from a VTU, read
// from "node,ux,uy,uz[,px,py,pz]" lines (the CSV reader of initial_velocity fields). Nodes not listed keep the
// reference; without director columns the directors stay the reference ones. Errors name the case line and
// the file (and its line).
TEST(VtuReader, InitialDisplacementFromACsvEqualsTheVtuOne) {
  Problem pb = panel();
  const State s = moving_state(*pb.model);
  const fs::path dir = scratch_dir("initial_displacement_csv");
  const std::string vtu = (dir / "state.vtu").string(), csv = (dir / "state.csv").string();
  write_vtu(vtu, pb.model->mesh(), state_fields(*pb.model, s));
  {
    std::ofstream f(csv);
    f.precision(17);
    f << "node,ux,uy,uz,px,py,pz\n";
    for (int i = 0; i < pb.model->mesh().num_nodes(); ++i) {
      const Vec3 d = s.u.segment<3>(DofMap::dof(i, 0)), p = pb.model->director(s, i);
      f << i << "," << d.x() << "," << d.y() << "," << d.z() << "," << p.x() << "," << p.y() << "," << p.z() << "\n";
    }
  }
  const State from_vtu = panel("initial_displacement: {field: " + vtu + "}\n").initial_state();
  Problem from_csv_problem = panel("initial_displacement: {field: " + csv + "}\n");
  const State from_csv = from_csv_problem.initial_state();
  EXPECT_EQ(from_csv.charts.size(), from_vtu.charts.size());
  for (size_t i = 0; i < from_csv.charts.size(); ++i) EXPECT_EQ(from_csv.charts[i].l, from_vtu.charts[i].l) << i;
  EXPECT_LE((from_csv.u - s.u).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LE((from_csv.u - from_vtu.u).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(from_csv.v.cwiseAbs().maxCoeff(), 0.0);  // at rest unless a velocity field is given
  const double V = pb.model->invariants(s).strain;
  ASSERT_GT(V, 0.0);
  EXPECT_NEAR(from_csv_problem.model->invariants(from_csv).strain, V, 1e-12 * V);

  // Translations only, for two nodes: the others and every director stay at the reference.
  {
    std::ofstream f(csv);
    f << "node,ux,uy,uz\n3,0.1,0.2,0.3\n\n7,-0.1,0,0\n";
  }
  const State part = panel("initial_displacement: {field: " + csv + "}\n").initial_state();
  State expected = pb.model->initial_state();
  expected.u.segment<3>(DofMap::dof(3, 0)) = Vec3(0.1, 0.2, 0.3);
  expected.u.segment<3>(DofMap::dof(7, 0)) = Vec3(-0.1, 0, 0);
  EXPECT_EQ((part.u - expected.u).cwiseAbs().maxCoeff(), 0.0);

  // Errors.
  auto csv_error = [&](const std::string& text, const std::string& extra = "") {
    std::ofstream(csv) << text;
    return error_of([&] { panel(extra + "initial_displacement: {field: " + csv + "}\n").initial_state(); });
  };
  std::string e = csv_error("node,ux,uy,uz,px,py,pz\n2,0,0,0,0,0,2\n");
  EXPECT_EQ(e.rfind("panel.yaml:5: initial_displacement.field: " + csv + ": the director (px, py, pz) of node 2 has length 2", 0), 0u) << e;
  e = csv_error("node,ux,uy,uz\n2,0,0\n");
  EXPECT_NE(e.find(csv + ":2: expected a node index in [0, 25) and 3 finite numbers"), std::string::npos) << e;
  e = csv_error("id,ux,uy,uz\n");
  EXPECT_NE(e.find(":1: expected the header 'node,ux,uy,uz' or 'node,ux,uy,uz,px,py,pz'"), std::string::npos) << e;
  e = csv_error("node,ux,uy,uz\n0,0,0,0.5\n", "boundary_conditions: [{set: x0, fix: [uz]}]\n");
  EXPECT_NE(e.find("node 0 has uz = 0.5"), std::string::npos) << e;
  EXPECT_NE(e.find("which a boundary condition fixes at 0"), std::string::npos) << e;
  EXPECT_NE(error_of([&] { panel("initial_displacement: {field: " + (dir / "missing.csv").string() + "}\n"); })
                .find("cannot open the displacement field"),
            std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace shelldyn
