// A mode of `shelldyn modes` as the initial velocity (docs/manual.md §2.6, docs/modal.md "Outputs"):
// mode_shapes.csv written by write_mode_shapes_csv() and read back through the case-file key
// initial_velocity: {mode: FILE, index: k, amplitude: A}. A simply supported plate started with v = A φ_k
// must vibrate in mode k alone, at its frequency ω_k (small amplitude: linear range).
#include "integrators/integrator_settings.hpp"
#include "integrators/runs/registry.hpp"
#include "lib/analysis/modal_analysis.hpp"
#include "lib/model/problem.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace shelldyn {
namespace {

// Simply supported square plate of docs/modal.md on a 4 × 4 mesh (hard support, Navier conditions).
const std::string kPlate = R"(
mesh: {generator: rectangle, a: 1.0, b: 1.0, nx: 4, ny: 4}
material: {E: 200.0e9, nu: 0.3, rho: 7850.0, thickness: 0.01}
boundary_conditions:
  - {set: left, fix: [ux, uy, uz, py]}
  - {set: right, fix: [ux, uy, uz, py]}
  - {set: bottom, fix: [ux, uy, uz, px]}
  - {set: top, fix: [ux, uy, uz, px]}
time: {dt: 1.0e-4, t_end: 0.01}
output: {vtu: false, history: false}
)";

struct Excited {
  double period_measured = 0.0, period_mode = 0.0, period_trapezoidal = 0.0;
  double other_modes = 0.0;  // max_t,j≠k |η_j| / max_t |η_k|
  double velocity_error = 0.0;  // ‖v(0) − A φ_k‖∞ / A
  int crossings = 0;
};

// Starts the plate with mode k (1-based) of its own modal analysis as velocity, amplitude A, and integrates
// `periods` + ½ periods with em-galpha (ρ∞ = 1) at `steps` steps per period. Modal coordinates
// η_j(t) = φ_jᵀ M₀ u(t) of the six lowest modes.
Excited excite(int k, double A, int steps, int periods) {
  Problem plate = make_problem(load_case_from_string(kPlate + "integrator: {name: em-galpha}\n", "plate.yaml"));
  const State s0 = plate.initial_state();
  ModalOptions mo;
  mo.num_modes = 6;
  const ModalResult modes = modal_analysis(*plate.model, s0, mo);
  const std::string file = testing::TempDir() + "/plate_mode_shapes.csv";
  write_mode_shapes_csv(file, *plate.model, s0, modes);

  const Mode& mk = modes.modes.at(static_cast<size_t>(k - 1));
  const double dt = mk.period / steps;
  char text[512];
  std::snprintf(text, sizeof text,
                "integrator: {name: em-galpha}\ninitial_velocity: {mode: %s, index: %d, amplitude: %.17g}\n",
                file.c_str(), k, A);
  Problem p = make_problem(load_case_from_string(kPlate + text, "plate_mode.yaml"));
  Model& model = *p.model;
  State s = p.initial_state();
  Excited out;
  out.velocity_error = (s.v - A * mk.shape).cwiseAbs().maxCoeff() / A;

  SparseMatrix M0;
  M0.pattern = model.pattern();
  M0.values.assign(static_cast<size_t>(M0.pattern->nnz()), 0.0);
  model.mass(s.u, s.charts, M0);
  std::vector<Eigen::VectorXd> Mphi;
  for (const Mode& m : modes.modes) {
    Eigen::VectorXd y(m.shape.size());
    multiply(M0.view(), m.shape.data(), y.data());
    Mphi.push_back(y);
  }

  IntegratorSettings settings(p.spec.integrator);
  auto integ = make_integrator(settings, dt);
  integ->initialize(model, s);
  double eta_prev = 0.0, max_k = 0.0, max_other = 0.0;
  std::vector<double> up;  // upward zero crossings of η_k after t = 0
  for (int n = 1; n <= steps * periods + steps / 2; ++n) {
    integ->advance(model, s, n * dt);
    for (size_t j = 0; j < Mphi.size(); ++j) {
      const double eta = Mphi[j].dot(s.u);
      if (static_cast<int>(j) == k - 1) {
        max_k = std::max(max_k, std::abs(eta));
        if (eta_prev < 0.0 && eta >= 0.0) up.push_back((n - 1) * dt + dt * eta_prev / (eta_prev - eta));
        eta_prev = eta;
      } else {
        max_other = std::max(max_other, std::abs(eta));
      }
    }
  }
  out.crossings = static_cast<int>(up.size());
  // η_k(0) = 0 going up: the crossings after it are at multiples of the period.
  if (!up.empty()) out.period_measured = up.back() / static_cast<double>(up.size());
  out.period_mode = mk.period;
  // The trapezoidal rule (em-galpha with ρ∞ = 1 on a linear system) has the discrete frequency
  // Ω = (2/Δt) atan(ωΔt/2) (docs/theory.md §6.7): its period.
  out.period_trapezoidal = 2 * M_PI / ((2.0 / dt) * std::atan(mk.omega * dt / 2.0));
  out.other_modes = max_other / max_k;
  return out;
}

TEST(ModalInitialVelocity, PlateVibratesInTheStartedModeAtItsFrequency) {
  // Mode 1 ((1,1)) and mode 4 ((2,2)) with A = 1e-3: the largest displacement is A max|φ|/ω ≈ 7.5e-7 m for
  // mode 1 (78.5 kg plate: max|φ| ≈ 2/√m = 0.23; ω₁ = 302 rad/s), 7.5e-5 of the thickness: linear range.
  for (int k : {1, 4}) {
    const Excited e = excite(k, 1e-3, 40, 3);
    std::printf("mode %d: T_k = %.6e s, measured %.6e (ratio %.6f), trapezoidal period %.6e (ratio measured/trap "
                "%.8f), other modes / mode k = %.2e, |v(0) - A phi_k|/A = %.1e\n",
                k, e.period_mode, e.period_measured, e.period_measured / e.period_mode, e.period_trapezoidal,
                e.period_measured / e.period_trapezoidal, e.other_modes, e.velocity_error);
    EXPECT_LT(e.velocity_error, 1e-13) << "mode " << k;
    EXPECT_EQ(e.crossings, 3) << "mode " << k;
    // 40 steps per period: the trapezoidal period is 0.206 % longer than T_k, and the measured period matches
    // it to 3.2e-6 (modes 1 and 4; the zero crossings are linearly interpolated): bound 2e-5. Started with
    // the wrong mode (index k ± 1) the period is off by > 20 %.
    EXPECT_NEAR(e.period_measured / e.period_trapezoidal, 1.0, 2e-5) << "mode " << k;
    EXPECT_NEAR(e.period_measured / e.period_mode, 1.0, 2.5e-3) << "mode " << k;
    // The other five modal coordinates stay at 6.5e-11 (mode 1) and 1.2e-13 (mode 4) of mode k's amplitude
    // (geometric nonlinearity at a displacement 1e-3 of the thickness): bound 1e-8.
    EXPECT_LT(e.other_modes, 1e-8) << "mode " << k;
  }
}

}  // namespace
}  // namespace shelldyn
