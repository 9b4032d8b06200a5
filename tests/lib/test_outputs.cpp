// Output writers: history.csv, VTU/PVD, run.json (architecture.md §5).
#include "lib/io/history_writer.hpp"
#include "lib/io/run_info.hpp"
#include "lib/io/vtu_writer.hpp"
#include "tests/support/test_files.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

using namespace shelldyn;
namespace fs = std::filesystem;

namespace {

using shelldyn::testing::error_of;
using shelldyn::testing::read_text;

fs::path scratch_dir(const std::string& name) { return shelldyn::testing::scratch_dir("outputs_" + name); }

std::vector<std::string> read_lines(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, sep);) out.push_back(item);
  return out;
}

size_t count(const std::string& s, const std::string& what) {
  size_t n = 0;
  for (size_t pos = s.find(what); pos != std::string::npos; pos = s.find(what, pos + 1)) ++n;
  return n;
}

TEST(HistoryWriter, HeaderHasStandardExtraAndMonitorColumns) {
  const fs::path dir = scratch_dir("header");
  HistoryWriter w((dir / "history.csv").string(), {"rejected"}, {"wA", "urB"});
  const auto lines = read_lines(dir / "history.csv");
  ASSERT_EQ(lines.size(), 1u);  // header is flushed before any row
  EXPECT_EQ(lines[0],
            "step,t,dt,kinetic,strain,external_work,total,rel_drift,Lx,Ly,Lz,Jx,Jy,Jz,nonlinear_iters,"
            "linear_setups,wall_s,rejected,wA,urB");
}

TEST(HistoryWriter, RowsRoundTripAtFullPrecision) {
  const fs::path dir = scratch_dir("rows");
  const fs::path file = dir / "history.csv";
  HistoryWriter w(file.string(), {}, {"wA"});
  HistoryRow r;
  r.step = 12345;
  r.t = 0.1 + 0.2;  // not representable in short decimal form
  r.dt = 1e-3;
  r.kinetic = 1.0 / 3.0;
  r.L = Eigen::Vector3d(1e-300, -2.5, M_PI);
  r.J = Eigen::Vector3d(0, 0, -1.0 / 7.0);
  r.nonlinear_iters = 3;
  r.linear_setups = 2;
  r.monitors = {std::exp(1.0)};
  w.write(r);
  r.step = 12346;
  w.write(r);
  const auto lines = read_lines(file);  // readable while the writer is still open: rows are flushed
  ASSERT_EQ(lines.size(), 3u);
  const auto cells = split(lines[1], ',');
  ASSERT_EQ(cells.size(), w.columns().size());
  EXPECT_EQ(cells[0], "12345");
  EXPECT_EQ(std::stod(cells[1]), 0.1 + 0.2);
  EXPECT_EQ(std::stod(cells[3]), 1.0 / 3.0);
  EXPECT_EQ(std::stod(cells[8]), 1e-300);
  EXPECT_EQ(std::stod(cells[10]), M_PI);
  EXPECT_EQ(std::stod(cells[13]), -1.0 / 7.0);
  EXPECT_EQ(cells[14], "3");
  EXPECT_EQ(cells[15], "2");
  EXPECT_EQ(std::stod(cells[17]), std::exp(1.0));
  EXPECT_EQ(split(lines[2], ',')[0], "12346");
}

TEST(HistoryWriter, RejectsBadColumnsAndMismatchedRows) {
  const fs::path dir = scratch_dir("bad");
  const std::string file = (dir / "h.csv").string();
  EXPECT_THROW(HistoryWriter(file, {}, {"a,b"}), std::invalid_argument);
  EXPECT_THROW(HistoryWriter(file, {}, {"total"}), std::invalid_argument);  // duplicates a standard column
  EXPECT_THROW(HistoryWriter(file, {"x"}, {"x"}), std::invalid_argument);
  EXPECT_THROW(HistoryWriter((dir / "missing" / "h.csv").string(), {}, {}), std::runtime_error);
  HistoryWriter w(file, {}, {"m"});
  HistoryRow r;
  EXPECT_THROW(w.write(r), std::invalid_argument);  // one monitor value missing
}

Mesh two_element_mesh() {
  // Two unit squares side by side, nodes on a 5 x 3 grid, Gmsh-10 order.
  Mesh m;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 5; ++i) m.X.emplace_back(0.5 * i, 0.5 * j, 0.0);
  auto id = [](int i, int j) { return j * 5 + i; };
  for (int e = 0; e < 2; ++e) {
    const int i = 2 * e;
    m.elements.push_back({id(i, 0), id(i + 2, 0), id(i + 2, 2), id(i, 2), id(i + 1, 0), id(i + 2, 1), id(i + 1, 2),
                          id(i, 1), id(i + 1, 1)});
  }
  return m;
}

TEST(VtuWriter, WritesBiquadraticQuadsWithFields) {
  const fs::path dir = scratch_dir("vtu");
  const Mesh m = two_element_mesh();
  VtuFields f;
  f.displacement.assign(m.X.size(), Vec3(0, 0, 0.25));
  f.velocity.assign(m.X.size(), Vec3(1, 2, 3));
  f.director.assign(m.X.size(), Vec3(0, 0, 1));
  f.point_scalars.push_back({"fixed_dofs", std::vector<double>(m.X.size(), 0.0)});
  f.cell_scalars.push_back({"element_id", {0.0, 1.0}});
  const fs::path file = dir / vtu_step_file_name(7);
  EXPECT_EQ(file.filename().string(), "step_000007.vtu");
  write_vtu(file.string(), m, f);
  const std::string xml = read_text(file);
  EXPECT_NE(xml.find("NumberOfPoints=\"15\" NumberOfCells=\"2\""), std::string::npos);
  EXPECT_NE(xml.find("Name=\"displacement\" NumberOfComponents=\"3\""), std::string::npos);
  EXPECT_NE(xml.find("Name=\"velocity\""), std::string::npos);
  EXPECT_NE(xml.find("Name=\"director\""), std::string::npos);
  EXPECT_NE(xml.find("Name=\"fixed_dofs\""), std::string::npos);
  EXPECT_NE(xml.find("<CellData>"), std::string::npos);
  EXPECT_EQ(count(xml, "          28\n"), 2u);  // one type entry per cell
  EXPECT_NE(xml.find("          9\n          18\n"), std::string::npos);  // offsets
  EXPECT_NE(xml.find("          0.5 0 0.25\n"), std::string::npos);     // points = X + d
  EXPECT_NE(xml.find("          0 2 12 10 1 7 11 5 6\n"), std::string::npos);  // connectivity in mesh order
}

TEST(VtuWriter, VectorAndTensorFieldsNameTheirComponents) {
  const fs::path dir = scratch_dir("vtu_names");
  const Mesh m = two_element_mesh();
  VtuFields f;
  f.displacement.assign(m.X.size(), Vec3::Zero());
  f.velocity.assign(m.X.size(), Vec3::Zero());
  f.director.assign(m.X.size(), Vec3::UnitZ());
  f.point_scalars.push_back({"reaction", std::vector<double>(3 * m.X.size(), 0.0), 3});
  f.cell_scalars.push_back({"shear_force", {0.0, 1.0, 2.0, 3.0}, 2, {"1", "2"}});
  write_vtu((dir / "a.vtu").string(), m, f);
  const std::string xml = read_text(dir / "a.vtu");
  for (const char* name : {"displacement", "velocity", "director", "reaction"})
    EXPECT_NE(xml.find(std::string("Name=\"") + name +
                       "\" NumberOfComponents=\"3\" ComponentName0=\"X\" ComponentName1=\"Y\" ComponentName2=\"Z\""),
              std::string::npos)
        << name;
  EXPECT_NE(xml.find("Name=\"shear_force\" NumberOfComponents=\"2\" ComponentName0=\"1\" ComponentName1=\"2\""),
            std::string::npos);
  f.cell_scalars.back().component_names = {"1"};  // one name for two components
  EXPECT_THROW(write_vtu((dir / "b.vtu").string(), m, f), std::invalid_argument);
}

TEST(VtuWriter, RejectsWrongFieldSizes) {
  const fs::path dir = scratch_dir("vtu_bad");
  const Mesh m = two_element_mesh();
  VtuFields f;
  f.displacement.assign(m.X.size(), Vec3::Zero());
  f.velocity.assign(m.X.size() - 1, Vec3::Zero());
  f.director.assign(m.X.size(), Vec3::UnitZ());
  EXPECT_THROW(write_vtu((dir / "a.vtu").string(), m, f), std::invalid_argument);
  f.velocity.assign(m.X.size(), Vec3::Zero());
  f.cell_scalars.push_back({"e", {1.0}});
  EXPECT_THROW(write_vtu((dir / "a.vtu").string(), m, f), std::invalid_argument);
}

TEST(PvdWriter, RewritesTheCollectionOnEveryAdd) {
  const fs::path dir = scratch_dir("pvd");
  PvdWriter pvd((dir / "fields.pvd").string());
  pvd.add(0.0, "fields/step_000000.vtu");
  std::string xml = read_text(dir / "fields.pvd");
  EXPECT_EQ(count(xml, "<DataSet "), 1u);
  EXPECT_NE(xml.find("</VTKFile>"), std::string::npos);  // complete after each add
  pvd.add(0.125, "fields/step_000001.vtu");
  xml = read_text(dir / "fields.pvd");
  EXPECT_EQ(count(xml, "<DataSet "), 2u);
  EXPECT_NE(xml.find("timestep=\"0.125\" group=\"\" part=\"0\" file=\"fields/step_000001.vtu\""), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "fields.pvd.tmp"));
}

TEST(RunInfo, JsonEscapesStringsAndNonFiniteNumbers) {
  EXPECT_EQ(json_quote("a\"b\\c\nd\te\x01"), "\"a\\\"b\\\\c\\nd\\te\\u0001\"");
  EXPECT_EQ(json_quote("π"), "\"π\"");
  EXPECT_EQ(json_number(0.1), "0.1");  // shortest form that reads back exactly
  EXPECT_EQ(std::stod(json_number(1.0 / 3.0)), 1.0 / 3.0);
  EXPECT_EQ(json_number(std::numeric_limits<double>::quiet_NaN()), "null");
  EXPECT_EQ(json_number(-std::numeric_limits<double>::infinity()), "null");
}

TEST(RunInfo, JsonFieldsKeepOrderAndReplace) {
  JsonFields f;
  f.set("steps", 10);
  f.set("name", "x");
  f.set("ok", true);
  f.set("steps", 20LL);
  ASSERT_EQ(f.entries().size(), 3u);
  EXPECT_EQ(f.entries()[0], std::make_pair(std::string("steps"), std::string("20")));
  EXPECT_EQ(f.entries()[1].second, "\"x\"");  // const char* must not decay to bool
  EXPECT_EQ(f.entries()[2].second, "true");
}

TEST(RunInfo, DocumentHasStatusVersionsCaseAndSummary) {
  const CaseSpec c = load_case_from_string(
      "name: demo\ndescription: \"quote \\\" and backslash \\\\\"\n"
      "mesh: {generator: hemisphere, radius: 10, hole_deg: 18, n: 2}\n"
      "material: {E: 1, nu: 0.3, rho: 1, thickness: 0.1}\n"
      "loads:\n  - {set: all, type: force, direction: [1, 0, 0], amplitude: 1, function: {type: hat, t1: 2}}\n"
      "integrator: {name: em-galpha, rho_inf: 1}\ntime: {dt: 0.1, t_end: 1}\n",
      "demo.yaml");
  RunInfo info;
  info.status = "incomplete: Newton failed at t = 0.5";
  info.sundials_version = "6.4.1";
  info.summary.set("steps", 5);
  info.summary.set("energy", std::numeric_limits<double>::quiet_NaN());
  const fs::path dir = scratch_dir("runjson");
  write_run_json((dir / "run.json").string(), c, info);
  const std::string json = read_text(dir / "run.json");
  EXPECT_NE(json.find("\"status\": \"incomplete: Newton failed at t = 0.5\""), std::string::npos);
  EXPECT_NE(json.find("\"shelldyn\": \"" + shelldyn_version() + "\""), std::string::npos);
  EXPECT_NE(json.find("\"sundials\": \"6.4.1\""), std::string::npos);
  EXPECT_NE(json.find("\"eigen\": \"" + eigen_version() + "\""), std::string::npos);
  EXPECT_NE(json.find("\"description\": \"quote \\\" and backslash \\\\\""), std::string::npos);
  EXPECT_NE(json.find("\"generator\": \"hemisphere\""), std::string::npos);
  EXPECT_NE(json.find("\"t1\": 2"), std::string::npos);
  EXPECT_NE(json.find("\"rho_inf\": \"1\""), std::string::npos);
  EXPECT_NE(json.find("\"num_steps\": 10"), std::string::npos);
  EXPECT_NE(json.find("\"energy\": null"), std::string::npos);
  EXPECT_FALSE(shelldyn_version().empty());
  EXPECT_NE(shelldyn_version(), "unknown");
  // Balanced brackets: a cheap structural check (a full parse is done by the CLI test in Python).
  EXPECT_EQ(count(json, "{"), count(json, "}"));
  EXPECT_EQ(count(json, "["), count(json, "]"));
}

}  // namespace

// A full disk without root: /dev/full accepts open() and fails every write with ENOSPC. A file the
// writers create is made a symbolic link to it; each writer must say "the disk is full", name the file
// it was writing, and leave no temporary or half-written file behind.
namespace {
bool have_dev_full() { return fs::exists("/dev/full"); }

}  // namespace

TEST(DiskFull, RunJsonSaysSoAndLeavesNoTemporary) {
  if (!have_dev_full()) GTEST_SKIP() << "no /dev/full";
  const fs::path dir = scratch_dir("full_runjson");
  fs::create_symlink("/dev/full", dir / "run.json.tmp");
  const std::string e = error_of([&] { write_text_atomically((dir / "run.json").string(), std::string(10000, 'x'), "run.json"); });
  EXPECT_NE(e.find((dir / "run.json").string() + ": cannot write run.json: the disk is full"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(fs::symlink_status(dir / "run.json.tmp"))) << "a stale run.json.tmp was left";
  EXPECT_FALSE(fs::exists(dir / "run.json"));
}

TEST(DiskFull, VtuSaysSoAndLeavesNoFile) {
  if (!have_dev_full()) GTEST_SKIP() << "no /dev/full";
  const fs::path dir = scratch_dir("full_vtu");
  const Mesh mesh = two_element_mesh();
  VtuFields f;
  f.displacement = f.velocity = f.director = std::vector<Vec3>(mesh.X.size(), Vec3(0.5, 0.25, 1.0));
  fs::create_symlink("/dev/full", dir / "step_000003.vtu");
  const std::string e = error_of([&] { write_vtu((dir / "step_000003.vtu").string(), mesh, f); });
  EXPECT_NE(e.find((dir / "step_000003.vtu").string() + ": cannot write: the disk is full"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(fs::symlink_status(dir / "step_000003.vtu"))) << "a half-written VTU was left";
}

TEST(DiskFull, HistorySaysSo) {
  if (!have_dev_full()) GTEST_SKIP() << "no /dev/full";
  const fs::path dir = scratch_dir("full_history");
  fs::create_symlink("/dev/full", dir / "history.csv");
  const std::string e = error_of([&] { HistoryWriter w((dir / "history.csv").string(), {}, {"tip"}); });
  EXPECT_NE(e.find((dir / "history.csv").string() + ": cannot write history.csv: the disk is full"), std::string::npos) << e;
}

TEST(DiskReserve, HoldsTheSpaceUntilReleased) {
  const fs::path dir = scratch_dir("reserve");
  const fs::path p = dir / "run.json.reserve";
  {
    DiskReserve r(p.string(), 65536);
    ASSERT_TRUE(r.held());
    ASSERT_TRUE(fs::exists(p));
    EXPECT_EQ(fs::file_size(p), 65536u);
    r.release();
    EXPECT_FALSE(r.held());
    EXPECT_FALSE(fs::exists(p));
  }
  { DiskReserve r(p.string(), 4096); }
  EXPECT_FALSE(fs::exists(p)) << "the destructor must delete the reserve";
  DiskReserve none((dir / "no-such-folder" / "x").string(), 4096);
  EXPECT_FALSE(none.held());
}
