// Holonomic constraints and their discrete gradients (docs/theory/multibody.md §2, §4).
//
// Every kind acts on "points": affine maps x(q) = x0 + Σ_j c_j q[b_j .. b_j+2] of the global unknown vector,
// so the same joint serves a shell node (position X + u, ℝ³ director p), a rigid body in director form
// (φ + Σ X_k d_k, Σ a_k d_k; lib/multibody/rigid_body.hpp) or the ground (a constant).
//
// Each constraint gives g(q, t) (size() rows), its Jacobian G = ∂g/∂q as sparse rows over the global columns
// it touches, ∂g/∂t (zero unless rheonomic) and a discrete gradient Ḡ(q_n, q_{n+1}) with
//     Ḡ Δq + τ = g(q_{n+1}, t_{n+1}) − g(q_n, t_n)        exactly (to round-off),                  (§2.2)
// where τ (the "time part", zero for a scleronomic constraint) is the discrete ∂g/∂t Δt whose product with
// the multipliers is the driver's work. Linear g: Ḡ = G; quadratic g: Ḡ = G(q_mid); general g: Gonzalez's
// midpoint formula (§2.3) or a constraint-specific form.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn::multibody {

using Vec3 = Eigen::Vector3d;
using Triplet = Eigen::Triplet<double>;

// x(q) = offset + Σ coeff · q.segment<3>(base) over the terms (§4.1).
struct PointMap {
  Vec3 offset = Vec3::Zero();
  std::vector<std::pair<int, double>> terms;  // (first index of a 3-block of q, coefficient)

  static PointMap ground(const Vec3& x);
  static PointMap node_position(int base, const Vec3& X);    // X + u (u = translations of a node)
  static PointMap vector3(int base);                         // an ℝ³ vector of the unknowns (a director p)
  static PointMap body_point(int body_base, const Vec3& X);  // φ + Σ X_k d_k of a rigid body at body_base
  static PointMap body_vector(int body_base, const Vec3& a);  // Σ a_k d_k

  Vec3 operator()(const Eigen::VectorXd& q) const;
  bool constant() const { return terms.empty(); }
  // Largest index of q the map reads (−1 for a constant).
  int max_index() const;
  // Appends scale · w^T ∂x/∂q to row `row` (w ∈ ℝ³).
  void add_row(int row, const Vec3& w, double scale, std::vector<Triplet>& out) const;
  // Appends scale · ∂x_k/∂q to rows row0 + k.
  void add_block(int row0, double scale, std::vector<Triplet>& out) const;
  // Appends scale · (∂x/∂q)ᵀ K (∂y/∂q) for this map x and another map y (an n × n contribution).
  void add_outer(const PointMap& y, const Eigen::Matrix3d& K, double scale, std::vector<Triplet>& out) const;
};

enum class ConstraintKind { linear, quadratic, general };

class Constraint {
 public:
  Constraint(std::string name, std::string type) : name_(std::move(name)), type_(std::move(type)) {}
  virtual ~Constraint() = default;

  const std::string& name() const { return name_; }
  const std::string& type() const { return type_; }
  virtual int size() const = 0;
  virtual ConstraintKind kind() const = 0;
  virtual bool rheonomic() const { return false; }
  // Sorted, unique indices of q that g depends on.
  virtual std::vector<int> unknowns() const = 0;

  virtual Eigen::VectorXd g(const Eigen::VectorXd& q, double t) const = 0;
  // Appends G = ∂g/∂q with rows 0 .. size()-1 (local) and global columns.
  virtual void jacobian(const Eigen::VectorXd& q, double t, std::vector<Triplet>& out) const = 0;
  virtual Eigen::VectorXd dg_dt(const Eigen::VectorXd& q, double t) const;
  // Appends Ḡ(q0, q1) (local rows) and writes τ (size() entries) so that Ḡ Δq + τ = g(q1, t1) − g(q0, t0).
  // The default follows kind(): linear and quadratic use G at the midpoint (exact for a scleronomic g of
  // degree ≤ 2), general uses gonzalez_discrete_gradient. Rheonomic kinds override it.
  virtual void discrete_gradient(const Eigen::VectorXd& q0, double t0, const Eigen::VectorXd& q1, double t1,
                                 std::vector<Triplet>& out, Eigen::VectorXd& tau) const;

  // Newton tangents of the constraint force (§5.1), as n × n triplets over the global unknowns, for the
  // multipliers `lambda` (size() entries):
  //   hessian_contraction:  ∂(G(q, t)ᵀλ)/∂q = Σ_i λ_i ∇²g_i   (index-3 schemes with the end-point Jacobian);
  //   discrete_tangent:     ∂(Ḡ(q0, q1)ᵀλ)/∂q1                (the conserving step).
  // Linear kinds add nothing; quadratic kinds give the constant Σλ_i H_i and ½Σλ_i H_i. The defaults for a
  // general kind are central differences over the constraint's unknowns; kinds override them where they can.
  virtual void hessian_contraction(const Eigen::VectorXd& q, double t, const Eigen::VectorXd& lambda,
                                   std::vector<Triplet>& out) const;
  virtual void discrete_tangent(const Eigen::VectorXd& q0, double t0, const Eigen::VectorXd& q1, double t1,
                                const Eigen::VectorXd& lambda, std::vector<Triplet>& out) const;

 private:
  std::string name_, type_;
};

// Gonzalez's midpoint discrete gradient of a general constraint, row by row over the constraint's unknowns
// (§2.3): Ḡ_i = G_i(q_mid) + [g_i(q1) − g_i(q0) − G_i(q_mid)Δq] Δqᵀ/|Δq|², and Ḡ_i = G_i(q_mid) when |Δq| is
// below √ε (1 + |q_mid|) over those unknowns, where the dropped term is O(|Δq|³), far under round-off.
void gonzalez_discrete_gradient(const Constraint& c, const Eigen::VectorXd& q0, const Eigen::VectorXd& q1,
                                double t, std::vector<Triplet>& out);

// g = a(q) − b(q): spherical joint between two points (or, with b constant, a fixed point). Linear, 3 rows.
std::unique_ptr<Constraint> spherical_joint(std::string name, PointMap a, PointMap b);
std::unique_ptr<Constraint> fixed_point(std::string name, PointMap a, const Vec3& x0);

// Revolute joint (§4.3): spherical joint a = b plus e_A · f_B = 0 and e_A · h_B = 0, where e_A is the hinge
// axis in the first body and f_B, h_B span the plane normal to the axis in the second (vector maps, e.g.
// PointMap::body_vector; a constant map for the ground). Quadratic, 5 rows.
std::unique_ptr<Constraint> revolute_joint(std::string name, PointMap a, PointMap b, PointMap axis_a,
                                           PointMap normal1_b, PointMap normal2_b);

// Rigid connection of a node to a rigid body (§4.2): x_node = φ + Σ X_k d_k, with X the node's position in
// the body frame at assembly, and a director condition:
//   equal:   p_node = Σ a_k d_k (3 linear rows) — for a director that is a free ℝ³ vector;
//   aligned: p_node · Σ b_k d_k = 0 and p_node · Σ c_k d_k = 0, (a, b, c) orthonormal (2 quadratic rows),
//            for a director that is unit by construction (a shell director through its chart, a body axis),
//            where the third row of `equal` would repeat the unit length and make G rank deficient.
enum class DirectorCondition { equal, aligned };
std::unique_ptr<Constraint> rigid_connection(std::string name, PointMap node_position, PointMap node_director,
                                             int body_base, const Vec3& X, const Vec3& a,
                                             DirectorCondition form = DirectorCondition::equal);

// The six orthonormality conditions ½(d_i·d_j − δ_ij) of a rigid body at body_base (§3). Quadratic.
std::unique_ptr<Constraint> orthonormality(std::string name, int body_base);

// Distance |a − b| − L = 0 between two points (a massless link). General (not polynomial). Its discrete
// gradient is either the invariant form (§2.3: through π = |a − b|², Ḡ = 2 r_midᵀ ∂r/∂q / (|r0| + |r1|),
// which keeps the momenta of a link between bodies) or Gonzalez's generic formula.
enum class DistanceGradient { invariant, gonzalez };
std::unique_ptr<Constraint> distance(std::string name, PointMap a, PointMap b, double length,
                                     DistanceGradient form = DistanceGradient::invariant);

// Prescribed rotation of a rigid hub about a ground axis (§4.4; rheonomic): the hub's body point X_pivot is
// at the ground point c, its body axis a_hub (unit) is along the unit ground axis n, and its body vector
// u_hub (unit, normal to a_hub) follows R(θ(t), n) u0, where u0 ⟂ n is its ground direction at θ = 0. The
// drive row u_hub · R(θ(t), n)(n × u0) = 0 is linear in q at fixed t; 6 rows in all.
struct AngleHistory {
  std::function<double(double)> theta, theta_dot;
};
std::unique_ptr<Constraint> prescribed_rotation(std::string name, int hub_base, const Vec3& X_pivot,
                                                const Vec3& a_hub, const Vec3& u_hub, const Vec3& c,
                                                const Vec3& n, const Vec3& u0, AngleHistory angle);

// The constraints of a model stacked in insertion order.
struct RankReport {
  int rows = 0, rank = 0;
  bool conflicting = false;           // the dependent combination of g is not zero at the state checked
  std::vector<std::string> involved;  // names of the constraints in the dependent rows (insertion order)
  std::string message;                // empty when G has full row rank
};

class ConstraintSet {
 public:
  explicit ConstraintSet(int num_unknowns) : n_(num_unknowns) {}
  // Throws std::invalid_argument if the constraint reads an unknown ≥ num_unknowns or its name is taken.
  void add(std::unique_ptr<Constraint> c);

  int num_unknowns() const { return n_; }
  int rows() const { return rows_; }
  int size() const { return static_cast<int>(list_.size()); }
  const Constraint& operator[](int i) const { return *list_[i]; }
  int offset(int i) const { return offsets_[i]; }

  Eigen::VectorXd g(const Eigen::VectorXd& q, double t) const;
  Eigen::SparseMatrix<double> G(const Eigen::VectorXd& q, double t) const;
  Eigen::VectorXd dg_dt(const Eigen::VectorXd& q, double t) const;
  // Ḡ and τ of §2.2 stacked.
  Eigen::SparseMatrix<double> Gbar(const Eigen::VectorXd& q0, double t0, const Eigen::VectorXd& q1, double t1,
                                   Eigen::VectorXd& tau) const;
  // The stacked tangents of §5.1 for the stacked multipliers lambda (rows() entries); n × n.
  Eigen::SparseMatrix<double> hessian_contraction(const Eigen::VectorXd& q, double t,
                                                  const Eigen::VectorXd& lambda) const;
  Eigen::SparseMatrix<double> discrete_tangent(const Eigen::VectorXd& q0, double t0,
                                               const Eigen::VectorXd& q1, double t1,
                                               const Eigen::VectorXd& lambda) const;

  // Row rank of G(q, t) by an SVD over the touched columns (§2.5): singular values ≤ tol · max(1, σ_max)
  // count as zero; the left null vectors name the constraints involved, and |yᵀ g(q, t)| > g_tol marks a
  // conflict. `fixed` (empty, or one flag per unknown) drops the unknowns a support already prescribes: a
  // joint acting only on such unknowns, or fixing again what a support fixes, is then reported as well.
  RankReport rank_check(const Eigen::VectorXd& q, double t, double tol = 1e-10, double g_tol = 1e-9,
                        const std::vector<bool>& fixed = {}) const;
  // Throws std::invalid_argument with RankReport::message if G is rank deficient.
  void require_full_rank(const Eigen::VectorXd& q, double t, const std::vector<bool>& fixed = {},
                         double tol = 1e-10) const;

 private:
  int n_;
  int rows_ = 0;
  std::vector<std::unique_ptr<Constraint>> list_;
  std::vector<int> offsets_;
};

}  // namespace shelldyn::multibody
