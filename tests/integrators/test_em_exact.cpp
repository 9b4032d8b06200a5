// em-exact (integrators/newmark/em_exact.hpp; docs/theory/exact-energy-momentum.md): exact discrete energy
// and momentum balances per step, for any Δt, through director chart switches, under loads, with symmetry
// planes, and a non-positive dissipation term when dissipative. Every conservation test also runs once with
// the element correction switched off (setting correction=false) and asserts that the check then fails.
#include "integrators/newmark/em_exact.hpp"
#include "integrators/runs/case_integrator.hpp"
#include "integrators/runs/registry.hpp"
#include "lib/model/problem.hpp"

#include "dynamics_fixtures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

namespace shelldyn {
namespace {

using testing::free_plate;
using testing::set_free_flight_velocity;
using testing::total_energy;

std::unique_ptr<Integrator> make(const std::string& name, double dt,
                                 std::vector<std::pair<std::string, std::string>> settings = {}) {
  IntegratorSettings s(name, std::move(settings));
  return make_integrator(s, dt);
}

struct Flight {
  double max_dH = 0, final_dH = 0, max_dJ = 0, max_dL = 0, max_increase = 0, max_strain = 0, max_balance = 0;
  long switches = 0, iterations = 0, steps = 0, residuals = 0, unevaluated_steps = 0, factorizations = 0;
  double dissipation = 0, min_step_dissipation = 0, max_residual = 0;
  double identity_gap = 0;  // |(H_end − H0) + D − Σ Δuᵀr| / H0: the energy change not explained by the residual
};

// Runs `steps` steps of `name` on model from state s; energies relative to K0 + V0. max_balance tracks
// |K + V + D − K0 − V0| / (K0 + V0) with D the dissipation em-exact reports (0 for other schemes).
Flight run(Model& model, State s, const std::string& name, double dt, int steps,
           std::vector<std::pair<std::string, std::string>> settings = {}) {
  auto integ = make(name, dt, std::move(settings));
  integ->initialize(model, s);
  const auto* diag = dynamic_cast<const EmExactDiagnostics*>(integ.get());
  const Invariants inv0 = model.invariants(s);
  const double H0 = total_energy(inv0);
  Flight r;
  double H_prev = H0;
  for (int k = 1; k <= steps; ++k) {
    const StepReport rep = integ->advance(model, s, k * dt);
    const Invariants inv = model.invariants(s);
    const double H = total_energy(inv);
    const double D = diag ? diag->diagnostics().dissipation : 0.0;
    r.max_dH = std::max(r.max_dH, std::abs(H - H0) / H0);
    r.max_balance = std::max(r.max_balance, std::abs(H + D - H0) / H0);
    r.max_dJ = std::max(r.max_dJ, (inv.J - inv0.J).norm() / inv0.J.norm());
    r.max_dL = std::max(r.max_dL, (inv.L - inv0.L).norm() / std::max(inv0.L.norm(), 1e-300));
    r.max_increase = std::max(r.max_increase, (H - H_prev) / H0);
    r.max_strain = std::max(r.max_strain, inv.strain / H);
    r.switches += rep.chart_switches;
    r.iterations += rep.nonlinear_iterations;
    r.residuals += rep.rhs_evaluations;
    r.factorizations += rep.factorizations;
    r.steps += rep.steps;
    r.final_dH = (H - H0) / H0;
    H_prev = H;
  }
  if (diag) {
    r.dissipation = diag->diagnostics().dissipation;
    r.min_step_dissipation = diag->diagnostics().min_step_dissipation;
    r.max_residual = diag->diagnostics().max_residual;
    r.unevaluated_steps = diag->diagnostics().unevaluated_steps;
    r.identity_gap = std::abs(r.final_dH * H0 + r.dissipation - diag->diagnostics().residual_work) / H0;
  }
  return r;
}

// docs/theory.md §7 item 12 plate (two 1×1 elements, h 0.1, ν 0.3, ρ 1) with its velocity field.
Flight fly(const std::string& name, double E, double dt, int steps, Eigen::Vector3d v0, Eigen::Vector3d w, double beta,
           std::vector<std::pair<std::string, std::string>> settings = {}) {
  auto model = free_plate(2.0, 1.0, 2, 1, ShellMaterial{E, 0.3, 1.0, 0.1});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, v0, w, beta);
  return run(*model, s, name, dt, steps, std::move(settings));
}

const Eigen::Vector3d kV0(0.1, 0.0, 0.2), kW(0.3, 0.5, 1.0);

// Full Newton (the paper's iteration; with it certify = auto is residual): every accepted iterate has its residual
// evaluated, which the identity check Σ Δuᵀr = ΔH needs. The default (modified Newton, certify = predicted) accepts
// most iterates unevaluated (docs/theory/newton-iteration.md §1).
const std::vector<std::pair<std::string, std::string>> kFullNewton = {{"newton", "full"}};

// Floor of the identity check: K + V and Σ Δuᵀr are sums of a few hundred terms evaluated every step, each
// with a relative rounding of a few ε; 4ε per step, accumulated linearly, bounds what they can agree to.
// With the correction off the gap is the scheme's own error (8.6e-8 on the free plate).
double round_off_bound(const Flight& r) { return 4.0 * 2.2e-16 * static_cast<double>(std::max(r.steps, 1L)); }

void print(const std::string& what, const Flight& r) {
  std::printf("%-42s max|dH|/H %.2e  max|dL|/|L| %.2e  max|dJ|/|J| %.2e  strain/H %.2e  %.2f it/step  %ld switches  res %.1e\n",
              what.c_str(), r.max_dH, r.max_dL, r.max_dJ, r.max_strain, double(r.iterations) / std::max(r.steps, 1L), r.switches,
              r.max_residual);
}

TEST(EmExact, FreePlateConservesEnergyAndMomentaForLargeSteps) {
  for (double dt : {0.02, 0.005}) {
    const Flight r = fly("em-exact", 1e6, dt, static_cast<int>(std::round(1.0 / dt)), kV0, kW, 0.5, kFullNewton);
    print(dt == 0.02 ? "free plate, dt 0.02, 1 s" : "free plate, dt 0.005, 1 s", r);
    print("  (em-galpha, same run)", fly("em-galpha", 1e6, dt, static_cast<int>(std::round(1.0 / dt)), kV0, kW, 0.5));
    EXPECT_LT(r.max_dH, 1e-10);
    EXPECT_LT(r.max_dL, 1e-12);  // ΔL = Δt Σ(translational residuals): at the solver residual
    EXPECT_LT(r.max_dJ, 1e-9);
    // Theory §4: the energy change is exactly the work of the Newton residual (EmExactDiagnostics).
    std::printf("  energy change not explained by the residual's work: %.1e of H\n", r.identity_gap);
    EXPECT_LT(r.identity_gap, round_off_bound(r));
  }
}

TEST(EmExact, WithoutTheCorrectionTheFreePlateIsNotExact) {
  const Flight off = fly("em-exact", 1e6, 0.02, 50, kV0, kW, 0.5, {{"correction", "false"}});
  print("free plate, correction off", off);
  EXPECT_GT(off.max_dH, 1e-8);
  // Without the correction the energy change is the scheme's error, not the residual's work.
  std::printf("  energy change not explained by the residual's work: %.1e of H\n", off.identity_gap);
  EXPECT_GT(off.identity_gap, 1e-8);
}

TEST(EmExact, StiffFreeFlightStaysExact) {
  // E = 1e9, Δt = 0.02 (bending modes far from resolved), 4 s; em-galpha drifts by 3.6e-4 here.
  const Flight r = fly("em-exact", 1e9, 0.02, 200, kV0, kW, 0.5);
  print("stiff free flight E 1e9, dt 0.02, 4 s", r);
  print("  (em-galpha, same run)", fly("em-galpha", 1e9, 0.02, 200, kV0, kW, 0.5));
  EXPECT_LT(r.max_dH, 1e-10);
  EXPECT_LT(r.max_dJ, 1e-9);
}

TEST(EmExact, ChartSwitchesAreExact) {
  // docs/theory.md §7.12 switching run (ω = (3, 0.4, 0.2), β = 0.3) at a 5x larger step: 1 s.
  const Flight r = fly("em-exact", 1e6, 0.01, 100, kV0, Eigen::Vector3d(3.0, 0.4, 0.2), 0.3);
  print("switching run, dt 0.01, 1 s", r);
  EXPECT_GE(r.switches, 30);
  EXPECT_LT(r.max_dH, 1e-10);
  EXPECT_LT(r.max_dJ, 1e-9);
  const Flight off = fly("em-exact", 1e6, 0.01, 100, kV0, Eigen::Vector3d(3.0, 0.4, 0.2), 0.3, {{"correction", "false"}});
  print("switching run, correction off", off);
  EXPECT_GT(off.max_dH, 1e-8);
}

// docs/benchmarks.md §6 plate (2 × 1, h 0.1, E 1e8, 4×2 mesh) tumbling about an axis 1 % off the intermediate one.
TEST(EmExact, TumblingStiffPlateShortRun) {
  auto model = free_plate(2.0, 1.0, 4, 2, ShellMaterial{1e8, 0.3, 1.0, 0.1});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.01, 1.0, 0.01), 0.0);
  const Flight r = run(*model, s, "em-exact", 0.01, 200, kFullNewton);
  print("tumbling plate, dt 0.01, 2 s", r);
  // 2.3e-13 measured; accepting the smallest-residual iterate at the floor instead of the last one gives a
  // one-signed drift of 2.5e-11 here (docs/theory/exact-energy-momentum.md §5.1).
  EXPECT_LT(r.max_dH, 5e-12);
  EXPECT_LT(r.max_dJ, 1e-9);
  EXPECT_LT(r.max_strain, 1e-6);
  // The energy identity of theory §4 on a stiff body: the energy change is the work of the Newton residual,
  // whose floor is set by the stored state (docs/theory/exact-energy-momentum.md §5.1). Measured gap over
  // these 200 steps: 1.0e-14 of H.
  std::printf("  energy change not explained by the residual's work: %.1e of H\n", r.identity_gap);
  EXPECT_LT(r.identity_gap, round_off_bound(r));
}

// Modified Newton (what the benchmark apps run: their cases ask for newton=modified): the trapezoidal
// predictor, refresh by contraction and the stall rule that accepts the round-off floor without a refresh
// once the corrections have shrunk by stall_step (docs/theory/exact-energy-momentum.md §5) keep the
// balances of the full-Newton runs above, with fewer iterations than the predictor u_n.
TEST(EmExact, ModifiedNewtonKeepsTheBalances) {
  // certify = floor: the accepted iterate's residual is not evaluated, so the identity check runs on the
  // same run with certify = residual below.
  const std::vector<std::pair<std::string, std::string>> modified = {{"newton", "modified"}};
  auto floor = modified;
  floor.emplace_back("certify", "floor");
  const Flight r = fly("em-exact", 1e6, 0.01, 200, kV0, kW, 0.5, floor);
  print("free plate, modified Newton, certify = floor, 2 s", r);
  EXPECT_LT(r.max_dH, 1e-10);
  EXPECT_LT(r.max_dJ, 1e-9);
  EXPECT_LT(r.max_dL, 1e-12);
  auto residual = modified;
  residual.emplace_back("certify", "residual");
  const Flight rr = fly("em-exact", 1e6, 0.01, 200, kV0, kW, 0.5, residual);
  print("  same, certify = residual", rr);
  EXPECT_LT(rr.max_dH, 1e-10);
  EXPECT_LT(rr.identity_gap, round_off_bound(rr));
  EXPECT_EQ(rr.unevaluated_steps, 0);
  // Certifying by the floor saves residuals: it skips the accepted iterate's residual in the steps
  // where the floor test sees the floor a correction early.
  std::printf("  residuals per step: certify floor %.2f, residual %.2f; steps accepted unevaluated %ld of %ld\n",
              double(r.residuals) / r.steps, double(rr.residuals) / rr.steps, r.unevaluated_steps, r.steps);
  EXPECT_GT(r.unevaluated_steps, r.steps / 4);
  EXPECT_LT(r.residuals, rr.residuals);
  // certify = predicted (theory §5.4; modified Newton's default, §5.8) stops a correction earlier still, on the
  // residual predicted from the contraction: fewer residuals, the balances within the same bounds.
  const Flight rp = fly("em-exact", 1e6, 0.01, 200, kV0, kW, 0.5, modified);
  print("  same, certify = predicted (default)", rp);
  std::printf("  residuals per step: certify predicted %.2f\n", double(rp.residuals) / rp.steps);
  EXPECT_LT(rp.max_dH, 1e-10);
  EXPECT_LT(rp.max_dJ, 1e-9);
  EXPECT_LT(rp.max_dL, 1e-12);
  EXPECT_LT(rp.residuals, r.residuals);
  auto u_n = floor;
  u_n.emplace_back("predictor", "none");
  const Flight r0 = fly("em-exact", 1e6, 0.01, 200, kV0, kW, 0.5, u_n);
  print("  same, certify = floor, predictor u_n", r0);
  EXPECT_LT(r.iterations, r0.iterations);
  // The stiff tumbling plate (E = 1e8), where the floor is highest (§5.1).
  for (const auto& settings : {modified, floor, residual}) {
    auto model = free_plate(2.0, 1.0, 4, 2, ShellMaterial{1e8, 0.3, 1.0, 0.1});
    State s = model->initial_state();
    set_free_flight_velocity(*model, s, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.01, 1.0, 0.01), 0.0);
    const Flight t = run(*model, s, "em-exact", 0.01, 200, settings);
    print(settings.size() == 1 ? "tumbling plate, modified Newton (certify = predicted), dt 0.01, 2 s"
                               : "  same, certify = " + settings.back().second, t);
    EXPECT_LT(t.max_dH, 1e-10);
    EXPECT_LT(t.max_dJ, 1e-9);
    if (settings == residual) {
      EXPECT_LT(t.identity_gap, round_off_bound(t));
    }
  }
}

// The modified-Newton predictor extrapolates the directors with their last acceleration too, p_n + Δt w_n +
// Δt²/2 ẇ_n (theory §5.7). On the pinched hemisphere (apps/cases/pinched-hemisphere.yaml, its first 150 steps,
// loads acting) the kept K̄ of the first step serves every step, and the error of a first-order director
// guess is the part it corrects worst: with the term the corrections reach the floor sooner. The better first
// guess also makes the first correction smaller, which must not turn stalls at the floor into refreshes of K̄
// (the stall rule's floor test, §5.7). The balance K + V − W_ext holds as with any predictor.
struct CaseRun {
  StepReport rep;
  double balance = 0.0;  // max |K + V − W_ext| / max(K + V)
};
// The first `steps` steps of apps/cases/FILE.yaml under the integrator make_integ builds for that problem.
CaseRun run_case(const std::string& file, int steps,
                 const std::function<std::unique_ptr<Integrator>(const Problem&)>& make_integ) {
  Problem p = load_problem(std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/" + file + ".yaml");
  State s = p.initial_state();
  const double dt = p.spec.time.dt;
  auto integ = make_integ(p);
  integ->initialize(*p.model, s);
  CaseRun r;
  double worst = 0.0, energy = 0.0;
  for (int k = 1; k <= steps; ++k) {
    r.rep.accumulate(integ->advance(*p.model, s, k * dt));
    const Invariants inv = p.model->invariants(s);
    worst = std::max(worst, std::abs(inv.kinetic + inv.strain - integ->external_work()));
    energy = std::max(energy, inv.kinetic + inv.strain);
  }
  r.balance = worst / energy;
  return r;
}
CaseRun run_hemisphere(const std::string& predictor, int steps) {
  return run_case("pinched-hemisphere", steps, [&](const Problem& p) {
    return make("em-exact", p.spec.time.dt,
                {{"newton", "modified"}, {"hysteresis", "1.1"}, {"predictor", predictor}, {"certify", "floor"}});
  });
}

TEST(EmExact, DirectorAccelerationInThePredictorSavesIterations) {
  const CaseRun a = run_hemisphere("trapezoidal", 150);
  const CaseRun v = run_hemisphere("trapezoidal-v", 150);
  std::printf("pinched hemisphere, 150 steps: iterations %ld (trapezoidal) against %ld (trapezoidal-v), factorizations "
              "%ld against %ld, max|K+V-W|/(K+V) %.2e against %.2e\n",
              a.rep.nonlinear_iterations, v.rep.nonlinear_iterations, a.rep.factorizations, v.rep.factorizations,
              a.balance, v.balance);
  EXPECT_LT(static_cast<double>(a.rep.nonlinear_iterations), 0.95 * static_cast<double>(v.rep.nonlinear_iterations));
  EXPECT_LE(a.rep.factorizations, v.rep.factorizations);
  EXPECT_LT(a.balance, 1e-10);
  EXPECT_LT(v.balance, 1e-10);
  // The flying plate's first 3 s (apps/cases/flying-plate.yaml): its K̄ ages fast, and the contraction rule refreshes
  // it more often after the smaller first corrections. The count moves with round-off: 165 against 95 and 178
  // against 88 factorizations on two element kernels that agree to round-off (the iterations: 13 439 against
  // 14 726 and 13 419 against 14 809), so the guard is 2.5×. Without the stall rule's floor test stalls at the floor
  // refreshed it too: 331 against 128 (checked).
  StepReport fa, fv;
  for (const auto& [predictor, rep] : {std::pair<std::string, StepReport*>{"trapezoidal", &fa}, {"trapezoidal-v", &fv}}) {
    Problem p = load_problem(std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/flying-plate.yaml");
    State s = p.initial_state();
    const double dt = p.spec.time.dt;
    auto integ = make("em-exact", dt, {{"newton", "modified"}, {"predictor", predictor}, {"certify", "floor"}});
    integ->initialize(*p.model, s);
    for (int k = 1; k <= 3000; ++k) rep->accumulate(integ->advance(*p.model, s, k * dt));
  }
  std::printf("flying plate, 3 s: iterations %ld (trapezoidal) against %ld, factorizations %ld against %ld\n",
              fa.nonlinear_iterations, fv.nonlinear_iterations, fa.factorizations, fv.factorizations);
  EXPECT_LT(fa.nonlinear_iterations, fv.nonlinear_iterations);
  EXPECT_LT(2 * fa.factorizations, 5 * fv.factorizations);
}

// certify = energy (theory §5.10) stops em-exact by em-galpha's modified-Newton rule: the paper's relative test
// E_k ≤ cc_tol·E_1 (eq. 39), the energy floor E_k ≤ e_floor·(K_0 + V_0 + |W_ext|) or its estimate for the next
// correction, and the scaled-correction test, with E_k = |Δu_k·r(u_{k−1})|. Under the same rule, on each benchmark's
// case file, em-exact takes no more iterations than em-galpha: the two schemes share K̄, and (hemisphere, newmark
// predictor) their iterates nearly coincide. Measured over the full runs: 60 020 against 60 842 (flying plate),
// 30 002 against 31 320 (panel), 30 015 against 30 014 (hemisphere: one step of 10 000 differs at the threshold).
// The windows here: the hemisphere's first 100 steps, where the loads start from zero (without the relative and
// the step tests em-exact takes 310 against 284 there; checked), the plate's first 2 000 and the panel's first 1 000.
TEST(EmExact, CertifyEnergyTakesNoMoreIterationsThanEmGalpha) {
  for (const auto& [file, steps] : {std::pair<const char*, int>{"pinched-hemisphere", 100}, {"flying-plate", 2000},
                                    {"cylindrical-panel", 1000}}) {
    const CaseRun galpha = run_case(file, steps, [](const Problem& p) { return make_case_integrator(p.spec, "", {}, p.spec.time.dt); });
    const CaseRun exact = run_case(file, steps, [](const Problem& p) {
      return make_case_integrator(p.spec, "em-exact", {{"certify", "energy"}}, p.spec.time.dt);
    });
    std::printf("%s, %d steps: iterations %ld (em-exact, certify = energy) against %ld (em-galpha); em-exact's "
                "max|K+V-W|/max(K+V) %.2e\n", file, steps, exact.rep.nonlinear_iterations, galpha.rep.nonlinear_iterations,
                exact.balance);
    EXPECT_LE(exact.rep.nonlinear_iterations, galpha.rep.nonlinear_iterations) << file;
    EXPECT_LT(exact.balance, 1e-10) << file;
  }
}

// predictor = newmark (theory §5.9) guesses with the end-point accelerations of Newmark's recursion
// a_{n+1} = 2Δv/Δt − a_n, em-galpha's predictor. The recursion has no damping: an error in its start stays in
// every later step as an alternating (−1)^n term. So it starts, as em-galpha does, from the acceleration that
// satisfies the equations of motion at t_0 (docs/theory.md §6.4 start-up). A plate at rest under a uniform
// gravity-like load (nodal forces ρh Σ_j m_ij g, the consistent mass's row sums) falls as a rigid body with
// a = g from the first instant: the recursion's accelerations (saved in checkpoints) must stay g. Started from
// a = 0 they alternate between 2g and 0 (checked: the test then fails).
TEST(EmExact, NewmarkPredictorStartsFromTheConsistentAcceleration) {
  Mesh mesh = make_rectangle(2.0, 1.0, 2, 1, -1.0, -0.5);
  auto normals = initial_normals(mesh);
  const ShellMaterial mat{1e6, 0.3, 1.0, 0.1};
  const int nn = mesh.num_nodes();
  const Eigen::Vector3d g(0.0, 0.3, -9.81);
  std::vector<NodalLoad> loads;
  {
    Model bare(Mesh(mesh), std::vector<Eigen::Vector3d>(normals), mat, DofMap(nn), {});
    Eigen::VectorXd ones = Eigen::VectorXd::Ones(3 * nn), zeros = Eigen::VectorXd::Zero(3 * nn), m, mw;
    bare.scalar_mass_times(ones, zeros, m, mw);
    for (int i = 0; i < nn; ++i) {
      NodalLoad f;
      f.node = i;
      f.vector = (mat.rho * mat.thickness * m[3 * i]) * g;
      f.function = TimeFunction::constant();
      loads.push_back(f);
    }
  }
  Model model(std::move(mesh), std::move(normals), mat, DofMap(nn), std::move(loads));
  State s = model.initial_state();
  const double dt = 0.01;
  auto integ = make("em-exact", dt, {{"newton", "modified"}, {"predictor", "newmark"}});
  integ->initialize(model, s);
  double worst_a = 0.0, worst_w = 0.0, worst_balance = 0.0;
  for (int k = 1; k <= 20; ++k) {
    integ->advance(model, s, k * dt);
    IntegratorCheckpoint c;
    integ->save(c);
    const Eigen::VectorXd& a = c.vector("newmark_acceleration", 3 * nn);
    const Eigen::VectorXd& w = c.vector("newmark_director_acceleration", 3 * nn);
    for (int i = 0; i < nn; ++i) worst_a = std::max(worst_a, (a.segment<3>(3 * i) - g).norm() / g.norm());
    worst_w = std::max(worst_w, w.norm());
    worst_balance = std::max(worst_balance, std::abs(total_energy(model.invariants(s)) - integ->external_work()));
  }
  const double W = integ->external_work();
  std::printf("falling plate, 20 steps: max |a - g|/|g| %.2e, max |dw/dt| %.2e, max|K+V-W|/W %.2e\n", worst_a, worst_w,
              worst_balance / W);
  EXPECT_LT(worst_a, 1e-6);  // the solves' residual, not Δt²/2 g
  EXPECT_LT(worst_w, 1e-6);  // the directors do not turn
  EXPECT_LT(worst_balance / W, 1e-10);
  EXPECT_NEAR(s.u[DofMap::dof(0, 2)], 0.5 * g.z() * 0.2 * 0.2, 1e-9);  // the fall itself: g t²/2 at t = 0.2
  // On the pinched hemisphere (loads from zero, so a_0 = 0) the newmark predictor's iterates are em-galpha's
  // (theory §5.9); its first 150 steps take no more iterations than with the trapezoidal predictor.
  const CaseRun hn = run_hemisphere("newmark", 150), ht = run_hemisphere("trapezoidal", 150);
  std::printf("pinched hemisphere, 150 steps: iterations %ld (newmark) against %ld (trapezoidal), max|K+V-W|/(K+V) "
              "%.2e against %.2e\n",
              hn.rep.nonlinear_iterations, ht.rep.nonlinear_iterations, hn.balance, ht.balance);
  // Measured 560 against 579 with the correction in the weighted metric (exact-energy-momentum.md §3).
  EXPECT_LE(hn.rep.nonlinear_iterations, ht.rep.nonlinear_iterations);
  EXPECT_LT(hn.balance, 1e-10);
}

// Integrator::set_residual_trace (theory §5.9: the iteration counts of the two schemes compared at equal
// accuracy): one report per accepted step with its Newton iterations and the scaled residual of every evaluated
// iterate, falling from the predictor's to the accepted one. Integrators without the report say so.
TEST(EmExact, ResidualTraceReportsEveryStep) {
  for (const std::string name : {"em-exact", "em-galpha"}) {
    for (const std::string newton : {"full", "modified"}) {
      auto model = free_plate(2.0, 1.0, 2, 1, ShellMaterial{1e6, 0.3, 1.0, 0.1});
      State s = model->initial_state();
      set_free_flight_velocity(*model, s, kV0, kW, 0.5);
      auto integ = make(name, 0.01, {{"newton", newton}});
      std::vector<std::vector<double>> rho;
      std::vector<int> its;
      ASSERT_TRUE(integ->set_residual_trace([&](const std::vector<double>& r, int iterations) {
        rho.push_back(r);
        its.push_back(iterations);
      }));
      integ->initialize(*model, s);
      StepReport rep;
      for (int k = 1; k <= 20; ++k) rep.accumulate(integ->advance(*model, s, k * 0.01));
      ASSERT_EQ(rho.size(), 20u) << name << " " << newton;
      long sum = 0;
      for (size_t k = 0; k < rho.size(); ++k) {
        const size_t m = rho[k].size();
        sum += its[k];
        ASSERT_GE(m, 2u) << name << " step " << k;
        EXPECT_TRUE(static_cast<size_t>(its[k]) == m || static_cast<size_t>(its[k]) + 1 == m) << name << " step " << k;
        for (double x : rho[k]) EXPECT_TRUE(std::isfinite(x) && x >= 0.0);
        // A converging iteration. (em-galpha's full Newton stops on the energy ratio cc of paper eq. 39 after
        // a correction whose residual it does not evaluate: its last evaluated one is 1e-5 to 2e-3 of the first.)
        EXPECT_LT(*std::min_element(rho[k].begin(), rho[k].end()), 1e-2 * rho[k].front()) << name << " step " << k;
      }
      EXPECT_EQ(sum, rep.nonlinear_iterations) << name << " " << newton;
    }
  }
  auto other = make("ida-bdf", 0.01);
  EXPECT_FALSE(other->set_residual_trace([](const std::vector<double>&, int) {}));
}

// The opt-in renewal refresh (refresh_cost, theory §5.5) adds refreshes of K̄ decided by iteration counts to the
// contraction rule. The balances must hold as with the contraction rule alone: when the renewal rule replaced it
// (contraction only a guard at 0.5), the stall rule took slow convergence for the floor and the free plate's
// energy erred by 2.5e-9 (checked; the 200 s tumbling plate of the study, 6.9e-10 with a guard of 0.2).
TEST(EmExact, RenewalRefreshKeepsTheBalances) {
  // With refresh 0.1 (as the panel's case file) and Δt 0.001 the plate keeps K̄ over many steps, so the
  // renewal rule has refreshes to add.
  const std::vector<std::pair<std::string, std::string>> modified = {{"newton", "modified"}, {"refresh", "0.1"}, {"certify", "floor"}};
  auto renewal = modified;
  renewal.emplace_back("refresh_cost", "12");
  const Flight base = fly("em-exact", 1e6, 0.001, 400, kV0, kW, 0.5, modified);
  const Flight r = fly("em-exact", 1e6, 0.001, 400, kV0, kW, 0.5, renewal);
  print("free plate, modified Newton, renewal refresh", r);
  std::printf("  factorizations: renewal %ld, contraction rule %ld; iterations %ld, %ld\n", r.factorizations,
              base.factorizations, r.iterations, base.iterations);
  // The rule is active: it changes the sequence of refreshes. (Whether their total rises or falls is a matter of
  // round-off: a refresh moves every later contraction test; on one CPU the contraction rule alone refreshed 36
  // times against the renewal rule's 33, on another fewer.)
  EXPECT_NE(r.factorizations, base.factorizations);
  EXPECT_LT(r.iterations, base.iterations);  // and saves iterations
  EXPECT_LT(r.max_dH, 1e-10);
  EXPECT_LT(r.max_dJ, 1e-9);
  EXPECT_LT(r.max_dL, 1e-12);
  auto model = free_plate(2.0, 1.0, 4, 2, ShellMaterial{1e8, 0.3, 1.0, 0.1});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.01, 1.0, 0.01), 0.0);
  const Flight t = run(*model, s, "em-exact", 0.01, 200, renewal);
  print("tumbling plate, modified Newton, renewal refresh", t);
  EXPECT_LT(t.max_dH, 1e-10);
  EXPECT_LT(t.max_dJ, 1e-9);
}

// A free plate at rest loaded by a force pulse and a moment pulse (hat functions): K + V − W_ext, with W_ext
// the scheme's own work F_ext(t_mid)·Δd + Σ (m × p_mid)·Δp, stays at 0 to the solver residual.
double load_balance(std::vector<std::pair<std::string, std::string>> settings, double* work) {
  Mesh mesh = make_rectangle(2.0, 1.0, 2, 1, -1.0, -0.5);
  auto normals = initial_normals(mesh);
  NodalLoad pulse, moment;
  pulse.node = mesh.node_sets.at("corner_ur").front();
  pulse.vector = Eigen::Vector3d(0.0, 0.5, 2.0);
  pulse.function = TimeFunction::hat(0.1);
  moment.node = mesh.node_sets.at("corner_ll").front();
  moment.kind = NodalLoad::Kind::Moment;
  moment.vector = Eigen::Vector3d(0.3, -0.2, 0.1);
  moment.function = TimeFunction::hat(0.15);
  DofMap dofs(mesh.num_nodes());
  Model model(std::move(mesh), std::move(normals), ShellMaterial{1e6, 0.3, 1.0, 0.1}, std::move(dofs), {pulse, moment});
  State s = model.initial_state();
  const double dt = 0.01;
  auto integ = make("em-exact", dt, std::move(settings));
  integ->initialize(model, s);
  double worst = 0.0;
  for (int k = 1; k <= 50; ++k) {
    integ->advance(model, s, k * dt);
    const double W = integ->external_work();
    worst = std::max(worst, std::abs(total_energy(model.invariants(s)) - W));
  }
  *work = integ->external_work();
  return worst / *work;
}

TEST(EmExact, EnergyBalanceHoldsThroughTheLoadPhase) {
  double W = 0.0, W_off = 0.0;
  const double e = load_balance({}, &W);
  const double e_off = load_balance({{"correction", "false"}}, &W_off);
  std::printf("load phase: W_ext %.6f, max|K+V-W|/W %.2e (correction off: %.2e)\n", W, e, e_off);
  EXPECT_GT(W, 0.0);
  EXPECT_LT(e, 1e-10);
  EXPECT_GT(e_off, 1e-8);
}

// Half of a free plate on the symmetry plane Y = 0 (d_y and p_y fixed there), symmetric motion: L_x, L_z and
// J_y are the conserved components.
TEST(EmExact, SymmetryPlaneConstraintsKeepTheBalances) {
  Mesh mesh = make_rectangle(2.0, 1.0, 2, 1, -1.0, 0.0);
  auto normals = initial_normals(mesh);
  DofMap dofs(mesh.num_nodes());
  for (int i : mesh.node_sets.at("bottom")) {
    dofs.fix(i, Fix::Uy);
    dofs.fix(i, Fix::Py);
  }
  Model model(std::move(mesh), std::move(normals), ShellMaterial{1e6, 0.3, 1.0, 0.1}, std::move(dofs));
  auto one = [&](std::vector<std::pair<std::string, std::string>> settings) {
    State s = model.initial_state();
    set_free_flight_velocity(model, s, kV0, Eigen::Vector3d(0.0, 3.0, 0.0), 0.5);  // symmetric about Y = 0
    auto integ = make("em-exact", 0.02, std::move(settings));
    integ->initialize(model, s);
    const Invariants inv0 = model.invariants(s);
    double dH = 0, dL = 0, dJ = 0, py = 0;
    long switches = 0;
    for (int k = 1; k <= 100; ++k) {
      switches += integ->advance(model, s, k * 0.02).chart_switches;
      const Invariants inv = model.invariants(s);
      dH = std::max(dH, std::abs(total_energy(inv) - total_energy(inv0)) / total_energy(inv0));
      dL = std::max({dL, std::abs(inv.L.x() - inv0.L.x()), std::abs(inv.L.z() - inv0.L.z())});
      dJ = std::max(dJ, std::abs(inv.J.y() - inv0.J.y()) / std::abs(inv0.J.y()));
      for (int i : model.mesh().node_sets.at("bottom")) py = std::max(py, std::abs(model.director(s, i).y()));
    }
    std::printf("symmetry plane Y = 0, dt 0.02, 2 s: max|dH|/H %.2e, |dLx|,|dLz| %.2e, |dJy|/|Jy| %.2e, max|p_y| on plane %.1e, %ld switches\n",
                dH, dL, dJ, py, switches);
    EXPECT_EQ(py, 0.0);
    return std::array<double, 3>{dH, dL, dJ};
  };
  const auto on = one({});
  EXPECT_LT(on[0], 1e-10);
  EXPECT_LT(on[1], 1e-12);
  EXPECT_LT(on[2], 1e-9);
  const auto off = one({{"correction", "false"}});
  EXPECT_GT(off[0], 1e-8);
}

TEST(EmExact, DissipationIsNonPositiveAndAccountedFor) {
  for (auto settings : {std::vector<std::pair<std::string, std::string>>{{"xi", "0.05"}},
                        std::vector<std::pair<std::string, std::string>>{{"rho_inf", "0.8"}}}) {
    const Flight r = fly("em-exact", 1e6, 0.02, 100, kV0, kW, 0.5, settings);
    std::printf("%s = %s: final dH/H %.4f, largest one-step increase %.2e, min step dissipation %.2e, "
                "max|K+V+D-H0|/H0 %.2e, max|dL|/|L| %.2e, max|dJ|/|J| %.2e\n",
                settings[0].first.c_str(), settings[0].second.c_str(), r.final_dH, r.max_increase,
                r.min_step_dissipation, r.max_balance, r.max_dL, r.max_dJ);
    EXPECT_LT(r.max_increase, 1e-13);         // energy never grows
    EXPECT_GE(r.min_step_dissipation, 0.0);   // the dissipation term ξ ΔuᵀGΔu is non-negative
    EXPECT_LT(r.final_dH, -1e-3);             // and it does remove energy
    EXPECT_LT(r.max_balance, 1e-10);          // K + V + D is conserved exactly
    // Momenta stay exact: G is orthogonal to the rigid modes. Measured 7.6e-14 / 7.3e-14 (ΔL) and 1.6e-14 /
    // 1.3e-14 (ΔJ) with ξ G Δu applied as a chain of products. Forming G first and multiplying (its rounding
    // scales with |G| |Δu|, Δu mostly rigid) gave 3.1e-13 / 8.9e-13 and 3.0e-13 / 1.5e-13 with the element
    // kernels of 5b34afd (4.8e-13 / 1.04e-12 and 1.7e-13 / 1.9e-13 before them): each case fails a bound.
    EXPECT_LT(r.max_dL, 4e-13);
    EXPECT_LT(r.max_dJ, 1e-13);
  }
}

TEST(EmExact, ReportedInvariantsUseTheEmbeddedVelocities) {
  auto model = free_plate(2.0, 1.0, 2, 1, ShellMaterial{1e6, 0.3, 1.0, 0.1});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, kV0, kW, 0.5);
  const Invariants before = model->invariants(s);
  auto integ = make("em-exact", 0.02);
  integ->initialize(*model, s);
  ASSERT_EQ(s.pdot.size(), 3 * model->mesh().num_nodes());
  const Invariants after = model->invariants(s);  // w = A1 q̇ initially: same numbers
  EXPECT_NEAR(after.kinetic, before.kinetic, 1e-14 * before.kinetic);
  EXPECT_LT((after.J - before.J).norm(), 1e-14 * before.J.norm());
  integ->advance(*model, s, 0.2);
  // After steps, w has a component along p: the reported K differs from ½ q̇ᵀ M q̇ of the stored q̇.
  State q_only = s;
  q_only.pdot.resize(0);
  const double K_embedded = model->invariants(s).kinetic, K_q = model->invariants(q_only).kinetic;
  std::printf("after 10 steps: K(embedded) %.15g, K(from q-dot) %.15g\n", K_embedded, K_q);
  EXPECT_NE(K_embedded, K_q);
  s.pdot.resize(5);
  EXPECT_THROW(model->invariants(s), std::invalid_argument);
}

// certify = auto (the default) is resolved when the system is known, and settings() (run.json) reports the
// result: residual with full Newton, predicted with modified Newton, floor with prescribed displacements
// (PrescribedMotion.EnergyBalanceClosesWithThePrescribedWork runs that case; theory §5.8).
TEST(EmExact, CertifyAutoIsResolvedAtInitialize) {
  auto certify_of = [](const Integrator& integ) {
    for (const auto& [key, value] : integ.settings())
      if (key == "certify") return value;
    return std::string("(none)");
  };
  for (const auto& [newton, expected] : {std::pair<std::string, std::string>{"full", "residual"}, {"modified", "predicted"}}) {
    auto model = free_plate(2.0, 1.0, 2, 1, ShellMaterial{1e6, 0.3, 1.0, 0.1});
    State s = model->initial_state();
    auto integ = make("em-exact", 0.01, {{"newton", newton}});
    EXPECT_EQ(certify_of(*integ), "auto");
    integ->initialize(*model, s);
    EXPECT_EQ(certify_of(*integ), expected) << newton;
    for (const char* rule : {"floor", "energy"}) {
      auto given = make("em-exact", 0.01, {{"newton", newton}, {"certify", rule}});
      given->initialize(*model, s);
      EXPECT_EQ(certify_of(*given), rule) << newton;
    }
  }
}

// docs/theory/newton-iteration.md §3: the stiff tumbling plate (E = 1e10, the benchmarks §6 plate about an axis 1 %
// off its intermediate one, Δt 0.01) with the defaults. Its residual's round-off floor, ~3e-6 of the force scale,
// lies above the fixed stall_tol (1e-6); the stall ceiling that scales with ε Σ|K̄_ij| max(1, |u|) accepts it.
// Before that ceiling every step failed (step 1: 25 iterations at ~3e-6, then the full-Newton retry likewise).
// docs/theory/newton-iteration.md §4: the stiff free flight (E = 1e9, Δt 0.02, rigid initial velocity) with em-exact's
// defaults. In the weighted
// metric (w = h ℓ_e) its first step stalls above the round-off ceiling (modified and full Newton); the step is then
// retried in the unweighted metric w = 1, which converges and stays in use. The retry is counted: rejected attempts
// in the StepReport, the switch in the diagnostics.
TEST(EmExact, FailedStepRetriesInTheOtherMetric) {
  auto model = free_plate(2.0, 1.0, 2, 1, ShellMaterial{1e9, 0.3, 1.0, 0.1});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, kV0, kW, 0.0);  // rigid initial velocity: scripts/newton_panel.py's case
  auto integ = make("em-exact", 0.02);
  integ->initialize(*model, s);
  const auto* diag = dynamic_cast<const EmExactDiagnostics*>(integ.get());
  ASSERT_NE(diag, nullptr);
  const double H0 = total_energy(model->invariants(s));
  long steps = 0, rejected = 0;
  double max_dH = 0.0;
  for (int k = 1; k <= 10; ++k) {
    StepReport rep;
    ASSERT_NO_THROW(rep = integ->advance(*model, s, k * 0.02)) << "step " << k;
    steps += rep.steps;
    rejected += rep.rejected_steps;
    max_dH = std::max(max_dH, std::abs(total_energy(model->invariants(s)) - H0) / H0);
  }
  std::printf("stiff free flight, 10 steps: %ld rejected attempts, %ld metric switches, max|dH|/H %.2e\n", rejected,
              diag->diagnostics().metric_switches, max_dH);
  EXPECT_EQ(steps, 10);                                   // no cut
  EXPECT_GE(diag->diagnostics().metric_switches, 1);      // the retry happened ...
  EXPECT_GE(rejected, 2 * diag->diagnostics().metric_switches);  // ... and its failed attempts are reported
  EXPECT_LT(max_dH, 1e-10);
}

TEST(EmExact, StiffTumblingPlateStopsAtTheResidualsRoundOffLevel) {
  auto model = free_plate(2.0, 1.0, 4, 2, ShellMaterial{1e10, 0.3, 1.0, 0.1});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.01, 1.0, 0.01), 0.0);
  Flight r;
  ASSERT_NO_THROW(r = run(*model, s, "em-exact", 0.01, 100));
  print("stiff tumbling plate E = 1e10, dt 0.01, 1 s", r);
  EXPECT_EQ(r.steps, 100);  // no step cut, no failure
  // Measured 1.1e-10 and 5.3e-11 (em-galpha on the same plate drifts by 4.9e-8 in 2 s).
  EXPECT_LT(r.max_dH, 5e-10);
  EXPECT_LT(r.max_dJ, 5e-10);
}

// docs/theory/newton-iteration.md §3.1: the tumbling plate at E = 1e11 (the stiff tumbling plate's stiffness × 10). K̄
// leaves out enough of the corrected force's tangent that the iteration contracts only linearly (~0.6 per iteration,
// with K̄ refreshed every second iteration, and in full Newton too); step 71 needs more than max_iters = 25 of them,
// and with the fixed count every attempt failed (modified, full Newton, the other metric). The iteration now goes on
// beyond max_iters while the residual still halves every 4 iterations.
TEST(EmExact, SlowlyContractingStiffStepsGoOnWhileTheyContract) {
  auto model = free_plate(2.0, 1.0, 4, 2, ShellMaterial{1e11, 0.3, 1.0, 0.1});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.01, 1.0, 0.01), 0.0);
  Flight r;
  ASSERT_NO_THROW(r = run(*model, s, "em-exact", 0.01, 100));
  print("tumbling plate E = 1e11, dt 0.01, 1 s", r);
  EXPECT_EQ(r.steps, 100);  // no step cut, no failure
  EXPECT_LT(r.max_dH, 5e-9);  // measured 1.4e-9 (the shelldyn CLI, same plate)
  EXPECT_LT(r.max_dJ, 5e-9);
}

// A step whose iteration is still contracting when it runs out of iterations says which setting helps.
TEST(EmExact, FailedStepThatStillContractsAsksForMoreIterations) {
  // The free flight of FailedStepSaysOneShortTrueLine, whose first step needs 6-10 iterations: with max_iters = 4
  // the iteration goes on to 8 (contracting) and stops there.
  auto model = free_plate(2.0, 1.0, 2, 1, ShellMaterial{1e6, 0.3, 1.0, 0.1});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, kV0, kW, 0.5);
  auto integ = make("em-exact", 0.02, {{"max_iters", "4"}});
  integ->initialize(*model, s);
  try {
    integ->advance(*model, s, 0.02);
    FAIL() << "expected a StepFailure";
  } catch (const StepFailure& e) {
    const std::string msg = e.what();
    std::printf("message: %s\n", msg.c_str());
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_NE(msg.find("step 1 at t = 0"), std::string::npos) << msg;
    EXPECT_NE(msg.find("no convergence in 8 iterations"), std::string::npos) << msg;
    EXPECT_NE(msg.find("max_iters=8 (still converging)"), std::string::npos) << msg;
  }
}

// docs/theory/newton-iteration.md §2: the free spinning plate (L = 1, h = 0.01, E = 1e7, ρ = 1000, 4 × 4, v = (0.1, 0, 0)
// + ω × r, ω = (0, −2, 0), Δt 0.01) with em-exact's defaults. With the correction's direction in the unweighted metric
// its β z term swamped the director stiffness and step 6 failed (25 iterations stalled at 2.5e-5); in the weighted
// metric W (director weight h ℓ_e, exact-energy-momentum.md §3) every step converges under the kept K̄.
TEST(EmExact, SpinningThinPlateConvergesWithTheDefaults) {
  auto model = free_plate(1.0, 1.0, 4, 4, ShellMaterial{1e7, 0.3, 1000.0, 0.01});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, Eigen::Vector3d(0.1, 0.0, 0.0), Eigen::Vector3d(0.0, -2.0, 0.0), 0.0);
  Flight r;
  ASSERT_NO_THROW(r = run(*model, s, "em-exact", 0.01, 20));
  print("spinning plate 4 x 4, h 0.01, dt 0.01, 20 steps", r);
  EXPECT_EQ(r.steps, 20);  // no step cut
  EXPECT_LT(r.factorizations, 20);  // the kept K̄ serves several steps (measured: 8 in 20 steps)
  EXPECT_LT(r.max_dH, 1e-12);      // measured 1.7e-14 over 200 steps (the CLI case)
  EXPECT_LT(r.max_dJ, 1e-12);
}

// docs/theory/newton-iteration.md §4: a step that does not converge says so in one short line: the step, the time,
// the last scaled residual (a "lowest" one only when it is lower) and the setting that would help.
TEST(EmExact, FailedStepSaysOneShortTrueLine) {
  auto model = free_plate(2.0, 1.0, 2, 1, ShellMaterial{1e6, 0.3, 1.0, 0.1});
  State s = model->initial_state();
  set_free_flight_velocity(*model, s, kV0, kW, 0.5);
  auto integ = make("em-exact", 0.02, {{"max_iters", "2"}});  // the step needs 6-10 iterations
  integ->initialize(*model, s);
  try {
    integ->advance(*model, s, 0.02);
    FAIL() << "expected a StepFailure";
  } catch (const StepFailure& e) {
    const std::string msg = e.what();
    std::printf("message (%zu characters): %s\n", msg.size(), msg.c_str());
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_LT(msg.size(), 200u) << msg;
    EXPECT_NE(msg.find("step 1 at t = 0"), std::string::npos) << msg;
    EXPECT_NE(msg.find("no convergence in 2 iterations"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("best"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("KIN"), std::string::npos) << msg;  // no solver internals
    EXPECT_NE(msg.find("max_cuts="), std::string::npos) << msg;
    const size_t at = msg.find("scaled residual ");
    ASSERT_NE(at, std::string::npos) << msg;
    const double last = std::stod(msg.substr(at + 16));
    const size_t low = msg.find("lowest ");
    if (low != std::string::npos) {
      EXPECT_LT(std::stod(msg.substr(low + 7)), last) << msg;
    }
  }
  EXPECT_EQ(s.t, 0.0);
}

TEST(EmExact, RejectsBadSettingsAndOtherSystems) {
  EXPECT_THROW(make("em-exact", 0.01, {{"rho_inf", "1.5"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"xi", "-1"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"newton", "quasi"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"certify", "contraction"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"floor_margin", "0.5"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"certify", "predicted"}, {"predict_factor", "0"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"predict_factor", "nan"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"refresh_cost", "-1"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"kbar_basis", "rotated"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"predictor", "trapezoidal-w"}}), std::invalid_argument);
  EXPECT_NO_THROW(make("em-exact", 0.01, {{"predictor", "newmark"}}));
  EXPECT_THROW(make("em-exact", -0.01), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"certify", "energy"}, {"e_floor", "-1e-20"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"certify", "energy"}, {"cc_tol", "-1e-14"}}), std::invalid_argument);
  EXPECT_THROW(make("em-exact", 0.01, {{"certify", "energy"}, {"step_tol", "-1"}}), std::invalid_argument);
  EXPECT_NO_THROW(make("em-exact", 0.01, {{"certify", "energy"}, {"cc_tol", "1e-6"}, {"e_floor", "1e-22"}}));
  EXPECT_THROW(make("em-exact", 0.01, {{"floor_test", "estimate"}}), std::invalid_argument);  // an em-galpha key only
  testing::SpringMass spring(1.0);
  State s = spring.initial_state();
  auto integ = make("em-exact", 0.01);
  EXPECT_THROW(integ->initialize(spring, s), std::invalid_argument);
}

}  // namespace
}  // namespace shelldyn
