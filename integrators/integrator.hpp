// The pluggable time-integrator interface (architecture.md §4.3) and the registry that makes integrators
// by name (`integrator.name` in a case file or `--integrator` on the command line).
//
// One Integrator object per run. initialize() makes the initial state consistent (e.g. the initial
// acceleration); advance() integrates up to t_out and reports what comparative studies need. Fixed-step
// schemes take steps of the configured dt (the last one shortened to land on t_out); adaptive SUNDIALS
// schemes take as many internal steps as they need and stop at director-chart events through root
// finding. Every integrator accumulates the external work W_ext consistently with its own time
// discretization, so that the total energy H = K + V − W_ext is comparable across integrators.
//
// Errors: a step that cannot be completed (after step cutting, where enabled) throws StepFailure, whose
// message names the integrator, the step, the time, the step size and the last residual; the state is
// then the last converged one.
#pragma once

#include "integrators/integrator_settings.hpp"
#include "lib/model/semi_discrete_system.hpp"
#include "lib/model/state.hpp"

#include <Eigen/Core>

#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

struct StepReport {
  long steps = 0;                 // accepted steps
  long rejected_steps = 0;        // failed / cut / error-test-rejected attempts
  long nonlinear_iterations = 0;  // Newton iterations (implicit schemes)
  long linear_setups = 0;         // Jacobian evaluations handed to the linear solver
  long factorizations = 0;        // numeric factorizations
  long rhs_evaluations = 0;       // residual / right-hand-side evaluations
  long chart_switches = 0;        // nodes whose director chart switched
  long root_events = 0;           // chart events found by root finding (adaptive schemes)
  long reinitializations = 0;     // integrator re-initializations after chart events
  double residual_norm = 0.0;     // last Newton residual norm (scaled max norm)
  double energy_ratio = 0.0;      // last paper eq. 39 ratio cc (em-galpha family)
  double last_dt = 0.0;           // size of the last step taken
  double wall_seconds = 0.0;

  void accumulate(const StepReport& r);
};

class StepFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Thrown by advance() when a stop request (see Integrator::set_stop_request) made it abandon the
// current output interval; the state passed to advance() is then unchanged (the last output state).
class RunInterrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What an integrator carries between advance() calls beyond the State (checkpoint/restart,
// docs/architecture.md "Checkpoints and resume"): named vectors and scalars, stored exactly.
struct IntegratorCheckpoint {
  std::map<std::string, Eigen::VectorXd> vectors;
  std::map<std::string, double> scalars;
  // true: a run restored from it continues bitwise as the uninterrupted run would; false: the
  // integrator restarts from the saved state (e.g. SUNDIALS re-initialization: step-size and order
  // history are lost, results agree to the tolerances only).
  bool exact = false;

  double scalar(const std::string& key) const;                 // throws naming the key if absent
  const Eigen::VectorXd& vector(const std::string& key) const;  // likewise
  // Likewise, and throws naming the key unless the vector has exactly `size` entries, all finite (a damaged file).
  const Eigen::VectorXd& vector(const std::string& key, Index size) const;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual std::string name() const = 0;
  // The settings actually used (defaults included), for run.json and summary tables.
  virtual std::vector<std::pair<std::string, std::string>> settings() const = 0;

  virtual void initialize(SemiDiscreteSystem& system, State& state) = 0;
  virtual StepReport advance(SemiDiscreteSystem& system, State& state, double t_out) = 0;

  // External work done on the system since initialize(), evaluated consistently with the scheme.
  virtual double external_work() const = 0;

  // Where to print progress lines while advance() runs long (adaptive integrators between output times);
  // null: none; in_place: the log is a terminal whose current line the run driver rewrites ('\r'), so
  // write the same way. The default ignores it.
  virtual void set_progress_log(std::ostream* /*log*/, const std::string& /*label*/, bool /*in_place*/ = false) {}
  // Work dissipated by Rayleigh damping so far, Σ Δqᵀ C q̇ with the scheme's own velocity (docs/theory.md
  // §8.5); H = K + V − W_ext + W_damp is then the conserved total. 0 for integrators that do not track it.
  virtual double damping_work() const { return 0.0; }
  // Work done on the system by prescribed displacement histories (docs/theory.md §8.6), Σ r_c Δu_c over the
  // prescribed DOFs with the scheme's own reaction r_c (the residual row of the DOF, at the scheme's
  // midpoint); H = K + V − W_ext − W_presc (+ W_damp) is then the conserved total.
  virtual double prescribed_work() const { return 0.0; }
  // Whether the integrator follows prescribed displacement histories. Cases that have them are refused by
  // integrators that do not (integrators/runs/case_integrator.cpp), never run with the DOFs held at 0.
  virtual bool supports_prescribed_motion() const { return false; }
  // Whether the integrator enforces holonomic constraints (joints: SemiDiscreteSystem::num_constraints() > 0,
  // docs/reference/system-interface.md "Constraints"). The run driver refuses a constrained system with an
  // integrator that does not, naming those that do (integrators/runs/run_driver.cpp).
  virtual bool supports_constraints() const { return false; }

  // The scaled residuals ρ_k = ‖r(u_k)‖∞ / (largest entry of the step's inertial, internal and external forces)
  // of every iterate a Newton-based step evaluated, reported once per accepted step with the step's Newton
  // iterations (corrections). When the last correction was accepted without evaluating its residual, the
  // iterations equal the residuals; otherwise there is one residual more. For studies of the iteration
  // (bench_step_breakdown --residual-trace; docs/theory/exact-energy-momentum.md §5.9). Returns false if the
  // integrator does not report them (the default); an empty function switches the report off.
  using ResidualTrace = std::function<void(const std::vector<double>& scaled, int iterations)>;
  virtual bool set_residual_trace(ResidualTrace /*trace*/) { return false; }

  // Checkpoint/restart. save() is called between advance() calls (or after an advance() that stopped
  // early on a stop request), restore() right after initialize() with the saved State already in
  // `state`. The defaults throw, so a new integrator compiles unchanged and says what is missing.
  virtual void save(IntegratorCheckpoint& out) const;
  virtual void restore(SemiDiscreteSystem& system, State& state, const IntegratorCheckpoint& in);

  // Cooperative stop (SIGINT/SIGTERM, --max-wall; integrators/runs/run_driver.hpp). Integrators poll
  // stop_requested() between steps (fixed-step schemes: advance() then returns early with
  // state.t < t_out at a step boundary) or inside their solver callbacks (SUNDIALS: advance() throws
  // RunInterrupted with the state unchanged). Integrators that never poll finish the output interval.
  void set_stop_request(std::function<bool()> requested) { stop_request_ = std::move(requested); }

 protected:
  bool stop_requested() const { return stop_request_ && stop_request_(); }

 private:
  std::function<bool()> stop_request_;
};

}  // namespace shelldyn
