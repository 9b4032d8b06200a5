#include "integrators/newmark/consistent_acceleration.hpp"

#include "lib/model/assembler.hpp"
#include "lib/linalg/linear_solver.hpp"

namespace shelldyn {

void acceleration_system(const SemiDiscreteSystem& sys, const State& s, SparseMatrix& M, Eigen::VectorXd& rhs) {
  const Index n = sys.num_dofs();
  M = SparseMatrix{sys.pattern(), std::vector<double>(static_cast<size_t>(sys.pattern()->nnz()), 0.0)};
  Eigen::VectorXd fint = Eigen::VectorXd::Zero(n), fm = Eigen::VectorXd::Zero(n), fext = Eigen::VectorXd::Zero(n);
  // docs/theory.md §6.4 start-up: M(u0) a0 = F_ext − F_int − F_m.
  sys.mass(s.u, s.charts, M);
  sys.internal(s.u, s.charts, fint.data(), nullptr);
  sys.inertial(s.u, s.v, s.charts, fm.data());
  sys.external(s.t, s.u, s.charts, fext.data());
  rhs = fext - fint - fm;
  apply_dirichlet(sys.dofs(), M, rhs.data());
}

void consistent_acceleration(const SemiDiscreteSystem& sys, const State& s, const std::string& linear_solver,
                             Eigen::VectorXd& a) {
  SparseMatrix M;
  Eigen::VectorXd rhs;
  acceleration_system(sys, s, M, rhs);
  auto solver = make_linear_solver(linear_solver);
  solver->factorize(M.view());
  a.resize(sys.num_dofs());
  solver->solve(rhs.data(), a.data());
}

}  // namespace shelldyn
