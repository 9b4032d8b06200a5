// Shared declarations of the translation units of the `shelldyn` Python module (python/src/).
#pragma once

#include <pybind11/pybind11.h>

#include "lib/model/model.hpp"
#include "lib/model/semi_discrete_system.hpp"
#include "lib/model/state.hpp"

#include <memory>
#include <string>
#include <vector>

PYBIND11_MAKE_OPAQUE(std::vector<shelldyn::DirectorChart>)

namespace shelldyn::python {

namespace py = pybind11;
using Charts = std::vector<DirectorChart>;

// shelldyn.Error, InputError, StepFailure (set by bind_all).
extern PyObject* g_error;
extern PyObject* g_input_error;
extern PyObject* g_step_failure;

// "Type: message" of a Python exception, on one line.
std::string python_error_text(const py::error_already_set& e);
// Converts a Python exception raised by user code into the C++ exception the run machinery expects:
// InputError -> std::invalid_argument (message unchanged), StepFailure -> StepFailure, ValueError ->
// std::invalid_argument, anything else -> std::runtime_error; `prefix` (e.g. "verlet: advance: ") is put first.
[[noreturn]] void rethrow_python_error(const py::error_already_set& e, const std::string& prefix);

// The Python view of a SemiDiscreteSystem: owning (a case's Problem) or not (the system an integrator
// is handed during a run; invalidated when the run's integrator is destroyed).
struct PySystem {
  PySystem(std::shared_ptr<void> owner, SemiDiscreteSystem* sys, Model* model);
  std::shared_ptr<void> owner;
  SemiDiscreteSystem* sys = nullptr;
  Model* model = nullptr;  // the shell Model when it is one
  py::object indptr, indices;  // int32 CSR pattern, made once

  SemiDiscreteSystem& get() const;
  // csr_matrix over `values` (moved into the array's owner, not copied) and the cached pattern.
  py::object to_csr(std::vector<double>&& values) const;
};

void bind_all(py::module_& m);
void bind_python_integrators(py::module_& m);

}  // namespace shelldyn::python
