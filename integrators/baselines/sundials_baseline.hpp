// What the three SUNDIALS baselines (ida-bdf, arkode-erk, arkode-dirk) share: the tolerance settings with
// per-kind absolute tolerances, progress output, and ONE evolve / root-event / re-initialization loop
// (advance()), so that IDA and ARKODE handle director-chart events, restarts and failures identically.
//
// Loop (advance to t_out): if the caller changed the state since the last call (state_in_sync() false),
// restart from it (acceleration computed, solver re-initialized). Then one internal step at a time towards
// t_out with the stop time at t_out (IDA_ONE_STEP / ARK_ONE_STEP): after each step a non-finite y stops the
// run; a root of the chart-margin function g = chart_margin + chart_overshoot (direction −1) re-charts the
// state (spec of SemiDiscreteSystem::rechart) and, when a node switched, re-initializes the solver from the
// converted state; every `progress_every` seconds of wall time a progress line (t, step size, steps,
// evaluations) goes to the progress log, so that long output intervals are not silent.
//
// Tolerances (docs/results.md, "Baseline tuning"): rtol, and absolute tolerances per component
//     atol_k = atol · scale_k,   atol = 0 (default) meaning atol = rtol / 1000,
// with the scales of FirstOrderSystem::tolerance_scales (translations L, director unknowns 1, velocities L/τ,
// director rates 1/τ, external work max(1, K₀ + |V₀|)). L = length_scale [0: the mesh's bounding-box diagonal],
// τ = time_scale [0: 1 s]. The resolved values are reported in
// the settings (run.json) after initialize(): atol_translation, atol_director, atol_velocity,
// atol_director_rate, atol_work, length_scale, time_scale.
//
// Common settings: rtol [1e-6], atol [0 = rtol/1000], length_scale [0 = auto], time_scale [0 = auto],
// max_step [0 = none], init_step [0 = solver's choice], max_steps [1e8], dt_min [0 = 1e-7 of the output interval:
// an output interval of length T may take at most T/dt_min + 1000 steps, and at most 1000 steps in a row below
// dt_min; beyond, the run fails with "crawling" instead of running for days], chart_overshoot [0.05],
// mass_solver [eigen-ldlt], mass_reuse [true] (FirstOrderSystem), progress_every [10 s wall; 0 = off].
#pragma once

#include "integrators/baselines/first_order_system.hpp"
#include "integrators/integrator.hpp"
#include "integrators/integrator_settings.hpp"
#include "integrators/sundials/sundials_support.hpp"

#include <chrono>
#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {

class SundialsBaseline : public Integrator {
 public:
  std::string name() const override { return name_; }
  std::vector<std::pair<std::string, std::string>> settings() const override;
  double external_work() const override { return w_; }
  // W_damp = ∫ vᵀ C v dt, integrated by the solver as the component d of y (first_order_system.hpp).
  double damping_work() const override { return d_; }
  void set_progress_log(std::ostream* log, const std::string& label, bool in_place = false) override {
    progress_log_ = log;
    progress_label_ = label;
    progress_in_place_ = in_place;
  }
  // Checkpoint by re-initialization (docs/architecture.md "Checkpoints and resume"): only W_ext and W_damp
  // at the last output time are saved; restore() restarts SUNDIALS from the saved State as after a chart event.
  // The step-size and order history is lost, so a resumed run agrees with an uninterrupted one to the
  // tolerances (rtol, atol), not bitwise.
  void save(IntegratorCheckpoint& c) const override;
  void restore(SemiDiscreteSystem& system, State& state, const IntegratorCheckpoint& c) override;
  void initialize(SemiDiscreteSystem& system, State& state) final;
  StepReport advance(SemiDiscreteSystem& system, State& state, double t_out) final;

 protected:
  SundialsBaseline(std::string name, IntegratorSettings& s);

  // What the loop asks of IDA / ARKStep. Flags: the solver's own return values.
  enum class StepOutcome { step, reached, root };
  virtual void create_solver(SemiDiscreteSystem& system, const State& state) = 0;  // y (and ẏ) packed
  virtual void set_stop_time(double t_out) = 0;
  virtual int one_step(double t_out, double& tret) = 0;  // < 0: failure (solver flag)
  virtual StepOutcome outcome(int flag) const = 0;
  virtual void pack(const State& s) = 0;              // s (with s.a) -> y (and ẏ)
  virtual void reinit() = 0;                          // re-initialize the solver at t_ from the packed y
  virtual void unpack(State& s) = 0;                  // y (and ẏ) -> s.u, s.v, w_, d_ (and s.a where ẏ holds it)
  virtual bool acceleration_in_y() const = 0;         // IDA: ẏ holds v̇; ARKStep: compute it
  virtual void add_counters(StepReport& rep) = 0;     // counters since the last call, then rebase
  virtual void rebase_counters() = 0;                 // after a re-initialization (counters restart at 0)
  virtual long factorizations() const = 0;
  virtual double last_step() const = 0;
  [[noreturn]] virtual void fail(int flag, double t, const std::string& what) = 0;
  virtual const double* y() const = 0;

  // The root function all three use.
  double chart_root(const double* y);

  // settings
  std::string name_, mass_solver_;
  double rtol_ = 1e-6, atol_ = 0.0, length_scale_ = 0.0, time_scale_ = 0.0, max_step_ = 0.0, init_step_ = 0.0,
         max_steps_ = 1e8, dt_min_ = 0.0, chart_overshoot_ = 0.05, progress_every_ = 10.0;
  bool mass_reuse_ = true;
  std::vector<std::pair<std::string, std::string>> resolved_, tolerance_report_;

  // run state
  SemiDiscreteSystem* sys_ = nullptr;
  std::unique_ptr<SunContext> ctx_;
  std::unique_ptr<FirstOrderSystem> fos_;
  Index n_ = 0;
  State work_;  // current charts; u, v, a are scratch inside callbacks
  double t_ = 0.0, w_ = 0.0, d_ = 0.0;  // d_: W_damp
  NVectorPtr atol_v_;
  CallbackError errors_;
  std::string sundials_message_;

 private:
  void restart_from(State& s, StepReport& rep);
  void progress(double t_out, const StepReport& rep);

  std::ostream* progress_log_ = nullptr;
  std::string progress_label_;
  bool progress_in_place_ = false;
  double w_out_ = 0.0, d_out_ = 0.0;  // W_ext, W_damp at the end of the last advance() (checkpoints)
  std::chrono::steady_clock::time_point last_progress_;
};

}  // namespace shelldyn
