#include "integrators/sundials/sun_linear_solver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace shelldyn {
namespace {

// Tag to recognise our own objects in the accessors (content pointers of other solvers differ).
constexpr unsigned kMagic = 0x5d1a7e11u;

struct Content {
  unsigned magic = kMagic;
  std::unique_ptr<LinearSolver> solver;
  std::vector<Index> colptr, rowind;  // pattern of the last analysis
  bool analysed = false;
  long last_flag = SUNLS_SUCCESS;
  std::string last_error;
  SolveObserver observer;
};

Content* content(SUNLinearSolver S) {
  auto* c = S ? static_cast<Content*>(S->content) : nullptr;
  if (c == nullptr || S->ops->getid == nullptr || S->ops->getid(S) != SUNLINEARSOLVER_CUSTOM ||
      c->magic != kMagic)
    throw std::invalid_argument("SUNLinearSolver was not created by make_sun_linear_solver");
  return c;
}

SUNLinearSolver_Type get_type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID get_id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int initialize(SUNLinearSolver) { return SUNLS_SUCCESS; }  // keep the analysis (header)

bool same_pattern(const Content& c, const CscView& A) {
  if (!c.analysed || static_cast<Index>(c.colptr.size()) != A.n + 1) return false;
  if (!std::equal(c.colptr.begin(), c.colptr.end(), A.colptr)) return false;
  return std::equal(c.rowind.begin(), c.rowind.end(), A.rowind);
}

int setup(SUNLinearSolver S, SUNMatrix A) {
  auto* c = static_cast<Content*>(S->content);
  try {
    c->last_error.clear();
    const CscView view = csc_view(A);
    if (!same_pattern(*c, view)) {
      c->analysed = false;
      c->solver->analyze(view);
      c->colptr.assign(view.colptr, view.colptr + view.n + 1);
      c->rowind.assign(view.rowind, view.rowind + view.nnz());
      c->analysed = true;
    }
    c->solver->factorize(view);
    c->last_flag = SUNLS_SUCCESS;
  } catch (const std::exception& e) {
    c->last_error = std::string("linear solver setup: ") + e.what();
    c->last_flag = SUNLS_PACKAGE_FAIL_REC;
  } catch (...) {
    c->last_error = "linear solver setup: unknown exception";
    c->last_flag = SUNLS_PACKAGE_FAIL_REC;
  }
  return static_cast<int>(c->last_flag);
}

int solve(SUNLinearSolver S, SUNMatrix, N_Vector x, N_Vector b, sunrealtype) {
  auto* c = static_cast<Content*>(S->content);
  try {
    if (!c->solver->factorized()) {
      c->last_error = "linear solver solve: no valid factorization (setup failed or never ran)";
      return static_cast<int>(c->last_flag = SUNLS_PACKAGE_FAIL_REC);
    }
    const Index n = N_VGetLength(b);
    const double* bp = N_VGetArrayPointer(b);
    double* xp = N_VGetArrayPointer(x);
    c->solver->solve(bp, xp);
    for (Index i = 0; i < n; ++i)
      if (!std::isfinite(xp[i])) {
        c->last_error = "linear solver solve: non-finite solution component " + std::to_string(i);
        return static_cast<int>(c->last_flag = SUNLS_PACKAGE_FAIL_REC);
      }
    if (c->observer) c->observer(bp, xp, n);
    c->last_flag = SUNLS_SUCCESS;
  } catch (const std::exception& e) {
    c->last_error = std::string("linear solver solve: ") + e.what();
    c->last_flag = SUNLS_PACKAGE_FAIL_UNREC;
  } catch (...) {
    c->last_error = "linear solver solve: unknown exception";
    c->last_flag = SUNLS_PACKAGE_FAIL_UNREC;
  }
  return static_cast<int>(c->last_flag);
}

sunindextype last_flag(SUNLinearSolver S) { return static_cast<Content*>(S->content)->last_flag; }

int free_solver(SUNLinearSolver S) {
  if (S == nullptr) return SUNLS_SUCCESS;
  delete static_cast<Content*>(S->content);
  S->content = nullptr;
  SUNLinSolFreeEmpty(S);
  return SUNLS_SUCCESS;
}

}  // namespace

SUNLinearSolver make_sun_linear_solver(SUNContext ctx, std::unique_ptr<LinearSolver> solver) {
  if (!solver) throw std::invalid_argument("make_sun_linear_solver: null LinearSolver");
  auto c = std::make_unique<Content>();
  c->solver = std::move(solver);
  SUNLinearSolver S = SUNLinSolNewEmpty(ctx);
  check_ptr(S, "SUNLinSolNewEmpty");
  S->ops->gettype = get_type;
  S->ops->getid = get_id;
  S->ops->initialize = initialize;
  S->ops->setup = setup;
  S->ops->solve = solve;
  S->ops->lastflag = last_flag;
  S->ops->free = free_solver;
  S->content = c.release();
  return S;
}

LinearSolver& sun_linear_solver_backend(SUNLinearSolver S) { return *content(S)->solver; }

const std::string& sun_linear_solver_last_error(SUNLinearSolver S) { return content(S)->last_error; }

void sun_linear_solver_set_observer(SUNLinearSolver S, SolveObserver observer) {
  content(S)->observer = std::move(observer);
}

}  // namespace shelldyn
