// Statics that never step over a limit point silently (docs/guide/statics-limit-points.md): the pull-out
// cylinder of Sze, Liu & Lo (2004) §3.5 with the case file's default increment, displacement control
// over its snap, the "path jump" warning of a step that may not be cut, progress lines inside long steps,
// and ramp loads traced through negative load factors (the thin hinged roof of Sze §3.8).
#include "integrators/runs/static_run.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace shelldyn {
namespace {

std::string case_path(const std::string& name) { return std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/" + name; }

// Sze's S4R curve (24 x 36 mesh, MBDyn's transcription): P/P_max, W_A, -U_B, -U_C.
struct SzeRow {
  double lambda, w_a, u_b, u_c;
};
const SzeRow kSze35[] = {
    {0.05, 1.260, 1.471, 1.493}, {0.10, 1.707, 2.217, 2.293}, {0.20, 2.079, 2.904, 3.106}, {0.30, 2.257, 3.227, 3.452},
    {0.40, 2.376, 3.443, 3.632}, {0.45, 2.425, 3.539, 3.688}, {0.55, 2.577, 4.171, 3.518}, {0.60, 2.618, 4.274, 3.452},
    {0.70, 2.672, 4.385, 3.378}, {0.80, 2.710, 4.455, 3.332}, {0.90, 2.741, 4.508, 3.297}, {1.00, 2.768, 4.551, 3.269},
};

std::vector<const CriticalPoint*> points_of_kind(const StaticReport& rep, const std::string& kind) {
  std::vector<const CriticalPoint*> out;
  for (const auto& cp : rep.critical_points)
    if (cp.kind == kind) out.push_back(&cp);
  return out;
}

// Monitor j of the rows interpolated at load factor lam on the monotone stretch rows[a..b].
double at_lambda(const std::vector<StaticRow>& rows, size_t a, size_t b, double lam, size_t j) {
  for (size_t k = a; k < b; ++k)
    if (rows[k].load_factor <= lam && rows[k + 1].load_factor >= lam) {
      const double t = (lam - rows[k].load_factor) / (rows[k + 1].load_factor - rows[k].load_factor);
      return rows[k].monitors[j] + t * (rows[k + 1].monitors[j] - rows[k].monitors[j]);
    }
  return std::nan("");
}

TEST(LimitPoints, PullOutCylinderSnapIsTracedWithTheDefaultIncrement) {
  // The case file as shipped: arc length with the default increment (time.dt = 0.025). The snap near
  // P/P_max = 0.5 is a narrow loop: a maximum 0.500383, then a minimum 0.487875, as located with increment
  // 0.001 and max_arc_factor 1 (108 steps). Before the step control of the turning tangent and the
  // location by bisection, the default increment jumped over it with no event.
  Problem p = make_problem(load_case(case_path("sze-pullout-cylinder.yaml")));
  StaticReport rep;
  const auto rows = run_static(p, "", nullptr, &rep);
  for (const auto& cp : rep.critical_points) std::printf("  %s\n", cp.note.c_str());
  const auto limits = points_of_kind(rep, "limit point");
  ASSERT_EQ(limits.size(), 2u) << "the snap of the pull-out cylinder was stepped over";
  EXPECT_EQ(rep.critical_points.size(), 2u);
  EXPECT_NEAR(limits[0]->estimate, 0.500383, 1e-4);  // the maximum
  EXPECT_NEAR(limits[1]->estimate, 0.487875, 1e-4);  // the minimum
  EXPECT_EQ(limits[0]->pivots_before, 0);
  EXPECT_EQ(limits[0]->pivots_after, 1);
  EXPECT_EQ(limits[1]->pivots_after, 0);
  EXPECT_NEAR(rows.back().load_factor, 1.0, 1e-12);
  // Against Sze's curve: the branch before the maximum and the branch after the minimum. Measured (8 x 12
  // CR9; Sze's mesh is 24 x 36 S4R): at most 3.2 % at these levels.
  size_t k_max = 0, k_min = 0;
  for (size_t k = 0; k < rows.size(); ++k) {
    if (rows[k].step == limits[0]->step) k_max = k;
    if (rows[k].step == limits[1]->step) k_min = k;
  }
  ASSERT_GT(k_min, k_max);
  double worst = 0.0;
  for (const auto& s : kSze35) {
    const bool before = s.lambda < 0.5;
    const size_t a = before ? 0 : k_min, b = before ? k_max : rows.size() - 1;
    const double ours[3] = {at_lambda(rows, a, b, s.lambda, 0), -at_lambda(rows, a, b, s.lambda, 1), -at_lambda(rows, a, b, s.lambda, 2)};
    const double ref[3] = {s.w_a, s.u_b, s.u_c};
    for (int j = 0; j < 3; ++j) {
      ASSERT_TRUE(std::isfinite(ours[j])) << "no point of the path brackets P/P_max " << s.lambda;
      worst = std::max(worst, std::abs(ours[j] - ref[j]) / ref[j]);
    }
  }
  std::printf("pull-out 8x12: %d steps, %d Newton iterations, %d steps cut back; max relative error vs Sze %.4f\n", rep.levels,
              rep.newton_iterations, rep.located_cuts, worst);
  EXPECT_LT(worst, 0.05);
}

TEST(LimitPoints, DisplacementControlOverTheSnapFindsLimitPointsNotABifurcation) {
  // Displacement control of W_A with 0.03 steps: W_A grows monotonically through the loop, so λ has a
  // maximum and a minimum inside single steps. It used to report the inertia change as a "bifurcation point".
  CaseSpec spec = load_case(case_path("sze-pullout-cylinder.yaml"));
  spec.integrator.settings = {{"control", "displacement"}, {"control_set", "corner_x0_arc0"}, {"control_dof", "uz"},
                              {"increment", "0.03"}, {"displacement_end", "2.6"}};
  Problem p = make_problem(spec);
  StaticReport rep;
  const auto rows = run_static(p, "", nullptr, &rep);
  for (const auto& cp : rep.critical_points) std::printf("  %s\n", cp.note.c_str());
  EXPECT_TRUE(points_of_kind(rep, "bifurcation point").empty());
  const auto limits = points_of_kind(rep, "limit point");
  ASSERT_EQ(limits.size(), 2u);
  EXPECT_NEAR(limits[0]->estimate, 0.500383, 1e-4);  // the same limit loads as arc length finds
  EXPECT_NEAR(limits[1]->estimate, 0.487875, 1e-4);
  EXPECT_NEAR(rows.back().monitors[0], 2.6, 1e-9);
}

TEST(LimitPoints, AStepThatMayNotBeCutIsReportedAsAPathJump) {
  // locate_tol = 1 and max_arc_factor = 1: no step may be shorter or longer than the first, so the
  // sharp turn of the path at the snap cannot be resolved. The step that jumps is reported, not silent.
  CaseSpec spec = load_case(case_path("sze-pullout-cylinder.yaml"));
  spec.integrator.settings = {{"control", "arc_length"}, {"locate_tol", "1"}, {"max_arc_factor", "1"}};
  Problem p = make_problem(spec);
  StaticReport rep;
  const auto rows = run_static(p, "", nullptr, &rep);
  for (const auto& cp : rep.critical_points) std::printf("  %s\n", cp.note.c_str());
  const auto jumps = points_of_kind(rep, "path jump");
  ASSERT_FALSE(jumps.empty()) << "a step turned sharply and nothing was reported";
  EXPECT_NE(jumps[0]->note.find("degrees within one step"), std::string::npos) << jumps[0]->note;
  EXPECT_GT(jumps[0]->load_factor, 0.4);
  bool flagged = false;
  for (const auto& r : rows) flagged = flagged || r.event.find("path jump") != std::string::npos;
  EXPECT_TRUE(flagged);  // static.csv's event column
}

TEST(LimitPoints, EulerColumnIsABifurcationPointAtItsBucklingLoad) {
  // The Sze 3.1 strip (EI = 100, L = 10, clamped) under an axial end force P_max = 4: the straight path
  // stays straight and λ keeps rising, while the tangent gets a negative pivot at the Euler load
  // P_cr = π² EI / (4 L²) = 2.4674, λ = π²/16 = 0.61685. A bifurcation point, located, not a limit point.
  CaseSpec spec = load_case(case_path("sze-cantilever-shear.yaml"));
  spec.loads[0].direction = Vec3(-1.0, 0.0, 0.0);
  spec.integrator.settings = {{"control", "arc_length"}};
  spec.output.vtu = false;
  Problem p = make_problem(spec);
  StaticReport rep;
  const auto rows = run_static(p, "", nullptr, &rep);
  for (const auto& cp : rep.critical_points) std::printf("  %s\n", cp.note.c_str());
  ASSERT_EQ(rep.critical_points.size(), 1u);
  EXPECT_EQ(rep.critical_points[0].kind, "bifurcation point");
  const double euler = 3.14159265358979323846 * 3.14159265358979323846 / 16.0;
  EXPECT_NEAR(rep.critical_points[0].estimate, euler, 0.005 * euler);  // measured 0.616637 (-0.03 %)
  EXPECT_NEAR(rows.back().load_factor, 1.0, 1e-12);
  EXPECT_EQ(rows.back().negative_pivots, 1);
}

TEST(LimitPoints, ArcLengthFollowsRampLoadsBelowZero) {
  // The thin hinged roof (Sze §3.8, h = 6.35, P/4 = 250 at P_max) snaps back below P = 0: a ramp is zero
  // for λ < 0, which left the arc length without a load to follow (18 failed attempts and a false
  // minimum at −0.115). Ramps are extended as odd functions (a reversed load).
  CaseSpec spec = load_case(case_path("sze-hinged-roof.yaml"));
  spec.material.thickness = 6.35;
  spec.loads[0].amplitude = 250.0;
  Problem p = make_problem(spec);
  StaticReport rep;
  const auto rows = run_static(p, "", nullptr, &rep);
  for (const auto& cp : rep.critical_points) std::printf("  %s\n", cp.note.c_str());
  double lam_min = 0.0;
  for (const auto& r : rows) lam_min = std::min(lam_min, r.load_factor);
  EXPECT_EQ(rep.failed_attempts, 0);
  EXPECT_NEAR(rows.back().load_factor, 1.0, 1e-12);
  EXPECT_LT(lam_min, -0.3);  // measured -0.386 (4 x 4 CR9)
  const auto limits = points_of_kind(rep, "limit point");
  ASSERT_EQ(limits.size(), 2u);
  EXPECT_NEAR(limits[1]->estimate, lam_min, 1e-3);
  EXPECT_LT(limits[1]->estimate, -0.3);
}

TEST(LimitPoints, ZeroLoadPatternIsNamedNotCalledALimitPoint) {
  // A table load that stops changing at t = 0.5: arc length has nothing to follow past it, and says so
  // instead of "a limit or bifurcation point is near".
  CaseSpec spec = load_case(case_path("sze-hinged-roof.yaml"));
  spec.loads[0].function = TimeFunction::table({{0.0, 0.0}, {0.5, 0.5}, {2.0, 0.5}});
  spec.time.t_end = 1.0;
  Problem p = make_problem(spec);
  try {
    run_static(p, "", nullptr);
    FAIL() << "expected an error: the load stops changing at t = 0.5";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("load pattern"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("limit or bifurcation point is near"), std::string::npos) << msg;
  }
}

TEST(StaticProgress, LongStepsPrintProgressLines) {
  // progress_seconds: 0 prints a line after every Newton iteration of every step (the default, 5 s, keeps a
  // 48 x 48 pinched cylinder from printing nothing for minutes).
  CaseSpec spec = load_case(case_path("sze-hinged-roof.yaml"));
  spec.integrator.settings = {{"control", "load"}, {"increment", "0.1"}, {"progress_seconds", "0"}};
  spec.time.t_end = 0.2;
  Problem p = make_problem(spec);
  std::ostringstream log;
  run_static(p, "", &log);
  const std::string text = log.str();
  EXPECT_NE(text.find("... step 1: Newton iteration 1, |R| = "), std::string::npos) << text;
  EXPECT_NE(text.find("... step 2: Newton iteration"), std::string::npos) << text;
  // Bad values are refused with the setting's name.
  spec.integrator.settings = {{"progress_seconds", "-1"}};
  Problem q = make_problem(spec);
  try {
    run_static(q, "", nullptr);
    FAIL() << "expected an error for progress_seconds = -1";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("progress_seconds"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace shelldyn
