// The `shelldyn` Python module (docs/tutorials/10-python.md): cases, the semi-discrete system as NumPy/SciPy
// objects, runs/compare/study, and integrators written in Python registered by name.
//
// Memory layout (zero-copy where it allows):
//   - State.u/v/a/pdot are NumPy views of the C++ vectors (Eigen, reference_internal);
//   - returned forces are NumPy arrays the C++ evaluation writes into directly;
//   - matrices are scipy.sparse.csr_matrix whose values array owns the assembled std::vector (moved, not
//     copied) and whose indices/indptr are int32 copies of the fixed pattern made once per system. The
//     C++ storage is CSC with both triangles of a symmetric matrix (lib/linalg/sparse_matrix.hpp), and the CSC
//     arrays of A are the CSR arrays of Aᵀ = A, so no transposition is needed.
//   - an input vector u is copied once into an Eigen::VectorXd (the interface takes const VectorXd&), O(n).
// The GIL is released during every C++ evaluation and run; C++ code calling back into Python (Python
// integrators, progress callbacks) takes it.
#include "python/src/bindings.hpp"

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl_bind.h>

#include "apps/app_common.hpp"
#include "integrators/runs/case_integrator.hpp"
#include "integrators/runs/compare.hpp"
#include "integrators/runs/registry.hpp"
#include "integrators/runs/run_driver.hpp"
#include "integrators/runs/study.hpp"
#include "lib/model/assembler.hpp"
#include "lib/model/discretization.hpp"
#include "lib/io/run_info.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <streambuf>

namespace fs = std::filesystem;

namespace shelldyn::python {

// ---------------------------------------------------------------------------------------------- errors
PyObject* g_error = nullptr;        // shelldyn.Error(RuntimeError)
PyObject* g_input_error = nullptr;  // shelldyn.InputError(Error, ValueError): bad input (std::invalid_argument)
PyObject* g_step_failure = nullptr; // shelldyn.StepFailure(Error)
PyObject* g_run_stopped = nullptr;  // shelldyn.RunStopped(Error)

std::string python_error_text(const py::error_already_set& e) {
  std::string type = "Exception";
  std::string msg;
  try {
    type = py::str(e.type().attr("__name__"));
    msg = py::str(e.value());
  } catch (...) {
    msg = e.what();
  }
  std::string out = type + ": " + msg;
  for (char& c : out)
    if (c == '\n' || c == '\r') c = ' ';
  return out;
}

[[noreturn]] void rethrow_python_error(const py::error_already_set& e, const std::string& prefix) {
  // Messages keep their C++ meaning across the boundary: an InputError (e.g. a bad setting read through
  // IntegratorSettings) stays std::invalid_argument with the same text, so the CLI's attribution
  // (case_integrator.hpp) still names the case file line.
  if (e.matches(g_input_error)) throw std::invalid_argument(std::string(py::str(e.value())));
  if (e.matches(g_step_failure)) throw StepFailure(prefix + std::string(py::str(e.value())));
  if (e.matches(PyExc_ValueError)) throw std::invalid_argument(prefix + python_error_text(e));
  throw std::runtime_error(prefix + python_error_text(e));
}

// ---------------------------------------------------------------------------------------------- system
namespace {
py::object csr_class() {
  static py::object* cls = nullptr;  // leaked on purpose: outlives the interpreter's module teardown
  if (!cls) cls = new py::object(py::module_::import("scipy.sparse").attr("csr_matrix"));
  return *cls;
}
}  // namespace

PySystem::PySystem(std::shared_ptr<void> owner_, SemiDiscreteSystem* sys_, Model* model_)
    : owner(std::move(owner_)), sys(sys_), model(model_) {
  const auto pat = sys->pattern();
  py::array_t<std::int32_t> ip(pat->n + 1), ix(pat->nnz());
  auto* p = ip.mutable_data();
  auto* q = ix.mutable_data();
  for (Index k = 0; k <= pat->n; ++k) p[k] = static_cast<std::int32_t>(pat->colptr[static_cast<size_t>(k)]);
  for (Index k = 0; k < pat->nnz(); ++k) q[k] = static_cast<std::int32_t>(pat->rowind[static_cast<size_t>(k)]);
  if (pat->nnz() > std::numeric_limits<std::int32_t>::max()) throw std::runtime_error("pattern too large for int32 indices");
  indptr = ip;
  indices = ix;
}

SemiDiscreteSystem& PySystem::get() const {
  if (!sys) throw std::runtime_error("this System is no longer valid (it belonged to an integrator call that has returned)");
  return *sys;
}

py::object PySystem::to_csr(std::vector<double>&& values) const {
  auto* heap = new std::vector<double>(std::move(values));
  py::capsule owner_capsule(heap, [](void* v) { delete static_cast<std::vector<double>*>(v); });
  py::array_t<double> data({static_cast<py::ssize_t>(heap->size())}, {sizeof(double)}, heap->data(), owner_capsule);
  const py::ssize_t n = static_cast<py::ssize_t>(get().num_dofs());
  return csr_class()(py::make_tuple(data, indices, indptr), py::arg("shape") = py::make_tuple(n, n));
}

namespace {

Eigen::VectorXd as_vector(const PySystem& s, const Eigen::Ref<const Eigen::VectorXd>& x, const char* what) {
  if (x.size() != s.get().num_dofs())
    throw std::invalid_argument(std::string(what) + ": expected " + std::to_string(s.get().num_dofs()) + " entries, got " +
                                std::to_string(x.size()));
  return x;
}

py::array_t<double> new_vector(Index n) { return py::array_t<double>(static_cast<py::ssize_t>(n)); }

void check_charts(const PySystem& s, const Charts& c) {
  if (static_cast<Index>(c.size()) * kDofsPerNode != s.get().num_dofs())
    throw std::invalid_argument("charts: expected one chart per node (" + std::to_string(s.get().num_dofs() / kDofsPerNode) +
                                "), got " + std::to_string(c.size()));
}

py::dict invariants_dict(const Invariants& inv) {
  py::dict d;
  d["kinetic"] = inv.kinetic;
  d["strain"] = inv.strain;
  d["L"] = Eigen::Vector3d(inv.L);
  d["J"] = Eigen::Vector3d(inv.J);
  return d;
}

py::array_t<Index> index_array(const std::vector<Index>& v) {
  py::array_t<Index> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

// A std::streambuf that hands every finished line ('\n' or '\r') to a Python callable (GIL taken).
class LineCallbackBuf : public std::streambuf {
 public:
  explicit LineCallbackBuf(py::object cb) : cb_(std::move(cb)) {}
  ~LineCallbackBuf() override {
    flush_line();
    py::gil_scoped_acquire g;
    cb_ = py::object();
  }

 protected:
  int overflow(int c) override {
    if (c == EOF) return 0;
    if (c == '\n' || c == '\r') {
      flush_line();
    } else {
      line_.push_back(static_cast<char>(c));
    }
    return c;
  }
  int sync() override { return 0; }

 private:
  void flush_line() {
    if (line_.empty()) return;
    py::gil_scoped_acquire g;
    try {
      cb_(line_);
    } catch (py::error_already_set& e) {
      e.discard_as_unraisable("shelldyn progress callback");
    }
    line_.clear();
  }
  py::object cb_;
  std::string line_;
};

// Optional log stream: none, or lines to a Python callable.
struct Log {
  std::unique_ptr<LineCallbackBuf> buf;
  std::unique_ptr<std::ostream> stream;
  explicit Log(const py::object& cb) {
    if (cb.is_none()) return;
    buf = std::make_unique<LineCallbackBuf>(cb);
    stream = std::make_unique<std::ostream>(buf.get());
  }
  ~Log() {
    stream.reset();
    if (buf) {
      py::gil_scoped_release r;  // the buffer takes the GIL itself
      buf.reset();
    }
  }
  std::ostream* get() { return stream.get(); }
};

// A case: the CaseSpec (mutable from Python) and the file it came from.
struct PyCase {
  CaseSpec spec;
  std::string path;  // the case file
};

std::string resolve_case_path(const std::string& name_or_path) {
  if (fs::exists(name_or_path)) return name_or_path;
  if (name_or_path.find('/') == std::string::npos)
    return app::find_case_file(name_or_path + (fs::path(name_or_path).extension() == ".yaml" ? "" : ".yaml"));
  return name_or_path;  // load_case reports the unreadable file
}

PySystem make_system(const CaseSpec& spec) {
  auto problem = std::make_shared<Problem>(make_problem(spec));
  Model* model = problem->model.get();
  auto s = PySystem(problem, model, model);
  return s;
}

py::dict summary_dict(const RunSummary& s) {
  py::dict d;
  d["integrator"] = s.integrator;
  d["status"] = s.status;
  d["t_end"] = s.t_end;
  d["steps"] = s.totals.steps;
  d["rejected_steps"] = s.totals.rejected_steps;
  d["nonlinear_iterations"] = s.totals.nonlinear_iterations;
  d["linear_setups"] = s.totals.linear_setups;
  d["factorizations"] = s.totals.factorizations;
  d["rhs_evaluations"] = s.totals.rhs_evaluations;
  d["chart_switches"] = s.totals.chart_switches;
  d["H0"] = s.H0;
  d["H_ref"] = s.H_ref;
  d["E_ref"] = s.E_ref;
  d["t_ref"] = s.t_ref;
  d["H_final"] = s.H_final;
  d["max_rel_drift"] = s.max_rel_drift;
  d["final_rel_drift"] = s.final_rel_drift;
  d["max_dL"] = s.max_dL;
  d["max_dJ"] = s.max_dJ;
  d["wall_s"] = s.wall_seconds;
  d["cpu_s"] = s.cpu_seconds;
  py::dict settings;
  for (const auto& [k, v] : s.settings) settings[py::str(k)] = v;
  d["settings"] = settings;
  py::dict mon;
  for (const auto& [k, v] : s.final_monitors) mon[py::str(k)] = v;
  d["final_monitors"] = mon;
  return d;
}

std::vector<std::pair<std::string, std::string>> settings_pairs(const py::object& settings) {
  std::vector<std::pair<std::string, std::string>> out;
  if (settings.is_none()) return out;
  for (auto item : py::cast<py::dict>(settings)) {
    py::object v = py::reinterpret_borrow<py::object>(item.second);
    std::string text;
    if (py::isinstance<py::bool_>(v))
      text = v.cast<bool>() ? "true" : "false";
    else if (py::isinstance<py::float_>(v)) {
      std::ostringstream os;
      os.precision(17);
      os << v.cast<double>();
      text = os.str();
    } else
      text = py::str(v);
    out.emplace_back(py::str(item.first), text);
  }
  return out;
}

py::dict run_case(PyCase& c, const std::string& integrator, const py::object& settings, double dt, double t_end,
                  double output_interval, int vtu_every, const std::string& out_dir, bool overwrite, int threads,
                  const py::object& progress, const std::string& command) {
  if (!integrator.empty()) app::check_integrator_name(integrator);
  RunOptions ro;
  ro.integrator = integrator;
  ro.settings = settings_pairs(settings);
  for (const auto& kv : ro.settings) ro.overrides.emplace_back("--set", kv.first + "=" + kv.second);
  const auto number = [](double x) {
    std::ostringstream os;
    os.precision(17);
    os << x;
    return os.str();
  };
  if (!integrator.empty()) ro.overrides.emplace_back("--integrator", integrator);
  if (dt > 0) ro.overrides.emplace_back("--dt", number(dt));
  if (t_end >= 0) ro.overrides.emplace_back("--t-end", number(t_end));
  if (output_interval > 0) ro.overrides.emplace_back("--output-every", number(output_interval));
  CaseSpec spec = c.spec;
  Log log(progress);
  py::dict out;
  {
    py::gil_scoped_release release;
    make_case_integrator(spec, integrator, ro.settings, dt > 0.0 ? dt : spec.time.dt);  // before any output
    ro.out_dir = out_dir;
    app::prepare_result_folder(ro.out_dir, overwrite);
    Problem problem = make_problem(std::move(spec));
    ro.dt = dt;
    ro.t_end = t_end;
    ro.output_interval = output_interval;
    ro.vtu_every = vtu_every;
    ro.threads = threads;
    ro.command = command;
    ro.log = log.get();
    const RunSummary s = run_dynamic(problem, ro);
    py::gil_scoped_acquire g;
    out = summary_dict(s);
  }
  out["out_dir"] = out_dir;
  return out;
}

py::dict compare_row_dict(const CompareRow& r) {
  py::dict d;
  d["label"] = r.run.label;
  d["integrator"] = r.run.integrator;
  d["dt"] = r.run.dt;
  d["adaptive"] = r.run.adaptive;
  py::dict ov;
  for (const auto& [k, v] : r.run.overrides) ov[py::str(k)] = v;
  d["overrides"] = ov;
  d["ok"] = r.ok;
  d["status"] = r.status;
  d["energy_error"] = r.energy_error;
  d["displacement_error"] = r.displacement_error;
  d["out_dir"] = r.out_dir;
  d["summary"] = r.ok ? py::object(summary_dict(r.summary)) : py::object(py::none());
  return d;
}

py::dict study_row_dict(const StudyRow& r) {
  py::dict d;
  d["group"] = r.group;
  d["label"] = r.label;
  d["integrator"] = r.integrator;
  d["kind"] = r.kind;
  d["dt"] = r.dt;
  d["rtol"] = r.rtol;
  d["status"] = r.status;
  d["t_reached"] = r.t_reached;
  d["steps"] = r.steps;
  d["rhs_evaluations"] = r.rhs_evaluations;
  d["factorizations"] = r.factorizations;
  d["nonlinear_iterations"] = r.nonlinear_iterations;
  d["cpu_s"] = r.cpu_s;
  d["wall_s"] = r.wall_s;
  d["energy_error"] = r.energy_error;
  d["energy_error_after_loads"] = r.energy_error_after_loads;
  d["displacement_error"] = r.displacement_error;
  d["max_dL"] = r.max_dL;
  d["max_dJ"] = r.max_dJ;
  d["t_end"] = r.t_end;
  return d;
}

// Case-file problems are std::runtime_error in C++ (lib/io/case_file.hpp); from Python they are bad input.
template <class F>
auto input_errors(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(e.what());
  }
}

template <class T>
void set_if(const py::dict& d, const char* key, T& target) {
  if (d.contains(key) && !d[key].is_none()) target = d[key].cast<T>();
}

}  // namespace

void bind_all(py::module_& m) {
  // --- exceptions -----------------------------------------------------------------------------------
  g_error = PyErr_NewExceptionWithDoc("shelldyn.Error", "An error reported by shelldyn (the CLI's one-line message).",
                                      PyExc_RuntimeError, nullptr);
  py::tuple input_bases = py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError));
  g_input_error = PyErr_NewExceptionWithDoc("shelldyn.InputError",
                                            "Bad input: a case file, a setting or an argument (the CLI's one-line message).",
                                            input_bases.ptr(), nullptr);
  g_step_failure = PyErr_NewExceptionWithDoc("shelldyn.StepFailure", "A time step could not be completed.", g_error, nullptr);
  g_run_stopped = PyErr_NewExceptionWithDoc("shelldyn.RunStopped", "A run stopped at a limit (resumable).", g_error, nullptr);
  m.add_object("Error", py::handle(g_error));
  m.add_object("InputError", py::handle(g_input_error));
  m.add_object("StepFailure", py::handle(g_step_failure));
  m.add_object("RunStopped", py::handle(g_run_stopped));
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const StepFailure& e) {
      PyErr_SetString(g_step_failure, e.what());
    } catch (const RunStopped& e) {
      PyErr_SetString(g_run_stopped, e.what());
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(g_input_error, e.what());
    } catch (const std::domain_error& e) {
      PyErr_SetString(g_error, e.what());
    } catch (const std::runtime_error& e) {
      PyErr_SetString(g_error, e.what());
    }
  });

  m.attr("__version__") = shelldyn_version();
  m.attr("DOFS_PER_NODE") = kDofsPerNode;

  // --- charts and states ----------------------------------------------------------------------------
  py::class_<DirectorChart>(m, "Chart", "Director chart (n, m, l, s) of docs/theory.md §2.1: q = (p_n, p_m), p_l = s·√(1−|q|²).")
      .def(py::init<>())
      .def_readwrite("n", &DirectorChart::n)
      .def_readwrite("m", &DirectorChart::m)
      .def_readwrite("l", &DirectorChart::l)
      .def_readwrite("s", &DirectorChart::s)
      .def("__repr__", [](const DirectorChart& c) {
        return "Chart(n=" + std::to_string(c.n) + ", m=" + std::to_string(c.m) + ", l=" + std::to_string(c.l) +
               ", s=" + (c.s > 0 ? "+1" : "-1") + ")";
      });
  py::bind_vector<Charts>(m, "Charts", "One director chart per node (a C++ vector; State.charts is a view of it).")
      .def("array", [](const Charts& c) {
        py::array_t<double> a({static_cast<py::ssize_t>(c.size()), py::ssize_t(4)});
        auto r = a.mutable_unchecked<2>();
        for (size_t i = 0; i < c.size(); ++i) {
          r(i, 0) = c[i].n;
          r(i, 1) = c[i].m;
          r(i, 2) = c[i].l;
          r(i, 3) = c[i].s;
        }
        return a;
      }, "(nodes, 4) array of n, m, l, s");

  py::class_<State>(m, "State",
                    "The state at one instant (lib/model/state.hpp): u, v, a hold 5 entries per node [dX, dY, dZ, q1, q2]; "
                    "the arrays are views of the C++ vectors (assigning to a slice writes through).")
      .def(py::init<>())
      .def_readwrite("t", &State::t)
      .def_property("u", [](State& s) -> Eigen::VectorXd& { return s.u; }, [](State& s, const Eigen::VectorXd& x) { s.u = x; },
                    py::return_value_policy::reference_internal)
      .def_property("v", [](State& s) -> Eigen::VectorXd& { return s.v; }, [](State& s, const Eigen::VectorXd& x) { s.v = x; },
                    py::return_value_policy::reference_internal)
      .def_property("a", [](State& s) -> Eigen::VectorXd& { return s.a; }, [](State& s, const Eigen::VectorXd& x) { s.a = x; },
                    py::return_value_policy::reference_internal)
      .def_property("pdot", [](State& s) -> Eigen::VectorXd& { return s.pdot; },
                    [](State& s, const Eigen::VectorXd& x) { s.pdot = x; }, py::return_value_policy::reference_internal)
      .def_readwrite("charts", &State::charts)
      .def("copy", [](const State& s) { return State(s); })
      .def("__copy__", [](const State& s) { return State(s); })
      .def("__deepcopy__", [](const State& s, py::dict) { return State(s); })
      .def("__repr__", [](const State& s) {
        return "State(t=" + std::to_string(s.t) + ", dofs=" + std::to_string(s.u.size()) + ")";
      });

  // --- the system -----------------------------------------------------------------------------------
  py::class_<PySystem>(m, "System",
                       "The semi-discrete system M(q) q'' + F_m(q, q') + F_int(q) = F_ext(t, q) (lib/model/semi_discrete_system.hpp). "
                       "Matrices are unconstrained scipy.sparse.csr_matrix on one fixed pattern.")
      .def_property_readonly("num_dofs", [](const PySystem& s) { return s.get().num_dofs(); })
      .def_property_readonly("num_nodes", [](const PySystem& s) { return s.get().dofs().num_nodes(); })
      .def_property_readonly("num_free", [](const PySystem& s) { return s.get().dofs().num_free(); })
      .def_property_readonly("nnz", [](const PySystem& s) { return s.get().pattern()->nnz(); })
      .def_property_readonly("dof_map", [](const PySystem& s) {
        const Index n = s.get().num_dofs();
        py::array_t<Index> a({static_cast<py::ssize_t>(n), py::ssize_t(2)});
        auto r = a.mutable_unchecked<2>();
        for (Index i = 0; i < n; ++i) {
          r(i, 0) = i / kDofsPerNode;
          r(i, 1) = i % kDofsPerNode;
        }
        return a;
      }, "(dofs, 2) array: node and component (0..2 translations dX, dY, dZ; 3, 4 director unknowns q1, q2)")
      .def_static("dof", &DofMap::dof, py::arg("node"), py::arg("component"), "Global index of (node, component)")
      .def_property_readonly("constrained_dofs", [](const PySystem& s) { return index_array(s.get().dofs().constrained_dofs()); },
                             "Sorted constrained DOFs for the current charts (director constraints move with chart switches)")
      .def_property_readonly("free_dofs", [](const PySystem& s) {
        std::vector<Index> f;
        const auto& d = s.get().dofs();
        for (Index i = 0; i < d.num_dofs(); ++i)
          if (!d.is_constrained(i)) f.push_back(i);
        return index_array(f);
      })
      .def_property_readonly("prescribed_dofs", [](const PySystem& s) { return index_array(s.get().prescribed_dofs()); })
      .def_property_readonly("has_prescribed_motion", [](const PySystem& s) { return s.get().has_prescribed_motion(); })
      .def_property_readonly("has_damping", [](const PySystem& s) { return s.get().has_damping(); })
      .def_property_readonly("loads_end", [](const PySystem& s) { return s.get().loads_end(); })
      .def_property_readonly("pattern", [](const PySystem& s) { return py::make_tuple(s.indptr, s.indices); },
                             "(indptr, indices) int32 arrays of the CSR pattern shared by every matrix")
      .def("initial_state", [](const PySystem& s) { return s.get().initial_state(); })
      .def(
          "internal",
          [](const PySystem& s, const Eigen::Ref<const Eigen::VectorXd>& u_in, const Charts& charts, bool force, bool tangent) {
            check_charts(s, charts);
            const Eigen::VectorXd u = as_vector(s, u_in, "u");
            py::object F = py::none();
            double* Fp = nullptr;
            if (force) {
              auto a = new_vector(u.size());
              Fp = a.mutable_data();
              F = a;
            }
            SparseMatrix K;
            double V = 0.0;
            {
              py::gil_scoped_release release;
              if (tangent) K = SparseMatrix{s.get().pattern(), std::vector<double>(static_cast<size_t>(s.get().pattern()->nnz()))};
              V = s.get().internal(u, charts, Fp, tangent ? &K : nullptr);
            }
            py::object Kp = tangent ? s.to_csr(std::move(K.values)) : py::object(py::none());
            return py::make_tuple(V, F, Kp);
          },
          py::arg("u"), py::arg("charts"), py::arg("force") = true, py::arg("tangent") = true,
          "(V, F_int, K): strain energy, internal force and its symmetric tangent at u (F or K None when not asked for)")
      .def(
          "algorithmic_internal",
          [](const PySystem& s, const Eigen::Ref<const Eigen::VectorXd>& un_in, const Eigen::Ref<const Eigen::VectorXd>& u1_in,
             const Charts& charts, double alpha_f, double xi, bool tangent) {
            check_charts(s, charts);
            const Eigen::VectorXd un = as_vector(s, un_in, "u_n"), u1 = as_vector(s, u1_in, "u_np1");
            auto F = new_vector(un.size());
            double* Fp = F.mutable_data();
            SparseMatrix K;
            double V = 0.0;
            {
              py::gil_scoped_release release;
              if (tangent) K = SparseMatrix{s.get().pattern(), std::vector<double>(static_cast<size_t>(s.get().pattern()->nnz()))};
              V = s.get().algorithmic_internal(un, u1, charts, alpha_f, xi, Fp, tangent ? &K : nullptr);
            }
            py::object Kp = tangent ? s.to_csr(std::move(K.values)) : py::object(py::none());
            return py::make_tuple(V, F, Kp);
          },
          py::arg("u_n"), py::arg("u_np1"), py::arg("charts"), py::arg("alpha_f") = 0.5, py::arg("xi") = 0.0,
          py::arg("tangent") = true, "Strain-averaged force of docs/theory.md §6.3: (V(u_np1), F*, K_mid)")
      .def(
          "mass",
          [](const PySystem& s, const Eigen::Ref<const Eigen::VectorXd>& u_in, const Charts& charts) {
            check_charts(s, charts);
            const Eigen::VectorXd u = as_vector(s, u_in, "u");
            SparseMatrix M{s.get().pattern(), std::vector<double>(static_cast<size_t>(s.get().pattern()->nnz()), 0.0)};
            {
              py::gil_scoped_release release;
              s.get().mass(u, charts, M);
            }
            return s.to_csr(std::move(M.values));
          },
          py::arg("u"), py::arg("charts"), "M(q), the configuration-dependent mass matrix (csr_matrix)")
      .def(
          "inertial",
          [](const PySystem& s, const Eigen::Ref<const Eigen::VectorXd>& u_in, const Eigen::Ref<const Eigen::VectorXd>& v_in,
             const Charts& charts) {
            check_charts(s, charts);
            const Eigen::VectorXd u = as_vector(s, u_in, "u"), v = as_vector(s, v_in, "v");
            auto F = new_vector(u.size());
            double* Fp = F.mutable_data();
            {
              py::gil_scoped_release release;
              s.get().inertial(u, v, charts, Fp);
            }
            return F;
          },
          py::arg("u"), py::arg("v"), py::arg("charts"), "F_m(q, q'): the velocity-dependent inertial force (+ C q' when damped)")
      .def(
          "inertia_force",
          [](const PySystem& s, const Eigen::Ref<const Eigen::VectorXd>& u_in, const Eigen::Ref<const Eigen::VectorXd>& v_in,
             const Eigen::Ref<const Eigen::VectorXd>& a_in, const Charts& charts) {
            check_charts(s, charts);
            const Eigen::VectorXd u = as_vector(s, u_in, "u"), v = as_vector(s, v_in, "v"), a = as_vector(s, a_in, "a");
            auto F = new_vector(u.size());
            double* Fp = F.mutable_data();
            {
              py::gil_scoped_release release;
              s.get().inertia_force(u, v, a, charts, Fp);
            }
            return F;
          },
          py::arg("u"), py::arg("v"), py::arg("a"), py::arg("charts"), "M(q) a + F_m(q, v) in one pass")
      .def(
          "external",
          [](const PySystem& s, double t, const Eigen::Ref<const Eigen::VectorXd>& u_in, const Charts& charts) {
            check_charts(s, charts);
            const Eigen::VectorXd u = as_vector(s, u_in, "u");
            auto F = new_vector(u.size());
            double* Fp = F.mutable_data();
            {
              py::gil_scoped_release release;
              s.get().external(t, u, charts, Fp);
            }
            return F;
          },
          py::arg("t"), py::arg("u"), py::arg("charts"), "F_ext(t, q)")
      .def(
          "load_stiffness",
          [](const PySystem& s, double t, const Eigen::Ref<const Eigen::VectorXd>& u_in, const Charts& charts) {
            check_charts(s, charts);
            const Eigen::VectorXd u = as_vector(s, u_in, "u");
            SparseMatrix K{s.get().pattern(), std::vector<double>(static_cast<size_t>(s.get().pattern()->nnz()), 0.0)};
            {
              py::gil_scoped_release release;
              s.get().add_load_stiffness(t, u, charts, K);
            }
            return s.to_csr(std::move(K.values));
          },
          py::arg("t"), py::arg("u"), py::arg("charts"), "-sym dF_ext/dq (configuration-dependent loads; zero for dead loads)")
      .def(
          "damping_force",
          [](const PySystem& s, const Eigen::Ref<const Eigen::VectorXd>& v_in) {
            const Eigen::VectorXd v = as_vector(s, v_in, "v");
            auto F = new_vector(v.size());
            std::fill(F.mutable_data(), F.mutable_data() + v.size(), 0.0);
            s.get().damping_force(v, F.mutable_data());
            return F;
          },
          py::arg("v"), "C v (Rayleigh damping; zero when undamped)")
      .def(
          "prescribed_displacement",
          [](const PySystem& s, double t, Eigen::Ref<Eigen::VectorXd> u) {
            if (u.size() != s.get().num_dofs()) throw std::invalid_argument("u: wrong size");
            s.get().prescribed_displacement(t, u.data());
          },
          py::arg("t"), py::arg("u").noconvert(), "Writes g(t) into the prescribed entries of u (in place)")
      .def(
          "prescribed_velocity",
          [](const PySystem& s, double t, Eigen::Ref<Eigen::VectorXd> v) {
            if (v.size() != s.get().num_dofs()) throw std::invalid_argument("v: wrong size");
            s.get().prescribed_velocity(t, v.data());
          },
          py::arg("t"), py::arg("v").noconvert(), "Writes g'(t+) into the prescribed entries of v (in place)")
      .def("invariants", [](const PySystem& s, const State& st) { return invariants_dict(s.get().invariants(st)); },
           py::arg("state"), "dict: kinetic, strain, L (linear momentum), J (angular momentum about the origin)")
      .def(
          "energy",
          [](const PySystem& s, const State& st) {
            const Invariants inv = s.get().invariants(st);
            return inv.kinetic + inv.strain;
          },
          py::arg("state"), "K + V")
      .def(
          "rechart", [](PySystem& s, State& st, double hysteresis) { return s.get().rechart(st, hysteresis); }, py::arg("state"),
          py::arg("hysteresis") = 1.0,
          "Re-selects director charts (docs/theory.md §2.3), converting state.u, v, a in place; returns the number of switches")
      .def("chart_margin", [](const PySystem& s, const State& st) { return s.get().chart_margin(st); }, py::arg("state"))
      .def(
          "apply_dirichlet",
          [](const PySystem& s, py::object A) {
            // In place on a csr_matrix of this system's pattern: constrained rows/columns -> identity.
            py::array_t<double> data = py::cast<py::array_t<double>>(A.attr("data"));
            if (!py::cast<py::array>(A.attr("data")).is(data)) throw std::invalid_argument("apply_dirichlet: matrix values must be float64");
            auto* vals = data.mutable_data();
            const auto pat = s.get().pattern();
            if (data.size() != pat->nnz()) throw std::invalid_argument("apply_dirichlet: matrix is not on this system's pattern");
            SparseMatrix M{pat, std::vector<double>(vals, vals + pat->nnz())};
            apply_dirichlet(s.get().dofs(), M, nullptr);
            std::copy(M.values.begin(), M.values.end(), vals);
            return A;
          },
          py::arg("A"), "Constrained rows and columns of A (a matrix of this system) replaced by the identity, in place")
      // Shell-model extras (not part of the SemiDiscreteSystem contract).
      .def_property_readonly("nodes", [](const PySystem& s) {
        if (!s.model) throw std::runtime_error("nodes: this system is not a shell Model");
        const auto& X = s.model->mesh().X;
        Eigen::MatrixXd out(static_cast<Eigen::Index>(X.size()), 3);
        for (size_t i = 0; i < X.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = X[i].transpose();
        return out;
      }, "(nodes, 3) reference coordinates")
      .def_property_readonly("num_elements", [](const PySystem& s) {
        if (!s.model) throw std::runtime_error("num_elements: this system is not a shell Model");
        return s.model->mesh().num_elements();
      })
      .def(
          "directors",
          [](const PySystem& s, const State& st) {
            if (!s.model) throw std::runtime_error("directors: this system is not a shell Model");
            const int n = s.get().dofs().num_nodes();
            Eigen::MatrixXd out(n, 3);
            for (int i = 0; i < n; ++i) out.row(i) = s.model->director(st, i).transpose();
            return out;
          },
          py::arg("state"), "(nodes, 3) unit directors p(q) of a state");

  // --- cases ----------------------------------------------------------------------------------------
  py::class_<PyCase>(m, "Case", "A case file (lib/io/case_file.hpp), loaded and validated; its settings can be overridden.")
      .def_readonly("path", &PyCase::path)
      .def_property_readonly("name", [](const PyCase& c) { return c.spec.name; })
      .def_property_readonly("description", [](const PyCase& c) { return c.spec.description; })
      .def_property("dt", [](const PyCase& c) { return c.spec.time.dt; }, [](PyCase& c, double v) {
        app::check_positive("dt", v, "case.dt = 1e-3");
        c.spec.time.dt = v;
      })
      .def_property("t_end", [](const PyCase& c) { return c.spec.time.t_end; }, [](PyCase& c, double v) {
        app::check_non_negative("t_end", v, "case.t_end = 2.0");
        c.spec.time.t_end = v;
      })
      .def_property("output_interval", [](const PyCase& c) { return c.spec.time.output_interval; }, [](PyCase& c, double v) {
        app::check_positive("output_interval", v, "case.output_interval = 0.01");
        c.spec.time.output_interval = v;
      })
      .def_property_readonly("num_steps", [](const PyCase& c) { return c.spec.time.num_steps(); })
      .def_property("integrator", [](const PyCase& c) { return c.spec.integrator.name; }, [](PyCase& c, const std::string& v) {
        app::check_integrator_name(v);
        if (v != c.spec.integrator.name) {
          c.spec.integrator.settings = settings_understood_by(v, c.spec.integrator.settings);
          c.spec.integrator.setting_where.assign(c.spec.integrator.settings.size(), c.spec.integrator.where);
        }
        c.spec.integrator.name = v;
      }, "The case's integrator; assigning another keeps only the settings it understands (as compare does)")
      .def_property(
          "integrator_settings",
          [](const PyCase& c) {
            py::dict d;
            for (const auto& [k, v] : c.spec.integrator.settings) d[py::str(k)] = v;
            return d;
          },
          [](PyCase& c, const py::object& d) {
            c.spec.integrator.settings = settings_pairs(d);
            c.spec.integrator.setting_where.assign(c.spec.integrator.settings.size(), "");
          },
          "The integrator block's settings as written (dict of strings)")
      .def(
          "set",
          [](PyCase& c, const std::string& key, py::object value) {
            py::dict d;
            d[py::str(key)] = value;
            const auto kv = settings_pairs(d).front();
            for (auto& [k, v] : c.spec.integrator.settings)
              if (k == key) {
                v = kv.second;
                return;
              }
            c.spec.integrator.settings.push_back(kv);
            c.spec.integrator.setting_where.push_back("");
          },
          py::arg("key"), py::arg("value"), "Sets one integrator setting (as `shelldyn run --set KEY=VALUE`)")
      .def_property(
          "material",
          [](const PyCase& c) {
            py::dict d;
            d["E"] = c.spec.material.E;
            d["nu"] = c.spec.material.nu;
            d["rho"] = c.spec.material.rho;
            d["thickness"] = c.spec.material.thickness;
            d["shear_factor"] = c.spec.material.shear_factor;
            return d;
          },
          [](PyCase& c, const py::dict& d) {
            for (auto item : d) {
              const std::string k = py::str(item.first);
              if (k != "E" && k != "nu" && k != "rho" && k != "thickness" && k != "shear_factor")
                throw std::invalid_argument("material." + k + ": unknown key (valid: E, nu, rho, thickness, shear_factor)");
            }
            set_if(d, "E", c.spec.material.E);
            set_if(d, "nu", c.spec.material.nu);
            set_if(d, "rho", c.spec.material.rho);
            set_if(d, "thickness", c.spec.material.thickness);
            set_if(d, "shear_factor", c.spec.material.shear_factor);
          },
          "Material dict (E, nu, rho, thickness, shear_factor); assigning a dict with some of them overrides those")
      .def_property("vtu", [](const PyCase& c) { return c.spec.output.vtu; }, [](PyCase& c, bool v) { c.spec.output.vtu = v; })
      .def_property_readonly("monitors", [](const PyCase& c) {
        std::vector<std::string> names;
        for (const auto& mon : c.spec.monitors) names.push_back(mon.name);
        return names;
      })
      .def(
          "check",
          [](const PyCase& c) {
            // What `shelldyn check` validates (apps/shelldyn.cpp run_check), without writing anything.
            py::dict d;
            CaseSpec spec = c.spec;
            py::gil_scoped_release release;
            const Discretization disc = input_errors([&] {
              validate_case_integrator(spec);
              Discretization dd = build_discretization(spec);
              if (!spec.initial_displacement.empty() || !dd.prescribed.empty()) {
                const Problem pb = make_problem(spec);
                (void)pb.initial_state();
              }
              return dd;
            });
            py::gil_scoped_acquire g;
            d["nodes"] = disc.mesh.num_nodes();
            d["elements"] = disc.mesh.num_elements();
            d["dofs"] = disc.dofs.num_dofs();
            d["constrained_dofs"] = disc.dofs.num_constrained();
            d["free_dofs"] = disc.dofs.num_free();
            d["nodal_loads"] = disc.loads.size();
            d["loads_end"] = disc.loads_end;
            d["surface_area"] = disc.surface_area;
            d["total_mass"] = disc.total_mass;
            d["integrator"] = spec.integrator.name;
            d["dt"] = spec.time.dt;
            d["t_end"] = spec.time.t_end;
            d["steps"] = spec.time.num_steps();
            return d;
          },
          "Validates the case as `shelldyn check` does (raises InputError/Error with the CLI's message); returns a summary dict")
      .def("system", [](const PyCase& c) {
        CaseSpec spec = c.spec;
        return input_errors([&] { return make_system(spec); });
      }, "Builds the discretization and the shell Model: a System")
      .def("initial_state", [](const PyCase& c) {
        const Problem pb = make_problem(c.spec);
        return pb.initial_state();
      }, "The case's initial state (initial velocity and displacement applied)")
      .def("copy", [](const PyCase& c) { return PyCase(c); })
      .def("__repr__", [](const PyCase& c) { return "Case('" + c.spec.name + "', path='" + c.path + "')"; });

  m.def(
      "load_case",
      [](const std::string& name_or_path) {
        PyCase c;
        c.path = resolve_case_path(name_or_path);
        c.spec = input_errors([&] { return load_case(c.path); });
        return c;
      },
      py::arg("name_or_path"),
      "Loads a case file, or a built-in case by name (e.g. 'flying-plate': apps/cases/flying-plate.yaml). "
      "Errors raise InputError/Error with the CLI's message.");
  m.def(
      "case_from_string",
      [](const std::string& text, const std::string& source, const std::string& base_dir) {
        PyCase c;
        c.path = "";
        c.spec = input_errors([&] { return load_case_from_string(text, source, base_dir); });
        return c;
      },
      py::arg("text"), py::arg("source") = "case.yaml", py::arg("base_dir") = ".");
  m.def("find_case_file", &app::find_case_file, py::arg("file_name"));
  m.def("find_script", &app::find_script, py::arg("file_name"));

  // --- integrators ----------------------------------------------------------------------------------
  m.def("integrator_names", &integrator_names);
  m.def("integrator_catalogue", [] {
    py::gil_scoped_release r;
    return integrator_catalogue();
  });
  m.def("integrator_origin", &integrator_origin, py::arg("name"));
  m.def("unregister_integrator", &unregister_integrator, py::arg("name"));
  bind_python_integrators(m);

  // --- runs -----------------------------------------------------------------------------------------
  m.def(
      "_run",
      [](PyCase& c, const std::string& integrator, const py::object& settings, double dt, double t_end, double output_interval,
         int vtu_every, const std::string& out_dir, bool overwrite, int threads, const py::object& progress,
         const std::string& command) {
        return run_case(c, integrator, settings, dt, t_end, output_interval, vtu_every, out_dir, overwrite, threads, progress,
                        command);
      },
      py::arg("case"), py::arg("integrator"), py::arg("settings"), py::arg("dt"), py::arg("t_end"), py::arg("output_interval"),
      py::arg("vtu_every"), py::arg("out_dir"), py::arg("overwrite"), py::arg("threads"), py::arg("progress"),
      py::arg("command"));

  m.def(
      "_compare",
      [](const std::string& case_path, const std::vector<std::string>& specs, const std::vector<double>& dts,
         const std::vector<double>& rtols, double t_end, double output_interval, int vtu_every, int jobs, int threads,
         const std::string& out_dir, const std::string& reference, bool resume, const py::object& progress,
         const std::string& command) {
        CompareOptions co;
        co.case_path = resolve_case_path(case_path);
        co.specs = specs;
        co.dts = dts;
        co.rtols = rtols;
        co.t_end = t_end;
        co.output_interval = output_interval;
        co.vtu_every = vtu_every;
        co.jobs = jobs;
        co.threads = threads;
        co.out_dir = out_dir;
        co.reference = reference;
        co.resume = resume;
        co.command = command;
        Log log(progress);
        co.log = log.get();
        for (double dt : dts) app::check_positive("dts", dt, "dts=[1e-3, 2e-3]");
        for (double r : rtols) app::check_positive("rtols", r, "rtols=[1e-6, 1e-8]");
        app::check_range("jobs", jobs, 1, 64, "jobs=2");
        CompareResult r;
        {
          py::gil_scoped_release release;
          expand_compare_runs(co);
          app::check_output_folder(co.out_dir);
          r = run_comparison(co);
        }
        py::dict d;
        py::list rows;
        for (const auto& row : r.rows) rows.append(compare_row_dict(row));
        d["rows"] = rows;
        d["reference"] = r.reference;
        d["monitors"] = r.monitors;
        d["summary_csv"] = r.summary_csv;
        d["summary_md"] = r.summary_md;
        d["out_dir"] = out_dir;
        return d;
      },
      py::arg("case"), py::arg("specs"), py::arg("dts"), py::arg("rtols"), py::arg("t_end"), py::arg("output_interval"),
      py::arg("vtu_every"), py::arg("jobs"), py::arg("threads"), py::arg("out_dir"), py::arg("reference"), py::arg("resume"),
      py::arg("progress"), py::arg("command"));

  // --- studies (integrators/runs/study.hpp; files: docs/reference/study-files.md) ---------------------
  m.def(
      "_study_files",
      [] {
        py::dict d;
        for (const auto& [name, path] : app::shipped_study_files()) d[py::str(name)] = path;
        return d;
      },
      "The shipped study files (apps/studies/*.yaml or <prefix>/share/shelldyn/studies): name -> path");
  py::class_<StudyPreset>(m, "Study",
                          "A study file (docs/reference/study-files.md), read and validated: the case, the methods, the "
                          "window's sweeps and reference, the full-duration runs. add_method(spec) adds a method.")
      .def_readonly("name", &StudyPreset::name)
      .def_readonly("source", &StudyPreset::source)
      .def_readonly("case_file", &StudyPreset::case_file)
      .def_readonly("case_path", &StudyPreset::case_path)
      .def_readonly("note", &StudyPreset::note)
      .def_readonly("has_window", &StudyPreset::has_window)
      .def_readonly("window_t_end", &StudyPreset::window_t_end)
      .def_readonly("window_output", &StudyPreset::window_output)
      .def_readonly("dts", &StudyPreset::dts)
      .def_readonly("rtols", &StudyPreset::rtols)
      .def_readonly("reference", &StudyPreset::reference_spec)
      .def_readonly("has_full", &StudyPreset::has_full)
      .def_readonly("full_t_end", &StudyPreset::full_t_end)
      .def_readonly("full_dt", &StudyPreset::full_dt)
      .def_readonly("full_output", &StudyPreset::full_output)
      .def_readonly("full_runs", &StudyPreset::full_baselines)
      .def_readonly("headline", &StudyPreset::headline)
      .def_property_readonly(
          "methods",
          [](const StudyPreset& p) {
            py::list l;
            for (const auto& mth : p.methods) {
              py::dict d;
              d["spec"] = mth.spec;
              d["integrator"] = mth.integrator;
              d["adaptive"] = mth.adaptive;
              d["sweep"] = mth.sweep;
              d["window"] = mth.window;
              d["full"] = mth.full;
              d["where"] = mth.where;
              l.append(d);
            }
            return l;
          },
          "One dict per method, in file order: spec, integrator, adaptive, sweep (its dt or rtol values), window, full, where")
      .def(
          "add_method",
          [](StudyPreset& p, const std::string& spec) { add_study_method(p, spec, "add_method('" + spec + "')"); },
          py::arg("spec"),
          "Adds a method NAME[:KEY=VALUE...] (any registered integrator, Python ones included), swept over the window's "
          "default dt or rtol list and (fixed-step) run over the full duration, as `shelldyn study --add-method`")
      .def("copy", [](const StudyPreset& p) { return p; }, "An independent copy (add_method on it leaves this one as it is)")
      .def("__repr__", [](const StudyPreset& p) {
        return "Study(" + p.name + ", " + std::to_string(p.methods.size()) + " methods, case " + p.case_file + ")";
      });
  m.def(
      "_load_study_file", [](const std::string& path) { return input_errors([&] { return load_study_file(path); }); },
      py::arg("path"));
  m.def(
      "_load_study_from_string",
      [](const std::string& text, const std::string& source, const std::string& base_dir) {
        return input_errors([&] { return load_study_from_string(text, source, base_dir); });
      },
      py::arg("text"), py::arg("source"), py::arg("base_dir"));
  m.def(
      "_study",
      [](const StudyPreset& preset, const std::string& case_path, const std::string& out_dir, const std::vector<std::string>& groups,
         bool rerun, bool dry_run, int jobs, double max_wall_per_run, long long max_steps_per_run, const py::object& progress,
         const std::string& command) {
        // The checks of `shelldyn study` (apps/shelldyn.cpp, run_study_command), with the keyword names.
        if (jobs < 1) throw std::invalid_argument("study: jobs must be >= 1 (got " + std::to_string(jobs) + ")");
        if (!(max_wall_per_run >= 0.0) || !std::isfinite(max_wall_per_run) || max_steps_per_run < 0)
          throw std::invalid_argument("study: max_wall_per_run and max_steps_per_run must be >= 0 (0: no budget)");
        for (const auto& g : groups) {
          if (g != "window" && g != "full")
            throw std::invalid_argument("study: groups must be 'window' and/or 'full' (got '" + g + "')");
          if ((g == "window" && !preset.has_window) || (g == "full" && !preset.has_full))
            throw std::invalid_argument("study: groups=['" + g + "']: " + (preset.source.empty() ? preset.name : preset.source) +
                                        " has no " + g + ": section");
        }
        StudyOptions so;
        so.preset = preset;
        so.case_path = case_path;
        so.out_dir = out_dir;
        if (!groups.empty()) so.groups = groups;
        so.rerun = rerun;
        so.dry_run = dry_run;
        so.execution.jobs = jobs;
        so.max_wall_per_run = max_wall_per_run;
        so.max_steps_per_run = max_steps_per_run;
        so.command = command;
        Log log(progress);
        so.log = log.get();
        StudyResult r;
        {
          py::gil_scoped_release release;
          if (!dry_run) app::check_output_folder(so.out_dir);
          r = run_study(so);
        }
        py::dict d;
        py::list rows;
        for (const auto& row : r.rows) rows.append(study_row_dict(row));
        d["rows"] = rows;
        d["ran"] = r.ran;
        d["skipped"] = r.skipped;
        d["failed"] = r.failed;
        d["stopped"] = r.stopped;
        d["study_csv"] = r.study_csv;
        d["study_md"] = r.study_md;
        d["out_dir"] = out_dir;
        return d;
      },
      py::arg("study"), py::arg("case"), py::arg("out_dir"), py::arg("groups"), py::arg("rerun"), py::arg("dry_run"),
      py::arg("jobs"), py::arg("max_wall_per_run"), py::arg("max_steps_per_run"), py::arg("progress"), py::arg("command"));

  // The same evaluation timed in C++ (preallocated F and K, no Python in the loop): the baseline of the
  // Python call-boundary measurement (python/examples/bench_internal.py).
  m.def(
      "_time_internal_cpp",
      [](const PySystem& s, const Eigen::Ref<const Eigen::VectorXd>& u_in, const Charts& charts, int repeats, bool tangent) {
        check_charts(s, charts);
        const Eigen::VectorXd u = as_vector(s, u_in, "u");
        Eigen::VectorXd F(u.size());
        SparseMatrix K{s.get().pattern(), std::vector<double>(static_cast<size_t>(s.get().pattern()->nnz()), 0.0)};
        py::gil_scoped_release release;
        const auto t0 = std::chrono::steady_clock::now();
        for (int k = 0; k < repeats; ++k) s.get().internal(u, charts, F.data(), tangent ? &K : nullptr);
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / repeats;
      },
      py::arg("system"), py::arg("u"), py::arg("charts"), py::arg("repeats"), py::arg("tangent") = true);
  m.def(
      "read_history",
      [](const std::string& path) {
        const CsvTable t = read_csv_table(path);
        py::dict d;
        for (size_t c = 0; c < t.columns.size(); ++c) {
          const auto& col = t.data[c];
          py::array_t<double> a(static_cast<py::ssize_t>(col.size()));
          std::copy(col.begin(), col.end(), a.mutable_data());
          d[py::str(t.columns[c])] = a;
        }
        return d;
      },
      py::arg("path"), "A history.csv (or any numeric CSV with a header) as a dict of NumPy arrays; 'nan' reads as NaN");
  m.def(
      "mechanical_energy_drift",
      [](const std::string& history_path, double loads_end) { return mechanical_energy_drift(read_csv_table(history_path), loads_end); },
      py::arg("history_csv"), py::arg("loads_end"));
  m.def(
      "run_script",
      [](const std::string& script, const std::vector<std::string>& args) {
        std::ostringstream warn;
        bool ok = false;
        {
          py::gil_scoped_release r;
          ok = app::run_python_script(app::find_script(script), args, warn);
        }
        return py::make_tuple(ok, warn.str());
      },
      py::arg("script"), py::arg("args"), "Runs scripts/SCRIPT with ARGS as the CLI does (e.g. plot_compare.py DIR)");
}

}  // namespace shelldyn::python

PYBIND11_MODULE(_shelldyn, m) {
  m.doc() = "shelldyn: nonlinear dynamics of thin shells and comparisons of time integrators (C++ core)";
  shelldyn::python::bind_all(m);
}
