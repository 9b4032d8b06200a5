#include "lib/model/semi_discrete_system.hpp"

#include "lib/model/assembler.hpp"

namespace shelldyn {

void SemiDiscreteSystem::inertia_force(const Eigen::VectorXd& u, const Eigen::VectorXd& v, const Eigen::VectorXd& a,
                                       const std::vector<DirectorChart>& charts, double* out) const {
  SparseMatrix M{pattern(), std::vector<double>(static_cast<size_t>(pattern()->nnz()), 0.0)};
  mass(u, charts, M);
  Eigen::VectorXd fm(num_dofs());
  inertial(u, v, charts, fm.data());
  multiply(M.view(), a.data(), out);
  for (Index i = 0; i < num_dofs(); ++i) out[i] += fm[i];
}

const std::vector<Index>& SemiDiscreteSystem::prescribed_dofs() const {
  static const std::vector<Index> none;
  return none;
}

// Defaults of a system without constraints (m = 0): empty values, an empty 0 × n Jacobian.
void SemiDiscreteSystem::constraint_values(double, const Eigen::VectorXd&, const std::vector<DirectorChart>&,
                                           Eigen::VectorXd& g) const {
  g.resize(0);
}
void SemiDiscreteSystem::constraint_jacobian(double, const Eigen::VectorXd&, const std::vector<DirectorChart>&,
                                             ConstraintMatrix& G) const {
  G.resize(0, num_dofs());
}
void SemiDiscreteSystem::constraint_time_derivative(double, const Eigen::VectorXd&, const std::vector<DirectorChart>&,
                                                    Eigen::VectorXd& g_t) const {
  g_t.resize(0);
}
void SemiDiscreteSystem::constraint_discrete_gradient(double, const Eigen::VectorXd&, double, const Eigen::VectorXd&,
                                                      const std::vector<DirectorChart>&, ConstraintMatrix& G_bar,
                                                      Eigen::VectorXd& tau) const {
  G_bar.resize(0, num_dofs());
  tau.resize(0);
}

}  // namespace shelldyn
