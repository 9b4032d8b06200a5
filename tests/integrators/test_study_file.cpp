// Study files (integrators/runs/study_file.cpp, docs/reference/study-files.md): the shipped ones describe
// today's three benchmark studies; bad files fail with FILE:LINE: key: reason; methods are any registered
// integrator, with per-method sweeps, and the run plan (dry run) follows the file.
#include "integrators/runs/registry.hpp"
#include "integrators/runs/study.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace shelldyn {
namespace {

namespace fs = std::filesystem;

const std::string kCases = std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases";
const std::string kStudies = std::string(SHELLDYN_SOURCE_DIR) + "/apps/studies";

StudyPreset parse(const std::string& text) { return load_study_from_string(text, "s.yaml", kCases); }

// The message of the std::invalid_argument that loading `text` throws ("" if none).
std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

const std::string kHead = "case: flying-plate.yaml\nwindow: {t_end: 0.04, dt: [0.01], rtol: [1e-4]}\n";

bool registered(const std::string& name) {
  const auto n = integrator_names();
  return std::find(n.begin(), n.end(), name) != n.end();
}

// The labels a study plans, in order (a dry run: nothing runs, nothing is written).
std::vector<std::string> planned(const StudyPreset& p, const std::vector<std::string>& groups) {
  StudyOptions o;
  o.preset = p;
  o.case_path = p.case_path.empty() ? kCases + "/" + p.case_file : p.case_path;
  o.out_dir = testing::TempDir() + "/shelldyn-study-file-plan";
  o.groups = groups;
  o.dry_run = true;
  std::vector<std::string> labels;
  for (const auto& r : run_study(o).rows) labels.push_back(r.group + "/" + r.label + "/" + r.kind);
  return labels;
}

// The shipped flying-plate study plans exactly the runs of the study preset it replaces (the table that was
// compiled into study.cpp): reference, adaptive methods by rtol ascending, fixed-step methods by dt ascending;
// full: the baseline, then every fixed-step method at the case's dt.
TEST(StudyFile, ShippedFlyingPlatePlansTodaysRuns) {
  const StudyPreset p = load_study_file(kStudies + "/flying-plate.yaml");
  EXPECT_EQ(p.name, "flying-plate");
  EXPECT_EQ(fs::path(p.case_path).filename(), "flying-plate.yaml");
  EXPECT_DOUBLE_EQ(p.window_t_end, 0.5);
  EXPECT_DOUBLE_EQ(p.window_output, 0.005);
  EXPECT_EQ(p.reference_spec, "em-galpha:dt=0.000125");
  EXPECT_DOUBLE_EQ(p.full_dt, 0.0);
  EXPECT_LT(p.full_t_end, 0.0);
  std::vector<std::string> fixed = {"em-galpha", "galpha:rho_inf=1", "galpha:rho_inf=0.8", "midpoint", "newmark"};
  if (registered("em-exact")) fixed.insert(fixed.begin() + 1, "em-exact");
  std::vector<std::string> expected = {"window/em-galpha_dt=0.000125/reference"};
  for (const char* r : {"1e-06", "1e-05", "0.0001", "0.001"})
    for (const char* a : {"ida-bdf", "arkode-dirk", "arkode-erk"}) expected.push_back(std::string("window/") + a + "_rtol=" + r + "/adaptive");
  auto label = [](std::string spec) {
    std::replace(spec.begin(), spec.end(), ':', '_');
    return spec;
  };
  for (const char* dt : {"0.0005", "0.001", "0.002", "0.004"})
    for (const auto& f : fixed) expected.push_back("window/" + label(f) + "_dt=" + dt + "/fixed");
  expected.push_back("full/ida-bdf_rtol=0.0001_atol=1e-06/baseline");
  for (const auto& f : fixed) expected.push_back("full/" + label(f) + "/fixed");
  EXPECT_EQ(planned(p, {"window", "full"}), expected);
}

TEST(StudyFile, ShippedStudiesLoad) {
  for (const char* name : {"flying-plate", "cylindrical-panel", "pinched-hemisphere"}) {
    const StudyPreset p = load_study_file(kStudies + "/" + name + ".yaml");
    EXPECT_EQ(p.name, name);
    EXPECT_FALSE(p.case_path.empty()) << name;
    EXPECT_EQ(p.methods.size(), registered("em-exact") ? 9u : 8u) << name;
    EXPECT_EQ(p.full_baselines, std::vector<std::string>{"ida-bdf:rtol=0.0001:atol=1e-06"}) << name;
  }
  const StudyPreset h = load_study_file(kStudies + "/pinched-hemisphere.yaml");
  EXPECT_DOUBLE_EQ(h.full_dt, 1.25e-3);
  EXPECT_DOUBLE_EQ(h.full_output, 1.25e-3);
  EXPECT_EQ(h.reference_spec, "em-galpha:dt=1.5625e-05");
}

// Per-method sweeps and groups, map-form methods, full.t_end, headline; the plan follows them.
TEST(StudyFile, MethodsWithTheirOwnSweepsAndSettings) {
  const StudyPreset p = parse(
      "name: mine\ncase: flying-plate.yaml\n"
      "window: {t_end: 0.04, output_interval: 0.01, dt: [0.01, 0.005], rtol: [1e-4], reference: {name: em-galpha, dt: 0.00125}}\n"
      "methods:\n"
      "  - {name: galpha, settings: {rho_inf: 0.8}, dt: [0.02, 0.01]}\n"
      "  - {name: newmark, full: false}\n"
      "  - {name: ida-bdf, rtol: [1e-3, 1e-5]}\n"
      "  - {name: em-galpha, window: false}\n"
      "full: {t_end: 0.1, runs: [{name: ida-bdf, settings: {rtol: 1e-4}}]}\n"
      "headline: [galpha]\n");
  EXPECT_EQ(p.name, "mine");
  ASSERT_EQ(p.methods.size(), 4u);
  EXPECT_EQ(p.methods[0].spec, "galpha:rho_inf=0.8");
  EXPECT_FALSE(p.methods[0].adaptive);
  EXPECT_EQ(p.methods[0].sweep, (std::vector<double>{0.02, 0.01}));
  EXPECT_EQ(p.methods[1].sweep, (std::vector<double>{0.01, 0.005}));  // window.dt
  EXPECT_TRUE(p.methods[2].adaptive);
  EXPECT_FALSE(p.methods[2].full);
  EXPECT_EQ(p.reference_spec, "em-galpha:dt=0.00125");
  EXPECT_DOUBLE_EQ(p.full_t_end, 0.1);
  EXPECT_EQ(p.full_baselines, std::vector<std::string>{"ida-bdf:rtol=1e-4"});
  EXPECT_EQ(p.headline, std::vector<std::string>{"galpha"});
  const std::vector<std::string> expected = {
      "window/em-galpha_dt=0.00125/reference",   "window/ida-bdf_rtol=1e-05/adaptive",   "window/ida-bdf_rtol=0.001/adaptive",
      "window/newmark_dt=0.005/fixed",           "window/galpha_rho_inf=0.8_dt=0.01/fixed", "window/newmark_dt=0.01/fixed",
      "window/galpha_rho_inf=0.8_dt=0.02/fixed", "full/ida-bdf_rtol=1e-4/baseline",       "full/galpha_rho_inf=0.8/fixed",
      "full/em-galpha/fixed"};
  EXPECT_EQ(planned(p, {"window", "full"}), expected);
}

TEST(StudyFile, AddedMethodJoinsTheSweepAndTheFullRuns) {
  StudyPreset p = parse(kHead + "methods: [em-galpha]\nfull:\n");
  add_study_method(p, "galpha:rho_inf=0.5", "--add-method 'galpha:rho_inf=0.5'");
  add_study_method(p, "arkode-erk", "--add-method 'arkode-erk'");
  ASSERT_EQ(p.methods.size(), 3u);
  EXPECT_EQ(p.methods[1].sweep, std::vector<double>{0.01});
  EXPECT_TRUE(p.methods[1].full);
  EXPECT_EQ(p.methods[2].sweep, std::vector<double>{1e-4});
  EXPECT_FALSE(p.methods[2].full);
  try {
    add_study_method(p, "leapfrog", "--add-method 'leapfrog'");
    FAIL() << "an unknown integrator was added";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--add-method 'leapfrog': unknown integrator 'leapfrog' (check the spelling; registered ones below)\nvalid: ", 0), 0u) << e.what();
  }
  try {
    add_study_method(p, "galpha:rho_inff=0.5", "--add-method 'galpha:rho_inff=0.5'");
    FAIL() << "an unknown setting was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--add-method 'galpha:rho_inff=0.5': setting 'rho_inff': unknown setting for integrator 'galpha'"),
              std::string::npos)
        << e.what();
  }
  EXPECT_NE(std::string([&] {
              try {
                add_study_method(p, "em-galpha", "--add-method 'em-galpha'");
              } catch (const std::invalid_argument& e) {
                return std::string(e.what());
              }
              return std::string();
            }())
                .find("the same method as the entry at s.yaml:3"),
            std::string::npos);
}

// A reference that is also a sweep run: the same label twice, refused before any run with the study file named.
TEST(StudyFile, ReferenceRepeatingASweepRunIsRefused) {
  const StudyPreset p = parse("case: flying-plate.yaml\nwindow: {t_end: 0.04, dt: [0.01], reference: em-galpha:dt=0.01}\nmethods: [em-galpha]\n");
  try {
    planned(p, {"window"});
    FAIL() << "the repeated run was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("s.yaml: window: run 'em-galpha_dt=0.01' is listed twice (the reference, a sweep value", 0), 0u) << e.what();
  }
}

TEST(StudyFile, OptionalMethodOfAnotherBuildIsLeftOut) {
  const StudyPreset p = parse(kHead + "methods: [em-galpha, {name: no-such-scheme, optional: true}]\nheadline: [no-such-scheme]\n");
  ASSERT_EQ(p.methods.size(), 1u);
  EXPECT_EQ(p.methods[0].integrator, "em-galpha");
  EXPECT_FALSE(p.has_full);
}

// Every error names the file, the line and the key, and says what is allowed (one line; the registry adds an
// second line "valid: ..." listing the valid settings, which the command line prints indented).
TEST(StudyFile, ErrorsNameFileLineAndKey) {
  struct Case {
    std::string text, message;
  };
  const std::vector<Case> cases = {
      {"case: flying-plate.yaml\nmethods: [em-galpha]\nwindw: {t_end: 1}\n",
       "s.yaml:3: windw: unknown key 'windw' (allowed here: name, case, note, window, methods, full, headline)"},
      {"methods: [em-galpha]\nwindow: {t_end: 1}\n", "s.yaml:1: case: missing required key 'case' (add it)"},
      {kHead + "methods: [em-galpha, leapfrog]\n", "s.yaml:3: methods[1]: unknown integrator 'leapfrog' (check the spelling; registered ones below)"},
      {kHead + "methods:\n  - {name: leapfrog}\n", "s.yaml:4: methods[0].name: unknown integrator 'leapfrog' (check the spelling; registered ones below)"},
      {kHead + "methods:\n  - name: galpha\n    settings:\n      rho_inf: 0.8\n      frobnicate: 1\n",
       "s.yaml:7: methods[0].settings.frobnicate: unknown setting for integrator 'galpha'"},
      {kHead + "methods:\n  - name: galpha\n    settings: {rho_inf: 2}\n", "s.yaml:5: methods[0].settings.rho_inf: "},
      {kHead + "methods: [em-galpha:frobnicate=1]\n", "s.yaml:3: methods[0]: setting 'frobnicate': unknown setting for integrator 'em-galpha'"},
      {kHead + "methods: [em-galpha:dt=1e-3]\n", "s.yaml:3: methods[0]: 'em-galpha:dt=1e-3': dt is swept here, not part of a method"},
      {kHead + "methods:\n  - {name: ida-bdf, dt: [1e-3]}\n", "s.yaml:4: methods[0].dt: 'ida-bdf' is adaptive (it has an rtol setting): sweep it with rtol"},
      {kHead + "methods:\n  - {name: newmark, rtol: [1e-3]}\n", "s.yaml:4: methods[0].rtol: 'newmark' is a fixed-step integrator (no rtol setting)"},
      {kHead + "methods:\n  - {name: newmark, dt: [1e-3, -1]}\n", "s.yaml:4: methods[0].dt[1]: must be a finite number > 0, got -1"},
      {kHead + "methods:\n  - {name: newmark, dt: [1e-3, 1e-3]}\n", "s.yaml:4: methods[0].dt[1]: value 1e-3 is listed twice"},
      {kHead + "methods:\n  - {name: newmark, sweep: [1e-3]}\n", "s.yaml:4: methods[0].sweep: unknown key 'sweep' (allowed here: name, settings, dt, rtol, window, full, optional)"},
      {kHead + "methods: [newmark, newmark]\n", "s.yaml:3: methods[1]: the same method as the entry at s.yaml:3 ('newmark')"},
      {kHead + "methods: [static]\n", "s.yaml:3: methods[0]: 'static' is the static solver, not a time integrator"},
      {kHead + "methods: []\n", "s.yaml:3: methods: expected a non-empty list of methods"},
      {"case: flying-plate.yaml\nwindow: {t_end: 0.04}\nmethods: [em-galpha]\n", "s.yaml:3: methods[0]: no dt values to sweep: give window.dt or this method's own dt: [...]"},
      {"case: flying-plate.yaml\nwindow: {t_end: zero}\nmethods: [em-galpha]\n", "s.yaml:2: window.t_end: expected a number > 0, got 'zero'"},
      {kHead + "methods: [em-galpha]\nwindow2: 1\n", "s.yaml:4: window2: unknown key 'window2'"},
      {"case: flying-plate.yaml\nwindow: {t_end: 0.04, dt: [0.01], reference: ida-bdf}\nmethods: [em-galpha]\n",
       "s.yaml:2: window.reference: the reference must be a fixed-step integrator with its dt ('ida-bdf' is adaptive)"},
      {"case: flying-plate.yaml\nwindow: {t_end: 0.04, dt: [0.01], reference: em-galpha}\nmethods: [em-galpha]\n",
       "s.yaml:2: window.reference: the reference needs its dt"},
      {kHead + "methods: [em-galpha]\nfull: {runs: [ida-bdf:rtol=-1]}\n", "s.yaml:4: full.runs[0]: "},
      {kHead + "methods:\n  - {name: ida-bdf, full: true}\nfull:\n", "s.yaml:4: methods[0].full: 'ida-bdf' is adaptive: a full-duration run needs its tolerance"},
      {kHead + "methods: [em-galpha]\nheadline: [newmark]\n", "s.yaml:4: headline[0]: 'newmark' is not the integrator of any method of this study (methods: em-galpha)"},
      {"case: /no/such/case.yaml\nwindow: {t_end: 1, dt: [0.1]}\nmethods: [em-galpha]\n", "s.yaml:1: case: cannot open the case file '/no/such/case.yaml'"},
      {"case: flying-plate.yaml\nmethods: [em-galpha]\n", "s.yaml:1: window: a study needs a window: section, a full: section or both"},
      {"case: flying-plate.yaml\nmethods: [em-galpha\n", "s.yaml:3: YAML syntax error"},
  };
  for (const auto& c : cases) {
    const std::string got = error_of(c.text);
    EXPECT_EQ(got.rfind(c.message, 0), 0u) << "file:\n" << c.text << "\nexpected: " << c.message << "\ngot:      " << got;
    // One line, plus a "valid: ..." line where the registry lists the valid names.
    const auto newline = got.find('\n');
    if (newline != std::string::npos) {
      EXPECT_EQ(got.substr(newline + 1, 7), "valid: ") << got;
    }
    EXPECT_LE(std::count(got.begin(), got.end(), '\n'), 1) << got;
  }
}

}  // namespace
}  // namespace shelldyn
