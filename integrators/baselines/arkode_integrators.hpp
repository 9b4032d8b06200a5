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
// given a user linear-system function (ARKStepSetLinSysFn) and a placeholder SUNMatrix with a callback
// SUNLinearSolver (integrators/sundials/callback_linear_solver.hpp): ARKODE keeps its own setup heuristics (re-evaluation every 20
// steps, on γ changes > 20 % and after convergence failures), the linear-system function assembles
// K(q) − K_load and M(q) when ARKODE asks for a new Jacobian (jok = false) and only records γ
// otherwise, and the solver solves (I − γJ) x = b with the approximation
//
//     J ≈ [[0, I, 0, 0]; [−M⁻¹K, −M⁻¹C, 0, 0]; [0, 0, 0, 0]; [0, 0, 0, 0]]   (y = [q; v; w; d])
//
// by the Schur complement (symmetric, factorized with linear_solver: eigen-ldlt|cholmod|mumps|klu;
// integrators/baselines/second_order_newton.hpp, shared with ida-bdf, docs/theory/baseline-newton.md §2):
//
//     (M + γC + γ²K) x_q = M (b_q + γ b_v) + γ C b_q,   x_v = (x_q − b_q)/γ,   x_w = b_w,   x_d = b_d,
//
// C the Rayleigh damping matrix (docs/theory.md §8.5; 0 without damping). Omitted from J (they slow Newton,
// they do not change the solution): the rest of −M⁻¹ ∂F_m/∂v (~|ω|), −∂(M⁻¹)/∂q (...) (~ω²), and the w- and
// d-row couplings. Constrained DOFs: x_v,c = b_v,c,
// x_q,c = b_q,c + γ b_v,c, with the K_fc x_q,c coupling moved to the right-hand side.
//
// Step control: adaptive (rtol, atol) by default; `fixed_step: true` takes steps of the case's dt
// (ARKStepSetFixedStep). Explicit fixed-step runs past the stability limit would silently produce NaN
// (docs/dependencies.md §7 item 11): a post-step hook checks every step and the run stops with a StepFailure.
//
// Director charts, tolerances, progress output and the evolve / root-event / re-init loop: shared with
// ida-bdf (integrators/baselines/sundials_baseline.hpp).
//
// Mass solves: every RHS evaluation needs M(q)⁻¹; FirstOrderSystem reuses the last factorization of M as a
// preconditioner of an iterative refinement to a 1e-12 residual and refactorizes only when the refinement
// stalls (mass_reuse, default true; first_order_system.hpp).
//
// Settings (plus the common ones: rtol, atol, length_scale, time_scale, max_step, init_step, max_steps,
// chart_overshoot, mass_solver, mass_reuse, progress_every):
// table [ARKODE_DORMAND_PRINCE_7_4_5 (erk) | ARKODE_ESDIRK547L2SA_7_4_5 (dirk)]; fixed_step [false];
// linear_solver [eigen-ldlt], max_nonlin_iters [3] and lsetup_frequency [0 = ARKODE default, a new
// Jacobian every 20 steps] (dirk only).
#pragma once

#include "integrators/integrator.hpp"

namespace shelldyn {

std::unique_ptr<Integrator> make_arkode_erk(IntegratorSettings& settings, double dt);
std::unique_ptr<Integrator> make_arkode_dirk(IntegratorSettings& settings, double dt);

}  // namespace shelldyn
