// Holonomic constraints and their discrete gradients (docs/theory/multibody.md §2, §4).
#include "lib/multibody/constraints.hpp"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

namespace shelldyn::multibody {

// ---- PointMap ------------------------------------------------------------------------------------------
PointMap PointMap::ground(const Vec3& x) {
  return PointMap{x, {}};
}
PointMap PointMap::node_position(int base, const Vec3& X) {
  return PointMap{X, {{base, 1.0}}};
}
PointMap PointMap::vector3(int base) {
  return PointMap{Vec3::Zero(), {{base, 1.0}}};
}
PointMap PointMap::body_point(int b, const Vec3& X) {
  return PointMap{Vec3::Zero(), {{b, 1.0}, {b + 3, X(0)}, {b + 6, X(1)}, {b + 9, X(2)}}};
}
PointMap PointMap::body_vector(int b, const Vec3& a) {
  return PointMap{Vec3::Zero(), {{b + 3, a(0)}, {b + 6, a(1)}, {b + 9, a(2)}}};
}

Vec3 PointMap::operator()(const Eigen::VectorXd& q) const {
  Vec3 x = offset;
  for (const auto& [b, c] : terms) x += c * q.segment<3>(b);
  return x;
}

int PointMap::max_index() const {
  int m = -1;
  for (const auto& t : terms) m = std::max(m, t.first + 2);
  return m;
}

void PointMap::add_row(int row, const Vec3& w, double scale, std::vector<Triplet>& out) const {
  for (const auto& [b, c] : terms)
    for (int k = 0; k < 3; ++k)
      if (c != 0.0 && w(k) != 0.0) out.emplace_back(row, b + k, scale * c * w(k));
}

void PointMap::add_block(int row0, double scale, std::vector<Triplet>& out) const {
  for (const auto& [b, c] : terms)
    for (int k = 0; k < 3; ++k)
      if (c != 0.0) out.emplace_back(row0 + k, b + k, scale * c);
}

void PointMap::add_outer(const PointMap& y, const Eigen::Matrix3d& K, double scale,
                         std::vector<Triplet>& out) const {
  for (const auto& [bx, cx] : terms)
    for (const auto& [by, cy] : y.terms) {
      const double c = scale * cx * cy;
      if (c == 0.0) continue;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (K(i, j) != 0.0) out.emplace_back(bx + i, by + j, c * K(i, j));
    }
}

namespace {

void collect(const PointMap& p, std::set<int>& s) {
  for (const auto& t : p.terms)
    if (t.second != 0.0)
      for (int k = 0; k < 3; ++k) s.insert(t.first + k);
}

std::vector<int> unknowns_of(std::initializer_list<const PointMap*> maps) {
  std::set<int> s;
  for (const PointMap* p : maps) collect(*p, s);
  return {s.begin(), s.end()};
}

// Dense local copy of sparse local-row triplets: rows × (columns listed in cols).
Eigen::MatrixXd dense_rows(const std::vector<Triplet>& t, int rows, const std::vector<int>& cols) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(rows, static_cast<Eigen::Index>(cols.size()));
  for (const auto& e : t) {
    const auto it = std::lower_bound(cols.begin(), cols.end(), e.col());
    D(e.row(), it - cols.begin()) += e.value();
  }
  return D;
}

// ---- point coincidences: spherical joint, fixed point, rigid connection (linear) ------------------------
class Coincidence : public Constraint {
 public:
  Coincidence(std::string name, std::string type, std::vector<std::pair<PointMap, PointMap>> pairs)
      : Constraint(std::move(name), std::move(type)), pairs_(std::move(pairs)) {
    std::set<int> s;
    for (const auto& [a, b] : pairs_) {
      collect(a, s);
      collect(b, s);
    }
    unknowns_.assign(s.begin(), s.end());
  }
  int size() const override { return 3 * static_cast<int>(pairs_.size()); }
  ConstraintKind kind() const override { return ConstraintKind::linear; }
  std::vector<int> unknowns() const override { return unknowns_; }
  Eigen::VectorXd g(const Eigen::VectorXd& q, double) const override {
    Eigen::VectorXd r(size());
    for (size_t p = 0; p < pairs_.size(); ++p) r.segment<3>(3 * p) = pairs_[p].first(q) - pairs_[p].second(q);
    return r;
  }
  void jacobian(const Eigen::VectorXd&, double, std::vector<Triplet>& out) const override {
    for (size_t p = 0; p < pairs_.size(); ++p) {
      pairs_[p].first.add_block(3 * static_cast<int>(p), 1.0, out);
      pairs_[p].second.add_block(3 * static_cast<int>(p), -1.0, out);
    }
  }

 private:
  std::vector<std::pair<PointMap, PointMap>> pairs_;
  std::vector<int> unknowns_;
};

// ---- coincidence + two bilinear axis conditions (quadratic): a = b, e·f = 0, e·h = 0 --------------------
// The revolute joint (§4.3: e the axis in one body, f, h normals to it in the other) and the rigid connection of
// a unit director p to a body (§4.2, aligned form: e = p, f, h the body vectors normal to p's body components).
class AxisCondition : public Constraint {
 public:
  AxisCondition(std::string name, std::string kind_label, PointMap a, PointMap b, PointMap e, PointMap f, PointMap h)
      : Constraint(std::move(name), std::move(kind_label)),
        a_(a),
        b_(b),
        e_(e),
        f_(f),
        h_(h),
        unknowns_(unknowns_of({&a_, &b_, &e_, &f_, &h_})) {}
  int size() const override { return 5; }
  // To the ground (a constant axis or constant normals) the axis rows are linear in q.
  ConstraintKind kind() const override {
    return e_.constant() || (f_.constant() && h_.constant()) ? ConstraintKind::linear
                                                             : ConstraintKind::quadratic;
  }
  std::vector<int> unknowns() const override { return unknowns_; }
  Eigen::VectorXd g(const Eigen::VectorXd& q, double) const override {
    Eigen::VectorXd r(5);
    r.head<3>() = a_(q) - b_(q);
    const Vec3 e = e_(q);
    r(3) = e.dot(f_(q));
    r(4) = e.dot(h_(q));
    return r;
  }
  void jacobian(const Eigen::VectorXd& q, double, std::vector<Triplet>& out) const override {
    a_.add_block(0, 1.0, out);
    b_.add_block(0, -1.0, out);
    const Vec3 e = e_(q), f = f_(q), h = h_(q);
    e_.add_row(3, f, 1.0, out);  // ∂(e·f) = fᵀ∂e + eᵀ∂f
    f_.add_row(3, e, 1.0, out);
    e_.add_row(4, h, 1.0, out);
    h_.add_row(4, e, 1.0, out);
  }
  void hessian_contraction(const Eigen::VectorXd&, double, const Eigen::VectorXd& lam,
                           std::vector<Triplet>& out) const override {
    // ∇²(e·f) couples the e and f blocks with the identity, both ways.
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    e_.add_outer(f_, I, lam(3), out);
    f_.add_outer(e_, I, lam(3), out);
    e_.add_outer(h_, I, lam(4), out);
    h_.add_outer(e_, I, lam(4), out);
  }

 private:
  PointMap a_, b_, e_, f_, h_;
  std::vector<int> unknowns_;
};

// ---- orthonormality of a rigid body's directors (§3; quadratic) ----------------------------------------
class Orthonormality : public Constraint {
 public:
  Orthonormality(std::string name, int base) : Constraint(std::move(name), "orthonormality"), base_(base) {}
  int size() const override { return 6; }
  ConstraintKind kind() const override { return ConstraintKind::quadratic; }
  std::vector<int> unknowns() const override {
    std::vector<int> u(9);
    for (int k = 0; k < 9; ++k) u[k] = base_ + 3 + k;
    return u;
  }
  Eigen::VectorXd g(const Eigen::VectorXd& q, double) const override {
    Eigen::VectorXd r(6);
    for (int row = 0; row < 6; ++row) {
      const auto [i, j] = pair(row);
      r(row) = 0.5 * (d(q, i).dot(d(q, j)) - (i == j ? 1.0 : 0.0));
    }
    return r;
  }
  void jacobian(const Eigen::VectorXd& q, double, std::vector<Triplet>& out) const override {
    for (int row = 0; row < 6; ++row) {
      const auto [i, j] = pair(row);
      for (int k = 0; k < 3; ++k) {
        out.emplace_back(row, base_ + 3 + 3 * i + k, 0.5 * q(base_ + 3 + 3 * j + k));
        out.emplace_back(row, base_ + 3 + 3 * j + k, 0.5 * q(base_ + 3 + 3 * i + k));
      }
    }
  }
  void hessian_contraction(const Eigen::VectorXd&, double, const Eigen::VectorXd& lam,
                           std::vector<Triplet>& out) const override {
    // ∇²(½ d_i·d_j) = ½ I at (d_i, d_j) and at (d_j, d_i) — I at (d_i, d_i) when i = j.
    for (int row = 0; row < 6; ++row) {
      const auto [i, j] = pair(row);
      for (int k = 0; k < 3; ++k) {
        out.emplace_back(base_ + 3 + 3 * i + k, base_ + 3 + 3 * j + k, 0.5 * lam(row));
        out.emplace_back(base_ + 3 + 3 * j + k, base_ + 3 + 3 * i + k, 0.5 * lam(row));
      }
    }
  }

 private:
  static std::pair<int, int> pair(int row) {
    static constexpr int p[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
    return {p[row][0], p[row][1]};
  }
  Vec3 d(const Eigen::VectorXd& q, int i) const { return q.segment<3>(base_ + 3 + 3 * i); }
  int base_;
};

// ---- distance |a − b| − L (general) ---------------------------------------------------------------------
class Distance : public Constraint {
 public:
  Distance(std::string name, PointMap a, PointMap b, double L, DistanceGradient form)
      : Constraint(std::move(name), "distance"),
        a_(a),
        b_(b),
        L_(L),
        form_(form),
        unknowns_(unknowns_of({&a_, &b_})) {}
  int size() const override { return 1; }
  ConstraintKind kind() const override { return ConstraintKind::general; }
  std::vector<int> unknowns() const override { return unknowns_; }
  Eigen::VectorXd g(const Eigen::VectorXd& q, double) const override {
    return Eigen::VectorXd::Constant(1, (a_(q) - b_(q)).norm() - L_);
  }
  void jacobian(const Eigen::VectorXd& q, double, std::vector<Triplet>& out) const override {
    const Vec3 r = a_(q) - b_(q);
    const Vec3 n = r / r.norm();
    a_.add_row(0, n, 1.0, out);
    b_.add_row(0, n, -1.0, out);
  }
  void discrete_gradient(const Eigen::VectorXd& q0, double t0, const Eigen::VectorXd& q1, double t1,
                         std::vector<Triplet>& out, Eigen::VectorXd& tau) const override {
    tau = Eigen::VectorXd::Zero(1);
    if (form_ == DistanceGradient::gonzalez) {
      gonzalez_discrete_gradient(*this, q0, q1, 0.5 * (t0 + t1), out);
      return;
    }
    // §2.3: g = √π − L with the quadratic invariant π = |r|²; π1 − π0 = 2 r_mid · Δr exactly, and
    // (√π1 − √π0)/(π1 − π0) = 1/(|r1| + |r0|) has no cancellation, so no small-step limit is needed.
    const Vec3 r0 = a_(q0) - b_(q0), r1 = a_(q1) - b_(q1);
    const Vec3 w = (r0 + r1) / (r0.norm() + r1.norm());
    a_.add_row(0, w, 1.0, out);
    b_.add_row(0, w, -1.0, out);
  }
  void hessian_contraction(const Eigen::VectorXd& q, double t, const Eigen::VectorXd& lam,
                           std::vector<Triplet>& out) const override {
    (void)t;
    // ∇²|r| = (I − n nᵀ)/|r| in r, mapped by ∂r/∂q = ∂a/∂q − ∂b/∂q.
    const Vec3 r = a_(q) - b_(q);
    const Vec3 n = r / r.norm();
    add_r_outer((Eigen::Matrix3d::Identity() - n * n.transpose()) / r.norm(), lam(0), out);
  }
  void discrete_tangent(const Eigen::VectorXd& q0, double t0, const Eigen::VectorXd& q1, double t1,
                        const Eigen::VectorXd& lam, std::vector<Triplet>& out) const override {
    if (form_ == DistanceGradient::gonzalez) {
      Constraint::discrete_tangent(q0, t0, q1, t1, lam, out);
      return;
    }
    // w = (r0 + r1)/s, s = |r0| + |r1|: ∂w/∂r1 = I/s − (r0 + r1) n1ᵀ/s² with n1 = r1/|r1|.
    const Vec3 r0 = a_(q0) - b_(q0), r1 = a_(q1) - b_(q1);
    const double s = r0.norm() + r1.norm();
    const Vec3 n1 = r1 / r1.norm();
    add_r_outer(Eigen::Matrix3d::Identity() / s - (r0 + r1) * n1.transpose() / (s * s), lam(0), out);
  }

 private:
  // scale · (∂r/∂q)ᵀ K (∂r/∂q) with r = a − b.
  void add_r_outer(const Eigen::Matrix3d& K, double scale, std::vector<Triplet>& out) const {
    a_.add_outer(a_, K, scale, out);
    a_.add_outer(b_, K, -scale, out);
    b_.add_outer(a_, K, -scale, out);
    b_.add_outer(b_, K, scale, out);
  }
  PointMap a_, b_;
  double L_;
  DistanceGradient form_;
  std::vector<int> unknowns_;
};

// ---- prescribed rotation of a hub about a ground axis (§4.4; rheonomic) ---------------------------------
Vec3 rotate(const Vec3& v, const Vec3& n, double th) {  // Rodrigues, n unit
  return std::cos(th) * v + std::sin(th) * n.cross(v) + (1.0 - std::cos(th)) * n.dot(v) * n;
}

class PrescribedRotation : public Constraint {
 public:
  PrescribedRotation(std::string name, int base, const Vec3& Xp, const Vec3& a, const Vec3& u, const Vec3& c,
                     const Vec3& n, const Vec3& u0, AngleHistory th)
      : Constraint(std::move(name), "prescribed rotation"),
        pivot_(PointMap::body_point(base, Xp)),
        axis_(PointMap::body_vector(base, a)),
        radial_(PointMap::body_vector(base, u)),
        c_(c),
        n_(n),
        th_(std::move(th)) {
    // t1, t2 ⟂ n: the axis rows a_hub · t_k = 0; w0 = n × u0: the drive row's direction at θ = 0.
    t1_ = u0;
    t2_ = n.cross(u0);
    w0_ = n.cross(u0);
    unknowns_ = unknowns_of({&pivot_, &axis_, &radial_});
  }
  int size() const override { return 6; }
  ConstraintKind kind() const override { return ConstraintKind::linear; }
  bool rheonomic() const override { return true; }
  std::vector<int> unknowns() const override { return unknowns_; }
  Eigen::VectorXd g(const Eigen::VectorXd& q, double t) const override {
    Eigen::VectorXd r(6);
    r.head<3>() = pivot_(q) - c_;
    const Vec3 a = axis_(q);
    r(3) = a.dot(t1_);
    r(4) = a.dot(t2_);
    r(5) = radial_(q).dot(w(t));
    return r;
  }
  void jacobian(const Eigen::VectorXd& q, double t, std::vector<Triplet>& out) const override {
    (void)q;
    pivot_.add_block(0, 1.0, out);
    axis_.add_row(3, t1_, 1.0, out);
    axis_.add_row(4, t2_, 1.0, out);
    radial_.add_row(5, w(t), 1.0, out);
  }
  Eigen::VectorXd dg_dt(const Eigen::VectorXd& q, double t) const override {
    Eigen::VectorXd r = Eigen::VectorXd::Zero(6);
    r(5) = radial_(q).dot(th_.theta_dot(t) * n_.cross(w(t)));  // ẇ = θ̇ n × w
    return r;
  }
  void discrete_gradient(const Eigen::VectorXd& q0, double t0, const Eigen::VectorXd& q1, double t1,
                         std::vector<Triplet>& out, Eigen::VectorXd& tau) const override {
    // Rows 0–4 are linear and time-independent: Ḡ = G, τ = 0. The drive row u(q)·w(t) is bilinear in
    // (u, w): u1·w1 − u0·w0 = ½(w0 + w1)·(u1 − u0) + ½(u0 + u1)·(w1 − w0), §4.4 eqs. (4.5)–(4.6).
    pivot_.add_block(0, 1.0, out);
    axis_.add_row(3, t1_, 1.0, out);
    axis_.add_row(4, t2_, 1.0, out);
    const Vec3 w0 = w(t0), w1 = w(t1);
    radial_.add_row(5, 0.5 * (w0 + w1), 1.0, out);
    tau = Eigen::VectorXd::Zero(6);
    tau(5) = 0.5 * (radial_(q0) + radial_(q1)).dot(w1 - w0);
  }

 private:
  Vec3 w(double t) const { return rotate(w0_, n_, th_.theta(t)); }
  PointMap pivot_, axis_, radial_;
  Vec3 c_, n_, t1_, t2_, w0_;
  AngleHistory th_;
  std::vector<int> unknowns_;
};

void require_unit(const std::string& name, const char* what, const Vec3& v) {
  if (!(std::abs(v.norm() - 1.0) < 1e-12)) {
    std::ostringstream os;
    os << "prescribed rotation '" << name << "': " << what << " (" << v.transpose()
       << ") must be a unit vector";
    throw std::invalid_argument(os.str());
  }
}

}  // namespace

// ---- Constraint defaults --------------------------------------------------------------------------------
Eigen::VectorXd Constraint::dg_dt(const Eigen::VectorXd&, double) const {
  return Eigen::VectorXd::Zero(size());
}

void Constraint::discrete_gradient(const Eigen::VectorXd& q0, double t0, const Eigen::VectorXd& q1, double t1,
                                   std::vector<Triplet>& out, Eigen::VectorXd& tau) const {
  if (rheonomic())
    throw std::logic_error("constraint '" + name() + "' (" + type() +
                           ") is rheonomic and must define its own discrete gradient");
  tau = Eigen::VectorXd::Zero(size());
  const double t = 0.5 * (t0 + t1);
  if (kind() == ConstraintKind::general) {
    gonzalez_discrete_gradient(*this, q0, q1, t, out);
    return;
  }
  // Linear: G is constant. Quadratic: g(q1) − g(q0) = G(q_mid)(q1 − q0) exactly (§2.2).
  jacobian(0.5 * (q0 + q1), t, out);
}

namespace {
// Central differences of q ↦ B(q)ᵀλ over the constraint's unknowns (the general-kind fallback of §5.1).
template <class F>
void fd_tangent(const Constraint& c, const Eigen::VectorXd& q, const Eigen::VectorXd& lam, F&& rows,
                std::vector<Triplet>& out) {
  const std::vector<int> cols = c.unknowns();
  auto product = [&](const Eigen::VectorXd& x) {
    std::vector<Triplet> t;
    rows(x, t);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(cols.size()));
    for (const auto& e : t) {
      const auto it = std::lower_bound(cols.begin(), cols.end(), e.col());
      f(it - cols.begin()) += e.value() * lam(e.row());
    }
    return f;
  };
  for (size_t k = 0; k < cols.size(); ++k) {
    const double h = 1e-6 * (1.0 + std::abs(q(cols[k])));
    Eigen::VectorXd qp = q, qm = q;
    qp(cols[k]) += h;
    qm(cols[k]) -= h;
    const Eigen::VectorXd d = (product(qp) - product(qm)) / (2.0 * h);
    for (size_t i = 0; i < cols.size(); ++i)
      if (d(i) != 0.0) out.emplace_back(cols[i], cols[k], d(i));
  }
}
}  // namespace

void Constraint::hessian_contraction(const Eigen::VectorXd& q, double t, const Eigen::VectorXd& lam,
                                     std::vector<Triplet>& out) const {
  if (kind() == ConstraintKind::linear) return;
  if (kind() == ConstraintKind::quadratic)
    throw std::logic_error("constraint '" + name() + "' (" + type() + ") must define its Hessian");
  fd_tangent(
      *this, q, lam, [&](const Eigen::VectorXd& x, std::vector<Triplet>& t_) { jacobian(x, t, t_); }, out);
}

void Constraint::discrete_tangent(const Eigen::VectorXd& q0, double t0, const Eigen::VectorXd& q1, double t1,
                                  const Eigen::VectorXd& lam, std::vector<Triplet>& out) const {
  if (kind() == ConstraintKind::linear) return;  // Ḡ = G does not depend on q (t enters rheonomic rows only)
  if (kind() == ConstraintKind::quadratic) {
    // Ḡ = G(q_mid): ∂(G(q_mid)ᵀλ)/∂q1 = ½ Σ λ_i H_i.
    std::vector<Triplet> h;
    hessian_contraction(0.5 * (q0 + q1), 0.5 * (t0 + t1), lam, h);
    for (const auto& e : h) out.emplace_back(e.row(), e.col(), 0.5 * e.value());
    return;
  }
  fd_tangent(
      *this, q1, lam,
      [&](const Eigen::VectorXd& x, std::vector<Triplet>& t_) {
        Eigen::VectorXd tau;
        discrete_gradient(q0, t0, x, t1, t_, tau);
      },
      out);
}

void gonzalez_discrete_gradient(const Constraint& c, const Eigen::VectorXd& q0, const Eigen::VectorXd& q1,
                                double t, std::vector<Triplet>& out) {
  const std::vector<int> cols = c.unknowns();
  const Eigen::VectorXd qm = 0.5 * (q0 + q1);
  std::vector<Triplet> Gm;
  c.jacobian(qm, t, Gm);
  Eigen::VectorXd dq(cols.size()), qml(cols.size());
  for (size_t k = 0; k < cols.size(); ++k) {
    dq(k) = q1(cols[k]) - q0(cols[k]);
    qml(k) = qm(cols[k]);
  }
  const double dq2 = dq.squaredNorm();
  const double eps = std::numeric_limits<double>::epsilon();
  out.insert(out.end(), Gm.begin(), Gm.end());
  // Safe limit (§2.3): the correction is O(|Δq|²) in Ḡ and O(|Δq|³) in ḠΔq, below round-off here.
  if (std::sqrt(dq2) <= std::sqrt(eps) * (1.0 + qml.norm())) return;
  const Eigen::MatrixXd D = dense_rows(Gm, c.size(), cols);
  const Eigen::VectorXd defect = c.g(q1, t) - c.g(q0, t) - D * dq;
  for (int i = 0; i < c.size(); ++i)
    for (size_t k = 0; k < cols.size(); ++k)
      if (dq(k) != 0.0) out.emplace_back(i, cols[k], defect(i) * dq(k) / dq2);
}

// ---- factories ------------------------------------------------------------------------------------------
std::unique_ptr<Constraint> spherical_joint(std::string name, PointMap a, PointMap b) {
  return std::make_unique<Coincidence>(std::move(name), "spherical joint",
                                       std::vector<std::pair<PointMap, PointMap>>{{a, b}});
}

std::unique_ptr<Constraint> fixed_point(std::string name, PointMap a, const Vec3& x0) {
  return std::make_unique<Coincidence>(std::move(name), "fixed point",
                                       std::vector<std::pair<PointMap, PointMap>>{{a, PointMap::ground(x0)}});
}

std::unique_ptr<Constraint> revolute_joint(std::string name, PointMap a, PointMap b, PointMap axis_a,
                                           PointMap normal1_b, PointMap normal2_b) {
  return std::make_unique<AxisCondition>(std::move(name), "revolute joint", a, b, axis_a, normal1_b, normal2_b);
}

std::unique_ptr<Constraint> rigid_connection(std::string name, PointMap x, PointMap p, int body_base,
                                             const Vec3& X, const Vec3& a, DirectorCondition form) {
  if (form == DirectorCondition::aligned) {
    if (!(std::abs(a.norm() - 1.0) < 1e-12)) {
      std::ostringstream os;
      os << "rigid connection '" << name << "': the director's body components (" << a.transpose()
         << ") must form a unit vector for the aligned form";
      throw std::invalid_argument(os.str());
    }
    // (a, b, c) orthonormal: b from the body axis least aligned with a.
    Eigen::Index k;
    a.cwiseAbs().minCoeff(&k);
    const Vec3 b = a.cross(Vec3::Unit(k)).normalized(), c = a.cross(b);
    return std::make_unique<AxisCondition>(std::move(name), "rigid connection", x, PointMap::body_point(body_base, X), p,
                                           PointMap::body_vector(body_base, b), PointMap::body_vector(body_base, c));
  }
  return std::make_unique<Coincidence>(
      std::move(name), "rigid connection",
      std::vector<std::pair<PointMap, PointMap>>{{x, PointMap::body_point(body_base, X)},
                                                 {p, PointMap::body_vector(body_base, a)}});
}

std::unique_ptr<Constraint> orthonormality(std::string name, int body_base) {
  return std::make_unique<Orthonormality>(std::move(name), body_base);
}

std::unique_ptr<Constraint> distance(std::string name, PointMap a, PointMap b, double length,
                                     DistanceGradient form) {
  if (!(std::isfinite(length) && length > 0.0)) {
    std::ostringstream os;
    os << "distance '" << name << "': length " << length << " must be a positive number";
    throw std::invalid_argument(os.str());
  }
  return std::make_unique<Distance>(std::move(name), a, b, length, form);
}

std::unique_ptr<Constraint> prescribed_rotation(std::string name, int hub_base, const Vec3& X_pivot,
                                                const Vec3& a_hub, const Vec3& u_hub, const Vec3& c,
                                                const Vec3& n, const Vec3& u0, AngleHistory angle) {
  require_unit(name, "hub axis", a_hub);
  require_unit(name, "hub radial vector", u_hub);
  require_unit(name, "ground axis", n);
  require_unit(name, "radial direction at zero angle", u0);
  if (std::abs(a_hub.dot(u_hub)) > 1e-12 || std::abs(n.dot(u0)) > 1e-12)
    throw std::invalid_argument("prescribed rotation '" + name +
                                "': the radial vectors must be normal to their axes (hub and ground)");
  if (!angle.theta || !angle.theta_dot)
    throw std::invalid_argument("prescribed rotation '" + name +
                                "': the angle history θ(t), θ̇(t) is missing");
  return std::make_unique<PrescribedRotation>(std::move(name), hub_base, X_pivot, a_hub, u_hub, c, n, u0,
                                              std::move(angle));
}

// ---- ConstraintSet --------------------------------------------------------------------------------------
void ConstraintSet::add(std::unique_ptr<Constraint> c) {
  if (!c) throw std::invalid_argument("ConstraintSet::add: null constraint");
  for (const auto& o : list_)
    if (o->name() == c->name())
      throw std::invalid_argument("constraint '" + c->name() + "': the name is already used by a " +
                                  o->type() + "; give each constraint its own name");
  const auto u = c->unknowns();
  if (!u.empty() && (u.front() < 0 || u.back() >= n_)) {
    std::ostringstream os;
    os << c->type() << " '" << c->name() << "' references unknown " << (u.front() < 0 ? u.front() : u.back())
       << " but the model has " << n_ << " unknowns (check the node or body it is attached to)";
    throw std::invalid_argument(os.str());
  }
  offsets_.push_back(rows_);
  rows_ += c->size();
  list_.push_back(std::move(c));
}

Eigen::VectorXd ConstraintSet::g(const Eigen::VectorXd& q, double t) const {
  Eigen::VectorXd r(rows_);
  for (size_t i = 0; i < list_.size(); ++i) r.segment(offsets_[i], list_[i]->size()) = list_[i]->g(q, t);
  return r;
}

Eigen::VectorXd ConstraintSet::dg_dt(const Eigen::VectorXd& q, double t) const {
  Eigen::VectorXd r(rows_);
  for (size_t i = 0; i < list_.size(); ++i) r.segment(offsets_[i], list_[i]->size()) = list_[i]->dg_dt(q, t);
  return r;
}

namespace {
Eigen::SparseMatrix<double> assemble(int rows, int cols, const std::vector<Triplet>& t) {
  Eigen::SparseMatrix<double> M(rows, cols);
  M.setFromTriplets(t.begin(), t.end());
  return M;
}
void shift(std::vector<Triplet>& all, const std::vector<Triplet>& local, int row0) {
  for (const auto& e : local) all.emplace_back(e.row() + row0, e.col(), e.value());
}
}  // namespace

Eigen::SparseMatrix<double> ConstraintSet::G(const Eigen::VectorXd& q, double t) const {
  std::vector<Triplet> all, local;
  for (size_t i = 0; i < list_.size(); ++i) {
    local.clear();
    list_[i]->jacobian(q, t, local);
    shift(all, local, offsets_[i]);
  }
  return assemble(rows_, n_, all);
}

Eigen::SparseMatrix<double> ConstraintSet::Gbar(const Eigen::VectorXd& q0, double t0,
                                                const Eigen::VectorXd& q1, double t1,
                                                Eigen::VectorXd& tau) const {
  std::vector<Triplet> all, local;
  tau.resize(rows_);
  Eigen::VectorXd tl;
  for (size_t i = 0; i < list_.size(); ++i) {
    local.clear();
    list_[i]->discrete_gradient(q0, t0, q1, t1, local, tl);
    shift(all, local, offsets_[i]);
    tau.segment(offsets_[i], list_[i]->size()) = tl;
  }
  return assemble(rows_, n_, all);
}

Eigen::SparseMatrix<double> ConstraintSet::hessian_contraction(const Eigen::VectorXd& q, double t,
                                                               const Eigen::VectorXd& lambda) const {
  std::vector<Triplet> all;
  for (size_t i = 0; i < list_.size(); ++i)
    list_[i]->hessian_contraction(q, t, lambda.segment(offsets_[i], list_[i]->size()), all);
  return assemble(n_, n_, all);
}

Eigen::SparseMatrix<double> ConstraintSet::discrete_tangent(const Eigen::VectorXd& q0, double t0,
                                                            const Eigen::VectorXd& q1, double t1,
                                                            const Eigen::VectorXd& lambda) const {
  std::vector<Triplet> all;
  for (size_t i = 0; i < list_.size(); ++i)
    list_[i]->discrete_tangent(q0, t0, q1, t1, lambda.segment(offsets_[i], list_[i]->size()), all);
  return assemble(n_, n_, all);
}

RankReport ConstraintSet::rank_check(const Eigen::VectorXd& q, double t, double tol, double g_tol,
                                     const std::vector<bool>& fixed) const {
  RankReport rep;
  rep.rows = rows_;
  if (rows_ == 0) return rep;
  if (!fixed.empty() && static_cast<int>(fixed.size()) != n_)
    throw std::invalid_argument("ConstraintSet::rank_check: the fixed-unknown mask has " +
                                std::to_string(fixed.size()) + " entries for " + std::to_string(n_) +
                                " unknowns");
  // Dense G over the touched free columns only: a shell model has many unknowns but few of them constrained.
  std::set<int> touched;
  for (const auto& c : list_)
    for (int k : c->unknowns())
      if (fixed.empty() || !fixed[k]) touched.insert(k);
  const std::vector<int> cols(touched.begin(), touched.end());
  const Eigen::SparseMatrix<double> Gs = G(q, t);
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(rows_, static_cast<Eigen::Index>(cols.size()));
  for (int k = 0; k < Gs.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(Gs, k); it; ++it) {
      const auto pos = std::lower_bound(cols.begin(), cols.end(), static_cast<int>(it.col()));
      if (pos != cols.end() && *pos == it.col()) D(it.row(), pos - cols.begin()) += it.value();
    }
  // Divide-and-conquer SVD: the clamp of a shell edge gives hundreds of rows, where Jacobi's is slow.
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(D, Eigen::ComputeFullU);
  const Eigen::VectorXd& s = svd.singularValues();
  const double cut = tol * std::max(1.0, s.size() ? s(0) : 0.0);
  int rank = 0;
  for (int i = 0; i < s.size(); ++i)
    if (s(i) > cut) ++rank;
  rep.rank = rank;
  if (rank == rows_) return rep;
  // Columns rank .. rows−1 of U span the left null space {y : yᵀG = 0}: the dependent combinations of rows.
  const Eigen::MatrixXd Y = svd.matrixU().rightCols(rows_ - rank);
  const Eigen::VectorXd gq = g(q, t);
  std::vector<bool> in(list_.size(), false);
  for (int j = 0; j < Y.cols(); ++j) {
    if (std::abs(Y.col(j).dot(gq)) > g_tol) rep.conflicting = true;
    for (size_t i = 0; i < list_.size(); ++i)
      if (Y.col(j).segment(offsets_[i], list_[i]->size()).norm() > 1e-6) in[i] = true;
  }
  std::ostringstream os;
  os << (rep.conflicting ? "conflicting" : "redundant") << " constraints: the " << rows_
     << " constraint rows have rank " << rank << " (" << rows_ - rank << " dependent) at t = " << t
     << "; the dependent rows involve";
  bool first = true;
  for (size_t i = 0; i < list_.size(); ++i)
    if (in[i]) {
      rep.involved.push_back(list_[i]->name());
      os << (first ? " " : ", ") << list_[i]->type() << " '" << list_[i]->name() << "'";
      first = false;
    }
  os << (rep.conflicting ? "; they cannot all hold: remove or correct one of them"
                         : "; remove one of them or free a direction it fixes twice");
  if (!fixed.empty()) os << " (unknowns fixed by supports are not counted as free)";
  rep.message = os.str();
  return rep;
}

void ConstraintSet::require_full_rank(const Eigen::VectorXd& q, double t, const std::vector<bool>& fixed,
                                      double tol) const {
  const RankReport r = rank_check(q, t, tol, 1e-9, fixed);
  if (!r.message.empty()) throw std::invalid_argument(r.message);
}

}  // namespace shelldyn::multibody
