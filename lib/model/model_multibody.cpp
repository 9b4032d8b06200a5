#include "lib/model/model_multibody.hpp"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

namespace {

using Mat32 = Eigen::Matrix<double, 3, 2>;
using UTriplet = Eigen::Triplet<double, Index>;

std::string num(double x) {
  std::ostringstream os;
  os.precision(3);
  os << x;
  return os.str();
}

// A unit vector normal to the unit vector n.
Eigen::Vector3d normal_to(const Eigen::Vector3d& n) {
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(n[i]) < std::abs(n[k])) k = i;
  return n.cross(Eigen::Vector3d::Unit(k)).normalized();
}

}  // namespace

const char* joint_type_name(JointDef::Type t) {
  switch (t) {
    case JointDef::Type::fixed_point: return "fixed_point";
    case JointDef::Type::spherical: return "spherical";
    case JointDef::Type::revolute: return "revolute";
    case JointDef::Type::rigid_connection: return "rigid_connection";
    case JointDef::Type::prescribed_rotation: return "prescribed_rotation";
  }
  return "?";
}

std::string JointEnd::describe(const std::vector<RigidBodyDef>& bodies) const {
  std::ostringstream os;
  switch (kind) {
    case Kind::node: os << "node " << node; break;
    case Kind::body: os << "body '" << bodies[static_cast<size_t>(body)].name << "' at [" << at.transpose() << "]"; break;
    case Kind::ground: os << "ground [" << at.transpose() << "]"; break;
    case Kind::none: os << "(none)"; break;
  }
  return os.str();
}

ModelMultibody::ModelMultibody(const std::vector<Eigen::Vector3d>& X, const std::vector<Eigen::Vector3d>& normals,
                               std::vector<RigidBodyDef> bodies, std::vector<JointDef> joints,
                               const Eigen::Vector3d& gravity)
    : shell_dofs_(static_cast<Index>(X.size()) * kDofsPerNode),
      X_(X),
      normals_(normals),
      bodies_(std::move(bodies)),
      joints_(std::move(joints)),
      gravity_(gravity) {
  const int nn = static_cast<int>(X_.size());
  // Bodies (multibody.md §3): E_i ≥ 0 (triangle inequalities) and mass > 0 are checked by RigidBody.
  for (const auto& b : bodies_) {
    rigid_.emplace_back(b.name, b.mass, b.inertia);
    const Eigen::Matrix3d& R = b.axes;
    if (!((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-9) || !(R.determinant() > 0.0))
      throw std::invalid_argument("rigid body '" + b.name +
                                  "': axes must be two orthonormal vectors d1, d2 (d3 = d1 × d2); normalize them");
    q0_.push_back(multibody::RigidBody::state(b.position, R));
  }
  // Pass 1: node slots (multibody.md §7: the ℝ³ quantities of the nodes the joints read).
  node_to_slot_.assign(static_cast<size_t>(nn), -1);
  auto check_body = [&](const JointDef& j, int b) {
    if (b < 0 || b >= num_bodies()) throw std::invalid_argument("joint '" + j.name + "': no such rigid body");
  };
  auto use_node = [&](const JointDef& j, int node, bool director) {
    if (node < 0 || node >= nn)
      throw std::invalid_argument("joint '" + j.name + "': node " + std::to_string(node) + " is outside the mesh");
    int& s = node_to_slot_[static_cast<size_t>(node)];
    if (s < 0) {
      s = static_cast<int>(slot_nodes_.size());
      slot_nodes_.push_back(node);
      director_used_.push_back(false);
    }
    if (director) director_used_[static_cast<size_t>(s)] = true;
  };
  for (const auto& j : joints_) {
    for (const JointEnd* e : {&j.a, &j.b}) {
      if (e->kind == JointEnd::Kind::node) use_node(j, e->node, false);
      if (e->kind == JointEnd::Kind::body) check_body(j, e->body);
    }
    if (j.type == JointDef::Type::rigid_connection) {
      check_body(j, j.body);
      if (j.nodes.empty()) throw std::invalid_argument("joint '" + j.name + "': the set has no nodes");
      for (int node : j.nodes) use_node(j, node, true);
    }
    if (j.type == JointDef::Type::prescribed_rotation) check_body(j, j.body);
  }
  const int body_y0 = 6 * static_cast<int>(slot_nodes_.size());
  ny_ = body_y0 + 12 * num_bodies();
  set_ = multibody::ConstraintSet(ny_);
  auto ybase = [&](int b) { return body_y0 + 12 * b; };
  auto R0 = [&](int b) { return bodies_[static_cast<size_t>(b)].axes; };
  auto phi0 = [&](int b) { return bodies_[static_cast<size_t>(b)].position; };
  auto body_coords = [&](int b, const Eigen::Vector3d& x) -> Eigen::Vector3d { return R0(b).transpose() * (x - phi0(b)); };

  auto add = [&](std::unique_ptr<multibody::Constraint> c, const std::string& user_name) {
    const std::string type = c->type();
    const Index first = set_.rows(), rows = c->size();
    set_.add(std::move(c));
    if (!blocks_.empty() && blocks_.back().name == user_name && blocks_.back().first_row + blocks_.back().rows == first)
      blocks_.back().rows += rows;
    else
      blocks_.push_back({type, user_name, first, rows});
  };
  for (int b = 0; b < num_bodies(); ++b)
    add(multibody::orthonormality(bodies_[static_cast<size_t>(b)].name + " frame", ybase(b)), bodies_[static_cast<size_t>(b)].name);

  auto point = [&](const JointDef& j, const JointEnd& e, const char* which) -> multibody::PointMap {
    switch (e.kind) {
      case JointEnd::Kind::node:
        return multibody::PointMap::node_position(6 * node_to_slot_[static_cast<size_t>(e.node)], X_[static_cast<size_t>(e.node)]);
      case JointEnd::Kind::body: return multibody::PointMap::body_point(ybase(e.body), body_coords(e.body, e.at));
      case JointEnd::Kind::ground: return multibody::PointMap::ground(e.at);
      case JointEnd::Kind::none: break;
    }
    throw std::invalid_argument("joint '" + j.name + "': end '" + which + "' is missing");
  };
  auto initial_point = [&](const JointEnd& e) -> Eigen::Vector3d {
    return e.kind == JointEnd::Kind::node ? X_[static_cast<size_t>(e.node)] : e.at;
  };
  for (const auto& j : joints_) {
    switch (j.type) {
      case JointDef::Type::fixed_point: {
        if (j.a.kind == JointEnd::Kind::ground || j.a.kind == JointEnd::Kind::none)
          throw std::invalid_argument("joint '" + j.name + "' (fixed_point): give a one-node `set` or {body, at}");
        add(multibody::fixed_point(j.name, point(j, j.a, "a"), initial_point(j.a)), j.name);
        break;
      }
      case JointDef::Type::spherical: {
        if (j.a.kind == JointEnd::Kind::ground && j.b.kind == JointEnd::Kind::ground)
          throw std::invalid_argument("joint '" + j.name + "' (spherical): both ends are the ground; one must be a node or a body");
        add(multibody::spherical_joint(j.name, point(j, j.a, "a"), point(j, j.b, "b")), j.name);
        break;
      }
      case JointDef::Type::revolute: {
        // (4.2): e_A on end a, f_B, h_B spanning the plane normal to the axis on end b; each a body or the ground.
        for (const JointEnd* e : {&j.a, &j.b})
          if (e->kind == JointEnd::Kind::node)
            throw std::invalid_argument("joint '" + j.name +
                                        "' (revolute): an end is a shell node, which has no frame to carry the axis; "
                                        "clamp the node to a body (rigid_connection) and hinge the body");
        if (j.a.kind == JointEnd::Kind::ground && j.b.kind == JointEnd::Kind::ground)
          throw std::invalid_argument("joint '" + j.name + "' (revolute): both ends are the ground; one must be a body");
        if (!(j.axis.norm() > 0.0)) throw std::invalid_argument("joint '" + j.name + "' (revolute): axis must not be zero");
        const Eigen::Vector3d n = j.axis.normalized(), f = normal_to(n), h = n.cross(f);
        auto vec = [&](const JointEnd& e, const Eigen::Vector3d& v) {
          return e.kind == JointEnd::Kind::body ? multibody::PointMap::body_vector(ybase(e.body), R0(e.body).transpose() * v)
                                                : multibody::PointMap::ground(v);
        };
        add(multibody::revolute_joint(j.name, point(j, j.a, "a"), point(j, j.b, "b"), vec(j.a, n), vec(j.b, f), vec(j.b, h)),
            j.name);
        break;
      }
      case JointDef::Type::rigid_connection: {
        // Node by node, aligned form (4.1a): a shell director is unit through its chart.
        for (int node : j.nodes) {
          const int s = node_to_slot_[static_cast<size_t>(node)];
          const Eigen::Vector3d& Xn = X_[static_cast<size_t>(node)];
          add(multibody::rigid_connection(j.name + " (node " + std::to_string(node) + ")",
                                          multibody::PointMap::node_position(6 * s, Xn), multibody::PointMap::vector3(6 * s + 3),
                                          ybase(j.body), body_coords(j.body, Xn),
                                          R0(j.body).transpose() * normals_[static_cast<size_t>(node)],
                                          multibody::DirectorCondition::aligned),
              j.name);
        }
        break;
      }
      case JointDef::Type::prescribed_rotation: {
        if (!(j.axis.norm() > 0.0))
          throw std::invalid_argument("joint '" + j.name + "' (prescribed_rotation): axis must not be zero");
        const Eigen::Vector3d n = j.axis.normalized(), u0 = normal_to(n);
        const int b = j.body;
        const TimeFunction f = j.angle;
        const double s = j.angle_scale;
        multibody::AngleHistory angle{[f, s](double t) { return s * f(t); }, [f, s](double t) { return s * f.rate(t); }};
        add(multibody::prescribed_rotation(j.name, ybase(b), body_coords(b, j.point), R0(b).transpose() * n,
                                           R0(b).transpose() * u0, j.point, n, u0, std::move(angle)),
            j.name);
        break;
      }
    }
  }
}

multibody::Vec12 ModelMultibody::body_q(int b, const Eigen::VectorXd& u) const {
  return q0_[static_cast<size_t>(b)] + u.segment<12>(body_first_dof(b));
}

multibody::Vec12 ModelMultibody::body_initial_velocity(int b) const {
  const RigidBodyDef& d = bodies_[static_cast<size_t>(b)];
  return multibody::RigidBody::velocity(q0_[static_cast<size_t>(b)], d.velocity, d.angular_velocity);
}

std::vector<std::vector<Index>> ModelMultibody::couplings() const {
  std::vector<std::vector<Index>> groups;
  const int body_y0 = 6 * static_cast<int>(slot_nodes_.size());
  for (int b = 0; b < num_bodies(); ++b) {
    std::vector<Index> g;
    for (int k = 0; k < 12; ++k) g.push_back(body_first_dof(b) + k);
    groups.push_back(std::move(g));
  }
  for (int i = 0; i < set_.size(); ++i) {
    std::set<Index> cols;
    for (int y : set_[i].unknowns()) {
      if (y >= body_y0) {
        cols.insert(shell_dofs_ + (y - body_y0));
        continue;
      }
      const int node = slot_nodes_[static_cast<size_t>(y / 6)], r = y % 6;
      if (r < 3) cols.insert(DofMap::dof(node, r));
      else {
        cols.insert(DofMap::dof(node, 3));
        cols.insert(DofMap::dof(node, 4));
      }
    }
    groups.emplace_back(cols.begin(), cols.end());
  }
  return groups;
}

Eigen::VectorXd ModelMultibody::to_y(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts) const {
  Eigen::VectorXd y(ny_);
  for (size_t k = 0; k < slot_nodes_.size(); ++k) {
    const int node = slot_nodes_[k];
    y.segment<3>(6 * static_cast<Index>(k)) = u.segment<3>(DofMap::dof(node, 0));
    y.segment<3>(6 * static_cast<Index>(k) + 3) =
        director_used_[k] ? director(u.segment<2>(DofMap::dof(node, 3)), charts[static_cast<size_t>(node)])
                          : Eigen::Vector3d::Zero();
  }
  const Index body_y0 = 6 * static_cast<Index>(slot_nodes_.size());
  for (int b = 0; b < num_bodies(); ++b) y.segment<12>(body_y0 + 12 * b) = body_q(b, u);
  return y;
}

std::vector<Mat32> ModelMultibody::director_jacobians(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts) const {
  std::vector<Mat32> A(slot_nodes_.size(), Mat32::Zero());
  for (size_t k = 0; k < slot_nodes_.size(); ++k)
    if (director_used_[k]) {
      const int node = slot_nodes_[k];
      A[k] = director_A1(u.segment<2>(DofMap::dof(node, 3)), charts[static_cast<size_t>(node)]);
    }
  return A;
}

// G_u = G_y T (module comment), with the columns of fixed DOFs dropped.
void ModelMultibody::chain(const Eigen::SparseMatrix<double>& Gy, const std::vector<Mat32>& A, const DofMap& dofs,
                           ConstraintMatrix& G) const {
  std::vector<UTriplet> trip;
  const Index body_y0 = 6 * static_cast<Index>(slot_nodes_.size());
  auto put = [&](Index r, Index c, double v) {
    if (!dofs.is_constrained(c)) trip.emplace_back(r, c, v);
  };
  for (int j = 0; j < Gy.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(Gy, j); it; ++it) {
      const Index row = it.row();
      if (j >= body_y0) {
        put(row, shell_dofs_ + (j - body_y0), it.value());
        continue;
      }
      const size_t k = static_cast<size_t>(j / 6);
      const int node = slot_nodes_[k], r = j % 6;
      if (r < 3) put(row, DofMap::dof(node, r), it.value());
      else
        for (int c = 0; c < 2; ++c) put(row, DofMap::dof(node, 3 + c), it.value() * A[k](r - 3, c));
    }
  G.resize(set_.rows(), shell_dofs_ + 12 * static_cast<Index>(num_bodies()));
  G.setFromTriplets(trip.begin(), trip.end());
}

void ModelMultibody::values(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                            Eigen::VectorXd& g) const {
  g = set_.g(to_y(u, charts), t);
}

void ModelMultibody::jacobian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                              const DofMap& dofs, ConstraintMatrix& G) const {
  chain(set_.G(to_y(u, charts), t), director_jacobians(u, charts), dofs, G);
}

void ModelMultibody::time_derivative(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                                     Eigen::VectorXd& g_t) const {
  g_t = set_.dg_dt(to_y(u, charts), t);
}

void ModelMultibody::discrete_gradient(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                       const std::vector<DirectorChart>& charts, const DofMap& dofs,
                                       ConstraintMatrix& G_bar, Eigen::VectorXd& tau) const {
  const Eigen::SparseMatrix<double> Gy = set_.Gbar(to_y(u0, charts), t0, to_y(u1, charts), t1, tau);
  // Per director, a discrete derivative D̄ of the chart map with D̄ Δq = Δp exactly (Gonzalez's midpoint form,
  // multibody.md (2.4), applied to p(q)): then Ḡ_y T̄ Δu = Ḡ_y Δy and (2.2) carries over to the u columns.
  std::vector<Mat32> A(slot_nodes_.size(), Mat32::Zero());
  for (size_t k = 0; k < slot_nodes_.size(); ++k) {
    if (!director_used_[k]) continue;
    const int node = slot_nodes_[k];
    const DirectorChart& ch = charts[static_cast<size_t>(node)];
    const Eigen::Vector2d qa = u0.segment<2>(DofMap::dof(node, 3)), qb = u1.segment<2>(DofMap::dof(node, 3));
    const Eigen::Vector2d dq = qb - qa, qm = 0.5 * (qa + qb);
    A[k] = director_A1(qm, ch);
    const double n2 = dq.squaredNorm();
    if (std::sqrt(n2) > std::sqrt(std::numeric_limits<double>::epsilon()) * (1.0 + qm.norm())) {
      const Eigen::Vector3d defect = director(qb, ch) - director(qa, ch) - A[k] * dq;
      A[k] += defect * dq.transpose() / n2;
    }
  }
  chain(Gy, A, dofs, G_bar);
}

void ModelMultibody::add_projected(const Eigen::SparseMatrix<double>& Hy, const std::vector<Mat32>& AL,
                                   const std::vector<Mat32>& AR, double c, const DofMap& dofs,
                                   std::vector<UTriplet>& out) const {
  const Index body_y0 = 6 * static_cast<Index>(slot_nodes_.size());
  // The u columns (with coefficients) of a y index through the maps A.
  auto expand = [&](Index y, const std::vector<Mat32>& A, std::pair<Index, double>* e) -> int {
    if (y >= body_y0) {
      e[0] = {shell_dofs_ + (y - body_y0), 1.0};
      return 1;
    }
    const size_t k = static_cast<size_t>(y / 6);
    const int node = slot_nodes_[k], r = static_cast<int>(y % 6);
    if (r < 3) {
      e[0] = {DofMap::dof(node, r), 1.0};
      return 1;
    }
    e[0] = {DofMap::dof(node, 3), A[k](r - 3, 0)};
    e[1] = {DofMap::dof(node, 4), A[k](r - 3, 1)};
    return 2;
  };
  std::pair<Index, double> ei[2], ej[2];
  for (int j = 0; j < Hy.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(Hy, j); it; ++it) {
      const int ni = expand(it.row(), AL, ei), nj = expand(j, AR, ej);
      for (int a = 0; a < ni; ++a)
        for (int b = 0; b < nj; ++b) {
          if (dofs.is_constrained(ei[a].first) || dofs.is_constrained(ej[b].first)) continue;
          const double v = c * it.value() * ei[a].second * ej[b].second;
          if (v != 0.0) out.emplace_back(ei[a].first, ej[b].first, v);
        }
    }
}

void ModelMultibody::hessian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                             const Eigen::VectorXd& lambda, double c, const DofMap& dofs, std::vector<UTriplet>& out) const {
  const Eigen::VectorXd y = to_y(u, charts);
  const std::vector<Mat32> A = director_jacobians(u, charts);
  add_projected(set_.hessian_contraction(y, t, lambda), A, A, c, dofs, out);
  // Σ w_l ∂²p_l/∂q² with w = G_yᵀλ on the director slots (module comment).
  bool any = false;
  for (bool d : director_used_) any = any || d;
  if (!any) return;
  const Eigen::VectorXd w = set_.G(y, t).transpose() * lambda;
  for (size_t k = 0; k < slot_nodes_.size(); ++k) {
    if (!director_used_[k]) continue;
    const int node = slot_nodes_[k];
    const DirectorChart& ch = charts[static_cast<size_t>(node)];
    const Eigen::Matrix2d H = w[6 * static_cast<Index>(k) + 3 + ch.l] * director_d2pl(u.segment<2>(DofMap::dof(node, 3)), ch);
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        const Index r = DofMap::dof(node, 3 + a), col = DofMap::dof(node, 3 + b);
        if (!dofs.is_constrained(r) && !dofs.is_constrained(col)) out.emplace_back(r, col, c * H(a, b));
      }
  }
}

void ModelMultibody::discrete_tangent(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                      const std::vector<DirectorChart>& charts, const Eigen::VectorXd& lambda, double c,
                                      const DofMap& dofs, std::vector<UTriplet>& out) const {
  const Eigen::VectorXd y0 = to_y(u0, charts), y1 = to_y(u1, charts);
  const Eigen::VectorXd um = 0.5 * (u0 + u1);
  // Exact for positions and bodies; for director rows T(u_mid)ᵀ (∂(Ḡ_yᵀλ)/∂y1) T(u1) + ½ Σ w_l ∂²p_l(q_mid), the
  // derivative of the chart-map correction of discrete_gradient left out (a Newton tangent, not a residual).
  add_projected(set_.discrete_tangent(y0, t0, y1, t1, lambda), director_jacobians(um, charts),
                director_jacobians(u1, charts), c, dofs, out);
  bool any = false;
  for (bool d : director_used_) any = any || d;
  if (!any) return;
  Eigen::VectorXd tau;
  const Eigen::VectorXd w = set_.Gbar(y0, t0, y1, t1, tau).transpose() * lambda;
  for (size_t k = 0; k < slot_nodes_.size(); ++k) {
    if (!director_used_[k]) continue;
    const int node = slot_nodes_[k];
    const DirectorChart& ch = charts[static_cast<size_t>(node)];
    const Eigen::Matrix2d H = 0.5 * w[6 * static_cast<Index>(k) + 3 + ch.l] * director_d2pl(um.segment<2>(DofMap::dof(node, 3)), ch);
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        const Index r = DofMap::dof(node, 3 + a), col = DofMap::dof(node, 3 + b);
        if (!dofs.is_constrained(r) && !dofs.is_constrained(col)) out.emplace_back(r, col, c * H(a, b));
      }
  }
}

void ModelMultibody::check_initial(const Eigen::VectorXd& u0, const Eigen::VectorXd& v0,
                                   const std::vector<DirectorChart>& charts, const DofMap& dofs, double tol,
                                   const std::string& advice) const {
  if (set_.rows() == 0) return;
  const Eigen::VectorXd y = to_y(u0, charts);
  // Constraint name → user-facing joint (or body) name and type.
  std::map<std::string, std::pair<std::string, std::string>> owner;
  for (int i = 0; i < set_.size(); ++i) {
    const Index off = set_.offset(i);
    for (const auto& b : blocks_)
      if (off >= b.first_row && off < b.first_row + b.rows) owner[set_[i].name()] = {b.name, b.type};
  }
  // 1. Redundant or conflicting joints among themselves (multibody.md §2.5).
  // A short form of RankReport::message with the user's joint names (one line).
  auto rank_message = [&](const multibody::RankReport& r, const std::string& extra) {
    std::string names;
    std::set<std::string> seen;
    for (const std::string& cname : r.involved) {
      const auto it = owner.find(cname);
      const std::string text = it == owner.end() ? cname : it->second.second + " '" + it->second.first + "'";
      if (seen.insert(text).second) names += (names.empty() ? "" : ", ") + text;
    }
    return std::string(r.conflicting ? "conflicting" : "redundant") + " joints: " + std::to_string(r.rows - r.rank) + " of " +
           std::to_string(r.rows) + " rows dependent at t = 0" + extra + ", involving " + names + "; remove one";
  };
  const multibody::RankReport free_rep = set_.rank_check(y, 0.0);
  if (!free_rep.message.empty()) throw std::invalid_argument(rank_message(free_rep, ""));
  // 2. Joints on DOFs that boundary conditions fix: the same check with those columns dropped.
  const Index body_y0 = 6 * static_cast<Index>(slot_nodes_.size());
  std::vector<bool> fixed(static_cast<size_t>(ny_), false);
  static const char* comp[] = {"ux", "uy", "uz"};
  for (size_t k = 0; k < slot_nodes_.size(); ++k) {
    const int node = slot_nodes_[k];
    for (int r = 0; r < 3; ++r) fixed[6 * k + static_cast<size_t>(r)] = dofs.is_constrained(DofMap::dof(node, r));
    const bool dir_fixed = dofs.is_constrained(DofMap::dof(node, 3)) && dofs.is_constrained(DofMap::dof(node, 4));
    for (int r = 3; r < 6; ++r) fixed[6 * k + static_cast<size_t>(r)] = dir_fixed;
  }
  const multibody::RankReport rep = set_.rank_check(y, 0.0, 1e-10, 1e-9, fixed);
  if (!rep.message.empty()) {
    std::set<std::string> names;
    std::string what;
    for (const std::string& cname : rep.involved) {
      const auto it = owner.find(cname);
      const std::string user = it == owner.end() ? cname : it->second.first;
      if (!names.insert(user).second) continue;
      std::string dofs_text;
      int ci = 0;
      for (int i = 0; i < set_.size(); ++i)
        if (set_[i].name() == cname) ci = i;
      for (int yk : set_[ci].unknowns()) {
        if (yk >= body_y0 || !fixed[static_cast<size_t>(yk)]) continue;
        const int node = slot_nodes_[static_cast<size_t>(yk / 6)], r = yk % 6;
        const std::string d = "node " + std::to_string(node) + " " + (r < 3 ? comp[r] : "director");
        if (dofs_text.find(d) == std::string::npos) dofs_text += (dofs_text.empty() ? "" : ", ") + d;
      }
      if (dofs_text.empty()) continue;
      what += (what.empty() ? "" : "; ") + std::string("joint '") + user + "' acts on " + dofs_text;
    }
    if (!what.empty())
      throw std::invalid_argument(what + ", which boundary_conditions fix: remove the joint or free those DOFs");
    throw std::invalid_argument(rank_message(rep, " with the supports"));
  }
  // 3. The initial state satisfies the joints (positions, then velocities).
  double scale = 1.0;
  for (const auto& x : X_) scale = std::max(scale, x.cwiseAbs().maxCoeff());
  for (const auto& b : bodies_) scale = std::max(scale, b.position.cwiseAbs().maxCoeff());
  const Eigen::VectorXd g = set_.g(y, 0.0);
  for (const auto& b : blocks_) {
    const double e = g.segment(b.first_row, b.rows).cwiseAbs().maxCoeff();
    if (e > tol * scale)
      throw std::invalid_argument(b.type + " '" + b.name + "' is violated by " + num(e) +
                                  (advice.empty() ? " at t = 0: put its ends together (`at`, body position, axes)"
                                                  : ": " + advice));
  }
  ConstraintMatrix G;
  jacobian(0.0, u0, charts, dofs, G);
  Eigen::VectorXd gt;
  time_derivative(0.0, u0, charts, gt);
  const Eigen::VectorXd gdot = G * v0 + gt;
  double vscale = 1.0;
  for (Index i = 0; i < v0.size(); ++i) vscale = std::max(vscale, std::abs(v0[i]));
  for (const auto& b : blocks_) {
    const double e = gdot.segment(b.first_row, b.rows).cwiseAbs().maxCoeff();
    if (e > tol * scale * vscale)
      throw std::invalid_argument(b.type + " '" + b.name + "': initial velocities violate it by " + num(e) +
                                  (advice.empty() ? " (|G v + dg/dt|): make them consistent with the joint" : ": " + advice));
  }
}

}  // namespace shelldyn
