// The acceleration that satisfies the semi-discrete equations at a state (docs/theory.md §6.4 start-up):
// M(u) a = F_ext(t, u) − F_int(u) − F_m(u, v), constrained rows zero. em-galpha starts its Newmark recursion
// from it; em-exact's `predictor = newmark` does the same (docs/theory/exact-energy-momentum.md §5.9).
#pragma once

#include "lib/model/semi_discrete_system.hpp"
#include "lib/model/state.hpp"

#include <Eigen/Core>
#include <string>

namespace shelldyn {

// Solves for a (size num_dofs) with a fresh factorization of M(u) by `linear_solver` (a registered name,
// lib/linalg/linear_solver.hpp). F_m includes the system's damping force C v, if it has one.
void consistent_acceleration(const SemiDiscreteSystem& sys, const State& s, const std::string& linear_solver,
                             Eigen::VectorXd& a);
// The system both solve: M = M(u) and rhs = F_ext − F_int − F_m, with the Dirichlet rows applied (M on sys.pattern()).
void acceleration_system(const SemiDiscreteSystem& sys, const State& s, SparseMatrix& M, Eigen::VectorXd& rhs);

}  // namespace shelldyn
