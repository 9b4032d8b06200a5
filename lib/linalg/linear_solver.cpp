// Back-ends of lib/linalg/linear_solver.hpp. See the header for the contract; the numbers behind the
// choices (AMD everywhere, supernodal CHOLMOD by default, KLU re-pivot threshold) are in
// docs/dependencies.md §§3.2, 5.
#include "lib/linalg/linear_solver.hpp"

#include "lib/analysis/profile.hpp"
#include "lib/linalg/single_precision_factor.hpp"

#include <Eigen/SparseCholesky>
#include <cholmod.h>
#include <dmumps_c.h>  // Debian libmumps-seq-dev (sequential MUMPS 5.5; libdmumps_seq is dlopen'ed, see MumpsSolver)
#include <klu.h>

#include <dlfcn.h>
#include <omp.h>

#include <algorithm>
#include <exception>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace shelldyn {

static_assert(std::is_same<Index, SuiteSparse_long>::value,
              "shelldyn::Index must equal SuiteSparse_long to hand CSC arrays to klu_l_/cholmod_l_");

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Values must be finite: a NaN would otherwise travel silently through the factorization.
void check_values(const CscView& A, const std::string& who) {
  if (A.values == nullptr) throw std::invalid_argument(who + ": matrix has no value array");
  const Index nnz = A.nnz();
  for (Index j = 0; j < A.n; ++j)
    for (Index p = A.colptr[j]; p < A.colptr[j + 1] && p < nnz; ++p)
      if (!std::isfinite(A.values[p])) {
        std::ostringstream os;
        os << who << ": non-finite matrix entry " << A.values[p] << " at (row " << A.rowind[p]
           << ", column " << j << "); fix the assembly that produced it";
        throw std::invalid_argument(os.str());
      }
}

// Pattern shape must match the analysed one (cheap O(1) check; the SUNDIALS adapter compares
// the full arrays).
void check_same_shape(const CscView& A, Index n, Index nnz, const std::string& who) {
  if (A.n != n || A.colptr == nullptr || A.nnz() != nnz) {
    std::ostringstream os;
    os << who << ": factorize() got a matrix with n = " << A.n << ", nnz = "
       << (A.colptr ? A.nnz() : 0) << " but the analysed pattern has n = " << n << ", nnz = " << nnz
       << "; call analyze() again after a pattern change";
    throw std::invalid_argument(os.str());
  }
}

// ------------------------------------------------------------------------------------------------
// CHOLMOD
// ------------------------------------------------------------------------------------------------
// No hidden threads (architecture: the only parallelism is the element loops' OpenMP team, sized by
// --threads). Two sources exist in Debian 12's CHOLMOD 3.0 / OpenBLAS build:
//  - CHOLMOD's supernodal kernels open OpenMP regions with a fixed num_threads(4) clause, which
//    overrides omp_set_num_threads(); on a 2-core machine those threads spin and burn CPU. We call
//    CHOLMOD with OpenMP's max-active-levels set to 0 (single_threaded below), so they run on one thread.
//  - OpenBLAS (pthread build) starts one thread per core for the dense supernode kernels; on matrices of
//    a few thousand unknowns they cost more than they save. openblas_set_num_threads(1) is called if the
//    symbol is present (looked up at run time, so a reference BLAS works as well). The pool's threads are
//    created when OpenBLAS is loaded and then sleep: they appear in /proc/self/task but burn no CPU.
//    Called by every CHOLMOD and MUMPS constructor (not once per process), so that a solver made after
//    someone raised the BLAS thread count still runs its kernels on one thread.
void limit_blas_threads() {
  using SetThreads = void (*)(int);
  static const auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  if (set) set(1);
}

}  // namespace

std::string blas_description() {
  using GetString = char* (*)();
  static const auto config = reinterpret_cast<GetString>(dlsym(RTLD_DEFAULT, "openblas_get_config"));
  static const auto core = reinterpret_cast<GetString>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  if (!config) return "unknown (not OpenBLAS)";
  std::string d = config();  // with DYNAMIC_ARCH it names the core chosen at load time
  if (core && d.find(core()) == std::string::npos) d += std::string(" (core: ") + core() + ")";
  return d;
}

namespace {
// A CHOLMOD view of A's upper triangle (stype = +1: entries below the diagonal are ignored).
cholmod_sparse header(const CscView& A) {
  cholmod_sparse S{};
  S.nrow = S.ncol = static_cast<size_t>(A.n);
  S.nzmax = static_cast<size_t>(A.nnz());
  S.p = const_cast<Index*>(A.colptr);  // CHOLMOD never writes its input matrix
  S.i = const_cast<Index*>(A.rowind);
  S.x = const_cast<double*>(A.values);
  S.stype = 1;
  S.itype = CHOLMOD_LONG;
  S.xtype = CHOLMOD_REAL;
  S.dtype = CHOLMOD_DOUBLE;
  S.sorted = 1;
  S.packed = 1;
  return S;
}

template <class F>
void single_threaded(const F& f) {
  if (omp_in_parallel()) {  // already inside a region: CHOLMOD's regions nest and stay inactive
    f();
    return;
  }
  // max-active-levels 0 makes every region started by this call run on the calling thread only; it is
  // restored at once (CHOLMOD is called between element loops, never concurrently with them).
  const int levels = omp_get_max_active_levels();
  omp_set_max_active_levels(0);
  try {
    f();
  } catch (...) {
    omp_set_max_active_levels(levels);
    throw;
  }
  omp_set_max_active_levels(levels);
}

class CholmodSolver final : public LinearSolver {
 public:
  CholmodSolver() {
    limit_blas_threads();
    cholmod_l_start(&cc_);
    cc_.print = 0;  // report through exceptions, not stderr
    cc_.nmethods = 1;
    cc_.method[0].ordering = CHOLMOD_AMD;
    cc_.postorder = 1;
    cc_.supernodal = CHOLMOD_SUPERNODAL;
    cc_.final_ll = 0;
  }
  ~CholmodSolver() override {
    release();
    cholmod_l_free_dense(&X_, &cc_);
    cholmod_l_free_dense(&Y_, &cc_);
    cholmod_l_free_dense(&E_, &cc_);
    cholmod_l_finish(&cc_);
  }
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  std::string name() const override { return "cholmod"; }
  bool factorized() const override { return factorized_; }

  void analyze(const CscView& A) override {
    profile::Scope prof(profile::Section::analyze);
    check_csc_pattern(A, "cholmod");
    const auto t0 = Clock::now();
    release();
    cholmod_sparse S = header(A);
    single_threaded([&] { L_ = cholmod_l_analyze(&S, &cc_); });
    if (L_ == nullptr || cc_.status < CHOLMOD_OK)
      throw std::runtime_error("cholmod: cholmod_l_analyze failed (status " +
                               std::to_string(cc_.status) + ")");
    n_ = A.n;
    nnz_ = A.nnz();
    ++stats_.analyses;
    stats_.analyze_s += seconds_since(t0);
  }

  void factorize(const CscView& A) override {
    profile::Scope prof(profile::Section::factorize);
    if (L_ == nullptr) analyze(A);
    check_same_shape(A, n_, nnz_, "cholmod");
    check_values(A, "cholmod");
    factorized_ = false;
    sp_.clear();
    dp_.clear();
    const auto t0 = Clock::now();
    cholmod_sparse S = header(A);
    single_threaded([&] { cholmod_l_factorize(&S, L_, &cc_); });
    if (cc_.status == CHOLMOD_NOT_POSDEF && !ldlt_) {
      // Documented fallback: switch to simplicial LDLᵀ for good (header), one re-analysis.
      ldlt_ = true;
      cc_.supernodal = CHOLMOD_SIMPLICIAL;
      cholmod_l_free_factor(&L_, &cc_);
      stats_.factorize_s += seconds_since(t0);
      analyze(A);
      return factorize(A);
    }
    stats_.factorize_s += seconds_since(t0);
    if (cc_.status < CHOLMOD_OK)
      throw std::runtime_error("cholmod: cholmod_l_factorize failed (status " +
                               std::to_string(cc_.status) + ", e.g. out of memory)");
    const char* kind = ldlt_ ? "simplicial LDL^T" : "supernodal LL^T";
    if (cc_.status == CHOLMOD_NOT_POSDEF) {
      std::ostringstream os;
      os << "cholmod (" << kind << "): zero pivot at column " << original_column(L_->minor)
         << " (matrix singular to working precision; LDL^T does not pivot)";
      throw std::runtime_error(os.str());
    }
    const double rc = cholmod_l_rcond(L_, &cc_);
    if (!(rc > 0.0) || !std::isfinite(rc)) {
      std::ostringstream os;
      os << "cholmod (" << kind << "): numerical breakdown, reciprocal condition estimate " << rc;
      throw std::runtime_error(os.str());
    }
    factorized_ = true;
    ++stats_.factorizations;
    copy_factor();
  }

  bool set_single_precision_solves(bool on) override {
    single_ = on;
    if (factorized_) copy_factor();
    return true;
  }

  // LLᵀ succeeded: positive definite. Simplicial LDLᵀ: D is the diagonal of L (CHOLMOD's LDL' layout).
  long negative_pivots() const override {
    if (!factorized_) throw std::logic_error("cholmod: negative_pivots() called without a valid factorization");
    if (L_->is_ll) return 0;
    const auto* Lp = static_cast<const Index*>(L_->p);
    const auto* Lx = static_cast<const double*>(L_->x);
    long neg = 0;
    for (size_t j = 0; j < L_->n; ++j) neg += Lx[Lp[j]] < 0.0 ? 1 : 0;
    return neg;
  }

  void solve(const double* b, double* x) const override {
    profile::Scope prof(profile::Section::solve);
    if (!factorized_) throw std::logic_error("cholmod: solve() called without a valid factorization");
    const auto t0 = Clock::now();
    if (!sp_.empty()) {  // single-precision copy of the supernodal factor (lib/linalg/single_precision_factor.hpp)
      sp_.solve(b, x);
      ++stats_.solves;
      ++stats_.single_solves;
      stats_.solve_s += seconds_since(t0);
      return;
    }
    if (!dp_.empty()) {  // the same solves on an exact copy (no per-supernode BLAS calls)
      dp_.solve(b, x);
      ++stats_.solves;
      stats_.solve_s += seconds_since(t0);
      return;
    }
    cholmod_dense B{};
    B.nrow = static_cast<size_t>(n_);
    B.ncol = 1;
    B.nzmax = B.nrow;
    B.d = B.nrow;
    B.x = const_cast<double*>(b);  // read only in cholmod_l_solve2
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    // solve2 reuses X, Y, E across calls: no allocation per solve.
    int ok = 0;
    single_threaded([&] { ok = cholmod_l_solve2(CHOLMOD_A, L_, &B, nullptr, &X_, nullptr, &Y_, &E_, &cc_); });
    if (!ok)
      throw std::runtime_error("cholmod: cholmod_l_solve2 failed (status " +
                               std::to_string(cc_.status) + ")");
    std::memcpy(x, X_->x, sizeof(double) * static_cast<size_t>(n_));  // alias-safe: X_ is separate
    ++stats_.solves;
    stats_.solve_s += seconds_since(t0);
  }

 private:
  Index original_column(size_t minor) const {
    if (L_ && L_->Perm && minor < L_->n) return static_cast<const Index*>(L_->Perm)[minor];
    return static_cast<Index>(minor);
  }
  void release() {
    if (L_) cholmod_l_free_factor(&L_, &cc_);
    factorized_ = false;
    sp_.clear();
    dp_.clear();
  }
  // Only a supernodal LLᵀ factor is copied, in float (single_) or exactly; a simplicial LDLᵀ one (the indefinite
  // fallback) keeps CHOLMOD's solves.
  void copy_factor() {
    sp_.clear();
    dp_.clear();
    if (!factorized_ || !L_->is_super || !L_->is_ll) return;
    SinglePrecisionFactor::Arrays a;
    a.n = static_cast<Index>(L_->n);
    a.nsuper = static_cast<Index>(L_->nsuper);
    a.super = static_cast<const Index*>(L_->super);
    a.pi = static_cast<const Index*>(L_->pi);
    a.px = static_cast<const Index*>(L_->px);
    a.s = static_cast<const Index*>(L_->s);
    a.x = static_cast<const double*>(L_->x);
    a.perm = static_cast<const Index*>(L_->Perm);
    if (single_ && sp_.assign(a)) return;  // false (sp_ stays empty): the factor does not fit in float
    dp_.assign(a);
  }

  mutable cholmod_common cc_{};
  cholmod_factor* L_ = nullptr;
  mutable cholmod_dense *X_ = nullptr, *Y_ = nullptr, *E_ = nullptr;
  Index n_ = 0, nnz_ = 0;
  bool ldlt_ = false;
  bool factorized_ = false;
  bool single_ = false;
  SinglePrecisionFactor sp_;  // non-empty: solves use it
  DoublePrecisionFactor dp_;  // non-empty (and sp_ empty): solves use it
};

// ------------------------------------------------------------------------------------------------
// Eigen SimplicialLDLT on a Map of the caller's arrays (no copy of the pattern on our side).
// ------------------------------------------------------------------------------------------------
class EigenLdltSolver final : public LinearSolver {
  using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, Index>;
  using MapT = Eigen::Map<const SpMat>;

 public:
  std::string name() const override { return "eigen-ldlt"; }
  bool factorized() const override { return factorized_; }

  void analyze(const CscView& A) override {
    profile::Scope prof(profile::Section::analyze);
    check_csc_pattern(A, "eigen-ldlt");
    const auto t0 = Clock::now();
    factorized_ = false;
    ldlt_.analyzePattern(map(A));
    if (ldlt_.info() != Eigen::Success)
      throw std::runtime_error("eigen-ldlt: analyzePattern failed");
    n_ = A.n;
    nnz_ = A.nnz();
    analysed_ = true;
    work_.resize(n_);
    ++stats_.analyses;
    stats_.analyze_s += seconds_since(t0);
  }

  void factorize(const CscView& A) override {
    profile::Scope prof(profile::Section::factorize);
    if (!analysed_) analyze(A);
    check_same_shape(A, n_, nnz_, "eigen-ldlt");
    check_values(A, "eigen-ldlt");
    factorized_ = false;
    const auto t0 = Clock::now();
    ldlt_.factorize(map(A));
    stats_.factorize_s += seconds_since(t0);
    const auto& D = ldlt_.vectorD();
    if (ldlt_.info() != Eigen::Success) {
      // Eigen stores the failing pivot before stopping: the first zero of D is the column.
      std::ostringstream os;
      os << "eigen-ldlt: zero pivot";
      for (Index k = 0; k < D.size(); ++k)
        if (D[k] == 0.0) {
          os << " at column " << ldlt_.permutationPinv().indices()[k];
          break;
        }
      os << " (matrix singular to working precision; LDL^T does not pivot)";
      throw std::runtime_error(os.str());
    }
    if (!D.allFinite())
      throw std::runtime_error("eigen-ldlt: numerical breakdown (non-finite pivot in D)");
    factorized_ = true;
    ++stats_.factorizations;
  }

  long negative_pivots() const override {
    if (!factorized_) throw std::logic_error("eigen-ldlt: negative_pivots() called without a valid factorization");
    return static_cast<long>((ldlt_.vectorD().array() < 0.0).count());
  }

  void solve(const double* b, double* x) const override {
    profile::Scope prof(profile::Section::solve);
    if (!factorized_)
      throw std::logic_error("eigen-ldlt: solve() called without a valid factorization");
    const auto t0 = Clock::now();
    // Eigen's permuted triangular solves are not alias-safe on Maps; go through work_.
    work_ = Eigen::Map<const Eigen::VectorXd>(b, n_);
    Eigen::Map<Eigen::VectorXd>(x, n_) = ldlt_.solve(work_);
    ++stats_.solves;
    stats_.solve_s += seconds_since(t0);
  }

 private:
  static MapT map(const CscView& A) {
    return MapT(A.n, A.n, A.nnz(), A.colptr, A.rowind, A.values);
  }
  Eigen::SimplicialLDLT<MapT, Eigen::Lower, Eigen::AMDOrdering<Index>> ldlt_;
  mutable Eigen::VectorXd work_;
  Index n_ = 0, nnz_ = 0;
  bool analysed_ = false;
  bool factorized_ = false;
};

// ------------------------------------------------------------------------------------------------
// KLU
// ------------------------------------------------------------------------------------------------
class KluSolver final : public LinearSolver {
 public:
  KluSolver() {
    klu_l_defaults(&common_);
    common_.ordering = 0;  // AMD (docs/dependencies.md §5.4)
  }
  ~KluSolver() override { release(); }
  KluSolver(const KluSolver&) = delete;
  KluSolver& operator=(const KluSolver&) = delete;

  std::string name() const override { return "klu"; }
  bool factorized() const override { return factorized_; }

  void analyze(const CscView& A) override {
    profile::Scope prof(profile::Section::analyze);
    check_csc_pattern(A, "klu");
    const auto t0 = Clock::now();
    release();
    symbolic_ = klu_l_analyze(A.n, const_cast<Index*>(A.colptr), const_cast<Index*>(A.rowind),
                              &common_);
    if (symbolic_ == nullptr)
      throw std::runtime_error("klu: klu_l_analyze failed (status " +
                               std::to_string(common_.status) + ")");
    n_ = A.n;
    nnz_ = A.nnz();
    ++stats_.analyses;
    stats_.analyze_s += seconds_since(t0);
  }

  void factorize(const CscView& A) override {
    profile::Scope prof(profile::Section::factorize);
    if (symbolic_ == nullptr) analyze(A);
    check_same_shape(A, n_, nnz_, "klu");
    check_values(A, "klu");
    factorized_ = false;
    const auto t0 = Clock::now();
    auto* Ap = const_cast<Index*>(A.colptr);
    auto* Ai = const_cast<Index*>(A.rowind);
    auto* Ax = const_cast<double*>(A.values);
    bool ok = false;
    if (numeric_ != nullptr) {
      // Reuse the pivot order; re-pivot if it has become poor (tiny reciprocal pivot growth).
      ok = klu_l_refactor(Ap, Ai, Ax, symbolic_, numeric_, &common_) &&
           klu_l_rcond(symbolic_, numeric_, &common_) && common_.rcond >= repivot_threshold();
    }
    if (!ok) {
      if (numeric_) klu_l_free_numeric(&numeric_, &common_);
      numeric_ = klu_l_factor(Ap, Ai, Ax, symbolic_, &common_);
      ok = numeric_ != nullptr && klu_l_rcond(symbolic_, numeric_, &common_);
    }
    stats_.factorize_s += seconds_since(t0);
    if (!ok || common_.status != KLU_OK || !(common_.rcond > 0.0) || !std::isfinite(common_.rcond)) {
      std::ostringstream os;
      os << "klu: ";
      if (common_.status == KLU_SINGULAR)
        os << "matrix is singular (zero pivot at column " << common_.singular_col << ")";
      else if (common_.status < 0)
        os << "klu_l_factor failed (status " << common_.status << ")";
      else
        os << "numerical breakdown (reciprocal pivot growth estimate " << common_.rcond << ")";
      if (numeric_) klu_l_free_numeric(&numeric_, &common_);
      throw std::runtime_error(os.str());
    }
    factorized_ = true;
    ++stats_.factorizations;
  }

  void solve(const double* b, double* x) const override {
    profile::Scope prof(profile::Section::solve);
    if (!factorized_) throw std::logic_error("klu: solve() called without a valid factorization");
    const auto t0 = Clock::now();
    if (x != b) std::memcpy(x, b, sizeof(double) * static_cast<size_t>(n_));
    if (!klu_l_solve(symbolic_, numeric_, n_, 1, x, &common_))
      throw std::runtime_error("klu: klu_l_solve failed (status " + std::to_string(common_.status) +
                               ")");
    ++stats_.solves;
    stats_.solve_s += seconds_since(t0);
  }

 private:
  // eps^(2/3) ≈ 3.7e-11, SUNDIALS' own threshold for a fresh factorization.
  static double repivot_threshold() {
    return std::pow(std::numeric_limits<double>::epsilon(), 2.0 / 3.0);
  }
  void release() {
    if (numeric_) klu_l_free_numeric(&numeric_, &common_);
    if (symbolic_) klu_l_free_symbolic(&symbolic_, &common_);
    factorized_ = false;
  }

  mutable klu_l_common common_{};
  klu_l_symbolic* symbolic_ = nullptr;
  klu_l_numeric* numeric_ = nullptr;
  Index n_ = 0, nnz_ = 0;
  bool factorized_ = false;
};


// ------------------------------------------------------------------------------------------------
// MUMPS (sequential, dmumps_c): multifrontal LDLᵀ with threshold pivoting (1×1 and 2×2 pivots) for
// general symmetric matrices, SYM = 2 (docs/dependencies.md §5.2). The centralized assembled input
// holds one triangle (row ≤ column) in 1-based coordinates; the index arrays are built once per pattern
// by analyze(), factorize() only gathers the values through pos_. Analysis uses the pattern only
// (ICNTL(6) = 0, ICNTL(12) = 1), so one analysis stays valid for any values on that pattern.
// Threads: Debian's sequential MUMPS has no OpenMP; its dense kernels go through the system BLAS, limited
// to one thread like CHOLMOD's (limit_blas_threads above).
// ------------------------------------------------------------------------------------------------
//
// Loaded at run time (dlopen, RTLD_LOCAL) rather than linked: Debian's sequential libraries carry their own
// MPI stubs and export the C symbols MPI_Init, MPI_Comm_rank, MPI_Finalize and MPI_Wtime. Linked into an
// executable that also uses Open MPI (the MPI sweep executor, integrators/runs/mpi_executor.hpp), they can
// come first in the global symbol lookup and turn the real MPI_Init into a stub. Loaded locally, they are
// seen by nobody but the solver (MUMPS calls only its Fortran stubs mpi_*_, which Open MPI's C library
// does not define). docs/dependencies.md §2.4.
using DmumpsC = void (*)(DMUMPS_STRUC_C*);
DmumpsC dmumps_entry() {
  static const DmumpsC entry = [] {
    void* lib = dlopen(SHELLDYN_DMUMPS_SEQ_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    if (lib == nullptr) {
      const char* why = dlerror();
      throw std::runtime_error(std::string("mumps: cannot load the sequential MUMPS library ") +
                               SHELLDYN_DMUMPS_SEQ_LIBRARY + " (" + (why ? why : "unknown error") +
                               "); install libmumps-seq-dev (scripts/install-deps.sh) or use linear_solver=cholmod");
    }
    void* f = dlsym(lib, "dmumps_c");
    if (f == nullptr)
      throw std::runtime_error(std::string("mumps: ") + SHELLDYN_DMUMPS_SEQ_LIBRARY + " has no dmumps_c");
    return reinterpret_cast<DmumpsC>(f);
  }();
  return entry;
}

class MumpsSolver final : public LinearSolver {
 public:
  MumpsSolver() : dmumps_c(dmumps_entry()) {
    limit_blas_threads();
    id_.comm_fortran = kUseCommWorld;  // the sequential library's stub communicator
    id_.par = 1;                       // the host works (the only process)
    id_.sym = 2;                       // general symmetric: indefinite matrices allowed
    id_.job = -1;                      // initialise the instance
    dmumps_c(&id_);
    if (id_.infog[0] < 0)
      throw std::runtime_error("mumps: initialisation failed (INFOG(1) = " + std::to_string(id_.infog[0]) + ")");
    alive_ = true;
    // Silence: no error, diagnostic or global-information output, print level 0 (ICNTL(1..4)).
    icntl(1) = -1;
    icntl(2) = -1;
    icntl(3) = -1;
    icntl(4) = 0;
    icntl(6) = 0;   // no value-based column permutation at analysis: the analysis depends on the pattern only
    icntl(7) = kOrdering;
    icntl(12) = 1;  // usual ordering on the pattern (no value-based compression of 2×2 pivot candidates)
    icntl(24) = 1;  // null pivot detection: a singular matrix is reported with its column (PIVNUL_LIST)
  }
  ~MumpsSolver() override {
    if (alive_) {
      id_.job = -2;  // free everything MUMPS allocated
      dmumps_c(&id_);
    }
  }
  MumpsSolver(const MumpsSolver&) = delete;
  MumpsSolver& operator=(const MumpsSolver&) = delete;

  std::string name() const override { return "mumps"; }
  bool factorized() const override { return factorized_; }

  void analyze(const CscView& A) override {
    profile::Scope prof(profile::Section::analyze);
    check_csc_pattern(A, "mumps");
    if (A.n > static_cast<Index>(std::numeric_limits<MUMPS_INT>::max()))
      throw std::invalid_argument("mumps: n = " + std::to_string(A.n) +
                                  " exceeds the 32-bit index range of Debian's MUMPS build; use cholmod");
    const auto t0 = Clock::now();
    factorized_ = false;
    analysed_ = false;
    // One triangle of the full storage, 1-based, once per pattern.
    irn_.clear();
    jcn_.clear();
    pos_.clear();
    for (Index j = 0; j < A.n; ++j)
      for (Index p = A.colptr[j]; p < A.colptr[j + 1]; ++p)
        if (A.rowind[p] <= j) {
          irn_.push_back(static_cast<MUMPS_INT>(A.rowind[p] + 1));
          jcn_.push_back(static_cast<MUMPS_INT>(j + 1));
          pos_.push_back(p);
        }
    a_.assign(pos_.size(), 0.0);
    rhs_.assign(static_cast<size_t>(A.n), 0.0);
    n_ = A.n;
    nnz_ = A.nnz();
    point_arrays();
    id_.job = 1;
    dmumps_c(&id_);
    if (id_.infog[0] < 0) throw std::runtime_error("mumps: analysis failed: " + describe_error());
    analysed_ = true;
    ++stats_.analyses;
    stats_.analyze_s += seconds_since(t0);
  }

  void factorize(const CscView& A) override {
    profile::Scope prof(profile::Section::factorize);
    if (!analysed_) analyze(A);
    check_same_shape(A, n_, nnz_, "mumps");
    check_values(A, "mumps");
    factorized_ = false;
    const auto t0 = Clock::now();
    for (size_t k = 0; k < pos_.size(); ++k) a_[k] = A.values[pos_[k]];
    point_arrays();
    id_.job = 2;
    dmumps_c(&id_);
    // Workspace estimates from the analysis can be too small once pivots are delayed (INFO(1) = -8/-9):
    // grow the relaxation ICNTL(14) and factorize again (MUMPS user guide, "Error diagnostics").
    for (int attempt = 0; attempt < 4 && (id_.infog[0] == -8 || id_.infog[0] == -9); ++attempt) {
      icntl(14) = 2 * std::max(icntl(14), 20);
      dmumps_c(&id_);
    }
    stats_.factorize_s += seconds_since(t0);
    if (id_.infog[0] < 0) {
      if (id_.infog[0] == -10)
        throw std::runtime_error("mumps: matrix is numerically singular (" + std::to_string(id_.info[1]) +
                                 " pivots eliminated before the breakdown)");
      throw std::runtime_error("mumps: factorization failed: " + describe_error());
    }
    if (id_.infog[27] > 0) {  // INFOG(28): null pivots found by ICNTL(24); PIVNUL_LIST holds their rows
      std::ostringstream os;
      os << "mumps: zero pivot at column " << (id_.pivnul_list ? id_.pivnul_list[0] - 1 : -1)
         << " (matrix singular to working precision; " << id_.infog[27] << " null pivot"
         << (id_.infog[27] > 1 ? "s" : "") << ")";
      throw std::runtime_error(os.str());
    }
    factorized_ = true;
    ++stats_.factorizations;
  }

  // INFOG(12): number of negative pivots of the LDLᵀ factorization (2×2 pivots counted by their
  // eigenvalues), i.e. the inertia by Sylvester's law.
  long negative_pivots() const override {
    if (!factorized_) throw std::logic_error("mumps: negative_pivots() called without a valid factorization");
    return static_cast<long>(id_.infog[11]);
  }

  void solve(const double* b, double* x) const override {
    profile::Scope prof(profile::Section::solve);
    if (!factorized_) throw std::logic_error("mumps: solve() called without a valid factorization");
    const auto t0 = Clock::now();
    std::memcpy(rhs_.data(), b, sizeof(double) * static_cast<size_t>(n_));  // alias-safe: rhs_ is separate
    id_.rhs = rhs_.data();
    id_.nrhs = 1;
    id_.lrhs = static_cast<MUMPS_INT>(n_);
    id_.job = 3;
    dmumps_c(&id_);
    if (id_.infog[0] < 0) throw std::runtime_error("mumps: solve failed: " + describe_error());
    std::memcpy(x, rhs_.data(), sizeof(double) * static_cast<size_t>(n_));
    ++stats_.solves;
    stats_.solve_s += seconds_since(t0);
  }

 private:
  static constexpr MUMPS_INT kUseCommWorld = -987654;  // MUMPS' "MPI_COMM_WORLD" for the C interface
  static constexpr MUMPS_INT kOrdering = 0;            // ICNTL(7): 0 = AMD, as for the other back-ends

  MUMPS_INT& icntl(int k) { return id_.icntl[k - 1]; }  // 1-based, as in the MUMPS user guide
  void point_arrays() const {
    id_.n = static_cast<MUMPS_INT>(n_);
    id_.nnz = static_cast<MUMPS_INT8>(pos_.size());
    id_.irn = const_cast<MUMPS_INT*>(irn_.data());  // read only by MUMPS
    id_.jcn = const_cast<MUMPS_INT*>(jcn_.data());
    id_.a = const_cast<double*>(a_.data());
  }
  std::string describe_error() const {
    std::ostringstream os;
    os << "INFOG(1) = " << id_.infog[0] << ", INFOG(2) = " << id_.infog[1];
    switch (id_.infog[0]) {
      case -5: case -7: case -13: os << " (out of memory)"; break;
      case -8: case -9: case -14: case -15: case -17: case -20: os << " (work array too small)"; break;
      case -10: os << " (numerically singular)"; break;
      case -16: os << " (bad n)"; break;
      default: break;
    }
    return os.str();
  }

  DmumpsC dmumps_c;
  mutable DMUMPS_STRUC_C id_{};
  bool alive_ = false;
  std::vector<MUMPS_INT> irn_, jcn_;
  std::vector<Index> pos_;  // CSC position of each triangle entry
  std::vector<double> a_;
  mutable std::vector<double> rhs_;
  Index n_ = 0, nnz_ = 0;
  bool analysed_ = false;
  bool factorized_ = false;
};

}  // namespace

template <typename Real>
bool copy_cholmod_factor(const CscView& A, SupernodalFactorCopy<Real>& out) {
  check_csc_pattern(A, "copy_cholmod_factor");
  limit_blas_threads();
  cholmod_common cc{};
  cholmod_l_start(&cc);
  cc.print = 0;
  cc.nmethods = 1;
  cc.method[0].ordering = CHOLMOD_AMD;
  cc.postorder = 1;
  cc.supernodal = CHOLMOD_SUPERNODAL;
  cc.final_ll = 0;
  cholmod_sparse S = header(A);
  cholmod_factor* L = nullptr;
  bool ok = false;
  single_threaded([&] {
    L = cholmod_l_analyze(&S, &cc);
    ok = L != nullptr && cholmod_l_factorize(&S, L, &cc) && cc.status == CHOLMOD_OK && L->is_super && L->is_ll;
  });
  if (ok) {
    SupernodalArrays a;
    a.n = static_cast<Index>(L->n);
    a.nsuper = static_cast<Index>(L->nsuper);
    a.super = static_cast<const Index*>(L->super);
    a.pi = static_cast<const Index*>(L->pi);
    a.px = static_cast<const Index*>(L->px);
    a.s = static_cast<const Index*>(L->s);
    a.x = static_cast<const double*>(L->x);
    a.perm = static_cast<const Index*>(L->Perm);
    ok = out.assign(a);
  }
  if (L) cholmod_l_free_factor(&L, &cc);
  cholmod_l_finish(&cc);
  return ok;
}
template bool copy_cholmod_factor(const CscView&, SupernodalFactorCopy<float>&);
template bool copy_cholmod_factor(const CscView&, SupernodalFactorCopy<double>&);

void check_csc_pattern(const CscView& A, const std::string& who) {
  std::ostringstream os;
  os << who << ": invalid CSC pattern: ";
  if (A.n <= 0 || A.colptr == nullptr) {
    os << "empty matrix (n = " << A.n << ")";
    throw std::invalid_argument(os.str());
  }
  if (A.colptr[0] != 0) {
    os << "colptr[0] = " << A.colptr[0] << " (must be 0)";
    throw std::invalid_argument(os.str());
  }
  if (A.nnz() > 0 && A.rowind == nullptr) {
    os << "row index array missing";
    throw std::invalid_argument(os.str());
  }
  for (Index j = 0; j < A.n; ++j) {
    if (A.colptr[j + 1] < A.colptr[j]) {
      os << "colptr decreases at column " << j;
      throw std::invalid_argument(os.str());
    }
    for (Index p = A.colptr[j]; p < A.colptr[j + 1]; ++p) {
      const Index i = A.rowind[p];
      if (i < 0 || i >= A.n) {
        os << "row index " << i << " out of range [0, " << A.n << ") in column " << j;
        throw std::invalid_argument(os.str());
      }
      if (p > A.colptr[j] && i <= A.rowind[p - 1]) {
        os << "row indices not strictly increasing in column " << j << " (row " << i
           << " after row " << A.rowind[p - 1] << "); sort and remove duplicates";
        throw std::invalid_argument(os.str());
      }
    }
  }
}

bool single_precision_setting(const std::string& value, const std::string& linear_solver, const std::string& who) {
  if (value != "double" && value != "single")
    throw std::invalid_argument(who + ".solve_precision: '" + value + "' (use double or single)");
  if (value == "double") return false;
  if (!make_linear_solver(linear_solver)->set_single_precision_solves(true))
    throw std::invalid_argument(who + ".solve_precision: single needs linear_solver=cholmod (got '" + linear_solver +
                                "', whose solves are double only; docs/dependencies.md §5.5)");
  return true;
}

std::vector<std::string> linear_solver_names() { return {"cholmod", "eigen-ldlt", "klu", "mumps"}; }

bool is_linear_solver_name(const std::string& name) {
  const auto names = linear_solver_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::unique_ptr<LinearSolver> make_linear_solver(const std::string& name) {
  if (name == "cholmod") return std::make_unique<CholmodSolver>();
  if (name == "eigen-ldlt") return std::make_unique<EigenLdltSolver>();
  if (name == "klu") return std::make_unique<KluSolver>();
  if (name == "mumps") return std::make_unique<MumpsSolver>();
  std::string valid;
  for (const auto& n : linear_solver_names()) valid += (valid.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown linear solver '" + name + "'; valid names: " + valid);
}

}  // namespace shelldyn
