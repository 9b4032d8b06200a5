#include "integrators/sundials/callback_linear_solver.hpp"

#include <memory>
#include <stdexcept>

namespace shelldyn {
namespace {

struct Content {
  CallbackSolverOps ops;
  int last_flag = SUNLS_SUCCESS;
};

Content* content(SUNLinearSolver S) { return static_cast<Content*>(S->content); }

int setup(SUNLinearSolver S, SUNMatrix) {
  Content* c = content(S);
  try {
    return c->last_flag = c->ops.setup();
  } catch (...) {
    return c->last_flag = SUNLS_PACKAGE_FAIL_UNREC;
  }
}

int solve(SUNLinearSolver S, SUNMatrix, N_Vector x, N_Vector b, sunrealtype) {
  Content* c = content(S);
  try {
    return c->last_flag = c->ops.solve(N_VGetArrayPointer(b), N_VGetArrayPointer(x));
  } catch (...) {
    return c->last_flag = SUNLS_PACKAGE_FAIL_UNREC;
  }
}

}  // namespace

SunLinearSolverPtr make_callback_linear_solver(SUNContext ctx, CallbackSolverOps ops) {
  if (!ops.setup || !ops.solve) throw std::invalid_argument("make_callback_linear_solver: setup and solve are required");
  auto c = std::make_unique<Content>();
  c->ops = std::move(ops);
  SunLinearSolverPtr S(SUNLinSolNewEmpty(ctx));
  check_ptr(S.get(), "SUNLinSolNewEmpty");
  S->ops->gettype = [](SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; };
  S->ops->getid = [](SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; };
  S->ops->initialize = [](SUNLinearSolver) { return static_cast<int>(SUNLS_SUCCESS); };
  S->ops->setup = setup;
  S->ops->solve = solve;
  S->ops->lastflag = [](SUNLinearSolver L) { return static_cast<sunindextype>(content(L)->last_flag); };
  S->ops->free = [](SUNLinearSolver L) {
    if (L == nullptr) return static_cast<int>(SUNLS_SUCCESS);
    delete content(L);
    L->content = nullptr;
    SUNLinSolFreeEmpty(L);
    return static_cast<int>(SUNLS_SUCCESS);
  };
  S->content = c.release();
  return S;
}

SunMatrixPtr make_placeholder_matrix(SUNContext ctx) {
  SunMatrixPtr A(SUNMatNewEmpty(ctx));
  check_ptr(A.get(), "SUNMatNewEmpty");
  A->ops->getid = [](SUNMatrix) { return SUNMATRIX_CUSTOM; };
  A->ops->zero = [](SUNMatrix) { return 0; };
  A->ops->destroy = [](SUNMatrix M) { SUNMatFreeEmpty(M); };
  A->ops->clone = [](SUNMatrix M) -> SUNMatrix {
    SUNMatrix B = SUNMatNewEmpty(M->sunctx);
    if (B == nullptr) return nullptr;
    if (SUNMatCopyOps(M, B) != 0) {
      SUNMatFreeEmpty(B);
      return nullptr;
    }
    return B;
  };
  return A;
}

}  // namespace shelldyn
