// The assembled semi-discretization (lib/model/model): assembly glue, invariants, re-charting, thread
// independence, and the linear pinched-hemisphere locking benchmark (docs/theory.md §7 item 9).
#include "lib/model/model.hpp"

#include "lib/linalg/linear_solver.hpp"
#include "lib/mesh/mesh_generators.hpp"
#include "lib/mesh/nodal_normals.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>

namespace shelldyn {
namespace {

const ShellMaterial kPlate{1.0e6, 0.3, 1.0, 0.1};

Model plate_model(int nx, int ny, std::vector<NodalLoad> loads = {}) {
  Mesh mesh = make_rectangle(2.0, 1.0, nx, ny, -1.0, -0.5);
  auto normals = initial_normals(mesh);
  DofMap dofs(mesh.num_nodes());
  return Model(std::move(mesh), std::move(normals), kPlate, std::move(dofs), std::move(loads));
}

Eigen::MatrixXd dense(const SparseMatrix& A) {
  const auto& p = *A.pattern;
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(p.n, p.n);
  for (Index c = 0; c < p.n; ++c)
    for (Index k = p.colptr[c]; k < p.colptr[c + 1]; ++k) D(p.rowind[k], c) = A.values[k];
  return D;
}

// A smooth deformed state of a plate: bending, stretching and a finite rotation of the directors.
State deformed(const Model& model, double amp) {
  State s = model.initial_state();
  for (int i = 0; i < model.mesh().num_nodes(); ++i) {
    const Vec3& X = model.mesh().X[static_cast<size_t>(i)];
    s.u.segment<3>(DofMap::dof(i, 0)) = amp * Vec3(0.1 * X.y() * X.x(), 0.05 * X.x(), 0.3 * X.x() * X.x());
    const Vec3 p = Vec3(-0.6 * amp * X.x(), 0.1 * amp * X.y(), 1.0).normalized();
    s.u.segment<2>(DofMap::dof(i, 3)) = chart_coordinates(p, s.charts[static_cast<size_t>(i)]);
  }
  return s;
}

TEST(Model, AssembledTangentIsTheDerivativeOfTheAssembledForce) {
  const Model model = plate_model(2, 1);
  const State s = deformed(model, 0.5);
  const Index n = model.num_dofs();
  SparseMatrix K = model.make_matrix();
  Eigen::VectorXd F(n), Fp(n), Fm(n);
  model.internal(s.u, s.charts, F.data(), &K);
  Eigen::MatrixXd Kfd(n, n);
  const double h = 1e-6;
  for (Index j = 0; j < n; ++j) {
    Eigen::VectorXd up = s.u, um = s.u;
    up[j] += h;
    um[j] -= h;
    model.internal(up, s.charts, Fp.data(), nullptr);
    model.internal(um, s.charts, Fm.data(), nullptr);
    Kfd.col(j) = (Fp - Fm) / (2 * h);
  }
  const Eigen::MatrixXd Kd = dense(K);
  EXPECT_LT((Kd - Kfd).norm(), 1e-6 * Kd.norm());
  EXPECT_LT((Kd - Kd.transpose()).norm(), 1e-14 * Kd.norm());
}

TEST(Model, RigidTranslationHasExactMassMomentumAndNoStrain) {
  const Model model = plate_model(4, 2);
  State s = model.initial_state();
  const Vec3 v0(0.3, -0.2, 0.5);
  for (int i = 0; i < model.mesh().num_nodes(); ++i) {
    s.u.segment<3>(DofMap::dof(i, 0)) = Vec3(1.0, 2.0, 3.0);
    s.v.segment<3>(DofMap::dof(i, 0)) = v0;
  }
  const Invariants inv = model.invariants(s);
  const double mass = kPlate.rho * kPlate.thickness * 2.0 * 1.0;
  EXPECT_NEAR(inv.kinetic, 0.5 * mass * v0.squaredNorm(), 1e-14);
  EXPECT_LT((inv.L - mass * v0).norm(), 1e-14);
  EXPECT_LT(inv.strain, 1e-20);
}

TEST(Model, RechartKeepsDirectorsRatesAndKineticEnergy) {
  Model model = plate_model(2, 1);
  State s = model.initial_state();
  // Tilt every director by 60° about Y (dependent component moves from Z to X) and spin it.
  const Vec3 w(0.2, 1.0, 0.4);
  for (int i = 0; i < model.mesh().num_nodes(); ++i) {
    const Vec3 p(std::sin(M_PI / 3), 0.0, std::cos(M_PI / 3));
    const auto& ch = s.charts[static_cast<size_t>(i)];
    s.u.segment<2>(DofMap::dof(i, 3)) = chart_coordinates(p, ch);
    s.v.segment<2>(DofMap::dof(i, 3)) = chart_coordinates(w.cross(p), ch);
  }
  const double K0 = model.invariants(s).kinetic;
  std::vector<Vec3> p0;
  for (int i = 0; i < model.mesh().num_nodes(); ++i) p0.push_back(model.director(s, i));
  EXPECT_EQ(model.rechart(s), model.mesh().num_nodes());
  EXPECT_EQ(model.rechart(s), 0);
  for (int i = 0; i < model.mesh().num_nodes(); ++i) {
    EXPECT_EQ(s.charts[static_cast<size_t>(i)].l, 0);
    EXPECT_LT((model.director(s, i) - p0[static_cast<size_t>(i)]).norm(), 1e-15);
  }
  EXPECT_NEAR(model.invariants(s).kinetic, K0, 1e-15 * K0);
}

// docs/theory.md §6.9: seen through δu_ref = T δu, the tangent and the mass of a stress-free body moved
// rigidly (a finite rotation that also switches director charts) are Tᵀ K_ref T and Tᵀ M_ref T, with R the
// rotation that kept_matrix_basis() recovers from the nodes.
TEST(Model, KeptMatrixBasisCarriesTangentAndMassThroughARigidRotationAndChartSwitches) {
  Model model = plate_model(2, 1);
  const State ref = model.initial_state();  // flat, stress-free
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(1.2, Vec3(1.0, 0.3, 0.2).normalized()).toRotationMatrix();
  const Vec3 shift(0.4, -1.0, 2.5);
  State rot = ref;
  const int nn = model.mesh().num_nodes();
  for (int i = 0; i < nn; ++i) {
    const Vec3& X = model.mesh().X[static_cast<size_t>(i)];
    rot.u.segment<3>(DofMap::dof(i, 0)) = Q * X + shift - X;
    const Vec3 p = Q * model.director(ref, i);
    rot.u.segment<2>(DofMap::dof(i, 3)) = chart_coordinates(p, rot.charts[static_cast<size_t>(i)]);
  }
  ASSERT_EQ(model.rechart(rot), nn) << "the rotation should switch every chart";
  std::vector<double> inv;
  ASSERT_TRUE(model.kept_matrix_basis(ref.u, ref.charts, rot.u, rot.charts, true, inv));
  ASSERT_EQ(inv.size(), static_cast<size_t>(25 * nn));
  const Index n = model.num_dofs();
  Eigen::MatrixXd Tinv = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < nn; ++i)
    for (int a = 0; a < 5; ++a)
      for (int b = 0; b < 5; ++b) Tinv(5 * i + a, 5 * i + b) = inv[static_cast<size_t>(25 * i + 5 * a + b)];
  // The translation blocks are R = Q.
  for (int i = 0; i < nn; ++i) EXPECT_LT((Tinv.block<3, 3>(5 * i, 5 * i) - Q).norm(), 1e-12) << "node " << i;
  const Eigen::MatrixXd T = Tinv.inverse();
  SparseMatrix K0{model.pattern(), {}}, K1{model.pattern(), {}}, M0{model.pattern(), {}}, M1{model.pattern(), {}};
  for (SparseMatrix* A : {&K0, &K1, &M0, &M1}) A->values.assign(model.pattern()->nnz(), 0.0);
  Eigen::VectorXd f(n);
  model.internal(ref.u, ref.charts, f.data(), &K0);
  model.internal(rot.u, rot.charts, f.data(), &K1);
  model.mass(ref.u, ref.charts, M0);
  model.mass(rot.u, rot.charts, M1);
  const Eigen::MatrixXd K0d = dense(K0), K1d = dense(K1), M0d = dense(M0), M1d = dense(M1);
  EXPECT_LT((T.transpose() * K0d * T - K1d).cwiseAbs().maxCoeff(), 1e-9 * K1d.cwiseAbs().maxCoeff());
  EXPECT_LT((T.transpose() * M0d * T - M1d).cwiseAbs().maxCoeff(), 1e-12 * M1d.cwiseAbs().maxCoeff());
  // Without the change the kept matrices are far off (what the test would see if T were ignored).
  EXPECT_GT((K0d - K1d).cwiseAbs().maxCoeff(), 0.1 * K1d.cwiseAbs().maxCoeff());

  // rotate = false: R = I, only the chart switches are carried.
  ASSERT_TRUE(model.kept_matrix_basis(ref.u, ref.charts, rot.u, rot.charts, false, inv));
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) EXPECT_EQ(inv[static_cast<size_t>(5 * a + b)], a == b ? 1.0 : 0.0);
  // Nothing changed: identity, and false.
  EXPECT_FALSE(model.kept_matrix_basis(ref.u, ref.charts, ref.u, ref.charts, false, inv));

  // A constrained body is not rotated; a switched chart of a constrained director cannot be carried.
  Mesh mesh = make_rectangle(2.0, 1.0, 2, 1, -1.0, -0.5);
  auto normals = initial_normals(mesh);
  DofMap dofs(mesh.num_nodes());
  dofs.fix(0, Fix::Director);
  Model clamped(std::move(mesh), std::move(normals), kPlate, std::move(dofs), {});
  EXPECT_THROW(clamped.kept_matrix_basis(ref.u, ref.charts, rot.u, rot.charts, true, inv), std::domain_error);
  State moved = ref;
  moved.u.segment<3>(0) += Vec3(0.1, 0.0, 0.0);  // translations only: R stays I although rotate = true
  EXPECT_FALSE(clamped.kept_matrix_basis(ref.u, ref.charts, moved.u, moved.charts, true, inv));
}

TEST(Model, ResultsDoNotDependOnTheThreadCount) {
  const Model model = plate_model(4, 4);
  const State s = deformed(model, 0.3);
  const Index n = model.num_dofs();
  SparseMatrix K1 = model.make_matrix(), K2 = model.make_matrix();
  Eigen::VectorXd F1(n), F2(n);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const double V1 = model.internal(s.u, s.charts, F1.data(), &K1);
  omp_set_num_threads(2);
  const double V2 = model.internal(s.u, s.charts, F2.data(), &K2);
  omp_set_num_threads(saved);
  EXPECT_EQ(V1, V2);  // energies are summed in element order
  EXPECT_LT((F1 - F2).norm(), 1e-14 * F1.norm());
  for (size_t k = 0; k < K1.values.size(); ++k) EXPECT_NEAR(K1.values[k], K2.values[k], 1e-13 * std::abs(K1.values[k]) + 1e-300);
}

TEST(Model, DeadMomentLoadIsTheWorkConjugateOfTheDirector) {
  // δW = m·δφ with δp = δφ × p  =>  f_q · δq = (m × p) · A1 δq (docs/theory.md §2.3 item 3).
  NodalLoad load;
  load.node = 4;
  load.kind = NodalLoad::Kind::Moment;
  load.vector = Vec3(0.0, -2.0, 0.5);
  const Model model = plate_model(1, 1, {load});
  State s = deformed(model, 0.8);
  Eigen::VectorXd F(model.num_dofs());
  model.external(0.0, s.u, s.charts, F.data());
  const Vec3 p = model.director(s, 4);
  const Eigen::Vector2d q = s.u.segment<2>(DofMap::dof(4, 3));
  const Eigen::Vector2d dq(1e-3, -2e-3);
  const Vec3 dp = director(q + dq, s.charts[4]) - director(q - dq, s.charts[4]);  // ≈ 2 A1 dq
  EXPECT_NEAR(F.segment<2>(DofMap::dof(4, 3)).dot(2 * dq), load.vector.cross(p).dot(dp), 1e-8);
  EXPECT_EQ(F.head<20>().norm(), 0.0);  // no force on other nodes' DOFs
}

// docs/theory.md §7 item 9: linear pinched hemisphere with an 18° hole, quarter model,
// R = 10, h = 0.04, E = 6.825e7, ν = 0.3, unit radial loads; reference ≈ 0.093–0.094.
double linear_hemisphere(int n) {
  Mesh mesh = make_hemisphere(10.0, 18.0, true, n);
  auto normals = initial_normals(mesh);
  DofMap dofs(mesh.num_nodes());
  for (int i : mesh.node_sets.at("sym_y0")) {
    dofs.fix(i, Fix::Uy);
    dofs.fix(i, Fix::Py);
  }
  for (int i : mesh.node_sets.at("sym_x0")) {
    dofs.fix(i, Fix::Ux);
    dofs.fix(i, Fix::Px);
  }
  dofs.fix(mesh.node_sets.at("hole").front(), Fix::Uz);  // W fixed at one node against rigid motion
  const int a = mesh.node_sets.at("point_xpos").front();
  const int b = mesh.node_sets.at("point_ypos").front();
  const Model model(std::move(mesh), std::move(normals), ShellMaterial{6.825e7, 0.3, 1.0, 0.04}, std::move(dofs));
  const State s = model.initial_state();
  SparseMatrix K = model.make_matrix();
  model.internal(s.u, s.charts, nullptr, &K);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(model.num_dofs()), x(model.num_dofs());
  f[DofMap::dof(a, 0)] = 1.0;   // outward at (R, 0, 0)
  f[DofMap::dof(b, 1)] = -1.0;  // inward at (0, R, 0)
  apply_dirichlet(model.dofs(), K, f.data());
  auto solver = make_linear_solver("eigen-ldlt");
  solver->factorize(K.view());
  solver->solve(f.data(), x.data());
  const double ua = x[DofMap::dof(a, 0)], ub = -x[DofMap::dof(b, 1)];
  EXPECT_NEAR(ua, ub, 1e-3 * ua);  // the two load points respond alike in the linear regime
  return ua;
}

TEST(Model, LinearPinchedHemisphereDoesNotLock) {
  const double u4 = linear_hemisphere(4), u8 = linear_hemisphere(8);
  std::printf("linear pinched hemisphere (quarter, MITC9): 4x4 %.5f, 8x8 %.5f (spec 0.0924, 0.0930)\n", u4, u8);
  EXPECT_NEAR(u8, 0.0924, 0.01 * 0.0924);   // issue: within 1 % of 0.0924 on 8×8
  EXPECT_NEAR(u4, 0.0924, 0.02 * 0.0924);   // spec prototype: 0.0924 on 4×4
  EXPECT_GT(u8, u4);                        // converges from below (stiff side)
}

}  // namespace
}  // namespace shelldyn
