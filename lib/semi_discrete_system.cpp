#include "lib/semi_discrete_system.hpp"

#include "lib/assembler.hpp"

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

}  // namespace shelldyn
