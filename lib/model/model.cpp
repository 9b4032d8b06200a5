#include "lib/model/model.hpp"

#include "elements/exact_energy.hpp"
#include "lib/analysis/profile.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <mutex>
#include <limits>
#include <optional>

#include <omp.h>
#include <stdexcept>
#include <string>

namespace shelldyn {
namespace {

// Runs body(e) for every element, colour by colour; elements of one colour share no node, so their
// scatter operations never collide. One parallel region for all colours (a barrier between colours);
// small meshes run serially, where thread start-up and barriers cost more than the element work.
// The first exception thrown by any element is rethrown afterwards (exceptions must not leave an
// OpenMP region).
constexpr int kMinElementsForThreads = 48;

template <class Body>
void for_each_element(const Assembler& assembler, const Body& body) {
  std::exception_ptr error;
  std::mutex error_mutex;
  const bool parallel = assembler.num_elements() >= kMinElementsForThreads && omp_get_max_threads() > 1;
#pragma omp parallel if (parallel)
  {
    for (const auto& colour : assembler.colours()) {
      const int count = static_cast<int>(colour.size());
#pragma omp for schedule(dynamic, 2)
      for (int k = 0; k < count; ++k) {
        try {
          body(colour[static_cast<size_t>(k)]);
        } catch (...) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
        }
      }
    }
  }
  if (error) std::rethrow_exception(error);
}

double sum(const std::vector<double>& values) {
  double s = 0.0;
  for (double x : values) s += x;  // fixed order: independent of the thread count
  return s;
}

}  // namespace

Model::Model(Mesh mesh, std::vector<Vec3> normals, const ShellMaterial& material, DofMap dofs,
             std::vector<NodalLoad> loads, CR9Shell::Options options)
    : mesh_(std::move(mesh)),
      normals_(std::move(normals)),
      material_(material),
      dofs_(std::move(dofs)),
      loads_(std::move(loads)),
      assembler_(mesh_.elements, mesh_.num_nodes()) {
  if (normals_.size() != mesh_.X.size())
    throw std::invalid_argument("Model: " + std::to_string(normals_.size()) + " normals for " +
                                std::to_string(mesh_.X.size()) + " nodes");
  if (dofs_.num_nodes() != mesh_.num_nodes())
    throw std::invalid_argument("Model: DOF map and mesh disagree on the number of nodes");
  for (const auto& load : loads_)
    if (load.node < 0 || load.node >= mesh_.num_nodes())
      throw std::invalid_argument("Model: load on node " + std::to_string(load.node) + " outside the mesh");
  elements_.reserve(mesh_.elements.size());
  for (size_t e = 0; e < mesh_.elements.size(); ++e) {
    std::array<Vec3, 9> X0, p0;
    for (int a = 0; a < 9; ++a) {
      X0[static_cast<size_t>(a)] = mesh_.X[static_cast<size_t>(mesh_.elements[e][static_cast<size_t>(a)])];
      p0[static_cast<size_t>(a)] = normals_[static_cast<size_t>(mesh_.elements[e][static_cast<size_t>(a)])];
    }
    try {
      elements_.emplace_back(X0, p0, material, options);
    } catch (const std::exception& ex) {
      throw std::invalid_argument("element " + std::to_string(e) + ": " + ex.what());
    }
  }
  // The elements' scalar masses side by side for scalar_mass_times: read from the (large) element objects they
  // were cache misses, most of that product's cost on the hemisphere.
  scalar_masses_.reserve(elements_.size());
  for (const CR9Shell& el : elements_) scalar_masses_.push_back(el.scalar_mass());
  dofs_.resolve(initial_state().charts);  // director-component constraints need the initial charts
}

SparseMatrix Model::make_matrix() const {
  return SparseMatrix{pattern(), std::vector<double>(static_cast<size_t>(pattern()->nnz()), 0.0)};
}

State Model::initial_state() const {
  State s;
  const Index n = num_dofs();
  s.u = Eigen::VectorXd::Zero(n);
  s.v = Eigen::VectorXd::Zero(n);
  s.a = Eigen::VectorXd::Zero(n);
  s.charts.resize(normals_.size());
  for (size_t i = 0; i < normals_.size(); ++i) {
    s.charts[i] = select_chart(normals_[i]);
    s.u.segment<2>(DofMap::dof(static_cast<int>(i), 3)) = chart_coordinates(normals_[i], s.charts[i]);
  }
  if (mb_)  // bodies start at u_b = 0 (q_b = q_b(0)) with φ̇ = v, ḋ_i = ω × d_i
    for (int b = 0; b < mb_->num_bodies(); ++b) s.v.segment<12>(mb_->body_first_dof(b)) = mb_->body_initial_velocity(b);
  return s;
}

void Model::gather(int e, const Eigen::VectorXd& global, CR9Shell::Vec45& ue) const {
  assembler_.gather(e, global.data(), ue);
}

CR9Shell::Charts Model::element_charts(int e, const std::vector<DirectorChart>& charts) const {
  CR9Shell::Charts ch;
  const auto& nodes = mesh_.elements[static_cast<size_t>(e)];
  for (size_t a = 0; a < 9; ++a) ch[a] = charts[static_cast<size_t>(nodes[a])];
  return ch;
}

double Model::internal(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, double* F,
                       SparseMatrix* K) const {
  profile::Scope prof(K ? profile::Section::tangent : profile::Section::internal_force);
  if (F) std::fill(F, F + num_dofs(), 0.0);
  if (K) K->set_zero();
  std::vector<double> energy(elements_.size(), 0.0);
  for_each_element(assembler_, [&](int e) {
    CR9Shell::Vec45 ue, fe;
    CR9Shell::Mat45 ke;
    gather(e, u, ue);
    energy[static_cast<size_t>(e)] =
        elements_[static_cast<size_t>(e)].internal(ue, element_charts(e, charts), F ? &fe : nullptr, K ? &ke : nullptr);
    if (F) assembler_.add_vector(e, fe, F);
    if (K) assembler_.add_matrix(e, ke, K->values.data());
  });
  return sum(energy);
}

// The step cache for (u_n, charts), filled if it holds another start (call with cache.mutex held).
const std::vector<CR9Shell::StepState>& Model::step_states(const Eigen::VectorXd& u_n,
                                                            const std::vector<DirectorChart>& charts) const {
  StepCache& cache = *step_cache_;
  const bool same_start = cache.valid && cache.u_n.size() == u_n.size() && cache.charts.size() == charts.size() &&
                          std::memcmp(cache.u_n.data(), u_n.data(), sizeof(double) * static_cast<size_t>(u_n.size())) == 0 &&
                          std::equal(charts.begin(), charts.end(), cache.charts.begin(), [](const DirectorChart& a, const DirectorChart& b) {
                            return a.n == b.n && a.m == b.m && a.l == b.l && a.s == b.s;
                          });
  if (!same_start) {
    profile::Scope prof(profile::Section::step_state);
    cache.valid = false;
    cache.states.resize(elements_.size());
    for_each_element(assembler_, [&](int e) {
      CR9Shell::Vec45 un;
      gather(e, u_n, un);
      elements_[static_cast<size_t>(e)].step_state(un, element_charts(e, charts), &cache.states[static_cast<size_t>(e)]);
    });
    cache.u_n = u_n;
    cache.charts = charts;
    cache.valid = true;
  }
  return cache.states;
}

double Model::algorithmic_internal(const Eigen::VectorXd& u_n, const Eigen::VectorXd& u_np1,
                                   const std::vector<DirectorChart>& charts, double alpha_f, double xi,
                                   double* F, SparseMatrix* K) const {
  StepCache& cache = *step_cache_;
  std::lock_guard<std::mutex> lock(cache.mutex);
  const std::vector<CR9Shell::StepState>& states = step_states(u_n, charts);
  profile::Scope prof(K ? profile::Section::tangent : profile::Section::internal_force);
  if (F) std::fill(F, F + num_dofs(), 0.0);
  if (K) K->set_zero();
  std::vector<double> energy(elements_.size(), 0.0);
  for_each_element(assembler_, [&](int e) {
    CR9Shell::Vec45 un, unp1, fe;
    CR9Shell::Mat45 ke;
    gather(e, u_n, un);
    gather(e, u_np1, unp1);
    energy[static_cast<size_t>(e)] = elements_[static_cast<size_t>(e)].algorithmic_internal(
        states[static_cast<size_t>(e)], un, unp1, element_charts(e, charts), alpha_f, xi, F ? &fe : nullptr,
        K ? &ke : nullptr);
    if (F) assembler_.add_vector(e, fe, F);
    if (K) assembler_.add_matrix(e, ke, K->values.data());
  });
  return sum(energy);
}

void Model::mass(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, SparseMatrix& M) const {
  profile::Scope prof(profile::Section::mass);
  M.set_zero();
  for_each_element(assembler_, [&](int e) {
    CR9Shell::Vec45 ue;
    CR9Shell::Mat45 me;
    gather(e, u, ue);
    elements_[static_cast<size_t>(e)].mass(ue, element_charts(e, charts), &me);
    assembler_.add_matrix(e, me, M.values.data());
  });
  if (mb_)  // constant body blocks diag(m I, E1 I, E2 I, E3 I) (multibody.md §3)
    for (int b = 0; b < mb_->num_bodies(); ++b) {
      const multibody::Vec12 m = mb_->body(b).mass_diagonal();
      for (int k = 0; k < 12; ++k) {
        const Index d = mb_->body_first_dof(b) + k;
        M.values[static_cast<size_t>(assembler_.find(d, d))] += m[k];
      }
    }
}

void Model::inertial(const Eigen::VectorXd& u, const Eigen::VectorXd& v, const std::vector<DirectorChart>& charts,
                     double* Fm) const {
  profile::Scope prof(profile::Section::inertia);
  std::fill(Fm, Fm + num_dofs(), 0.0);
  for_each_element(assembler_, [&](int e) {
    CR9Shell::Vec45 ue, ve, fe;
    gather(e, u, ue);
    gather(e, v, ve);
    elements_[static_cast<size_t>(e)].inertial(ue, ve, element_charts(e, charts), &fe);
    assembler_.add_vector(e, fe, Fm);
  });
  if (has_damping()) add_damping(v, Fm);
}

void Model::inertia_force(const Eigen::VectorXd& u, const Eigen::VectorXd& v, const Eigen::VectorXd& a,
                          const std::vector<DirectorChart>& charts, double* out) const {
  profile::Scope prof(profile::Section::inertia);
  std::fill(out, out + num_dofs(), 0.0);
  for_each_element(assembler_, [&](int e) {
    CR9Shell::Vec45 ue, ve, ae, fe;
    gather(e, u, ue);
    gather(e, v, ve);
    gather(e, a, ae);
    elements_[static_cast<size_t>(e)].inertia_force(ue, ve, ae, element_charts(e, charts), &fe);
    assembler_.add_vector(e, fe, out);
  });
  if (mb_)  // bodies: M_b a_b (constant mass, no F_m)
    for (int b = 0; b < mb_->num_bodies(); ++b) {
      const Index k = mb_->body_first_dof(b);
      const multibody::Vec12 m = mb_->body(b).mass_diagonal();
      for (int j = 0; j < 12; ++j) out[k + j] += m[j] * a[k + j];
    }
  if (has_damping()) add_damping(v, out);
}

void Model::external(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                     double* F) const {
  profile::Scope prof(profile::Section::external);
  std::fill(F, F + num_dofs(), 0.0);
  for (const auto& load : loads_) {
    const double f = load.function(t);
    if (f == 0.0) continue;
    if (load.kind == NodalLoad::Kind::Force) {
      for (int c = 0; c < 3; ++c) F[DofMap::dof(load.node, c)] += f * load.vector[c];
    } else {
      // Dead moment m: δW = m·δφ with δp = δφ × p, so f_q = A1ᵀ (m × p) (docs/theory.md §2.3 item 3).
      const Eigen::Vector2d q = u.segment<2>(DofMap::dof(load.node, 3));
      const DirectorChart& ch = charts[static_cast<size_t>(load.node)];
      const Eigen::Vector2d fq = director_A1(q, ch).transpose() * (f * load.vector).cross(shelldyn::director(q, ch));
      F[DofMap::dof(load.node, 3)] += fq[0];
      F[DofMap::dof(load.node, 4)] += fq[1];
    }
  }
  if (!follower_.empty()) add_follower_pressures(follower_, mesh_, assembler_, t, u, F, nullptr, false);
  if (mb_)  // uniform gravity on the bodies: m g on φ (its potential −m g·φ is linear, multibody.md §3)
    for (int b = 0; b < mb_->num_bodies(); ++b)
      for (int c = 0; c < 3; ++c) F[mb_->body_first_dof(b) + c] += mb_->body(b).mass() * mb_->gravity()[c];
}

void Model::add_load_stiffness(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                               SparseMatrix& K) const {
  profile::Scope prof(profile::Section::external);
  for (const auto& load : loads_) {
    const double f = load.function(t);
    if (f == 0.0 || load.kind != NodalLoad::Kind::Moment) continue;
    const Eigen::Vector2d q = u.segment<2>(DofMap::dof(load.node, 3));
    const DirectorChart& ch = charts[static_cast<size_t>(load.node)];
    const Vec3 w = (f * load.vector).cross(shelldyn::director(q, ch));
    const Eigen::Matrix2d dF = w[ch.l] * director_d2pl(q, ch);  // symmetric part of ∂(A1ᵀ w)/∂q
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        K.values[static_cast<size_t>(assembler_.find(DofMap::dof(load.node, 3 + a), DofMap::dof(load.node, 3 + b)))] -=
            dF(a, b);
  }
  if (!follower_.empty()) add_follower_pressures(follower_, mesh_, assembler_, t, u, nullptr, &K, !full_load_tangent_);
}

Invariants Model::invariants(const State& s) const {
  Invariants inv;
  std::vector<double> kinetic(elements_.size(), 0.0);
  std::vector<Vec3> L(elements_.size(), Vec3::Zero()), J(elements_.size(), Vec3::Zero());
  const bool embedded = s.pdot.size() == 3 * static_cast<Index>(mesh_.num_nodes());
  if (s.pdot.size() != 0 && !embedded)
    throw std::invalid_argument("Model::invariants: state.pdot has " + std::to_string(s.pdot.size()) +
                                " entries, expected 3 per node (" + std::to_string(3 * mesh_.num_nodes()) + ")");
  for_each_element(assembler_, [&](int e) {
    CR9Shell::Vec45 ue, ve;
    gather(e, s.u, ue);
    gather(e, s.v, ve);
    const auto ch = element_charts(e, s.charts);
    const auto& el = elements_[static_cast<size_t>(e)];
    if (embedded) {  // em-exact: K, L, J from the embedded director velocities (state.hpp, theory §2)
      NodeVectors x, p, v, w;
      const auto& nodes = mesh_.elements[static_cast<size_t>(e)];
      for (size_t a = 0; a < 9; ++a) {
        const int i = nodes[a];
        x[a] = mesh_.X[static_cast<size_t>(i)] + ue.segment<3>(5 * static_cast<Index>(a));
        p[a] = shelldyn::director(ue.segment<2>(5 * static_cast<Index>(a) + 3), ch[a]);
        v[a] = ve.segment<3>(5 * static_cast<Index>(a));
        w[a] = s.pdot.segment<3>(3 * static_cast<Index>(i));
      }
      const double rh = material_.rho * material_.thickness, rh3 = rh * material_.thickness * material_.thickness / 12.0;
      kinetic[static_cast<size_t>(e)] = embedded_kinetic(el.scalar_mass(), rh, rh3, v, w);
      embedded_momenta(el.scalar_mass(), rh, rh3, x, p, v, w, &L[static_cast<size_t>(e)], &J[static_cast<size_t>(e)]);
      return;
    }
    kinetic[static_cast<size_t>(e)] = el.kinetic(ue, ve, ch);
    el.momenta(ue, ve, ch, &L[static_cast<size_t>(e)], &J[static_cast<size_t>(e)]);
  });
  inv.kinetic = sum(kinetic);
  for (size_t e = 0; e < elements_.size(); ++e) {
    inv.L += L[e];
    inv.J += J[e];
  }
  if (mb_)  // bodies (multibody.md (3.4)): ½m|φ̇|² + ½ΣE_i|ḋ_i|², L = mφ̇, J = φ × mφ̇ + Σ E_i d_i × ḋ_i
    for (int b = 0; b < mb_->num_bodies(); ++b) {
      const multibody::Vec12 q = mb_->body_q(b, s.u);
      const multibody::Vec12 qd = s.v.segment<12>(mb_->body_first_dof(b));
      inv.kinetic += mb_->body(b).kinetic_energy(qd);
      inv.L += mb_->body(b).linear_momentum(qd);
      inv.J += mb_->body(b).angular_momentum(q, qd);
    }
  inv.strain = internal(s.u, s.charts, nullptr, nullptr);
  return inv;
}

double Model::loads_end() const {
  double end = 0.0;
  for (const auto& load : loads_) end = std::max(end, load.function.end_of_support());
  for (const auto& load : follower_) end = std::max(end, load.function.end_of_support());
  for (const auto& m : prescribed_) end = std::max(end, m.function.end_of_variation());
  if (mb_) {
    if (mb_->num_bodies() > 0 && mb_->gravity().norm() > 0.0) end = std::numeric_limits<double>::infinity();
    for (const auto& j : mb_->joints())
      if (j.type == JointDef::Type::prescribed_rotation) end = std::max(end, j.angle.end_of_variation());
  }
  return end;
}

void Model::set_prescribed_motion(std::vector<PrescribedMotion> motion) {
  std::sort(motion.begin(), motion.end(), [](const PrescribedMotion& a, const PrescribedMotion& b) { return a.dof < b.dof; });
  for (size_t k = 0; k < motion.size(); ++k) {
    const Index dof = motion[k].dof;
    if (dof < 0 || dof >= num_dofs() || dof % kDofsPerNode >= 3 || !dofs_.is_constrained(dof))
      throw std::invalid_argument("prescribed motion on DOF " + std::to_string(dof) +
                                  ", which is not a constrained translation of the model");
    if (k > 0 && motion[k - 1].dof == dof)
      throw std::invalid_argument("prescribed motion given twice for DOF " + std::to_string(dof));
  }
  prescribed_ = std::move(motion);
  prescribed_dofs_.clear();
  for (const auto& m : prescribed_) prescribed_dofs_.push_back(m.dof);
}

void Model::prescribed_displacement(double t, double* u) const {
  for (const auto& m : prescribed_) u[m.dof] = m.value * m.function(t);
}

void Model::prescribed_velocity(double t, double* v) const {
  for (const auto& m : prescribed_) v[m.dof] = m.value * m.function.rate(t);
}

void Model::set_rayleigh_damping(double mass_coefficient, double stiffness_coefficient) {
  if (!(mass_coefficient >= 0.0) || !(stiffness_coefficient >= 0.0))
    throw std::invalid_argument("Rayleigh damping coefficients must be >= 0");
  damping_ = SparseMatrix{};
  if (mass_coefficient == 0.0 && stiffness_coefficient == 0.0) return;
  // C = a_M M_0 + a_K K_0 at the reference state (docs/theory.md §8.5).
  const State s0 = initial_state();
  SparseMatrix M = make_matrix(), K = make_matrix();
  mass(s0.u, s0.charts, M);
  internal(s0.u, s0.charts, nullptr, &K);
  SparseMatrix C = make_matrix();
  for (size_t k = 0; k < C.values.size(); ++k)
    C.values[k] = mass_coefficient * M.values[k] + stiffness_coefficient * K.values[k];
  damping_ = std::move(C);
}

void Model::damping_force(const Eigen::VectorXd& v, double* out) const {
  std::fill(out, out + num_dofs(), 0.0);
  if (has_damping()) add_damping(v, out);
}

void Model::add_damping(const Eigen::VectorXd& v, double* out) const {
  Eigen::VectorXd cv(num_dofs());
  multiply(damping_.view(), v.data(), cv.data());
  for (Index i = 0; i < num_dofs(); ++i) out[i] += cv[i];
}

void Model::add_damping_matrix(double c, SparseMatrix& J) const {
  if (!has_damping()) return;
  for (size_t k = 0; k < J.values.size(); ++k) J.values[k] += c * damping_.values[k];
}

double Model::chart_margin(const State& s) const {
  double margin = 1.0;
  for (int i = 0; i < mesh_.num_nodes(); ++i) {
    const Vec3 p = director(s, i);
    const DirectorChart& ch = s.charts[static_cast<size_t>(i)];
    margin = std::min(margin, std::abs(p[ch.l]) - std::max(std::abs(p[ch.n]), std::abs(p[ch.m])));
  }
  return margin;
}

Vec3 Model::director(const State& s, int node) const {
  return shelldyn::director(s.u.segment<2>(DofMap::dof(node, 3)), s.charts[static_cast<size_t>(node)]);
}

void Model::adopt_charts(const std::vector<DirectorChart>& charts) {
  if (static_cast<int>(charts.size()) != mesh_.num_nodes())
    throw std::invalid_argument("adopt_charts: " + std::to_string(charts.size()) + " charts for " +
                                std::to_string(mesh_.num_nodes()) + " nodes");
  for (const auto& c : charts) check_chart(c);
  dofs_.resolve(charts);
}

int Model::rechart(State& s, double hysteresis) {
  int switched = 0;
  for (int i = 0; i < mesh_.num_nodes(); ++i) {
    const Index k = DofMap::dof(i, 3);
    Eigen::Vector2d q = s.u.segment<2>(k), qd = s.v.segment<2>(k), qdd = s.a.segment<2>(k);
    if (shelldyn::rechart(q, qd, qdd, s.charts[static_cast<size_t>(i)], hysteresis)) {
      s.u.segment<2>(k) = q;
      s.v.segment<2>(k) = qd;
      s.a.segment<2>(k) = qdd;
      ++switched;
    }
  }
  if (switched) dofs_.resolve(s.charts);
  return switched;
}

bool Model::kept_matrix_basis(const Eigen::VectorXd& u_ref, const std::vector<DirectorChart>& charts_ref,
                              const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, bool rotate,
                              std::vector<double>& node_inverse) const {
  const int nn = mesh_.num_nodes();
  // Body unknowns (after the shell's) are ℝ³ vectors in space: T = I for them (no block).
  if (u_ref.size() != num_dofs() || u.size() != num_dofs() || static_cast<int>(charts_ref.size()) != nn ||
      static_cast<int>(charts.size()) != nn)
    throw std::invalid_argument("Model::kept_matrix_basis: u and charts do not match the model");
  // A rotation would mix constrained and free unknowns: only for unconstrained bodies (docs/theory.md §6.9).
  if (rotate && (!dofs_.constrained_dofs().empty() || has_prescribed_motion() || mb_)) rotate = false;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (rotate) {  // least-squares rotation about the centroids (Kabsch): x − c ≈ R (x_ref − c_ref)
    Vec3 c_ref = Vec3::Zero(), c = Vec3::Zero();
    for (int i = 0; i < nn; ++i) {
      c_ref += mesh_.X[static_cast<size_t>(i)] + u_ref.segment<3>(DofMap::dof(i, 0));
      c += mesh_.X[static_cast<size_t>(i)] + u.segment<3>(DofMap::dof(i, 0));
    }
    c_ref /= nn;
    c /= nn;
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    for (int i = 0; i < nn; ++i) {
      const Vec3 a = mesh_.X[static_cast<size_t>(i)] + u_ref.segment<3>(DofMap::dof(i, 0)) - c_ref;
      const Vec3 b = mesh_.X[static_cast<size_t>(i)] + u.segment<3>(DofMap::dof(i, 0)) - c;
      H.noalias() += a * b.transpose();
    }
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Vec3 sv = svd.singularValues();
    if (!(sv[1] > 1e-8 * sv[0]))  // nodes (nearly) on a line: the rotation about it is not determined
      throw std::domain_error("the nodes are too close to a line to fix the body's rotation");
    Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
    D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
    R = svd.matrixV() * D * svd.matrixU().transpose();
    // A body that does not turn (the pinched hemisphere's self-equilibrated loads) gets an R that differs from I
    // by round-off only: keep I, so that its solves stay exactly those of the kept matrix.
    if ((R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-12) R.setIdentity();
  }
  const bool rotated = !R.isIdentity(0.0);
  auto switched = [&](int i) {
    const DirectorChart& a = charts_ref[static_cast<size_t>(i)];
    const DirectorChart& b = charts[static_cast<size_t>(i)];
    return a.n != b.n || a.m != b.m || a.l != b.l || a.s != b.s;
  };
  if (!rotated) {  // T = I unless a chart switched (a body that does not turn: every iteration ends here)
    bool any = false;
    for (int i = 0; i < nn && !any; ++i) any = switched(i);
    if (!any) return false;
  }
  node_inverse.assign(static_cast<size_t>(25 * nn), 0.0);
  for (int i = 0; i < nn; ++i) {
    double* B = node_inverse.data() + 25 * i;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) B[5 * a + b] = R(a, b);  // T_d⁻¹ = R
    const DirectorChart& cr = charts_ref[static_cast<size_t>(i)];
    const DirectorChart& ch = charts[static_cast<size_t>(i)];
    const bool node_switched = switched(i);
    Eigen::Matrix2d Tq_inv = Eigen::Matrix2d::Identity();
    if (rotated || node_switched) {
      const Index k = DofMap::dof(i, 3);
      if (node_switched && (dofs_.is_constrained(k) || dofs_.is_constrained(k + 1)))
        throw std::domain_error("node " + std::to_string(i) + " switched the chart of constrained director unknowns");
      // T_q = S_ref Rᵀ A1(q): rows n_ref, m_ref of Rᵀ A1.
      const Eigen::Matrix<double, 3, 2> RA = R.transpose() * shelldyn::director_A1(u.segment<2>(k), ch);
      Eigen::Matrix2d Tq;
      Tq.row(0) = RA.row(cr.n);
      Tq.row(1) = RA.row(cr.m);
      const double det = Tq.determinant();
      if (!(std::abs(det) > 1e-3))
        throw std::domain_error("node " + std::to_string(i) + ": the director turned too far from the kept chart");
      Tq_inv = Tq.inverse();
    }
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) B[5 * (3 + a) + 3 + b] = Tq_inv(a, b);
  }
  return true;
}

// ---- Rigid bodies and joints (lib/model/model_multibody.hpp) ----------------------------------------------

void Model::set_multibody(std::vector<RigidBodyDef> bodies, std::vector<JointDef> joints, const Vec3& gravity) {
  if (bodies.empty() && joints.empty()) return;  // nothing changes (the pattern stays the element pattern)
  if (has_damping()) throw std::logic_error("Model::set_multibody: call before set_rayleigh_damping");
  auto mb = std::make_unique<ModelMultibody>(mesh_.X, normals_, std::move(bodies), std::move(joints), gravity);
  dofs_.set_extra_dofs(12 * static_cast<Index>(mb->num_bodies()));
  assembler_ = Assembler(mesh_.elements, mesh_.num_nodes(), dofs_.num_extra(), mb->couplings());
  mb_ = std::move(mb);
  const State s0 = initial_state();
  dofs_.resolve(s0.charts);
  step_cache_->valid = false;
}

ExactEnergySystem::RigidBlock Model::rigid_block(int b) const {
  if (!mb_ || b < 0 || b >= mb_->num_bodies()) throw std::out_of_range("Model::rigid_block: no body " + std::to_string(b));
  return {mb_->body_first_dof(b), mb_->body(b).mass(), mb_->body(b).euler_tensor()};
}

void Model::constraint_values(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                              Eigen::VectorXd& g) const {
  if (!mb_) return SemiDiscreteSystem::constraint_values(t, u, charts, g);
  mb_->values(t, u, charts, g);
}

void Model::constraint_jacobian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                                ConstraintMatrix& G) const {
  if (!mb_) return SemiDiscreteSystem::constraint_jacobian(t, u, charts, G);
  mb_->jacobian(t, u, charts, dofs_, G);
}

void Model::constraint_time_derivative(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                                       Eigen::VectorXd& g_t) const {
  if (!mb_) return SemiDiscreteSystem::constraint_time_derivative(t, u, charts, g_t);
  mb_->time_derivative(t, u, charts, g_t);
}

void Model::constraint_discrete_gradient(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                         const std::vector<DirectorChart>& charts, ConstraintMatrix& G_bar,
                                         Eigen::VectorXd& tau) const {
  if (!mb_) return SemiDiscreteSystem::constraint_discrete_gradient(t0, u0, t1, u1, charts, G_bar, tau);
  mb_->discrete_gradient(t0, u0, t1, u1, charts, dofs_, G_bar, tau);
}

namespace {
void add_triplets(const Assembler& a, const std::vector<Eigen::Triplet<double, Index>>& trip, SparseMatrix& K) {
  for (const auto& t : trip) {
    const Index pos = a.find(t.row(), t.col());
    if (pos < 0)
      throw std::logic_error("Model: constraint tangent entry (" + std::to_string(t.row()) + ", " + std::to_string(t.col()) +
                             ") outside the pattern");
    K.values[static_cast<size_t>(pos)] += t.value();
  }
}
}  // namespace

void Model::add_constraint_hessian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                                   const Eigen::VectorXd& lambda, double c, SparseMatrix& K) const {
  if (!mb_ || mb_->num_constraints() == 0) return;
  std::vector<Eigen::Triplet<double, Index>> trip;
  mb_->hessian(t, u, charts, lambda, c, dofs_, trip);
  add_triplets(assembler_, trip, K);
}

void Model::add_constraint_discrete_tangent(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                            const std::vector<DirectorChart>& charts, const Eigen::VectorXd& lambda,
                                            double c, SparseMatrix& K) const {
  if (!mb_ || mb_->num_constraints() == 0) return;
  std::vector<Eigen::Triplet<double, Index>> trip;
  mb_->discrete_tangent(t0, u0, t1, u1, charts, lambda, c, dofs_, trip);
  add_triplets(assembler_, trip, K);
}

// ---- em-exact (docs/theory/exact-energy-momentum.md) ------------------------------------------------------

void Model::scalar_mass_times(const Eigen::VectorXd& x, const Eigen::VectorXd& y, Eigen::VectorXd& mx,
                              Eigen::VectorXd& my) const {
  const Index n3 = 3 * static_cast<Index>(mesh_.num_nodes());
  if (x.size() != n3 || y.size() != n3)
    throw std::invalid_argument("Model::scalar_mass_times: x and y need 3 entries per node");
  mx.setZero(n3);
  my.setZero(n3);
  for_each_element(assembler_, [&](int e) {  // colours: no two elements of a colour share a node
    const auto& nodes = mesh_.elements[static_cast<size_t>(e)];
    // Y = m X, X the element's nodal 3-vectors of x and y (one node per row, 6 columns), written out as one
    // 6-wide multiply-add per node pair, with m from the contiguous copy of the scalar masses (constructor).
    double X[9][6];
    for (size_t a = 0; a < 9; ++a) {
      const Index k = 3 * static_cast<Index>(nodes[a]);
      for (int c = 0; c < 3; ++c) {
        X[a][c] = x[k + c];
        X[a][3 + c] = y[k + c];
      }
    }
    const Eigen::Matrix<double, 9, 9>& m = scalar_masses_[static_cast<size_t>(e)];
    for (int a = 0; a < 9; ++a) {
      double Y[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
      for (int b = 0; b < 9; ++b) {
        const double mab = m(a, b);
        for (int c = 0; c < 6; ++c) Y[c] += mab * X[b][c];
      }
      const Index k = 3 * static_cast<Index>(nodes[static_cast<size_t>(a)]);
      for (int c = 0; c < 3; ++c) {
        mx[k + c] += Y[c];
        my[k + c] += Y[3 + c];
      }
    }
  });
}

void Model::step_energies(const Eigen::VectorXd& u_n, const std::vector<DirectorChart>& charts,
                          std::vector<double>& U) const {
  StepCache& cache = *step_cache_;
  std::lock_guard<std::mutex> lock(cache.mutex);
  const std::vector<CR9Shell::StepState>& states = step_states(u_n, charts);
  U.resize(states.size());
  for_each_element(assembler_, [&](int e) {
    U[static_cast<size_t>(e)] = elements_[static_cast<size_t>(e)].step_energy(states[static_cast<size_t>(e)]);
  });
}

CR9Shell::Mat45 Model::reference_local_stiffness(int e) const {
  const auto& nodes = mesh_.elements[static_cast<size_t>(e)];
  CR9Shell::Charts ch;
  CR9Shell::Vec45 u = CR9Shell::Vec45::Zero();
  for (size_t a = 0; a < 9; ++a) {
    const Vec3& p0 = normals_[static_cast<size_t>(nodes[a])];
    ch[a] = select_chart(p0);
    u.segment<2>(5 * static_cast<Index>(a) + 3) = chart_coordinates(p0, ch[a]);
  }
  CR9Shell::Mat45 kL;
  elements_[static_cast<size_t>(e)].local(u, ch, nullptr, nullptr, &kL);
  return kL;
}

double Model::exact_internal(const Eigen::VectorXd& u_n, const Eigen::VectorXd& u_np1,
                             const std::vector<DirectorChart>& charts, const std::vector<double>& U_n, bool correct,
                             double xi, const std::vector<CR9Shell::Mat45>* k0, double* F, SparseMatrix* K,
                             std::vector<double>* U_np1, ExactForceInfo* info, const Eigen::VectorXd* p_mid,
                             double director_weight) const {
  if (!(director_weight >= 0.0) || !std::isfinite(director_weight))
    throw std::invalid_argument("Model::exact_internal: director_weight must be finite and >= 0 (0: w = h l_e)");
  if (U_n.size() != elements_.size()) throw std::invalid_argument("Model::exact_internal: U_n needs one entry per element");
  if (p_mid && p_mid->size() != 3 * static_cast<Index>(mesh_.num_nodes()))
    throw std::invalid_argument("Model::exact_internal: p_mid needs 3 entries per node");
  if (xi > 0.0 && (!k0 || k0->size() != elements_.size()))
    throw std::invalid_argument("Model::exact_internal: xi > 0 needs the reference local stiffness of every element");
  if (F) std::fill(F, F + num_dofs(), 0.0);
  if (K) K->set_zero();
  std::vector<double> energy(elements_.size(), 0.0), beta_z(elements_.size(), 0.0), diss(elements_.size(), 0.0);
  std::vector<char> guard(elements_.size(), 0);
  // u_n is fixed during a step: its element state comes from the step cache (as algorithmic_internal()).
  StepCache& cache = *step_cache_;
  std::lock_guard<std::mutex> lock(cache.mutex);
  const std::vector<CR9Shell::StepState>& states = step_states(u_n, charts);
  profile::Scope prof(K ? profile::Section::tangent : profile::Section::internal_force);
  for_each_element(assembler_, [&](int e) {
    const auto& el = elements_[static_cast<size_t>(e)];
    const auto ch = element_charts(e, charts);
    CR9Shell::Vec45 un, u1, fe;
    CR9Shell::Mat45 ke;
    gather(e, u_n, un);
    gather(e, u_np1, u1);
    // Paper force F = T(u_mid)ᵀ f*_L (§6.3 at α_f = ½, ξ = 0) and its symmetric tangent K_mid.
    const double U1 = el.algorithmic_internal(states[static_cast<size_t>(e)], un, u1, ch, 0.5, 0.0, &fe, K ? &ke : nullptr);
    energy[static_cast<size_t>(e)] = U1;
    const CR9Shell::Vec45 du = u1 - un;
    std::optional<MidpointRigidRows> R;
    if (correct || xi > 0.0) {
      NodeVectors xm, pm;
      const auto& nodes = mesh_.elements[static_cast<size_t>(e)];
      for (size_t a = 0; a < 9; ++a) {
        const Index k = 5 * static_cast<Index>(a);
        xm[a] = mesh_.X[static_cast<size_t>(nodes[a])] + 0.5 * (un.segment<3>(k) + u1.segment<3>(k));
        pm[a] = p_mid ? Vec3(p_mid->segment<3>(3 * static_cast<Index>(nodes[a])))
                      : Vec3(0.5 * (shelldyn::director(un.segment<2>(k + 3), ch[a]) +
                                    shelldyn::director(u1.segment<2>(k + 3), ch[a])));
      }
      R.emplace(xm, pm, ch);
    }
    if (correct) {  // theory §3: R F* = 0, Δuᵀ F* = ΔU
      const double fmax = fe.cwiseAbs().maxCoeff();
      // The correction's direction in the metric W = diag(1 on d, w on q), w = h ℓ_e (theory §3): ℓ_e = the reference
      // element's largest node distance / √2 (its side for a square). A caller's director_weight > 0 replaces it.
      double w = director_weight;
      if (w == 0.0) {
        double diag2 = 0.0;
        const auto& en = mesh_.elements[static_cast<size_t>(e)];
        for (size_t a = 0; a < 9; ++a)
          for (size_t b = a + 1; b < 9; ++b)
            diag2 = std::max(diag2, (mesh_.X[static_cast<size_t>(en[a])] - mesh_.X[static_cast<size_t>(en[b])]).squaredNorm());
        w = material_.thickness * std::sqrt(0.5 * diag2);
      }
      const CorrectionInfo ci = energy_momentum_correction(*R, du, U1 - U_n[static_cast<size_t>(e)], fe, 1e-20, w);
      guard[static_cast<size_t>(e)] = ci.rigid_guard;
      if (fmax > 0.0) beta_z[static_cast<size_t>(e)] = ci.correction_norm / fmax;
    }
    if (xi > 0.0) {  // theory §6: ξ G Δu with G = Π Tᵀ k0 T Π (PSD, G Rᵀ = 0)
      const CR9Shell::Vec45 um = 0.5 * (un + u1);
      const CR9Shell::Mat45 T = el.frame(um, ch).matrix();
      const CR9Shell::Mat45 P = rigid_complement_projector(R->dense());
      const CR9Shell::Mat45& k0e = (*k0)[static_cast<size_t>(e)];
      // G Δu as a chain of products, Pᵀ(Tᵀ(k0 (T (P Δu)))), not through the matrix G: Δu is mostly rigid
      // motion, which G annihilates, so (G)Δu would carry a rounding of ~1e-16 |G| |Δu| in every direction,
      // including a resultant and a moment (the linear and angular momentum errors of a dissipative run).
      // The chain removes the rigid part first and applies Pᵀ last, so the rigid rows of f_d keep only the
      // rounding of f_d's own size. It is also ~45× cheaper than forming G.
      const CR9Shell::Vec45 fd = xi * (P.transpose() * (T.transpose() * (k0e * (T * (P * du)))));
      fe += fd;
      diss[static_cast<size_t>(e)] = du.dot(fd);
      if (K) {
        const CR9Shell::Mat45 TP = T * P;
        ke += (2.0 * xi) * (TP.transpose() * k0e * TP);
      }
    }
    if (F) assembler_.add_vector(e, fe, F);
    if (K) assembler_.add_matrix(e, ke, K->values.data());
  });
  if (U_np1) *U_np1 = energy;
  if (info) {
    *info = ExactForceInfo{};
    for (size_t e = 0; e < elements_.size(); ++e) {
      info->rigid_guards += guard[e];
      info->max_beta_z = std::max(info->max_beta_z, beta_z[e]);
    }
    info->dissipation = sum(diss);
  }
  return sum(energy);
}

void Model::embedded_external(double t, const Eigen::VectorXd& p_mid, Eigen::VectorXd& Fd, Eigen::VectorXd& g) const {
  const Index n3 = 3 * static_cast<Index>(mesh_.num_nodes());
  Fd.setZero(n3);
  g.setZero(n3);
  for (const auto& load : loads_) {
    const double f = load.function(t);
    if (f == 0.0) continue;
    const Index k = 3 * static_cast<Index>(load.node);
    if (load.kind == NodalLoad::Kind::Force) {
      Fd.segment<3>(k) += f * load.vector;
    } else if (load.kind == NodalLoad::Kind::Moment) {
      // Dead moment m: its work on a director increment Δp is (m × p_mid)·Δp (theory §4).
      g.segment<3>(k) += (f * load.vector).cross(Vec3(p_mid.segment<3>(k)));
    } else {
      throw std::invalid_argument("Model::embedded_external: load kind not supported by em-exact (node " +
                                  std::to_string(load.node) + ")");
    }
  }
}

}  // namespace shelldyn
