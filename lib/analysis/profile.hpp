// Opt-in accounting of where a time step's cost goes (benchmarks/bench_step_breakdown.cpp).
//
// A handful of code sections (the sparse factorization, the tangent assembly, the residual's element
// work, ...) open a profile::Scope; when profiling is enabled the scope adds the process CPU time
// (all threads, CLOCK_PROCESS_CPUTIME_ID), the wall time and one call to its section's totals. When
// disabled (the default) a Scope costs one relaxed atomic load. Sections must not nest (each instrumented
// call site is a leaf of the step), so the totals add up and "the rest" of a step is Newton overhead.
// Scopes are opened from the thread that drives the integrator only (element loops are inside them).
#pragma once

#include <array>
#include <string>

namespace shelldyn::profile {

enum class Section : int {
  factorize,        // numeric factorization of an iteration matrix (LinearSolver::factorize)
  analyze,          // ordering + symbolic analysis (LinearSolver::analyze)
  solve,            // triangular solves with a factorization (LinearSolver::solve)
  krylov,           // preconditioned Krylov iterations outside the solves (matrix-vector products)
  tangent,          // element tangents (+ forces computed with them) and their assembly
  internal_force,   // element internal forces alone and their assembly
  inertia,          // M a + F_m (element-wise) in residuals
  mass,             // assembly of the mass matrix
  combine,          // K̄ = c M + (1 − α_f) K, Dirichlet rows/columns
  external,         // external loads and load stiffness
  step_state,       // per-step element state (frames, element mass at u_n, ...) computed once per step
  count_
};
constexpr int kSections = static_cast<int>(Section::count_);
const char* name(Section s);

struct Totals {
  double cpu_s = 0.0, wall_s = 0.0;
  long calls = 0;
};

void enable(bool on);
bool enabled();
void reset();
Totals totals(Section s);

double process_cpu_seconds();  // CLOCK_PROCESS_CPUTIME_ID
double wall_seconds();         // steady clock

class Scope {
 public:
  explicit Scope(Section s);
  ~Scope();
  Scope(const Scope&) = delete;
  Scope& operator=(const Scope&) = delete;

 private:
  Section s_;
  bool on_;
  double cpu0_ = 0.0, wall0_ = 0.0;
};

}  // namespace shelldyn::profile
