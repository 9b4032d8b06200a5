// Rigid bodies in director form and the constraint kinds: discrete gradients, Jacobians, rank check
// (docs/theory/multibody.md §2–§4).
#include "lib/multibody/constraints.hpp"
#include "lib/multibody/rigid_body.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

namespace shelldyn::multibody {
namespace {

Mat3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::Quaterniond qt(N(rng), N(rng), N(rng), N(rng));
  return qt.normalized().toRotationMatrix();
}

Vec3 random_vec(std::mt19937& rng, double s = 1.0) {
  std::uniform_real_distribution<double> U(-s, s);
  return Vec3(U(rng), U(rng), U(rng));
}

TEST(RigidBody, EulerTensorMassMatrixAndMomentaMatchTheRotationForm) {
  const RigidBody b("box", 2.5, Vec3(0.7, 0.9, 1.1));
  // E_i = ½(J_j + J_k − J_i), and J_i = E_j + E_k back.
  EXPECT_NEAR(b.euler_tensor()(0), 0.5 * (0.9 + 1.1 - 0.7), 1e-15);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(b.euler_tensor()((i + 1) % 3) + b.euler_tensor()((i + 2) % 3), b.principal_inertia()(i),
                1e-15);
  std::mt19937 rng(7);
  const Mat3 R = random_rotation(rng);
  const Vec3 phi = random_vec(rng), v = random_vec(rng), w = random_vec(rng, 3.0);
  const Vec12 q = RigidBody::state(phi, R), qd = RigidBody::velocity(q, v, w);
  // Rotation form: T = ½ m|v|² + ½ ωᵀ R J Rᵀ ω, L = m v, J = φ × m v + R J Rᵀ ω.
  const Mat3 Jw = R * b.principal_inertia().asDiagonal() * R.transpose();
  EXPECT_NEAR(b.kinetic_energy(qd), 0.5 * 2.5 * v.squaredNorm() + 0.5 * w.dot(Jw * w), 1e-13);
  EXPECT_NEAR((b.linear_momentum(qd) - 2.5 * v).norm(), 0.0, 1e-14);
  EXPECT_NEAR((b.angular_momentum(q, qd) - (2.5 * phi.cross(v) + Jw * w)).norm(), 0.0, 1e-13);
  EXPECT_NEAR(0.5 * qd.dot(b.mass_matrix() * qd), b.kinetic_energy(qd), 1e-13);
  // Attachment point x = φ + R X, and the orthonormality rows vanish on a rotation.
  const Vec3 X(0.3, -0.2, 0.5);
  EXPECT_NEAR((RigidBody::point(q, X) - (phi + R * X)).norm(), 0.0, 1e-15);
  EXPECT_LT(RigidBody::orthonormality(q).norm(), 1e-15);
}

TEST(RigidBody, OrthonormalityJacobianMatchesFiniteDifferences) {
  std::mt19937 rng(3);
  Vec12 q;
  for (int i = 0; i < 12; ++i) q(i) = std::uniform_real_distribution<double>(-1, 1)(rng);
  const auto G = RigidBody::orthonormality_jacobian(q);
  const double h = 1e-6;
  for (int k = 0; k < 12; ++k) {
    Vec12 qp = q, qm = q;
    qp(k) += h;
    qm(k) -= h;
    const Eigen::Matrix<double, 6, 1> fd =
        (RigidBody::orthonormality(qp) - RigidBody::orthonormality(qm)) / (2 * h);
    EXPECT_LT((G.col(k) - fd).norm(), 1e-9) << "column " << k;
  }
}

TEST(RigidBody, ImpossibleInertiasAreRefusedWithTheBodyName) {
  try {
    RigidBody("crank", 1.0, Vec3(1.0, 0.2, 0.3));
    FAIL() << "J1 > J2 + J3 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rigid body 'crank'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("J1 <= J2 + J3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(RigidBody("m0", 0.0, Vec3(1, 1, 1)), std::invalid_argument);
  EXPECT_THROW(RigidBody("nan", 1.0, Vec3(1, NAN, 1)), std::invalid_argument);
}

// A model with two rigid bodies (unknowns 0–11, 12–23) and one shell-like node: translations u at 24–26 and
// an ℝ³ director p at 27–29.
constexpr int kN = 30;
constexpr int kB1 = 0, kB2 = 12, kU = 24, kP = 27;

AngleHistory spin_up() {
  return {[](double t) { return 0.7 * t * t + 0.2 * std::sin(3 * t); },
          [](double t) { return 1.4 * t + 0.6 * std::cos(3 * t); }};
}

std::vector<std::unique_ptr<Constraint>> every_kind() {
  std::vector<std::unique_ptr<Constraint>> c;
  const Vec3 X1(0.3, -0.1, 0.2), X2(-0.25, 0.15, 0.05);
  c.push_back(fixed_point("pin", PointMap::body_point(kB1, X1), Vec3(0.1, 0.2, -0.3)));
  c.push_back(spherical_joint("ball", PointMap::body_point(kB1, X1), PointMap::body_point(kB2, X2)));
  c.push_back(spherical_joint("node-ball", PointMap::node_position(kU, Vec3(1, 2, 0)),
                              PointMap::body_point(kB2, X2)));
  c.push_back(revolute_joint("hinge", PointMap::body_point(kB1, X1), PointMap::body_point(kB2, X2),
                             PointMap::body_vector(kB1, Vec3(0, 0, 1)),
                             PointMap::body_vector(kB2, Vec3(1, 0, 0)),
                             PointMap::body_vector(kB2, Vec3(0, 1, 0))));
  c.push_back(revolute_joint("ground-hinge", PointMap::body_point(kB2, X2), PointMap::ground(Vec3(0, 0, 1)),
                             PointMap::ground(Vec3(0, 1, 0)), PointMap::body_vector(kB2, Vec3(1, 0, 0)),
                             PointMap::body_vector(kB2, Vec3(0, 0, 1))));
  c.push_back(rigid_connection("clamp", PointMap::node_position(kU, Vec3(1, 2, 0)), PointMap::vector3(kP),
                               kB1, Vec3(0.4, 0.1, -0.2), Vec3(0.6, 0.0, 0.8)));
  c.push_back(rigid_connection("clamp-aligned", PointMap::body_point(kB2, X2),
                               PointMap::body_vector(kB2, Vec3(0, 0, 1)), kB1, Vec3(0.4, 0.1, -0.2),
                               Vec3(0.6, 0.0, 0.8), DirectorCondition::aligned));
  c.push_back(orthonormality("frame", kB2));
  c.push_back(
      distance("link", PointMap::body_point(kB1, X1), PointMap::node_position(kU, Vec3(1, 2, 0)), 1.3));
  c.push_back(distance("link-gonzalez", PointMap::body_point(kB2, X2), PointMap::vector3(kP), 0.9,
                       DistanceGradient::gonzalez));
  c.push_back(prescribed_rotation("hub", kB1, Vec3(0.1, 0.0, 0.0), Vec3(0, 0, 1), Vec3(1, 0, 0),
                                  Vec3(0, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 0), spin_up()));
  return c;
}

Eigen::MatrixXd dense(const Constraint& c, const std::vector<Triplet>& t) {
  Eigen::SparseMatrix<double> S(c.size(), kN);
  S.setFromTriplets(t.begin(), t.end());
  return Eigen::MatrixXd(S);
}

Eigen::VectorXd random_state(std::mt19937& rng, double s) {
  Eigen::VectorXd q(kN);
  for (int i = 0; i < kN; ++i) q(i) = std::uniform_real_distribution<double>(-s, s)(rng);
  return q;
}

TEST(Constraints, DiscreteGradientReproducesTheIncrementForEveryKind) {
  std::mt19937 rng(11);
  for (const auto& c : every_kind()) {
    double worst = 0.0, worst_small = 0.0, endpoint_defect = 0.0;
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::VectorXd q0 = random_state(rng, 1.0);
      for (double step : {1.0, 1e-3, 1e-9}) {
        const Eigen::VectorXd q1 = q0 + random_state(rng, step);
        const double t0 = 0.3 * trial, t1 = t0 + 0.05;
        std::vector<Triplet> tb;
        Eigen::VectorXd tau;
        c->discrete_gradient(q0, t0, q1, t1, tb, tau);
        const Eigen::VectorXd dg = c->g(q1, t1) - c->g(q0, t0);
        const double e = (dense(*c, tb) * (q1 - q0) + tau - dg).norm() / (1.0 + c->g(q1, t1).norm());
        (step < 1e-6 ? worst_small : worst) = std::max(step < 1e-6 ? worst_small : worst, e);
        if (step == 1.0) {  // the end-point Jacobian is no discrete gradient unless g is linear in q
          std::vector<Triplet> t1g;
          c->jacobian(q1, t1, t1g);
          endpoint_defect = std::max(endpoint_defect, (dense(*c, t1g) * (q1 - q0) + tau - dg).norm());
        }
      }
    }
    EXPECT_LT(worst, 1e-14) << c->type() << " '" << c->name() << "'";
    EXPECT_LT(worst_small, 1e-15) << c->type() << " '" << c->name() << "' (|Δq| ~ 1e-9)";
    if (c->kind() != ConstraintKind::linear) {
      EXPECT_GT(endpoint_defect, 1e-2) << c->name();
    }
  }
}

TEST(Constraints, JacobianAndTimeDerivativeMatchFiniteDifferences) {
  std::mt19937 rng(5);
  const double h = 1e-6;
  for (const auto& c : every_kind()) {
    const Eigen::VectorXd q = random_state(rng, 1.0);
    const double t = 0.8;
    std::vector<Triplet> tg;
    c->jacobian(q, t, tg);
    const Eigen::MatrixXd G = dense(*c, tg);
    Eigen::MatrixXd fd(c->size(), kN);
    for (int k = 0; k < kN; ++k) {
      Eigen::VectorXd qp = q, qm = q;
      qp(k) += h;
      qm(k) -= h;
      fd.col(k) = (c->g(qp, t) - c->g(qm, t)) / (2 * h);
    }
    EXPECT_LT((G - fd).cwiseAbs().maxCoeff(), 1e-8) << c->name();
    const Eigen::VectorXd dt_fd = (c->g(q, t + h) - c->g(q, t - h)) / (2 * h);
    EXPECT_LT((c->dg_dt(q, t) - dt_fd).cwiseAbs().maxCoeff(), 1e-8) << c->name();
    if (c->rheonomic()) {
      EXPECT_GT(dt_fd.norm(), 1e-2) << c->name();
    }
    // Every column G touches is listed in unknowns().
    const auto u = c->unknowns();
    for (const auto& e : tg)
      EXPECT_TRUE(std::binary_search(u.begin(), u.end(), static_cast<int>(e.col()))) << c->name();
  }
}

// §5.1: the Newton tangents of the constraint force against central differences of G(q)ᵀλ and Ḡ(q0, q1)ᵀλ.
TEST(Constraints, ForceTangentsMatchFiniteDifferences) {
  std::mt19937 rng(17);
  const double h = 1e-6;
  for (const auto& c : every_kind()) {
    const Eigen::VectorXd q0 = random_state(rng, 1.0), q1 = q0 + random_state(rng, 0.3);
    Eigen::VectorXd lam(c->size());
    for (int i = 0; i < c->size(); ++i) lam(i) = std::normal_distribution<double>(0, 1)(rng);
    auto GTl = [&](const Eigen::VectorXd& q) {
      std::vector<Triplet> t;
      c->jacobian(q, 0.4, t);
      return Eigen::VectorXd(dense(*c, t).transpose() * lam);
    };
    auto GbTl = [&](const Eigen::VectorXd& q) {
      std::vector<Triplet> t;
      Eigen::VectorXd tau;
      c->discrete_gradient(q0, 0.4, q, 0.45, t, tau);
      return Eigen::VectorXd(dense(*c, t).transpose() * lam);
    };
    Eigen::MatrixXd fdH(kN, kN), fdT(kN, kN);
    for (int k = 0; k < kN; ++k) {
      Eigen::VectorXd qp = q1, qm = q1;
      qp(k) += h;
      qm(k) -= h;
      fdH.col(k) = (GTl(qp) - GTl(qm)) / (2 * h);
      fdT.col(k) = (GbTl(qp) - GbTl(qm)) / (2 * h);
    }
    std::vector<Triplet> th, tt;
    c->hessian_contraction(q1, 0.4, lam, th);
    c->discrete_tangent(q0, 0.4, q1, 0.45, lam, tt);
    Eigen::SparseMatrix<double> H(kN, kN), T(kN, kN);
    H.setFromTriplets(th.begin(), th.end());
    T.setFromTriplets(tt.begin(), tt.end());
    EXPECT_LT((Eigen::MatrixXd(H) - fdH).cwiseAbs().maxCoeff(), 1e-7) << c->name();
    EXPECT_LT((Eigen::MatrixXd(T) - fdT).cwiseAbs().maxCoeff(), 1e-7) << c->name();
    if (c->kind() != ConstraintKind::linear) {
      EXPECT_GT(fdT.cwiseAbs().maxCoeff(), 1e-3) << c->name();  // the check compares something
    }
  }
}

TEST(Constraints, StackedSetMatchesTheKindsRowByRow) {
  ConstraintSet set(kN);
  for (auto& c : every_kind()) set.add(std::move(c));
  std::mt19937 rng(9);
  const Eigen::VectorXd q0 = random_state(rng, 1.0), q1 = q0 + random_state(rng, 0.1);
  Eigen::VectorXd tau;
  const Eigen::SparseMatrix<double> Gb = set.Gbar(q0, 0.1, q1, 0.2, tau);
  EXPECT_EQ(Gb.rows(), set.rows());
  EXPECT_LT((Gb * (q1 - q0) + tau - (set.g(q1, 0.2) - set.g(q0, 0.1))).norm(), 1e-13);
  EXPECT_EQ(set.rows(), 3 + 3 + 3 + 5 + 5 + 6 + 5 + 6 + 1 + 1 + 6);
}

TEST(Constraints, BadReferencesAndDuplicateNamesAreRefused) {
  ConstraintSet set(24);
  try {
    set.add(fixed_point("pin", PointMap::body_point(24, Vec3::Zero()), Vec3::Zero()));
    FAIL() << "a joint on body unknowns 24–26 of a 24-unknown model was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fixed point 'pin' references unknown 26"), std::string::npos)
        << e.what();
  }
  set.add(orthonormality("frame", 0));
  EXPECT_THROW(set.add(orthonormality("frame", 12)), std::invalid_argument);
  EXPECT_THROW(prescribed_rotation("hub", 0, Vec3::Zero(), Vec3(0, 0, 2), Vec3(1, 0, 0), Vec3::Zero(),
                                   Vec3(0, 0, 1), Vec3(1, 0, 0), spin_up()),
               std::invalid_argument);
  EXPECT_THROW(distance("rod", PointMap::vector3(0), PointMap::vector3(3), -1.0), std::invalid_argument);
}

// §2.4: the discrete constraint forces −Ḡᵀλ of a joint between bodies have zero resultant and zero moment
// about the origin, taken with the midpoint configuration, on two consistent states — which is what keeps L
// and J of a conserving step. The distance is checked off its manifold (|r0| ≠ |r1| ≠ L), as in a Newton
// iterate: there the invariant form (2.5) keeps the property and Gonzalez's generic formula (2.4) does not
// (§2.3).
TEST(Constraints, JointsBetweenBodiesExertNoDiscreteNetForceOrMoment) {
  std::mt19937 rng(21);
  const Vec3 rA(0.5, 0.1, -0.2), rB(-0.3, 0.2, 0.1), X1(0.2, -0.4, 0.3), X2(0.1, 0.3, -0.2);
  auto consistent = [&](const Mat3& RA, double turn) {  // the bodies share the joint point and the d3 axis
    const Mat3 RB = RA * Eigen::AngleAxisd(turn, Vec3::UnitZ()).toRotationMatrix();
    const Vec3 xA = random_vec(rng);
    Eigen::VectorXd q(24);
    q << RigidBody::state(xA, RA), RigidBody::state(xA + RA * rA - RB * rB, RB);
    return q;
  };
  const Eigen::VectorXd q0 = consistent(random_rotation(rng), 0.3),
                        q1 = consistent(random_rotation(rng), -1.1);
  std::vector<std::unique_ptr<Constraint>> kinds;
  kinds.push_back(orthonormality("A frame", 0));
  kinds.push_back(spherical_joint("ball", PointMap::body_point(0, rA), PointMap::body_point(12, rB)));
  kinds.push_back(revolute_joint("hinge", PointMap::body_point(0, rA), PointMap::body_point(12, rB),
                                 PointMap::body_vector(0, Vec3::UnitZ()),
                                 PointMap::body_vector(12, Vec3::UnitX()),
                                 PointMap::body_vector(12, Vec3::UnitY())));
  kinds.push_back(distance("rod", PointMap::body_point(0, X1), PointMap::body_point(12, X2), 1.0));
  kinds.push_back(distance("rod (Gonzalez)", PointMap::body_point(0, X1), PointMap::body_point(12, X2), 1.0,
                           DistanceGradient::gonzalez));
  const Eigen::VectorXd qm = 0.5 * (q0 + q1);
  for (const auto& c : kinds) {
    if (c->type() != "distance") {
      ASSERT_LT(c->g(q0, 0).norm() + c->g(q1, 0).norm(), 1e-14) << c->name();
    }
    std::vector<Triplet> t;
    Eigen::VectorXd tau;
    c->discrete_gradient(q0, 0.0, q1, 0.0, t, tau);
    Eigen::SparseMatrix<double> B(c->size(), 24);
    B.setFromTriplets(t.begin(), t.end());
    Eigen::VectorXd mu(c->size());
    for (int i = 0; i < c->size(); ++i) mu(i) = std::normal_distribution<double>(0, 1)(rng);
    const Eigen::VectorXd f = B.transpose() * mu;
    Vec3 force = Vec3::Zero(), moment = Vec3::Zero();
    for (int a = 0; a < 8; ++a) {  // the eight 3-blocks (φ, d1, d2, d3) of the two bodies
      if (a % 4 == 0) force += f.segment<3>(3 * a);
      moment += Vec3(qm.segment<3>(3 * a)).cross(Vec3(f.segment<3>(3 * a)));
    }
    if (c->name() == "rod (Gonzalez)") {
      EXPECT_GT(force.norm() + moment.norm(), 1e-3) << c->name();
    } else {
      EXPECT_LT(force.norm(), 1e-14) << c->name();
      EXPECT_LT(moment.norm(), 1e-14) << c->name();
    }
  }
}

// Rank check (§2.5): a body pinned at two points is free only to turn about the line through them, so the 6 +
// 6 rows have rank 11; the check names both pins (and the frame rows they depend on), not the other body's
// joint.
TEST(Constraints, RankCheckNamesTheJointsOfARedundantSet) {
  std::mt19937 rng(1);
  const Mat3 R1 = random_rotation(rng), R2 = random_rotation(rng);
  Eigen::VectorXd q(24);
  q.segment<12>(0) = RigidBody::state(Vec3(0.2, 0.1, 0.4), R1);
  q.segment<12>(12) = RigidBody::state(Vec3(1.5, -0.3, 0.0), R2);
  const Vec3 Xa(0.5, 0, 0), Xb(-0.2, 0.3, 0.1), Xc(0, 0, 0.4);
  auto build = [&](bool redundant, Vec3 shift) {
    auto s = std::make_unique<ConstraintSet>(24);
    s->add(orthonormality("body1 frame", 0));
    s->add(orthonormality("body2 frame", 12));
    s->add(fixed_point("pin A", PointMap::body_point(0, Xa), RigidBody::point(q.segment<12>(0), Xa)));
    s->add(spherical_joint("knee", PointMap::body_point(0, Xc),
                           PointMap::body_point(12, R2.transpose() * (RigidBody::point(q.segment<12>(0), Xc) -
                                                                      q.segment<3>(12)))));
    if (redundant)
      s->add(
          fixed_point("pin B", PointMap::body_point(0, Xb), RigidBody::point(q.segment<12>(0), Xb) + shift));
    return s;
  };
  const RankReport ok = build(false, Vec3::Zero())->rank_check(q, 0.0);
  EXPECT_EQ(ok.rank, ok.rows);
  EXPECT_TRUE(ok.message.empty());
  const auto set = build(true, Vec3::Zero());
  const RankReport r = set->rank_check(q, 0.0);
  EXPECT_EQ(r.rows, 6 + 6 + 3 + 3 + 3);
  EXPECT_EQ(r.rank, r.rows - 1);
  EXPECT_FALSE(r.conflicting);
  auto has = [&](const RankReport& rep, const std::string& n) {
    return std::find(rep.involved.begin(), rep.involved.end(), n) != rep.involved.end();
  };
  EXPECT_TRUE(has(r, "pin A") && has(r, "pin B")) << r.message;
  EXPECT_FALSE(has(r, "knee") || has(r, "body2 frame")) << r.message;
  EXPECT_NE(r.message.find("redundant constraints"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("fixed point 'pin B'"), std::string::npos) << r.message;
  EXPECT_THROW(set->require_full_rank(q, 0.0), std::invalid_argument);
  // The second pin 1 cm off the body's point: the dependent rows cannot all hold.
  const RankReport c = build(true, Vec3(0.01, 0, 0))->rank_check(q, 0.0);
  EXPECT_TRUE(c.conflicting) << c.message;
  EXPECT_NE(c.message.find("conflicting constraints"), std::string::npos) << c.message;
}

// A joint on unknowns a support already fixes: a node whose translations are Dirichlet-fixed and a fixed
// point on that node. Over the free unknowns the joint's rows vanish, so the check names it; without the mask
// it passes. A clamp of many nodes to a body is full rank.
TEST(Constraints, RankCheckNamesAJointOnFixedUnknowns) {
  constexpr int n = 12 + 3 * 40;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  q.head<12>() = RigidBody::state(Vec3::Zero(), Mat3::Identity());
  ConstraintSet s(n);
  s.add(orthonormality("hub frame", 0));
  for (int k = 0; k < 40; ++k) {
    const Vec3 X(0.1 * k, 0.05 * (k % 3), 0.0);
    s.add(spherical_joint("clamp " + std::to_string(k), PointMap::node_position(12 + 3 * k, X),
                          PointMap::body_point(0, X)));
  }
  std::vector<bool> fixed(n, false);
  EXPECT_TRUE(s.rank_check(q, 0.0, 1e-10, 1e-9, fixed).message.empty());
  s.add(fixed_point("pin", PointMap::node_position(12 + 3 * 39, Vec3(3.9, 0.0, 0.0)), Vec3(3.9, 0.0, 0.0)));
  // Without supports the pin only stops the clamped assembly's translation: full rank.
  EXPECT_TRUE(s.rank_check(q, 0.0).message.empty());
  for (int k = 0; k < 3; ++k) fixed[12 + 3 * 39 + k] = true;  // a support on node 39's translations
  const RankReport r = s.rank_check(q, 0.0, 1e-10, 1e-9, fixed);
  EXPECT_EQ(r.rows - r.rank, 3) << r.message;
  EXPECT_NE(r.message.find("fixed point 'pin'"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("fixed by supports"), std::string::npos) << r.message;
  EXPECT_THROW(s.require_full_rank(q, 0.0, fixed), std::invalid_argument);
  EXPECT_THROW(s.rank_check(q, 0.0, 1e-10, 1e-9, std::vector<bool>(5, false)), std::invalid_argument);
}

TEST(Constraints, RankCheckFlagsAHingeAddedToADrivenHub) {
  Eigen::VectorXd q(12);
  q = RigidBody::state(Vec3::Zero(), Mat3::Identity());
  ConstraintSet s(12);
  s.add(orthonormality("hub frame", 0));
  s.add(prescribed_rotation("drive", 0, Vec3::Zero(), Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3::Zero(),
                            Vec3(0, 0, 1), Vec3(1, 0, 0), spin_up()));
  EXPECT_TRUE(s.rank_check(q, 0.0).message.empty());
  s.add(revolute_joint("extra hinge", PointMap::body_point(0, Vec3::Zero()), PointMap::ground(Vec3::Zero()),
                       PointMap::ground(Vec3(0, 0, 1)), PointMap::body_vector(0, Vec3(1, 0, 0)),
                       PointMap::body_vector(0, Vec3(0, 1, 0))));
  const RankReport r = s.rank_check(q, 0.0);
  EXPECT_EQ(r.rows - r.rank, 5);
  EXPECT_NE(r.message.find("revolute joint 'extra hinge'"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("prescribed rotation 'drive'"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace shelldyn::multibody
