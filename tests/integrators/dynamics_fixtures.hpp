// Shared set-ups for the time-integration tests: a linear spring–mass system behind the
// SemiDiscreteSystem interface, and the free-flying plates of docs/theory.md §7 item 12 and
// docs/benchmarks.md §6.
#pragma once

#include "integrators/newmark/em_generalized_alpha.hpp"
#include "lib/mesh/mesh_generators.hpp"
#include "lib/model/model.hpp"
#include "lib/mesh/nodal_normals.hpp"

#include <cmath>
#include <memory>

namespace shelldyn::testing {

// m ü + k u = 0 with m = 1, k = ω² (one "node" with 5 DOFs, only the first one active; the other four are
// constrained). The algorithmic force is k[(1−α_f+ξ)u_{n+1} + (α_f−ξ)u_n] (docs/theory.md §6.7 SDOF
// reference) with the symmetric tangent k, as the CR9 element provides.
class SpringMass final : public SemiDiscreteSystem {
 public:
  explicit SpringMass(double omega) : k_(omega * omega), dofs_(1) {
    for (Fix f : {Fix::Uy, Fix::Uz, Fix::Director}) dofs_.fix(0, f);
    dofs_.resolve({DirectorChart{}});
    auto p = std::make_shared<SparsePattern>();
    p->n = 5;
    for (Index c = 0; c <= 5; ++c) p->colptr.push_back(c);
    for (Index c = 0; c < 5; ++c) p->rowind.push_back(c);
    pattern_ = p;
  }
  Index num_dofs() const override { return 5; }
  std::shared_ptr<const SparsePattern> pattern() const override { return pattern_; }
  const DofMap& dofs() const override { return dofs_; }
  State initial_state() const override {
    State s;
    s.u = s.v = s.a = Eigen::VectorXd::Zero(5);
    s.charts.assign(1, DirectorChart{});
    return s;
  }
  double internal(const Eigen::VectorXd& u, const std::vector<DirectorChart>&, double* F, SparseMatrix* K) const override {
    if (F) {
      std::fill(F, F + 5, 0.0);
      F[0] = k_ * u[0];
    }
    if (K) diagonal(*K, k_);
    return 0.5 * k_ * u[0] * u[0];
  }
  double algorithmic_internal(const Eigen::VectorXd& un, const Eigen::VectorXd& u1, const std::vector<DirectorChart>&,
                              double af, double xi, double* F, SparseMatrix* K) const override {
    if (F) {
      std::fill(F, F + 5, 0.0);
      F[0] = k_ * ((1 - af + xi) * u1[0] + (af - xi) * un[0]);
    }
    if (K) diagonal(*K, k_);
    return 0.5 * k_ * u1[0] * u1[0];
  }
  void mass(const Eigen::VectorXd&, const std::vector<DirectorChart>&, SparseMatrix& M) const override { diagonal(M, 1.0); }
  void inertial(const Eigen::VectorXd&, const Eigen::VectorXd&, const std::vector<DirectorChart>&, double* Fm) const override {
    std::fill(Fm, Fm + 5, 0.0);
  }
  void external(double, const Eigen::VectorXd&, const std::vector<DirectorChart>&, double* F) const override {
    std::fill(F, F + 5, 0.0);
  }
  Invariants invariants(const State& s) const override {
    Invariants inv;
    inv.kinetic = 0.5 * s.v[0] * s.v[0];
    inv.strain = 0.5 * k_ * s.u[0] * s.u[0];
    return inv;
  }
  double loads_end() const override { return 0.0; }
  int rechart(State&, double) override { return 0; }
  double chart_margin(const State&) const override { return 1.0; }

 private:
  static void diagonal(SparseMatrix& A, double value) { std::fill(A.values.begin(), A.values.end(), value); }
  double k_;
  DofMap dofs_;
  std::shared_ptr<const SparsePattern> pattern_;
};

// Free plate [x0, x0+a] × [y0, y0+b] of nx × ny CR9 elements (no constraints, no loads).
inline std::unique_ptr<Model> free_plate(double a, double b, int nx, int ny, const ShellMaterial& mat) {
  Mesh mesh = make_rectangle(a, b, nx, ny, -0.5 * a, -0.5 * b);
  auto normals = initial_normals(mesh);
  DofMap dofs(mesh.num_nodes());
  return std::make_unique<Model>(std::move(mesh), std::move(normals), mat, std::move(dofs));
}

// Sets the velocity field of docs/theory.md §7 item 12 about the centroid c = 0:
//   ḋ_i = v0 + ω × X_i + (0, 0, β(X_i,x² − 0.3)),   ṗ_i = ω × p_i + (−2β X_i,x, 0, 0) projected ⊥ p_i.
inline void set_free_flight_velocity(const Model& model, State& s, const Eigen::Vector3d& v0, const Eigen::Vector3d& w,
                                     double beta) {
  for (int i = 0; i < model.mesh().num_nodes(); ++i) {
    const Eigen::Vector3d X = model.mesh().X[static_cast<size_t>(i)];
    const Eigen::Vector3d p = model.director(s, i);
    s.v.segment<3>(DofMap::dof(i, 0)) = v0 + w.cross(X) + Eigen::Vector3d(0, 0, beta * (X.x() * X.x() - 0.3));
    Eigen::Vector3d pd = w.cross(p) + Eigen::Vector3d(-2 * beta * X.x(), 0, 0);
    pd -= pd.dot(p) * p;
    s.v.segment<2>(DofMap::dof(i, 3)) = chart_coordinates(pd, s.charts[static_cast<size_t>(i)]);
  }
}

inline double total_energy(const Invariants& inv) { return inv.kinetic + inv.strain; }

}  // namespace shelldyn::testing
