// `shelldyn study` machinery (integrators/runs/study.hpp) on a tiny preset: the runs are made through
// run_comparison(), measured from their folders, and a second call resumes (runs nothing that completed).
#include "integrators/runs/study.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace shelldyn {
namespace {

namespace fs = std::filesystem;

StudyOptions tiny_study(const std::string& dir) {
  StudyOptions o;
  StudyPreset& p = o.preset;
  p.name = "flying-plate-tiny";
  p.window_t_end = 0.04;
  p.window_output = 0.01;
  p.fixed_specs = {"em-galpha"};
  p.dts = {0.01, 0.005};
  p.adaptive_specs = {"ida-bdf"};
  p.rtols = {1e-4};
  p.reference_spec = "em-galpha:dt=0.00125";
  o.case_path = std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/flying-plate.yaml";
  o.out_dir = dir;
  o.groups = {"window"};
  o.execution.jobs = 2;
  o.command = "test_study";
  return o;
}

const StudyRow& row(const StudyResult& r, const std::string& label) {
  for (const auto& x : r.rows)
    if (x.label == label) return x;
  throw std::runtime_error("no row " + label);
}

TEST(Study, RunsMeasuresAndResumes) {
  const std::string dir = testing::TempDir() + "/shelldyn-study-test";
  fs::remove_all(dir);
  const StudyOptions o = tiny_study(dir);
  const StudyResult first = run_study(o);
  ASSERT_EQ(first.rows.size(), 4u);
  EXPECT_EQ(first.ran, 4);
  EXPECT_EQ(first.skipped, 0);
  EXPECT_EQ(first.failed, 0);
  for (const auto& r : first.rows) {
    EXPECT_EQ(r.status, "complete") << r.label;
    EXPECT_GT(r.steps, 0) << r.label;
    EXPECT_GT(r.rhs_evaluations, 0) << r.label;
    EXPECT_GT(r.cpu_s, 0.0) << r.label;
    EXPECT_TRUE(std::isfinite(r.energy_error)) << r.label;
  }
  // Convergence against the reference: halving dt reduces the displacement error (ratio ~2 in this start-up
  // window with the case's modified Newton; the order is not what this test checks).
  const double e1 = row(first, "em-galpha_dt=0.01").displacement_error;
  const double e2 = row(first, "em-galpha_dt=0.005").displacement_error;
  EXPECT_GT(e1, 0.0);
  EXPECT_GT(e1 / e2, 1.5);
  EXPECT_TRUE(std::isnan(row(first, "em-galpha_dt=0.00125").displacement_error));  // the reference itself
  EXPECT_EQ(row(first, "ida-bdf_rtol=0.0001").kind, "adaptive");
  {
    std::ifstream csv(first.study_csv);
    const std::string text((std::istreambuf_iterator<char>(csv)), std::istreambuf_iterator<char>());
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 5);
  }

  // Resume: nothing reruns, the measures are the same (read back from the run folders).
  const StudyResult second = run_study(o);
  EXPECT_EQ(second.ran, 0);
  EXPECT_EQ(second.skipped, 4);
  EXPECT_DOUBLE_EQ(row(second, "em-galpha_dt=0.01").displacement_error, e1);
  EXPECT_DOUBLE_EQ(row(second, "ida-bdf_rtol=0.0001").cpu_s, row(first, "ida-bdf_rtol=0.0001").cpu_s);

  // An interrupted run (no complete run.json) is run again, and only that one.
  fs::remove(fs::path(dir) / "window" / "em-galpha_dt=0.005" / "run.json");
  const StudyResult third = run_study(o);
  EXPECT_EQ(third.ran, 1);
  EXPECT_EQ(third.skipped, 3);
  EXPECT_EQ(row(third, "em-galpha_dt=0.005").status, "complete");
  fs::remove_all(dir);
}

TEST(Study, BadPresetFailsBeforeAnyRun) {
  const std::string dir = testing::TempDir() + "/shelldyn-study-bad";
  fs::remove_all(dir);
  StudyOptions o = tiny_study(dir);
  o.preset.fixed_specs.push_back("leapfrog");
  EXPECT_THROW(run_study(o), std::invalid_argument);
  EXPECT_FALSE(fs::exists(fs::path(dir) / "window" / "em-galpha_dt=0.01"));
  EXPECT_THROW(study_preset("no-such-benchmark"), std::invalid_argument);
  fs::remove_all(dir);
}

TEST(Study, RunJsonFields) {
  const std::string json = "{\n  \"status\": \"complete\",\n  \"case\": {\"steps\": 7},\n  \"summary\": {\n    \"steps\": 42,\n"
                           "    \"cpu_s\": 1.5e-3\n  }\n}\n";
  EXPECT_EQ(run_json_status(json), "complete");
  EXPECT_DOUBLE_EQ(run_json_number(json, "steps"), 42.0);  // the summary's, not the case's
  EXPECT_DOUBLE_EQ(run_json_number(json, "cpu_s"), 1.5e-3);
  EXPECT_TRUE(std::isnan(run_json_number(json, "wall_s")));
}

}  // namespace
}  // namespace shelldyn
