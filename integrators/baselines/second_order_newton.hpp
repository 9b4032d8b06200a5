// The Newton matrix of the SUNDIALS baselines, solved on the size of q instead of the size of y = (q, v)
// (docs/theory/baseline-newton.md).
//
// IDA and ARKODE integrate the first-order form q̇ = v, M(q) v̇ = F(q, v). Both Newton systems are, after a
// scaling, the block system
//
//     [ I      −γ I     ] [x_q]   [r_q    ]
//     [ γ K    M + γ G  ] [x_v] = [M m + p]        (free rows)
//     x_v,c = m_c + p_c                             (rows of constrained dofs c: v̇_c = 0)
//
// with K the stiffness (∂ of the forces in q), G the velocity Jacobian (damping C, or a difference quotient of
// the inertial forces), γ the package's step factor (ARKODE: γ = h·a_ii; IDA: γ = 1/c_j). The first row gives
// x_v = (x_q − r_q)/γ on free dofs; putting that into the second leaves the n × n Schur complement
//
//     S x_q = M (z + γ m) + γ G z + γ p − γ² K x_q,c,    S = M + γ G + γ² K,
//     z = r_q on free dofs and −γ x_v,c on constrained ones, x_q,c = r_q,c + γ x_v,c,
//
// solved on the free rows (constrained rows and columns of S are the identity). S is symmetric whenever K and G
// are, so a Cholesky / LDLᵀ back-end factorizes it; the (2n+2)² LU of the first-order matrix is never formed.
//
// m or p may be null (taken as zero). K, M and G share the system's pattern and are filled by the caller
// before factorize(); the values are kept, so solve() uses the blocks of the last factorize().
#pragma once

#include "lib/model/dof_map.hpp"
#include "lib/linalg/linear_solver.hpp"
#include "lib/linalg/sparse_matrix.hpp"

#include <Eigen/Core>
#include <memory>
#include <string>

namespace shelldyn {

class SecondOrderNewton {
 public:
  // `linear_solver` is a make_linear_solver() name; it must factor non-symmetric matrices ("klu") if K or G
  // is not symmetric.
  SecondOrderNewton(std::shared_ptr<const SparsePattern> pattern, const DofMap& dofs, const std::string& linear_solver);

  SparseMatrix K, M, G;  // caller-filled blocks (G zero when there is no velocity dependence)

  // S = M + γ G + γ² K with the constrained rows and columns set to the identity; factorize. Throws on failure.
  void factorize(double gamma);
  // The block solve above with the γ of the last factorize(). x_q, x_v: length n; they may not alias the inputs.
  void solve(const double* r_q, const double* m, const double* p, double* x_q, double* x_v);

  double gamma() const { return gamma_; }
  const LinearSolver& backend() const { return *solver_; }

 private:
  const DofMap& dofs_;
  std::unique_ptr<LinearSolver> solver_;
  SparseMatrix S_;
  double gamma_ = 0.0;
  bool g_zero_ = false;  // G was all zeros at the last factorize()
  Eigen::VectorXd z_, xc_, rhs_, tmp_;
};

}  // namespace shelldyn
