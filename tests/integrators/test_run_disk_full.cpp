// A full disk during `run` and `static` (docs/architecture.md "Checkpoints and resume"): every output is
// written through a checked writer, a failure stops the run with "PATH: ... the disk is full", run.json
// says why, and no temporary or reserve file is left. /dev/full (open succeeds, every write fails with
// ENOSPC) stands in for a full disk without root: the file a writer is about to write is made a symbolic
// link to it.
#include "integrators/runs/run_driver.hpp"
#include "integrators/runs/static_run.hpp"
#include "lib/model/problem.hpp"
#include "tests/support/test_files.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <streambuf>

namespace shelldyn {
namespace {

namespace fs = std::filesystem;

using testing::error_of;
using testing::read_text;

fs::path scratch_dir(const std::string& name) { return testing::scratch_dir("disk_full_" + name, {"fields"}); }

std::vector<std::string> leftovers(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".tmp" || name == "run.json.reserve") out.push_back(name);
  }
  return out;
}

const char* kStatic = R"(
mesh: {generator: rectangle, a: 10, b: 1, nx: 4, ny: 1}
material: {E: 1.2e6, nu: 0, rho: 1, thickness: 0.1}
sets: {tip: {point: [10, 0, 0]}}
boundary_conditions: [{set: left, fix: [ux, uy, uz, director]}]
loads: [{type: gravity, direction: [0, 0, -1], amplitude: 1.0, function: {type: ramp, t1: 1}}]
monitors: [{name: w, set: tip, quantity: uz}]
integrator: {name: static}
time: {dt: 0.25, t_end: 1}
output: {vtu: true, vtu_every: 1}
)";

// A stream whose first output runs an action: here, filling the disk under a file after the run started.
class TriggerBuf : public std::streambuf {
 public:
  explicit TriggerBuf(std::function<void()> action) : action_(std::move(action)) {}

 protected:
  int overflow(int c) override {
    fire();
    return c == EOF ? 0 : c;
  }
  std::streamsize xsputn(const char*, std::streamsize n) override {
    fire();
    return n;
  }

 private:
  void fire() {
    if (action_) std::exchange(action_, nullptr)();
  }
  std::function<void()> action_;
};

}  // namespace

TEST(DiskFull, StaticCsvSaysSoAndRunJsonRecordsIt) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const fs::path dir = scratch_dir("static_csv");
  fs::create_symlink("/dev/full", dir / "static.csv");
  Problem p = make_problem(load_case_from_string(kStatic, "gravity.yaml"));
  const std::string e = error_of([&] { run_static(p, dir.string(), nullptr); });
  EXPECT_NE(e.find((dir / "static.csv").string() + ": cannot write static.csv: the disk is full"), std::string::npos) << e;
  const std::string json = read_text(dir / "run.json");
  EXPECT_NE(json.find("\"status\": \"incomplete: " + (dir / "static.csv").string() + ": cannot write static.csv: the disk is full"),
            std::string::npos)
      << json;
  EXPECT_TRUE(leftovers(dir).empty()) << leftovers(dir).front();
}

TEST(DiskFull, FieldsPvdErrorNamesFieldsPvd) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const fs::path dir = scratch_dir("static_pvd");
  fs::create_symlink("/dev/full", dir / "fields.pvd.tmp");
  Problem p = make_problem(load_case_from_string(kStatic, "gravity.yaml"));
  const std::string e = error_of([&] { run_static(p, dir.string(), nullptr); });
  EXPECT_NE(e.find((dir / "fields.pvd").string() + ": cannot write: the disk is full"), std::string::npos) << e;
  EXPECT_EQ(e.find("fields.pvd.tmp"), std::string::npos) << e;
  EXPECT_NE(read_text(dir / "run.json").find("\"status\": \"incomplete: "), std::string::npos);
  EXPECT_TRUE(leftovers(dir).empty()) << leftovers(dir).front();
}

// A run.json update after a checkpoint that fails (the disk filled up meanwhile) stops the run: it is not
// ignored, so run.json never silently lags behind the checkpoint. The disk "fills" (run.json.tmp becomes
// /dev/full) when the run prints its first progress line, after the initial run.json was written. The
// failed write removes the link, so the final status can then be written: it must name the cause.
TEST(DiskFull, FailedRunJsonUpdateStopsTheRun) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const fs::path dir = scratch_dir("run_json_update");
  Problem p = make_problem(load_case_from_string(R"(
mesh: {generator: rectangle, a: 2, b: 1, nx: 2, ny: 1}
material: {E: 1.0e5, nu: 0.3, rho: 10, thickness: 0.05}
initial_velocity: {translation: [0.1, 0, 0.3], angular: [0.4, 1.0, 0.2]}
integrator: {name: em-galpha}
time: {dt: 0.01, t_end: 0.2, output_interval: 0.01}
output: {vtu: false}
)",
                                                 "tumbling.yaml"));
  TriggerBuf buf([&] { fs::create_symlink("/dev/full", dir / "run.json.tmp"); });
  std::ostream log(&buf);
  RunOptions o;
  o.out_dir = dir.string();
  o.log = &log;
  o.checkpoint.steps = 5;
  const std::string e = error_of([&] { run_dynamic(p, o); });
  EXPECT_NE(e.find((dir / "run.json").string() + ": cannot write run.json: the disk is full"), std::string::npos) << e;
  const std::string json = read_text(dir / "run.json");
  EXPECT_NE(json.find("\"status\": \"incomplete: " + (dir / "run.json").string() + ": cannot write run.json: the disk is full"),
            std::string::npos)
      << json;
  // Stopped at the first checkpoint (step 5, t = 0.05), not at the end.
  std::ifstream h(dir / "history.csv");
  int lines = 0;
  for (std::string line; std::getline(h, line);) ++lines;
  EXPECT_EQ(lines, 1 + 6) << "history.csv rows: the run went on after the failed run.json update";
  EXPECT_TRUE(leftovers(dir).empty()) << leftovers(dir).front();
}

}  // namespace shelldyn
