// Integrators written in Python (docs/tutorials/10-python.md §4): a Python class (or any callable
// factory(settings, dt) returning an object) wrapped in a C++ shelldyn::Integrator and registered by name
// through the open registry (integrators/runs/registry.hpp), so that run, compare and study run it beside
// the built-ins with the same history.csv, run.json and plots.
//
// The object provides
//   initialize(system, state)            optional: make the state consistent (e.g. a0)
//   step(system, state, h)               one step of size h from state.t; updates state.u, v, a in place
//                                        (the wrapper then sets state.t += h); may return a dict of
//                                        StepReport counters (nonlinear_iterations, rhs_evaluations, ...)
//   or advance(system, state, t_out)     the whole output interval (the object moves state.t itself);
//                                        returns a dict of counters (steps, ...) or None
//   external_work                        a float attribute or a method: W_ext since initialize()
// and optionally settings() (list of (key, value) or dict; default: what the constructor read from the
// settings, plus dt), hysteresis (charts re-selected before every step of the step() loop, as the
// Newmark family does, docs/theory.md §2.3; default 1.0), damping_work, supports_prescribed_motion.
// With step(), the wrapper owns the time grid: steps of dt, the last one of an output interval shortened
// to land on t_out (the rule of em_generalized_alpha.cpp), and stop requests are honoured between steps.
//
// Every call into Python holds the GIL; a Python exception becomes the C++ exception the run machinery
// expects (see rethrow_python_error), with the integrator's name and the method in the message, so a run
// that fails in Python ends with run.json "incomplete: ..." like any other failure.
#include "python/src/bindings.hpp"

#include "integrators/integrator.hpp"
#include "integrators/integrator_settings.hpp"
#include "integrators/runs/registry.hpp"

#include <pybind11/stl.h>

#include <chrono>
#include <set>
#include <sstream>

namespace shelldyn::python {
namespace {

// The settings handed to a Python constructor: readable only during the factory call.
struct PySettings {
  IntegratorSettings* s = nullptr;
  std::string name;
  IntegratorSettings& get() const {
    if (!s) throw std::runtime_error("integrator settings can only be read inside the integrator's constructor");
    return *s;
  }
};

std::string text_of(const py::handle& v) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::float_>(v)) {
    std::ostringstream os;
    os.precision(17);
    os << v.cast<double>();
    return os.str();
  }
  return py::str(v);
}

void add_counters(const py::handle& r, StepReport& rep) {
  if (r.is_none()) return;
  const py::dict d = py::cast<py::dict>(r);
  for (auto item : d) {
    const std::string k = py::str(item.first);
    const auto as_long = [&] { return py::cast<long>(item.second); };
    if (k == "steps") rep.steps += as_long();
    else if (k == "rejected_steps") rep.rejected_steps += as_long();
    else if (k == "nonlinear_iterations") rep.nonlinear_iterations += as_long();
    else if (k == "linear_setups") rep.linear_setups += as_long();
    else if (k == "factorizations") rep.factorizations += as_long();
    else if (k == "rhs_evaluations") rep.rhs_evaluations += as_long();
    else if (k == "chart_switches") rep.chart_switches += as_long();
    else if (k == "residual_norm") rep.residual_norm = py::cast<double>(item.second);
    else if (k == "last_dt") rep.last_dt = py::cast<double>(item.second);
    else
      throw std::invalid_argument("unknown step counter '" + k +
                                  "' (valid: steps, rejected_steps, nonlinear_iterations, linear_setups, factorizations, "
                                  "rhs_evaluations, chart_switches, residual_norm, last_dt)");
  }
}

class PythonIntegrator final : public Integrator {
 public:
  PythonIntegrator(std::string name, py::object obj, std::vector<std::pair<std::string, std::string>> resolved, double dt)
      : name_(std::move(name)), obj_(std::move(obj)), resolved_(std::move(resolved)), dt_(dt) {
    bool has_dt = false;
    for (const auto& kv : resolved_) has_dt = has_dt || kv.first == "dt";
    if (!has_dt) {
      std::ostringstream os;
      os.precision(17);
      os << dt_;
      resolved_.insert(resolved_.begin(), {"dt", os.str()});
    }
    has_step_ = py::hasattr(obj_, "step");
    has_advance_ = py::hasattr(obj_, "advance");
    if (!has_step_ && !has_advance_)
      throw std::invalid_argument(name_ + ": the Python integrator has neither step(system, state, h) nor advance(system, state, t_out)");
    if (py::hasattr(obj_, "hysteresis")) hysteresis_ = py::cast<double>(obj_.attr("hysteresis"));
    if (!(hysteresis_ >= 1.0)) throw std::invalid_argument(name_ + ": hysteresis must be >= 1");
  }

  ~PythonIntegrator() override {
    if (!Py_IsInitialized()) {  // interpreter gone (process exit): leak rather than touch it
      obj_.release();
      sys_obj_.release();
      return;
    }
    py::gil_scoped_acquire g;
    if (sys_view_) sys_view_->sys = nullptr;  // a System kept by Python now raises instead of dangling
    sys_obj_ = py::object();
    obj_ = py::object();
  }

  std::string name() const override { return name_; }

  std::vector<std::pair<std::string, std::string>> settings() const override {
    py::gil_scoped_acquire g;
    if (!py::hasattr(obj_, "settings")) return resolved_;
    return guarded("settings", [&] {
      py::object r = obj_.attr("settings");
      if (PyCallable_Check(r.ptr())) r = r();
      std::vector<std::pair<std::string, std::string>> out;
      if (py::isinstance<py::dict>(r)) {
        for (auto item : py::cast<py::dict>(r)) out.emplace_back(py::str(item.first), text_of(item.second));
      } else {
        for (auto item : r) {
          const py::tuple kv = py::cast<py::tuple>(item);
          out.emplace_back(py::str(kv[0]), text_of(kv[1]));
        }
      }
      return out;
    });
  }

  void initialize(SemiDiscreteSystem& sys, State& state) override {
    py::gil_scoped_acquire g;
    view(sys);
    if (py::hasattr(obj_, "initialize"))
      guarded("initialize", [&] { obj_.attr("initialize")(sys_obj_, py::cast(&state, py::return_value_policy::reference)); });
  }

  StepReport advance(SemiDiscreteSystem& sys, State& s, double t_out) override {
    const auto start = std::chrono::steady_clock::now();
    StepReport rep;
    if (has_advance_ && !has_step_) {
      py::gil_scoped_acquire g;
      view(sys);
      guarded("advance", [&] {
        add_counters(obj_.attr("advance")(sys_obj_, py::cast(&s, py::return_value_policy::reference), t_out), rep);
      });
    } else {
      // The fixed-step loop of the Newmark family (em_generalized_alpha.cpp advance/step): charts are
      // re-selected between steps only (docs/theory.md §2.3), the last step lands exactly on t_out.
      while (s.t < t_out - 1e-12 * dt_) {
        double h = std::min(dt_, t_out - s.t);
        if (t_out - (s.t + h) < 1e-9 * dt_) h = t_out - s.t;
        rep.chart_switches += sys.rechart(s, hysteresis_);
        {
          py::gil_scoped_acquire g;
          view(sys);
          guarded("step", [&] {
            add_counters(obj_.attr("step")(sys_obj_, py::cast(&s, py::return_value_policy::reference), h), rep);
          });
        }
        s.t = s.t + h;
        ++rep.steps;
        rep.last_dt = h;
        if (stop_requested()) break;
      }
    }
    rep.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return rep;
  }

  double external_work() const override { return work_attribute("external_work", true); }
  double damping_work() const override { return work_attribute("damping_work", false); }
  double prescribed_work() const override { return work_attribute("prescribed_work", false); }
  bool supports_prescribed_motion() const override {
    py::gil_scoped_acquire g;
    return py::hasattr(obj_, "supports_prescribed_motion") && py::cast<bool>(obj_.attr("supports_prescribed_motion"));
  }

 private:
  template <class F>
  auto guarded(const char* what, F&& f) const -> decltype(f()) {
    try {
      return f();
    } catch (py::error_already_set& e) {
      rethrow_python_error(e, name_ + ": " + what + ": ");
    } catch (py::cast_error& e) {
      throw std::runtime_error(name_ + ": " + what + ": " + e.what());
    }
  }

  double work_attribute(const char* attr, bool required) const {
    py::gil_scoped_acquire g;
    if (!py::hasattr(obj_, attr)) {
      if (required)
        throw std::runtime_error(name_ + ": the Python integrator has no '" + attr + "' (a float attribute or a method)");
      return 0.0;
    }
    return guarded(attr, [&] {
      py::object r = obj_.attr(attr);
      if (PyCallable_Check(r.ptr())) r = r();
      return py::cast<double>(r);
    });
  }

  // The Python System for `sys` (made once per run; GIL held).
  void view(SemiDiscreteSystem& sys) {
    if (sys_view_ && sys_view_->sys == &sys) return;
    if (sys_view_) sys_view_->sys = nullptr;
    sys_obj_ = py::cast(PySystem(nullptr, &sys, dynamic_cast<Model*>(&sys)));
    sys_view_ = sys_obj_.cast<PySystem*>();
  }

  std::string name_;
  py::object obj_;
  std::vector<std::pair<std::string, std::string>> resolved_;
  double dt_;
  double hysteresis_ = 1.0;
  bool has_step_ = false, has_advance_ = false;
  py::object sys_obj_;
  PySystem* sys_view_ = nullptr;
};

// Names registered from Python: unregistered at interpreter exit, before the registry (a C++ static)
// would destroy Python objects without an interpreter.
std::set<std::string>& python_names() {
  static auto* s = new std::set<std::string>();
  return *s;
}

void register_python_integrator(const std::string& name, py::object factory, const std::string& summary,
                                const std::string& origin, bool replace) {
  if (!PyCallable_Check(factory.ptr()))
    throw std::invalid_argument("register_integrator('" + name + "'): the factory must be a class or a callable (settings, dt)");
  if (replace && python_names().count(name)) {
    unregister_integrator(name);
    python_names().erase(name);
  }
  std::shared_ptr<py::object> holder(new py::object(std::move(factory)), [](py::object* o) {
    if (!Py_IsInitialized()) return;  // leak at process exit
    py::gil_scoped_acquire g;
    delete o;
  });
  IntegratorFactory make = [holder, name](IntegratorSettings& settings, double dt) -> std::unique_ptr<Integrator> {
    py::gil_scoped_acquire g;
    auto proxy = std::make_shared<PySettings>();
    proxy->s = &settings;
    proxy->name = name;
    py::object inst;
    try {
      inst = (*holder)(py::cast(proxy), dt);
    } catch (py::error_already_set& e) {
      proxy->s = nullptr;
      rethrow_python_error(e, name + ": ");
    }
    proxy->s = nullptr;
    return std::make_unique<PythonIntegrator>(name, std::move(inst), settings.resolved(), dt);
  };
  register_integrator(name, summary, std::move(make), origin);
  python_names().insert(name);
}

}  // namespace

void register_test_integrators(py::module_& m);

void bind_python_integrators(py::module_& m) {
  py::class_<PySettings, std::shared_ptr<PySettings>>(
      m, "IntegratorSettings",
      "The settings of a run's integrator (case file block + overrides), handed to a Python integrator's constructor. "
      "get(key, default) reads one with the type of the default; keys never read are refused after the constructor "
      "returns, listing the valid ones (as for the built-ins).")
      .def_property_readonly("name", [](const PySettings& p) { return p.name; })
      .def(
          "get",
          [](const PySettings& p, const std::string& key, const py::object& fallback) -> py::object {
            IntegratorSettings& s = p.get();
            if (py::isinstance<py::bool_>(fallback)) return py::bool_(s.get(key, fallback.cast<bool>()));
            if (py::isinstance<py::int_>(fallback)) return py::int_(s.get(key, fallback.cast<int>()));
            if (py::isinstance<py::float_>(fallback)) return py::float_(s.get(key, fallback.cast<double>()));
            if (py::isinstance<py::str>(fallback)) return py::str(s.get(key, fallback.cast<std::string>()));
            throw std::invalid_argument("IntegratorSettings.get('" + key + "'): the default must be a bool, int, float or str");
          },
          py::arg("key"), py::arg("default"));

  m.def("_register_integrator", &register_python_integrator, py::arg("name"), py::arg("factory"), py::arg("summary"),
        py::arg("origin"), py::arg("replace") = false);
  m.def("_python_integrator_names", [] { return std::vector<std::string>(python_names().begin(), python_names().end()); });
  m.def("_unregister_python_integrators", [] {
    for (const auto& n : python_names()) unregister_integrator(n);
    python_names().clear();
  });
  register_test_integrators(m);
}

}  // namespace shelldyn::python
