// The energy–momentum generalized-α scheme of Li & Qian (2025) §3 (docs/theory.md §6), and the classical
// schemes that share its Newmark bookkeeping and KINSOL solve, so that comparisons isolate what the strain
// averaging buys:
//
//   em-galpha  internal force from strains averaged between the step's end states (§6.3), T and K_σ at
//              the generalized midpoint; M, F_m, F_ext at the generalized midpoint.      [the paper]
//   midpoint   internal force F_int(u_{n+1−α_f}) at the midpoint configuration (em-galpha without strain
//              averaging); everything else as em-galpha.
//   galpha     Chung–Hulbert: F_int and F_ext as (1−α_f)·F(t_{n+1}) + α_f·F(t_n); M and F_m at the midpoint.
//   newmark    α_m = α_f = 0 with free β, γ: all forces at t_{n+1}.
//
// Parameters (§6.1): α_m = (2ρ∞−1)/(ρ∞+1), α_f = ρ∞/(ρ∞+1), γ = ½ − α_m + α_f, β = ¼(1 − α_m + α_f)²; ξ ≥ 0
// strain-interpolation dissipation (em-galpha only). Each step (§6.6): re-select charts, predictor
// u_{n+1} = u_n, Newton on the residual R = M_mid ü_{n+1−α_m} + F_m,mid + F_int,mid − F_ext,mid with the
// symmetric K̄ = (1−α_m)/(βΔt²) M_mid + (1−α_f) K_mid (§6.4), then the Newmark updates of u̇, ü (§6.2).
//
// Settings (case file `integrator:` block or --set key=value):
//   rho_inf [1], xi [0] (em-galpha), beta [0.25] and gamma [0.5] (newmark),
//   newton: modified|full [modified]. Modified Newton keeps K̄'s factorization over iterations and steps and
//     refreshes it when the observed contraction θ = ‖Δu_k‖/‖Δu_{k−1}‖ exceeds refresh [0.1] (0: every
//     setup_every [20] iterations instead); it starts from the Newmark predictor (predictor: none|newmark
//     [newmark with modified, none with full]; none = u_n as in §6.4) and stops on the first of: the paper's
//     cc ≤ cc_tol; the energy floor E_k = |Δu_k·P̄(u_{k−1})| ≤ e_floor·(K_0 + V_0 + |W_ext|) (e_floor [1e-20 with
//     modified, 0 = off with full]; docs/theory.md §6.5), with floor_test: correction|estimate [estimate with
//     modified] (estimate: also accept u_k once 10 θ_E E_k, the estimated next correction, is below the floor);
//     the scaled step test |Δu_i| ≤ step_tol max(1, |u_n,i|)
//     (round-off reached; step_refresh = true: KINSOL's test instead, which refreshes K̄ and iterates once
//     more). A step that fails is retried with full Newton. linear_solver: cholmod|eigen-ldlt|klu|mumps [cholmod],
//   solve_precision: double|single [double] (single: triangular solves with a float copy of CHOLMOD's factor,
//     docs/dependencies.md §5.5; cholmod only),
//   cc_tol [1e-12; 1e-14 with modified Newton] (paper eq. 39 energy ratio; the paper uses 1e-6), step_tol [1e-14],
//   min_iters [1], max_iters [25],
//   max_cuts [0] (step cutting: a failed step is retried as two half steps, recursively), hysteresis [1].
#pragma once

#include "integrators/integrator.hpp"

namespace shelldyn {

std::unique_ptr<Integrator> make_em_galpha(IntegratorSettings& settings, double dt);
std::unique_ptr<Integrator> make_galpha(IntegratorSettings& settings, double dt);
std::unique_ptr<Integrator> make_midpoint(IntegratorSettings& settings, double dt);
std::unique_ptr<Integrator> make_newmark(IntegratorSettings& settings, double dt);

// Chung–Hulbert parameters from the spectral radius at infinity ρ∞ ∈ [0, 1] (docs/theory.md §6.1).
struct GeneralizedAlphaParameters {
  double alpha_m, alpha_f, beta, gamma;
};
GeneralizedAlphaParameters generalized_alpha_parameters(double rho_inf);

}  // namespace shelldyn
