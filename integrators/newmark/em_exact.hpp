// em-exact: an exactly energy–momentum conserving step for the CR9 shell model
// (docs/theory/exact-energy-momentum.md; it goes beyond Li & Qian (2025), whose scheme em-galpha reproduces).
//
// Per node the scheme carries position, director and their velocities in ℝ³ (d_i, p_i, v_i, w_i; State::pdot
// holds w). The unknowns of a step are u_{n+1} = [d, q] in the charts fixed at the step start. Trapezoidal
// relations v_{n+1} = 2Δd/Δt − v_n, w_{n+1} = 2Δp/Δt − w_n; balance at the midpoint (theory §2, §4):
//   translations  M_d (v_{n+1} − v_n)/Δt + F*_d − F_ext(t_mid) = 0
//   directors     A1(p_mid)ᵀ [M_p (w_{n+1} − w_n)/Δt − g(t_mid)] + F*_q = 0,   p_mid = (p_n + p_{n+1})/2
// with the per-element corrected force F* of theory §3 (R F* = 0, Δuᵀ F* = ΔU) plus, when dissipative, the
// force ξ G Δu of theory §6. Results, for any Δt, to the Newton residual:
//   K + V − W_ext constant (ξ = 0) or decreasing by Σ ξ ΔuᵀGΔu ≥ 0 per step; L exact; J exact without loads.
//
// Settings: rho_inf [1] and xi [0] (dissipation; ξ_eff = ξ + (1−ρ∞)/(2(1+ρ∞)), theory §6),
//   newton modified|full [modified], refresh [0.03 with modified Newton, else 0: refresh K̄ when the observed
//   contraction exceeds it], refresh_cost [0: off; opt-in renewal rule, also refresh K̄ when a step's iterations
//   exceed the average since the last refresh with the refresh counted as this many iterations, theory §5.5],
//   setup_every [20; 1e6 when refresh > 0], predictor none|trapezoidal|trapezoidal-v|newmark [trapezoidal with
//   modified Newton, else none; trapezoidal-v leaves out the directors' acceleration term, theory §5.7; newmark
//   takes the end-point accelerations of Newmark's recursion, em-galpha's predictor, theory §5.9], linear_solver [cholmod], solve_precision [double] (or single: float copy
//   of the factor, docs/dependencies.md §5.5), res_tol [1e-12], stall_tol [1e-6; a stall below the residual's round-off level
//   ε max_i Σ_j |K̄_ij| max(1, ‖u_n‖∞) / scale counts as well, docs/theory/newton-iteration.md §3], stall_ratio [0.5],
//   stall_step [1e-6], max_iters [25; up to 2 max_iters while the residual
//   still halves every 4 iterations, docs/theory/newton-iteration.md §3.1], max_cuts [0], hysteresis [1], certify auto|residual|floor|predicted|energy
//   [auto: with modified Newton predicted, or floor when the system prescribes displacements (theory §5.8); else
//   residual] and floor_margin [1.5] (theory §5.3), predict_factor [1] (certify = predicted: safety factor on
//   the predicted residual, theory §5.4), cc_tol [1e-14], e_floor [1e-20], step_tol [1e-14] (certify = energy:
//   em-galpha's modified-Newton stopping rule, theory §5.10),
//   correction [true] (false = the paper's force without the §3 correction: for tests that must fail).
// Checkpoints (docs/architecture.md "Checkpoints and resume"): save/restore continue bitwise, with modified
// Newton too; a stop request (SIGINT, --max-wall) is honoured at the next step boundary.
// Stopping (theory §5): the scaled residual ‖r‖∞ / (‖inertia‖∞ + ‖F*‖∞ + ‖F_ext‖∞) ≤ res_tol, or, once it is
// below stall_tol, an iteration that does not reduce the best residual by stall_ratio (the round-off floor of
// the co-rotational force), accepted with a fresh K̄, once the corrections have shrunk by stall_step
// relative to the first, or at the recent steps' floor (§5.7); the last iterate is accepted (docs/theory/exact-energy-momentum.md §5, §5.1). With
// certify = floor that iterate is accepted without evaluating its residual, once the one before it is
// seen to be at the floor (§5.3). certify = predicted (modified Newton's default) accepts one correction
// earlier, once the contraction predicts the floor for the iterate (§5.4, §5.8): fewer iterations, a larger
// (still round-off-sized, but one-signed) energy error; certify = floor is the choice for long stiff runs.
// certify = energy (opt-in, §5.10) stops by em-galpha's rule instead (the energy of the correction against the
// paper's relative test, an absolute floor and its estimate, or a round-off-sized correction): em-galpha's
// iterations on the benchmarks at a similar energy error there, but 1e-9 to 1e-7 on long runs of stiff bodies.
#pragma once

#include "integrators/integrator.hpp"

namespace shelldyn {

std::unique_ptr<Integrator> make_em_exact(IntegratorSettings& settings, double dt);

// What em-exact measured beyond StepReport (for tests and studies): read through
// dynamic_cast<const EmExactDiagnostics*>(integrator.get()).
class EmExactDiagnostics {
 public:
  virtual ~EmExactDiagnostics() = default;
  struct Data {
    double dissipation = 0.0;       // Σ over steps of ξ ΔuᵀGΔu (energy removed, ≥ 0)
    double min_step_dissipation = 0.0;  // smallest per-step dissipation seen (≥ 0 by theory §6)
    double max_residual = 0.0;      // largest accepted scaled residual of any step
    double max_beta_z = 0.0;        // largest relative size of the energy correction β z
    long rigid_guards = 0;          // element-steps treated as rigid (β = 0)
    // Σ over steps of Δuᵀr, the work of the Newton residual r at the accepted iterate. By the energy
    // identity (docs/theory/exact-energy-momentum.md §4) this is the whole change of K + V + D − W_ext.
    // Summed over the steps whose accepted iterate had its residual evaluated; the steps that certify =
    // floor or predicted ended on its floor or prediction test accept u_k without its residual, and are
    // counted instead.
    double residual_work = 0.0;
    long unevaluated_steps = 0;
    // Steps accepted only after a retry in the other metric of the correction (w = 1 or the system's), which then
    // stays in use (docs/theory/newton-iteration.md §4); their failed attempts count in StepReport::rejected_steps.
    long metric_switches = 0;
  };
  virtual const Data& diagnostics() const = 0;
};

}  // namespace shelldyn
