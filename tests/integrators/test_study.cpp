// `shelldyn study` machinery (integrators/runs/study.hpp) on a tiny preset: the runs are made through
// run_comparisons(), measured from their folders, and a second call resumes (runs nothing that completed).
#include "integrators/runs/study.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace shelldyn {
namespace {

namespace fs = std::filesystem;

// The flying plate's study shrunk to a few cheap runs, as a study file (docs/reference/study-files.md).
const char* kTinyStudy = R"(name: flying-plate-tiny
case: flying-plate.yaml
window:
  t_end: 0.04
  output_interval: 0.01
  dt: [0.01, 0.005]
  rtol: [1e-4]
  reference: em-galpha:dt=0.00125
methods: [em-galpha, ida-bdf]
full:
)";

StudyOptions tiny_study(const std::string& dir) {
  StudyOptions o;
  o.preset = load_study_from_string(kTinyStudy, "tiny.yaml", std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases");
  o.case_path = o.preset.case_path;
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

std::string file_text(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A per-run step budget: runs that hit it are "stopped at budget" rows with the time they reached (never
// complete, never failed), the others complete; a stopped reference measures nothing; resuming with the same
// budget keeps them, without a budget they run again to the end.
TEST(Study, StoppedAtBudgetIsReportedWithTheTimeReached) {
  const std::string dir = testing::TempDir() + "/shelldyn-study-budget";
  fs::remove_all(dir);
  StudyOptions o = tiny_study(dir);
  o.max_steps_per_run = 6;  // checked at the output times 0.01, 0.02, 0.03 (the last one, 0.04, completes the run)
  const StudyResult first = run_study(o);
  EXPECT_EQ(first.failed, 0);
  EXPECT_EQ(first.stopped, 3);
  const StudyRow& coarse = row(first, "em-galpha_dt=0.01");  // 4 steps: below the budget
  EXPECT_EQ(coarse.status, "complete");
  EXPECT_NEAR(coarse.t_reached, 0.04, 1e-12);
  EXPECT_TRUE(std::isnan(coarse.displacement_error));  // the reference did not complete
  const StudyRow& fine = row(first, "em-galpha_dt=0.005");  // 2 steps per output: 6 at t = 0.03
  EXPECT_EQ(fine.status, "stopped at budget");
  EXPECT_EQ(fine.steps, 6);
  EXPECT_NEAR(fine.t_reached, 0.03, 1e-12);
  EXPECT_NE(fine.stop_note.find("--max-steps 6"), std::string::npos) << fine.stop_note;
  EXPECT_TRUE(std::isnan(fine.energy_error));
  EXPECT_EQ(row(first, "em-galpha_dt=0.00125").status, "stopped at budget");
  EXPECT_NEAR(row(first, "em-galpha_dt=0.00125").t_reached, 0.01, 1e-12);
  EXPECT_EQ(row(first, "ida-bdf_rtol=0.0001").status, "stopped at budget");
  const std::string md = file_text(first.study_md);
  EXPECT_NE(md.find("per-run budget: 6 steps"), std::string::npos);
  EXPECT_NE(md.find("**stopped at budget** (stopped: --max-steps 6 reached), t reached = 0.03 of 0.04 s"), std::string::npos) << md;
  EXPECT_EQ(md.find("No baseline"), std::string::npos);
  const std::string csv = file_text(first.study_csv);
  EXPECT_NE(csv.find(",stopped at budget (stopped: --max-steps 6 reached)\n"), std::string::npos) << csv;

  const StudyResult again = run_study(o);  // same budget: nothing runs
  EXPECT_EQ(again.ran, 0);
  EXPECT_EQ(again.skipped, 4);
  EXPECT_EQ(again.stopped, 3);

  // Report only: nothing runs (not even the stopped runs, which a call without a budget would repeat); a run
  // whose run.json still says "running" (the study was killed during it) is "not run", not failed.
  {
    StudyOptions r = o;
    r.max_steps_per_run = 0;
    r.report_only = true;
    const std::string ref_json = (fs::path(dir) / "window" / "em-galpha_dt=0.00125" / "run.json").string();
    std::string text = file_text(ref_json);
    text.replace(text.find("stopped: --max-steps"), 20, "incomplete: running ");
    std::ofstream(ref_json) << text;
    const StudyResult report = run_study(r);
    EXPECT_EQ(report.ran, 0);
    EXPECT_EQ(report.failed, 0);
    EXPECT_EQ(report.stopped, 2);
    EXPECT_EQ(row(report, "em-galpha_dt=0.00125").status, "not run (the study was stopped during this run)");
    EXPECT_EQ(row(report, "em-galpha_dt=0.005").status, "stopped at budget");
    EXPECT_NE(file_text(report.study_md).find("not run (the study was stopped during this run)"), std::string::npos);
  }

  o.max_steps_per_run = 0;  // no budget: the three stopped runs run again, to the end
  const StudyResult last = run_study(o);
  EXPECT_EQ(last.ran, 3);
  EXPECT_EQ(last.stopped, 0);
  for (const auto& r : last.rows) EXPECT_EQ(r.status, "complete") << r.label;
  EXPECT_GT(row(last, "em-galpha_dt=0.01").displacement_error, 0.0);
  fs::remove_all(dir);
}

TEST(Study, StoppedBudgetParsing) {
  EXPECT_EQ(stopped_budget("stopped: --max-wall 300 s reached at t = 0.1 of 1 (step 7)"),
            (std::pair<std::string, double>{"max-wall", 300.0}));
  EXPECT_EQ(stopped_budget("stopped: --max-steps 6 reached at t = 0.03 of 0.04 (step 6)"),
            (std::pair<std::string, double>{"max-steps", 6.0}));
  EXPECT_EQ(stopped_budget("complete").first, "");
  EXPECT_EQ(stopped_budget("interrupted: SIGINT at t = 1").first, "");
}

// The window and full groups go to the executor as ONE batch (run_comparisons), so the full group's long
// baseline run starts first and overlaps the window's runs instead of running alone at the end. A recording
// executor runs nothing: it checks what it is handed and reports every run as not run.
class RecordingExecutor final : public RunExecutor {
 public:
  std::vector<std::vector<RunJob>> batches;
  std::vector<RunOutcome> execute(const std::vector<RunJob>& jobs, const RunFunction&, const OutcomeCallback& on_outcome,
                                  std::ostream*) override {
    batches.push_back(jobs);
    std::vector<RunOutcome> out(jobs.size());
    for (size_t k = 0; k < jobs.size(); ++k) {
      out[k].status = "failed: not run (recording executor)";
      if (on_outcome) on_outcome(k, out[k], k + 1 < jobs.size());
    }
    return out;
  }
  int workers() const override { return 2; }
  std::string describe() const override { return "recording executor"; }
};

TEST(Study, WindowAndFullGroupsAreOneBatchLongestFirst) {
  const std::string dir = testing::TempDir() + "/shelldyn-study-batch";
  fs::remove_all(dir);
  StudyOptions o = tiny_study(dir);
  o.groups = {"window", "full"};
  o.preset.full_baselines = {"ida-bdf:rtol=0.0001"};
  RecordingExecutor rec;
  o.execution.executor = &rec;
  const StudyResult r = run_study(o);
  ASSERT_EQ(rec.batches.size(), 1u);  // one batch, not one per group
  const std::vector<RunJob>& jobs = rec.batches.front();
  ASSERT_EQ(jobs.size(), 6u);        // window: 2 em-galpha + reference + ida-bdf; full: em-galpha + ida-bdf
  int window = 0, full = 0;
  for (const auto& j : jobs) {
    window += j.label.rfind("flying-plate-tiny/window/", 0) == 0;  // log labels: preset/group/run
    full += j.label.rfind("flying-plate-tiny/full/", 0) == 0;
  }
  EXPECT_EQ(window, 4);
  EXPECT_EQ(full, 2);
  // The 20 s baseline run is the longest expected and starts first.
  EXPECT_EQ(jobs[longest_first(jobs).front()].label, "flying-plate-tiny/full/ida-bdf_rtol=0.0001");
  EXPECT_EQ(r.ran, 6);
  for (const auto& x : r.rows) EXPECT_NE(x.status, "complete") << x.label;

  // Two studies (`shelldyn study all`): still one batch, each study reporting its own rows.
  StudyOptions o2 = o;
  o2.preset.name = "flying-plate-tiny-2";
  o2.out_dir = dir + "-2";
  const std::vector<StudyResult> both = run_studies({o, o2});
  ASSERT_EQ(rec.batches.size(), 2u);  // the first call's batch + exactly one more
  EXPECT_EQ(rec.batches.back().size(), 12u);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].rows.size(), 6u);
  EXPECT_EQ(both[1].rows.size(), 6u);
  EXPECT_EQ(both[1].ran, 6);
  fs::remove_all(dir);
  fs::remove_all(dir + "-2");
}

TEST(Study, BadPresetFailsBeforeAnyRun) {
  const std::string dir = testing::TempDir() + "/shelldyn-study-bad";
  fs::remove_all(dir);
  StudyOptions o = tiny_study(dir);
  StudyMethod bad = o.preset.methods.front();
  bad.spec = bad.integrator = "leapfrog";  // not registered: compare's check refuses it before any run
  o.preset.methods.push_back(bad);
  EXPECT_THROW(run_study(o), std::invalid_argument);
  EXPECT_FALSE(fs::exists(fs::path(dir) / "window" / "em-galpha_dt=0.01"));
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
