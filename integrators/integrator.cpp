#include "integrators/integrator.hpp"

namespace shelldyn {

void StepReport::accumulate(const StepReport& r) {
  steps += r.steps;
  rejected_steps += r.rejected_steps;
  nonlinear_iterations += r.nonlinear_iterations;
  linear_setups += r.linear_setups;
  factorizations += r.factorizations;
  rhs_evaluations += r.rhs_evaluations;
  chart_switches += r.chart_switches;
  root_events += r.root_events;
  reinitializations += r.reinitializations;
  residual_norm = r.residual_norm;
  energy_ratio = r.energy_ratio;
  if (r.steps > 0) last_dt = r.last_dt;
  wall_seconds += r.wall_seconds;
}

}  // namespace shelldyn
