#include "integrators/sundials/sundials_support.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

SunContext::SunContext() {
  // nullptr communicator = serial (SUNDIALS 6.x signature, docs/dependencies.md §3.2).
  const int flag = SUNContext_Create(nullptr, &ctx_);
  if (flag != 0 || ctx_ == nullptr)
    throw std::runtime_error("SUNContext_Create failed with flag " + std::to_string(flag));
}

SunContext::~SunContext() {
  if (ctx_) SUNContext_Free(&ctx_);
}

std::string flag_name(FlagNameFn fn, long int flag) {
  if (fn == nullptr) return {};
  char* s = fn(flag);
  if (s == nullptr) return {};
  std::string out(s);
  std::free(s);  // SUNDIALS 6 allocates these names with malloc
  return out;
}

void check_flag(int flag, const char* call, FlagNameFn fn) {
  if (flag >= 0) return;
  std::ostringstream os;
  os << call << " failed with flag " << flag;
  const std::string name = flag_name(fn, flag);
  if (!name.empty()) os << " (" << name << ")";
  throw std::runtime_error(os.str());
}

void check_ptr(const void* p, const char* call) {
  if (p == nullptr)
    throw std::runtime_error(std::string(call) + " returned NULL (out of memory or invalid input)");
}

NVectorPtr make_serial_vector(Index n, SUNContext ctx, const double* init) {
  if (n <= 0) throw std::invalid_argument("make_serial_vector: length must be positive, got " + std::to_string(n));
  NVectorPtr v(N_VNew_Serial(n, ctx));
  check_ptr(v.get(), "N_VNew_Serial");
  if (init) std::copy(init, init + n, data(v.get()));
  else N_VConst(0.0, v.get());
  return v;
}

namespace {
using Arr = Eigen::Map<Eigen::ArrayXd>;
Arr arr(N_Vector v) { return Arr(N_VGetArrayPointer(v), static_cast<Eigen::Index>(N_VGetLength(v))); }

realtype wl2norm(N_Vector x, N_Vector w) { return std::sqrt((arr(x) * arr(w)).square().sum()); }
realtype maxnorm(N_Vector x) { return arr(x).abs().maxCoeff(); }
realtype minval(N_Vector x) { return arr(x).minCoeff(); }
realtype dotprod(N_Vector x, N_Vector y) { return (arr(x) * arr(y)).sum(); }
void linearsum(realtype a, N_Vector x, realtype b, N_Vector y, N_Vector z) {
  // The special cases of N_VLinearSum_Serial give the same values as a x + b y; x + y is written as such so
  // that no multiplication (and no fused multiply-add in a -march=native build) enters the Newton update.
  if (a == 1.0 && b == 1.0) arr(z) = arr(x) + arr(y);
  else if (a == 1.0 && b == -1.0) arr(z) = arr(x) - arr(y);
  else if (a == -1.0 && b == 1.0) arr(z) = arr(y) - arr(x);
  else arr(z) = a * arr(x) + b * arr(y);
}
void constant(realtype c, N_Vector z) { arr(z).setConstant(c); }
void prod(N_Vector x, N_Vector y, N_Vector z) { arr(z) = arr(x) * arr(y); }
void div(N_Vector x, N_Vector y, N_Vector z) { arr(z) = arr(x) / arr(y); }
void scale(realtype c, N_Vector x, N_Vector z) { arr(z) = c * arr(x); }
void absval(N_Vector x, N_Vector z) { arr(z) = arr(x).abs(); }
void inv(N_Vector x, N_Vector z) { arr(z) = arr(x).inverse(); }
}  // namespace

void use_vectorized_ops(N_Vector v) {
  check_ptr(v, "use_vectorized_ops");
  if (N_VGetVectorID(v) != SUNDIALS_NVEC_SERIAL) throw std::invalid_argument("use_vectorized_ops: not a serial N_Vector");
  v->ops->nvwl2norm = wl2norm;
  v->ops->nvmaxnorm = maxnorm;
  v->ops->nvmin = minval;
  v->ops->nvdotprod = dotprod;
  v->ops->nvlinearsum = linearsum;
  v->ops->nvconst = constant;
  v->ops->nvprod = prod;
  v->ops->nvdiv = div;
  v->ops->nvscale = scale;
  v->ops->nvabs = absval;
  v->ops->nvinv = inv;
}

double* data(N_Vector v) {
  double* p = N_VGetArrayPointer(v);
  check_ptr(p, "N_VGetArrayPointer");
  return p;
}

SunMatrixPtr make_csc_matrix(const SparsePattern& pattern, SUNContext ctx) {
  if (pattern.n <= 0 || pattern.colptr.size() != static_cast<size_t>(pattern.n) + 1)
    throw std::invalid_argument("make_csc_matrix: pattern has n = " + std::to_string(pattern.n) +
                                " and " + std::to_string(pattern.colptr.size()) + " column pointers");
  // SUNSparseMatrix refuses a zero capacity; an all-zero pattern still gets one slot.
  SunMatrixPtr A(SUNSparseMatrix(pattern.n, pattern.n, std::max<Index>(pattern.nnz(), 1), CSC_MAT, ctx));
  check_ptr(A.get(), "SUNSparseMatrix");
  std::copy(pattern.colptr.begin(), pattern.colptr.end(), SUNSparseMatrix_IndexPointers(A.get()));
  std::copy(pattern.rowind.begin(), pattern.rowind.end(), SUNSparseMatrix_IndexValues(A.get()));
  std::fill_n(SUNSparseMatrix_Data(A.get()), pattern.nnz(), 0.0);
  return A;
}

void copy_to_sun_matrix(const SparseMatrix& M, SUNMatrix A) {
  const SparsePattern& P = *M.pattern;
  if (SUNMatGetID(A) != SUNMATRIX_SPARSE || SUNSparseMatrix_SparseType(A) != CSC_MAT)
    throw std::invalid_argument("copy_to_sun_matrix: target is not a CSC SUNSparseMatrix");
  if (SUNSparseMatrix_Rows(A) != P.n || SUNSparseMatrix_Columns(A) != P.n ||
      SUNSparseMatrix_NNZ(A) < P.nnz() || static_cast<Index>(M.values.size()) != P.nnz()) {
    std::ostringstream os;
    os << "copy_to_sun_matrix: matrix n = " << P.n << ", nnz = " << P.nnz() << ", values = "
       << M.values.size() << " does not fit SUNSparseMatrix " << SUNSparseMatrix_Rows(A) << " x "
       << SUNSparseMatrix_Columns(A) << " with capacity " << SUNSparseMatrix_NNZ(A);
    throw std::invalid_argument(os.str());
  }
  std::copy(P.colptr.begin(), P.colptr.end(), SUNSparseMatrix_IndexPointers(A));
  std::copy(P.rowind.begin(), P.rowind.end(), SUNSparseMatrix_IndexValues(A));
  std::copy(M.values.begin(), M.values.end(), SUNSparseMatrix_Data(A));
}

CscView csc_view(SUNMatrix A) {
  if (SUNMatGetID(A) != SUNMATRIX_SPARSE || SUNSparseMatrix_SparseType(A) != CSC_MAT)
    throw std::invalid_argument("csc_view: matrix is not a CSC SUNSparseMatrix");
  CscView v;
  v.n = SUNSparseMatrix_Columns(A);
  v.colptr = SUNSparseMatrix_IndexPointers(A);
  v.rowind = SUNSparseMatrix_IndexValues(A);
  v.values = SUNSparseMatrix_Data(A);
  return v;
}

void CallbackError::capture(const char* where) noexcept {
  if (!message_.empty()) return;
  try {
    throw;
  } catch (const std::exception& e) {
    try {
      message_ = std::string(where) + ": " + e.what();
    } catch (...) {
    }
  } catch (...) {
    try {
      message_ = std::string(where) + ": unknown exception";
    } catch (...) {
    }
  }
}

void record_sundials_error(int error_code, const char* module, const char* function, char* msg,
                           void* user_data) {
  if (user_data == nullptr) return;
  try {
    auto& out = *static_cast<std::string*>(user_data);
    std::ostringstream os;
    os << "[" << (module ? module : "?") << " " << (error_code < 0 ? "ERROR" : "WARNING") << "] "
       << (function ? function : "?") << ": " << (msg ? msg : "");
    out = os.str();
  } catch (...) {
  }
}

}  // namespace shelldyn
