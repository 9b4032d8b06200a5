// The shell Model with rigid bodies and joints (lib/model/model_multibody.hpp; docs/theory/multibody.md §7):
// mass and invariants against RigidBody, the constraint rows against finite differences and the ConstraintSet,
// the discrete gradient identity (2.2) over the Model's unknowns, and the pattern holding the tangents.
#include "lib/io/case_file.hpp"
#include "lib/model/problem.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <string>

using namespace shelldyn;

namespace {

// 1 × 1 plate (9 nodes); hub clamped to the edge x = 0 (directors, aligned form) and hinged to the ground; bob on a
// ball joint at the corner (1, 1); drum driven about z (θ = 0.5 ramp(t), so it starts with ω_z = 0.5).
const std::string kCase = R"(
name: mb
mesh: {generator: rectangle, a: 1, b: 1, nx: 1, ny: 1}
material: {E: 1.0e6, nu: 0.3, rho: 1, thickness: 0.01}
integrator: {name: em-galpha}
time: {dt: 0.01, t_end: 0.1}
gravity: [0, 0, -9.81]
boundary_conditions: [{set: corner_lr, fix: [uz]}]
rigid_bodies:
  hub: {mass: 2.0, inertia: [0.1, 0.2, 0.25], position: [-0.5, 0, 0]}
  bob: {mass: 0.5, inertia: [0.01, 0.01, 0.01], position: [1.5, 1, 0], axes: [[0, 1, 0], [-1, 0, 0]]}
  drum: {mass: 1.0, inertia: [0.3, 0.3, 0.5], position: [3, 0, 0], angular_velocity: [0, 0, 0.5]}
joints:
  - {name: clamp, type: rigid_connection, set: left, body: hub}
  - {name: hinge, type: revolute, a: {body: hub, at: [-0.5, 0, 0]}, b: {ground: [-0.5, 0, 0]}, axis: [0, 1, 0]}
  - {name: ball, type: spherical, a: {set: corner_ur}, b: {body: bob, at: [1, 1, 0]}}
  - {name: drive, type: prescribed_rotation, body: drum, point: [3, 0, 0], axis: [0, 0, 1], angle: {type: ramp, t1: 1}, amplitude: 0.5}
)";

Problem problem(const std::string& text = kCase) { return make_problem(load_case_from_string(text, "mb.yaml")); }

Eigen::MatrixXd dense(const SemiDiscreteSystem::ConstraintMatrix& G) { return Eigen::MatrixXd(G); }

Eigen::MatrixXd dense(const SparseMatrix& K) {
  const SparsePattern& P = *K.pattern;
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(P.n, P.n);
  for (Index j = 0; j < P.n; ++j)
    for (Index k = P.colptr[j]; k < P.colptr[j + 1]; ++k) D(P.rowind[k], j) = K.values[k];
  return D;
}

// A state near the initial one: random translations, director chart coordinates and body unknowns.
Eigen::VectorXd perturbed(const Model& m, const State& s0, double size, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-size, size);
  Eigen::VectorXd u = s0.u;
  for (Index i = 0; i < u.size(); ++i)
    if (!m.dofs().is_constrained(i)) u[i] += U(rng);
  return u;
}

}  // namespace

TEST(ModelMultibody, UnknownsMassAndInvariantsOfTheBodies) {
  const Problem p = problem();
  const Model& m = *p.model;
  const int nn = m.mesh().num_nodes();
  ASSERT_EQ(m.num_rigid_bodies(), 3);
  EXPECT_EQ(m.num_dofs(), 5 * nn + 36);
  EXPECT_EQ(m.dofs().num_dofs(), m.num_dofs());
  // 18 frame rows + 3 × (3 + 2) clamp + 5 hinge + 3 ball + 6 drive.
  EXPECT_EQ(m.num_constraints(), 18 + 15 + 5 + 3 + 6);
  const State s = p.initial_state();
  ASSERT_EQ(s.u.size(), m.num_dofs());
  EXPECT_EQ(s.u.tail(36).cwiseAbs().maxCoeff(), 0.0);  // bodies start at u_b = 0
  SparseMatrix M = m.make_matrix();
  m.mass(s.u, s.charts, M);
  const Eigen::MatrixXd Md = dense(M);
  const ModelMultibody& mb = *m.multibody();
  for (int b = 0; b < 3; ++b) {
    const ExactEnergySystem::RigidBlock blk = m.rigid_block(b);
    EXPECT_EQ(blk.first_dof, 5 * nn + 12 * b);
    EXPECT_EQ(blk.mass, mb.body(b).mass());
    const Eigen::MatrixXd block = Md.block(blk.first_dof, blk.first_dof, 12, 12);
    EXPECT_EQ((block - Eigen::MatrixXd(mb.body(b).mass_matrix())).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(Md.block(0, blk.first_dof, 5 * nn, 12).cwiseAbs().maxCoeff(), 0.0);  // no shell–body mass coupling
  }
  // The drum's angular velocity gives ḋ_i = ω × d_i; the invariants add (3.4) of the bodies.
  State t = s;
  t.v.setZero();
  const Index k = m.rigid_block(2).first_dof;
  t.v.segment<12>(k) = mb.body_initial_velocity(2);
  t.v.segment<3>(m.rigid_block(1).first_dof) = Eigen::Vector3d(0.3, -0.2, 0.1);
  const Invariants inv = m.invariants(t);
  multibody::Vec12 qd1 = multibody::Vec12::Zero();
  qd1.head<3>() = Eigen::Vector3d(0.3, -0.2, 0.1);
  const multibody::Vec12 qd2 = t.v.segment<12>(k);
  const double K = mb.body(1).kinetic_energy(qd1) + mb.body(2).kinetic_energy(qd2);
  EXPECT_NEAR(inv.kinetic, K, 1e-15 * K);
  EXPECT_NEAR(inv.kinetic, 0.5 * 0.5 * 0.14 + 0.5 * 0.5 * 0.25, 1e-14);  // ½m|v|² + ½ J_z ω²
  const Eigen::Vector3d L = mb.body(1).linear_momentum(qd1);
  const Eigen::Vector3d J = mb.body(1).angular_momentum(mb.body_q(1, t.u), qd1) + mb.body(2).angular_momentum(mb.body_q(2, t.u), qd2);
  EXPECT_LE((inv.L - L).norm(), 1e-15);
  EXPECT_LE((inv.J - J).norm(), 1e-14);
  EXPECT_NEAR(inv.J.z(), 0.5 * 0.5 + (Eigen::Vector3d(1.5, 1, 0).cross(0.5 * Eigen::Vector3d(0.3, -0.2, 0.1))).z(), 1e-14);
  // Gravity on the bodies: m g on φ.
  Eigen::VectorXd F(m.num_dofs());
  m.external(0.0, s.u, s.charts, F.data());
  for (int b = 0; b < 3; ++b) EXPECT_NEAR(F[m.rigid_block(b).first_dof + 2], -9.81 * mb.body(b).mass(), 1e-14);
  // Body inertia force: M_b a_b.
  Eigen::VectorXd a = Eigen::VectorXd::Zero(m.num_dofs()), out(m.num_dofs());
  a.segment<12>(k).setConstant(2.0);
  m.inertia_force(s.u, s.v, a, s.charts, out.data());
  EXPECT_LE((out.segment<12>(k) - 2.0 * mb.body(2).mass_diagonal()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ModelMultibody, JacobianTimeDerivativeAndHessianMatchFiniteDifferences) {
  const Problem p = problem();
  const Model& m = *p.model;
  const State s0 = p.initial_state();
  const Index n = m.num_dofs(), rows = m.num_constraints();
  std::mt19937 rng(7);
  std::normal_distribution<double> N(0.0, 1.0);
  for (unsigned trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd u = perturbed(m, s0, 0.05, 11 + trial);
    const double t = 0.3;
    SemiDiscreteSystem::ConstraintMatrix G;
    m.constraint_jacobian(t, u, s0.charts, G);
    ASSERT_EQ(G.rows(), rows);
    ASSERT_EQ(G.cols(), n);
    const Eigen::MatrixXd Gd = dense(G);
    Eigen::VectorXd gp, gm;
    Eigen::MatrixXd Gfd = Eigen::MatrixXd::Zero(rows, n);
    const double h = 1e-6;
    for (Index j = 0; j < n; ++j) {
      if (m.dofs().is_constrained(j)) continue;
      Eigen::VectorXd up = u, um = u;
      up[j] += h;
      um[j] -= h;
      m.constraint_values(t, up, s0.charts, gp);
      m.constraint_values(t, um, s0.charts, gm);
      Gfd.col(j) = (gp - gm) / (2 * h);
    }
    EXPECT_LE((Gd - Gfd).cwiseAbs().maxCoeff(), 1e-8) << "trial " << trial;
    // Columns of supported DOFs are dropped.
    for (Index j : m.dofs().constrained_dofs()) EXPECT_EQ(Gd.col(j).cwiseAbs().maxCoeff(), 0.0);
    // ∂g/∂t (only the drive row depends on t).
    Eigen::VectorXd gt, g1, g2;
    m.constraint_time_derivative(t, u, s0.charts, gt);
    m.constraint_values(t + h, u, s0.charts, g1);
    m.constraint_values(t - h, u, s0.charts, g2);
    EXPECT_LE((gt - (g1 - g2) / (2 * h)).cwiseAbs().maxCoeff(), 1e-8);
    EXPECT_GT(gt.cwiseAbs().maxCoeff(), 0.1);
    // Hessian contraction ∂(Gᵀλ)/∂u, in the pattern (add_constraint_hessian throws otherwise).
    Eigen::VectorXd lambda(rows);
    for (Index i = 0; i < rows; ++i) lambda[i] = N(rng);
    SparseMatrix K = m.make_matrix();
    m.add_constraint_hessian(t, u, s0.charts, lambda, 1.0, K);
    const Eigen::MatrixXd Kd = dense(K);
    Eigen::MatrixXd Hfd = Eigen::MatrixXd::Zero(n, n);
    SemiDiscreteSystem::ConstraintMatrix Gp, Gm;
    for (Index j = 0; j < n; ++j) {
      if (m.dofs().is_constrained(j)) continue;
      Eigen::VectorXd up = u, um = u;
      up[j] += h;
      um[j] -= h;
      m.constraint_jacobian(t, up, s0.charts, Gp);
      m.constraint_jacobian(t, um, s0.charts, Gm);
      Hfd.col(j) = (Eigen::VectorXd(Gp.transpose() * lambda) - Eigen::VectorXd(Gm.transpose() * lambda)) / (2 * h);
    }
    for (Index j : m.dofs().constrained_dofs()) Hfd.row(j).setZero();
    EXPECT_LE((Kd - Hfd).cwiseAbs().maxCoeff(), 1e-7 * (1.0 + Hfd.cwiseAbs().maxCoeff())) << "trial " << trial;
    EXPECT_GT(Kd.cwiseAbs().maxCoeff(), 0.1);  // the quadratic rows do contribute
  }
}

TEST(ModelMultibody, DiscreteGradientIsExactOverTheModelUnknowns) {
  const Problem p = problem();
  const Model& m = *p.model;
  const State s0 = p.initial_state();
  for (double size : {0.1, 1e-3, 1e-7}) {
    for (unsigned trial = 0; trial < 4; ++trial) {
      const Eigen::VectorXd u0 = perturbed(m, s0, 0.05, 100 + trial);
      Eigen::VectorXd u1 = perturbed(m, s0, 0.0, 0);
      u1 = u0 + (perturbed(m, s0, size, 200 + trial) - s0.u);
      const double t0 = 0.2, t1 = 0.2 + size;
      SemiDiscreteSystem::ConstraintMatrix Gb;
      Eigen::VectorXd tau, g0, g1;
      m.constraint_discrete_gradient(t0, u0, t1, u1, s0.charts, Gb, tau);
      m.constraint_values(t0, u0, s0.charts, g0);
      m.constraint_values(t1, u1, s0.charts, g1);
      const Eigen::VectorXd defect = Gb * (u1 - u0) + tau - (g1 - g0);
      EXPECT_LE(defect.cwiseAbs().maxCoeff(), 1e-14 * (1.0 + g1.cwiseAbs().maxCoeff())) << "step " << size;
      // The end-point Jacobian misses Δg at the larger steps (the rows are nonlinear in u).
      if (size == 0.1) {
        SemiDiscreteSystem::ConstraintMatrix G1;
        m.constraint_jacobian(t1, u1, s0.charts, G1);
        Eigen::VectorXd gt;
        m.constraint_time_derivative(t1, u1, s0.charts, gt);
        EXPECT_GT((G1 * (u1 - u0) + gt * (t1 - t0) - (g1 - g0)).cwiseAbs().maxCoeff(), 1e-4);
      }
    }
  }
}

TEST(ModelMultibody, BodyRowsAreThoseOfTheConstraintSetAndTheDiscreteTangentMatchesFiniteDifferences) {
  // Positions and bodies only (no director rows): a fixed point and a ball joint between the plate and a body.
  const std::string text = R"(
name: mb2
mesh: {generator: rectangle, a: 1, b: 1, nx: 1, ny: 1}
material: {E: 1.0e6, nu: 0.3, rho: 1, thickness: 0.01}
integrator: {name: em-galpha}
time: {dt: 0.01, t_end: 0.1}
rigid_bodies:
  bob: {mass: 0.5, inertia: [0.01, 0.02, 0.02], position: [1.5, 1, 0]}
joints:
  - {name: pin, type: fixed_point, set: corner_ll}
  - {name: ball, type: spherical, a: {set: corner_ur}, b: {body: bob, at: [1, 1, 0]}}
  - {name: tie, type: revolute, a: {body: bob, at: [1.5, 1, 0]}, b: {ground: [1.5, 1, 0]}, axis: [0, 0, 1]}
)";
  const Problem p = problem(text);
  const Model& m = *p.model;
  const State s0 = p.initial_state();
  const ModelMultibody& mb = *m.multibody();
  const Eigen::VectorXd u = perturbed(m, s0, 0.05, 3);
  // y = [node slots (u, p) | q_b]: rebuild it and compare G with the set's, column by column.
  const int slots = 2;  // corner_ll, corner_ur
  Eigen::VectorXd y = Eigen::VectorXd::Zero(6 * slots + 12);
  const int ll = p.disc.mesh.node_sets.at("corner_ll")[0], ur = p.disc.mesh.node_sets.at("corner_ur")[0];
  y.segment<3>(0) = u.segment<3>(DofMap::dof(ll, 0));
  y.segment<3>(6) = u.segment<3>(DofMap::dof(ur, 0));
  y.segment<12>(12) = mb.body_q(0, u);
  const Eigen::MatrixXd Gy = Eigen::MatrixXd(mb.set().G(y, 0.0));
  SemiDiscreteSystem::ConstraintMatrix G;
  m.constraint_jacobian(0.0, u, s0.charts, G);
  const Eigen::MatrixXd Gd = dense(G);
  const Index b0 = m.rigid_block(0).first_dof;
  EXPECT_EQ((Gd.block(0, b0, Gd.rows(), 12) - Gy.block(0, 12, Gy.rows(), 12)).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((Gd.block(0, DofMap::dof(ll, 0), Gd.rows(), 3) - Gy.block(0, 0, Gy.rows(), 3)).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((Gd.block(0, DofMap::dof(ur, 0), Gd.rows(), 3) - Gy.block(0, 6, Gy.rows(), 3)).cwiseAbs().maxCoeff(), 0.0);
  // Discrete tangent ∂(Ḡ(u0, u1)ᵀλ)/∂u1 against central differences.
  const Eigen::VectorXd u1 = perturbed(m, s0, 0.05, 4);
  Eigen::VectorXd lambda = Eigen::VectorXd::LinSpaced(m.num_constraints(), -1.0, 2.0);
  SparseMatrix K = m.make_matrix();
  m.add_constraint_discrete_tangent(0.0, u, 0.1, u1, s0.charts, lambda, 1.0, K);
  const Eigen::MatrixXd Kd = dense(K);
  const Index n = m.num_dofs();
  Eigen::MatrixXd fd = Eigen::MatrixXd::Zero(n, n);
  const double h = 1e-6;
  SemiDiscreteSystem::ConstraintMatrix Gp, Gm;
  Eigen::VectorXd tau;
  for (Index j = 0; j < n; ++j) {
    Eigen::VectorXd up = u1, um = u1;
    up[j] += h;
    um[j] -= h;
    m.constraint_discrete_gradient(0.0, u, 0.1, up, s0.charts, Gp, tau);
    m.constraint_discrete_gradient(0.0, u, 0.1, um, s0.charts, Gm, tau);
    fd.col(j) = (Eigen::VectorXd(Gp.transpose() * lambda) - Eigen::VectorXd(Gm.transpose() * lambda)) / (2 * h);
  }
  EXPECT_LE((Kd - fd).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_GT(Kd.cwiseAbs().maxCoeff(), 0.1);
}

TEST(ModelMultibody, ACaseWithoutBodiesOrJointsKeepsTheElementPattern) {
  const std::string text = R"(
name: plain
mesh: {generator: rectangle, a: 1, b: 1, nx: 2, ny: 1}
material: {E: 1.0e6, nu: 0.3, rho: 1, thickness: 0.01}
integrator: {name: em-galpha}
time: {dt: 0.01, t_end: 0.1}
)";
  const Problem p = problem(text);
  const Model& m = *p.model;
  EXPECT_EQ(m.multibody(), nullptr);
  EXPECT_EQ(m.num_constraints(), 0);
  EXPECT_EQ(m.num_dofs(), 5 * m.mesh().num_nodes());
  const Assembler plain(m.mesh().elements, m.mesh().num_nodes());
  EXPECT_EQ(m.pattern()->colptr, plain.pattern()->colptr);
  EXPECT_EQ(m.pattern()->rowind, plain.pattern()->rowind);
}
