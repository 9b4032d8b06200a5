// `arkode-erk` and `arkode-dirk`: SUNDIALS ARKStep (explicit / diagonally implicit Runge–Kutta) on the
// first-order form of the shell semi-discretization (integrators/baselines/first_order_system.hpp), y = [q; v; w]:
//
//     ẏ = f(t, y) = [ v ;  M(q)⁻¹ (F_ext − F_int − F_m) ;  F_ext·v ]
//
// ARKStep's mass matrix cannot depend on y in SUNDIALS 6.4.1 (docs/dependencies.md §4.5), so M(q) is factorized
// inside every RHS evaluation (mass_solver: eigen-ldlt|cholmod, one symbolic analysis per run);
// constrained DOFs get v̇_c = 0.
//
// arkode-dirk Newton matrix. The exact Jacobian of M⁻¹(...) is dense and is never formed. ARKODE is
// given a user linear-system function (ARKStepSetLinSysFn) and a matrix-less custom SUNMatrix/
// SUNLinearSolver pair (type DIRECT): ARKODE keeps its own setup heuristics (re-evaluation every 20
// steps, on γ changes > 20 % and after convergence failures), the linear-system function assembles
// K(q) − K_load and M(q) when ARKODE asks for a new Jacobian (jok = false) and only records γ
// otherwise, and the solver solves (I − γJ) x = b with the approximation
//
//     J ≈ [[0, I, 0]; [−M⁻¹K, 0, 0]; [0, 0, 0]]
//
// by the Schur complement (symmetric, factorized with linear_solver: eigen-ldlt|cholmod|klu):
//
//     (M + γ²K) x_q = M (b_q + γ b_v),   x_v = (x_q − b_q)/γ,   x_w = b_w.
//
// Omitted from J (they slow Newton, they do not change the solution): −M⁻¹ ∂F_m/∂v (~|ω|),
// −∂(M⁻¹)/∂q (...) (~ω²), and the w-row couplings. Constrained DOFs: x_v,c = b_v,c,
// x_q,c = b_q,c + γ b_v,c, with the K_fc x_q,c coupling moved to the right-hand side.
//
// Step control: adaptive (rtol, atol) by default; `fixed_step: true` takes steps of the case's dt
// (ARKStepSetFixedStep). Explicit fixed-step runs past the stability limit would silently produce NaN
// (docs/dependencies.md §7 item 11): a post-step hook checks every step and the run stops with a StepFailure.
//
// Director charts (docs/theory.md §2.3): root function g = chart_margin(state(y)) + δ (δ = chart_overshoot, see
// ida_bdf.hpp), direction −1; at a root the state is written back, system.rechart() converts it, ARKStepReInit restarts from it.
//
// Settings: table [ARKODE_DORMAND_PRINCE_7_4_5 (erk) | ARKODE_ESDIRK547L2SA_7_4_5 (dirk)];
// rtol [1e-6]; atol [1e-9] (scaled per block as in FirstOrderSystem::absolute_tolerances);
// fixed_step [false]; max_step [0 = none]; init_step [0 = ARKODE's choice]; max_steps [1e8];
// mass_solver [eigen-ldlt]; linear_solver [eigen-ldlt] (dirk only); max_nonlin_iters [3] and lsetup_frequency
// [0 = ARKODE default, a new Jacobian every 20 steps] (dirk only);
// chart_overshoot [0.05].
#pragma once

#include "integrators/integrator.hpp"

namespace shelldyn {

std::unique_ptr<Integrator> make_arkode_erk(IntegratorSettings& settings, double dt);
std::unique_ptr<Integrator> make_arkode_dirk(IntegratorSettings& settings, double dt);

}  // namespace shelldyn
