// `ida-bdf`: SUNDIALS IDA (variable-order, variable-step BDF) on the residual form of the shell
// semi-discretization (integrators/baselines/first_order_system.hpp), y = [q; v; w; d]:
//
//     F(t, y, ẏ) = [ q̇ − v ;  M(q) v̇ + F_m(q, v) + F_int(q) − F_ext(t, q) ;  ẇ − F_ext·v ;  ḋ − vᵀC v ]
//
// (F_m contains the Rayleigh damping force C v of a damped model, docs/theory.md §8.5; d = W_damp.)
// M(q) is handled exactly (ARKStep cannot: docs/dependencies.md §4.5). Constrained DOFs c keep q̇_c − v_c = 0 and
// replace their momentum row by v̇_c = 0, so every component is differential (IDASetId all ones).
//
// Newton matrix ∂F/∂y + c_j ∂F/∂ẏ (2n + 2 unknowns):
//
//     [ c_j I                      −I                   0     0  ]
//     [ K − K_load  (+ G_q)        c_j M + C  (+ G_v)    0     0  ]      constrained momentum rows: c_j e_cᵀ
//     [ 0                          −F_extᵀ              c_j   0  ]
//     [ 0                          −2 (C v)ᵀ            0     c_j ]
//
// with K the exact tangent of F_int and K_load the symmetric load stiffness (add_load_stiffness).
// What is NOT in the default ("approximate") Jacobian: G_q = ∂(M(q) v̇ + F_m(q, v))/∂q and
// G_v = ∂F_m/∂v − C (the Model provides no derivatives of its inertia terms), and ∂(F_ext·v)/∂q.
// These terms scale like |ω|·c_j M and ω²M against c_j M and K, so omitting them slows Newton (more
// iterations) but does not change the solution. `jacobian: fd-inertia` adds G_q and G_v by forward
// differences of the Model's mass()/inertial() (2n evaluations per Jacobian: for measurements only;
// see tests/integrators/test_ida_bdf.cpp and benchmarks/bench_sundials_baselines.cpp for the cost).
//
// Linear solves: the matrix is never formed. IDA gets a placeholder matrix and a callback solver
// (integrators/sundials/callback_linear_solver.hpp); the Jacobian callback assembles K, M, C (or G_v), F_ext
// and C v, and the solver eliminates the velocity block (integrators/baselines/second_order_newton.hpp,
// docs/theory/baseline-newton.md §3): it factorizes the n × n Schur complement c_j² M + c_j (C + G_v) + K and
// recovers x_v, x_w and x_d from it exactly. With the approximate Jacobian the Schur complement is symmetric:
// linear_solver cholmod (default), eigen-ldlt, mumps or klu; fd-inertia's is not, and needs klu (its default).
// (Before 2026-11-29 ida-bdf factorized the (2n+2)² matrix with KLU: about half of its run time, docs/results.md §7.2.)
//
// Consistent initial ẏ: computed directly, v̇₀ = M(q₀)⁻¹(F_ext − F_int − F_m) with a mass-matrix
// factorization (exact; no IDACalcIC Newton solve). After a chart switch the Model converts (q, v, v̇)
// exactly, so IDAReInit gets a consistent (y, ẏ) again.
//
// Director charts (docs/theory.md §2.3), tolerances, progress output and the evolve / root-event / re-init
// loop: shared with the ARKODE baselines (integrators/baselines/sundials_baseline.hpp). The chart-margin root
// is shifted by chart_overshoot δ (g = margin + δ), so the event fires when a director has turned slightly
// past the diagonal and every node already past it switches in the same event. After a switch the Model
// converts (q, v, v̇) exactly, so IDAReInit gets a consistent (y, ẏ) again.
//
// Tuning (docs/results.md, "Baseline tuning"): max_order 2 by default. The semi-discrete shell is undamped:
// its stiff modes have eigenvalues near the imaginary axis, where BDF3–5 are not stable (they are only
// A(α)-stable); with orders > 2 IDA must resolve every stiff vibration to stay stable, with BDF2 (A-stable) it
// steps over them. The Newton matrix is re-evaluated only when IDA asks (failed convergence, or c_j
// changed by more than delta_cj_lsetup, default 0.25 as in IDA).
//
// Settings (plus the common ones of sundials_baseline.hpp: rtol, atol, length_scale, time_scale, max_step,
// init_step, max_steps, chart_overshoot, mass_solver (initial acceleration), mass_reuse, progress_every):
// max_order [2]; linear_solver [cholmod; klu with fd-inertia]; jacobian: approximate|fd-inertia [approximate];
// delta_cj_lsetup [0.25]; jacobian_reuse [20]: steps for which the assembled blocks K, M, G are reused by
// Newton-matrix setups that only follow a change of c_j (0: assemble at every setup, IDA's own behaviour).
#pragma once

#include "integrators/integrator.hpp"

namespace shelldyn {

std::unique_ptr<Integrator> make_ida_bdf(IntegratorSettings& settings, double dt);

}  // namespace shelldyn
