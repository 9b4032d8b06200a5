#include "integrators/baselines/sundials_baseline.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

namespace {
std::string num(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", x);
  return b;
}
}  // namespace

SundialsBaseline::SundialsBaseline(std::string name, IntegratorSettings& s) : name_(std::move(name)) {
  rtol_ = s.get("rtol", 1e-6);
  atol_ = s.get("atol", 0.0);
  length_scale_ = s.get("length_scale", 0.0);
  time_scale_ = s.get("time_scale", 0.0);
  max_step_ = s.get("max_step", 0.0);
  init_step_ = s.get("init_step", 0.0);
  max_steps_ = s.get("max_steps", 1e8);
  dt_min_ = s.get("dt_min", 0.0);
  chart_overshoot_ = s.get("chart_overshoot", 0.05);
  mass_solver_ = s.get("mass_solver", "eigen-ldlt");
  mass_reuse_ = s.get("mass_reuse", true);
  progress_every_ = s.get("progress_every", 10.0);
  check_tolerances(name_, rtol_, atol_ > 0.0 ? atol_ : rtol_);
  if (!(atol_ >= 0.0)) throw std::invalid_argument(name_ + ": atol must be >= 0 (0 = rtol/1000), got " + num(atol_));
  if (!(length_scale_ >= 0.0) || !(time_scale_ >= 0.0))
    throw std::invalid_argument(name_ + ": length_scale and time_scale must be >= 0 (0 = automatic)");
  if (!(chart_overshoot_ >= 0.0 && chart_overshoot_ < 0.3))
    throw std::invalid_argument(name_ + ": chart_overshoot must be in [0, 0.3), got " + num(chart_overshoot_));
  if (!(max_step_ >= 0.0) || !(init_step_ >= 0.0))
    throw std::invalid_argument(name_ + ": max_step and init_step must be >= 0 (0 = the solver's choice)");
  if (!(max_steps_ >= 1.0)) throw std::invalid_argument(name_ + ": max_steps must be >= 1");
  if (!(dt_min_ >= 0.0) || !std::isfinite(dt_min_))
    throw std::invalid_argument(name_ + ": dt_min must be >= 0 (0 = 1e-7 of the output interval), got " + num(dt_min_));
  if (!(progress_every_ >= 0.0)) throw std::invalid_argument(name_ + ": progress_every must be >= 0 (seconds; 0 = off)");
  if (mass_solver_ != "eigen-ldlt" && mass_solver_ != "cholmod")
    throw std::invalid_argument(name_ + ": mass_solver '" + mass_solver_ +
                                "' is not valid (the mass matrix is SPD: use eigen-ldlt or cholmod)");
}

std::vector<std::pair<std::string, std::string>> SundialsBaseline::settings() const {
  auto out = resolved_;
  out.insert(out.end(), tolerance_report_.begin(), tolerance_report_.end());
  return out;
}

double SundialsBaseline::chart_root(const double* y) {
  fos_->unpack(y, work_);
  return sys_->chart_margin(work_) + chart_overshoot_;
}

void SundialsBaseline::initialize(SemiDiscreteSystem& system, State& state) {
  // Prescribed displacement histories (docs/manual.md §2.12) are not part of the first-order form: refuse them
  // rather than hold those DOFs at 0 (runs of a case are refused earlier, by make_case_integrator).
  if (system.has_prescribed_motion())
    throw std::invalid_argument(name_ + ": prescribed displacement histories (prescribed_displacements) are not supported "
                                        "by this integrator (use em-galpha, em-exact, galpha, midpoint or newmark)");
  // Joints: only ida-bdf carries them (GGL, ida_bdf.hpp); the explicit ARKODE baselines would drift off them.
  if (system.num_constraints() > 0 && !supports_constraints())
    throw std::invalid_argument(name_ + ": cannot enforce joints (" + std::to_string(system.num_constraints()) +
                                " constraint rows); use ida-bdf or a conserving integrator that supports them");
  sys_ = &system;
  n_ = system.num_dofs();
  if (!ctx_) ctx_ = std::make_unique<SunContext>();  // one context per integrator object
  fos_ = std::make_unique<FirstOrderSystem>(system, mass_solver_, mass_reuse_);
  // A director past its chart's margin at the start: switch first (docs/theory.md §2.3).
  if (system.chart_margin(state) < 0.0) system.rechart(state);
  fos_->acceleration(state.t, state, state.a);
  w_ = w_out_ = d_ = d_out_ = 0.0;
  t_ = state.t;
  work_ = state;

  // Absolute tolerances per variable kind (header).
  const double lt = system.loads_end();
  (void)lt;  // τ = loads_end was too loose for bodies that barely move (hemisphere at ρ = 1000): τ = 1 s
  const double tau = time_scale_ > 0.0 ? time_scale_ : 1.0;
  const FirstOrderSystem::ToleranceScales sc = fos_->tolerance_scales(state, length_scale_, tau);
  const double atol = atol_ > 0.0 ? atol_ : rtol_ / 1000.0;
  atol_v_ = make_serial_vector(fos_->size(), *ctx_);
  fos_->absolute_tolerances(sc, atol, data(atol_v_.get()));
  tolerance_report_ = {{"length_scale", num(sc.length)},
                       {"time_scale", num(sc.time)},
                       {"atol_translation", num(atol * sc.length)},
                       {"atol_director", num(sc.shell ? atol : std::nan(""))},
                       {"atol_velocity", num(atol * sc.velocity)},
                       {"atol_director_rate", num(sc.shell ? atol / sc.time : std::nan(""))},
                       {"atol_work", num(atol * sc.energy)}};
  create_solver(system, state);
  last_progress_ = std::chrono::steady_clock::now();
}

void SundialsBaseline::save(IntegratorCheckpoint& c) const {
  c.exact = false;
  c.scalars["W_ext"] = w_out_;
  c.scalars["W_damp"] = d_out_;
}

void SundialsBaseline::restore(SemiDiscreteSystem& system, State& state, const IntegratorCheckpoint& c) {
  if (!fos_) throw std::logic_error(name_ + ": restore() before initialize()");
  sys_ = &system;
  w_ = w_out_ = c.scalar("W_ext");
  d_ = d_out_ = c.scalars.count("W_damp") ? c.scalar("W_damp") : 0.0;  // checkpoints before W_damp: undamped
  StepReport ignored;
  restart_from(state, ignored);
}

void SundialsBaseline::restart_from(State& s, StepReport& rep) {
  add_counters(rep);
  t_ = s.t;
  fos_->acceleration(s.t, s, s.a);
  work_ = s;
  pack(s);
  reinit();
  rebase_counters();
  ++rep.reinitializations;
}

void SundialsBaseline::progress(double t_out, const StepReport& rep) {
  if (!progress_log_ || progress_every_ <= 0.0) return;
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_progress_).count() < progress_every_) return;
  last_progress_ = now;
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s | (inside the output interval) t = %.6g -> %.6g  step size %.3g  steps %ld and evaluations %ld in this interval",
                progress_label_.c_str(), t_, t_out, last_step(), rep.steps, rep.rhs_evaluations);
  if (progress_in_place_)
    *progress_log_ << '\r' << buf << "\x1b[K" << std::flush;
  else
    *progress_log_ << buf << std::endl;
}

StepReport SundialsBaseline::advance(SemiDiscreteSystem& system, State& state, double t_out) {
  if (!fos_) throw std::logic_error(name_ + ": advance() before initialize()");
  const auto wall0 = std::chrono::steady_clock::now();
  sys_ = &system;
  StepReport rep;
  const long fact0 = factorizations();
  // The caller may have re-charted or replaced the state between calls: re-initialize from it then.
  if (!state_in_sync(state, t_, work_, y(), n_)) restart_from(state, rep);
  if (t_out < t_) {
    std::ostringstream os;
    os << name_ << ": t_out = " << t_out << " is before the current time " << t_;
    throw std::invalid_argument(os.str());
  }
  const double t_tol = 1e-12 * std::max(1.0, std::abs(t_out));
  if (t_out - t_ > t_tol) set_stop_time(t_out);
  // Step-count guard (header, dt_min): an interval of length T needs at most T/dt_min steps; an integrator that
  // takes more (or 1000 steps in a row below dt_min) is crawling, e.g. under a load far too large for the model.
  const double t_start = t_, dt_min = dt_min_ > 0.0 ? dt_min_ : 1e-7 * (t_out - t_);
  const double guard = std::ceil((t_out - t_) / std::max(dt_min, 1e-300)) + 1000.0;
  double taken = 0.0, below = 0.0;
  while (t_out - t_ > t_tol) {
    errors_.clear();
    sundials_message_.clear();
    double tret = t_;
    const int flag = one_step(t_out, tret);
    if (flag < 0) {
      add_counters(rep);
      fail(flag, tret, "");
    }
    t_ = tret;
    if (!all_finite(y(), fos_->size())) {
      add_counters(rep);
      fail(0, tret, "non-finite solution");
    }
    if (stop_requested()) {  // signal or --max-wall: abandon the interval, `state` stays the last output state
      add_counters(rep);
      std::ostringstream os;
      os << name_ << ": stopped on request at t = " << t_ << " (state kept at t = " << state.t << ")";
      throw RunInterrupted(os.str());
    }
    taken += 1.0;
    below = last_step() < dt_min ? below + 1.0 : 0.0;
    if (taken > guard || below >= 1000.0) {
      add_counters(rep);
      std::ostringstream os;
      os.precision(3);
      os << name_ << ": crawling at t = " << t_ << " (";
      if (below >= 1000.0)
        os << "1000 steps below dt_min = " << dt_min << ", last " << last_step();
      else
        os << taken << " steps since t = " << t_start << ", more than the interval / dt_min = " << dt_min;
      os << "); raise rtol, lower dt_min or use a fixed-step integrator";
      throw StepFailure(os.str());
    }
    const StepOutcome what = outcome(flag);
    if (what == StepOutcome::reached) break;
    if (what == StepOutcome::root) {
      ++rep.root_events;
      unpack(work_);
      work_.t = t_;
      if (!acceleration_in_y()) fos_->acceleration(t_, work_, work_.a);
      const int switched = system.rechart(work_);
      rep.chart_switches += switched;
      if (switched > 0) {
        add_counters(rep);
        pack(work_);
        reinit();
        rebase_counters();
        ++rep.reinitializations;
        set_stop_time(t_out);
      }
    }
    if (progress_log_) {
      add_counters(rep);
      progress(t_out, rep);
    }
  }
  add_counters(rep);
  unpack(work_);
  work_.t = t_out;
  t_ = t_out;
  if (!acceleration_in_y()) fos_->acceleration(t_, work_, work_.a);  // state.a = v̇(t_out)
  state = work_;
  w_out_ = w_;
  d_out_ = d_;
  rep.last_dt = last_step();
  rep.factorizations = factorizations() - fact0;
  rep.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return rep;
}

}  // namespace shelldyn
