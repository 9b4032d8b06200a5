// Small RAII and error-checking helpers shared by every SUNDIALS adapter (KINSOL, IDA, ARKODE).
// SUNDIALS 6.4.1, sunindextype = int64_t = shelldyn::Index (docs/dependencies.md §2.3).
//
// Conventions (style.md habit 4): every SUNDIALS return code goes through check_flag() (or a
// package-specific name lookup) and becomes a std::runtime_error naming the call; constructors that
// return NULL go through check_ptr(). Exceptions never cross SUNDIALS' C frames: callbacks catch
// everything and store the message in a CallbackError (see below).
#pragma once

#include "lib/linalg/sparse_matrix.hpp"

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_types.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <exception>
#include <memory>
#include <string>
#include <type_traits>

namespace shelldyn {

static_assert(std::is_same<sunindextype, Index>::value,
              "SUNDIALS must be built with 64-bit sunindextype (Debian 12 default)");
static_assert(std::is_same<sunrealtype, double>::value, "SUNDIALS must be double precision");

// Owns one SUNContext (SUNContext_Create(nullptr, ...) for serial runs). Every SUNDIALS object of
// a run must come from the same context and be freed before it (declare the context first).
class SunContext {
 public:
  SunContext();
  ~SunContext();
  SunContext(const SunContext&) = delete;
  SunContext& operator=(const SunContext&) = delete;
  operator SUNContext() const { return ctx_; }
  SUNContext get() const { return ctx_; }

 private:
  SUNContext ctx_ = nullptr;
};

// Throws std::runtime_error("<call> failed with flag <flag>[ (<name>)]") when flag < 0.
// `flag_name` is the package's name lookup (KINGetReturnFlagName, IDAGetReturnFlagName,
// ARKStepGetReturnFlagName: they return malloc'ed strings, freed here); may be null.
using FlagNameFn = char* (*)(long int);
void check_flag(int flag, const char* call, FlagNameFn flag_name = nullptr);

// The name of a package flag as a std::string (frees SUNDIALS' malloc'ed string).
std::string flag_name(FlagNameFn fn, long int flag);

// Throws std::runtime_error("<call> returned NULL ...") for a null constructor result.
void check_ptr(const void* p, const char* call);

// RAII owners for the generic SUNDIALS objects.
struct NVectorDeleter {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
struct SunMatrixDeleter {
  void operator()(SUNMatrix A) const { SUNMatDestroy(A); }
};
struct SunLinSolDeleter {
  void operator()(SUNLinearSolver S) const { SUNLinSolFree(S); }
};
using NVectorPtr = std::unique_ptr<std::remove_pointer_t<N_Vector>, NVectorDeleter>;
using SunMatrixPtr = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, SunMatrixDeleter>;
using SunLinearSolverPtr = std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, SunLinSolDeleter>;

// Serial vector of length n (checked), optionally initialised from `init` (n values).
NVectorPtr make_serial_vector(Index n, SUNContext ctx, const double* init = nullptr);
double* data(N_Vector v);  // N_VGetArrayPointer, checked non-null

// Replaces the reductions and element-wise operations of a serial N_Vector (N_VWL2Norm, N_VMaxNorm, N_VMin,
// N_VDotProd, N_VLinearSum, N_VConst, N_VProd, N_VDiv, N_VScale, N_VAbs, N_VInv) by Eigen's vectorized loops
// (docs/dependencies.md §3.6). Vectors cloned from v later inherit them (N_VClone copies the operation table), so
// call it on the template vector before it is given to the package (KINInit, ...). The element-wise operations
// give the same values as SUNDIALS' (the same IEEE operation per entry, no fused multiply-add in a portable
// build); reductions differ in the order of summation, i.e. at round-off.
void use_vectorized_ops(N_Vector v);

// CSC SUNSparseMatrix with capacity pattern.nnz(), structure filled from the pattern.
SunMatrixPtr make_csc_matrix(const SparsePattern& pattern, SUNContext ctx);

// Writes colptr, rowind AND values of M into the SUNSparseMatrix A. Needed in every Jacobian
// callback because KINSOL/IDA/ARKODE call SUNMatZero (which also zeroes indexptrs/indexvals) before
// the user Jacobian (docs/dependencies.md §3.2 pitfall 2, §7 item 5). Throws std::invalid_argument when A is not
// CSC, has other dimensions or too little capacity.
void copy_to_sun_matrix(const SparseMatrix& M, SUNMatrix A);

// Non-owning view of a CSC SUNSparseMatrix (uses colptr[n] as nnz, not the capacity).
CscView csc_view(SUNMatrix A);

// Carries a failure out of a C callback: the callback catches, stores, returns a SUNDIALS error
// code; the C++ caller rethrows or reports after the SUNDIALS call returns.
class CallbackError {
 public:
  // Call inside a catch block: stores "<where>: <what()>" (first failure wins until clear()).
  void capture(const char* where) noexcept;
  bool has_error() const { return !message_.empty(); }
  const std::string& message() const { return message_; }
  void clear() { message_.clear(); }

 private:
  std::string message_;
};

// SUNDIALS error-handler function (same signature for KINSOL, IDA and ARKODE) that records the
// last message into the std::string passed as user data instead of printing it to stderr.
// Install with e.g. KINSetErrHandlerFn(mem, record_sundials_error, &some_string).
void record_sundials_error(int error_code, const char* module, const char* function, char* msg,
                           void* user_data);

}  // namespace shelldyn
