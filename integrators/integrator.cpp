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

double IntegratorCheckpoint::scalar(const std::string& key) const {
  const auto it = scalars.find(key);
  if (it == scalars.end()) throw std::runtime_error("checkpoint: integrator scalar '" + key + "' is missing");
  return it->second;
}

const Eigen::VectorXd& IntegratorCheckpoint::vector(const std::string& key) const {
  const auto it = vectors.find(key);
  if (it == vectors.end()) throw std::runtime_error("checkpoint: integrator vector '" + key + "' is missing");
  return it->second;
}

const Eigen::VectorXd& IntegratorCheckpoint::vector(const std::string& key, Index size) const {
  const Eigen::VectorXd& v = vector(key);
  if (v.size() != size || !v.allFinite())
    throw std::runtime_error("checkpoint: integrator vector '" + key + "' has " + std::to_string(v.size()) +
                             " entries or a non-finite one; expected " + std::to_string(size) + " finite entries");
  return v;
}

void Integrator::save(IntegratorCheckpoint&) const {
  throw std::runtime_error("integrator " + name() + " does not support checkpoints (use --checkpoint-every 0)");
}

void Integrator::restore(SemiDiscreteSystem&, State&, const IntegratorCheckpoint&) {
  throw std::runtime_error("integrator " + name() + " does not support checkpoints: rerun from the start");
}

}  // namespace shelldyn
