// The semi-discretization M(q) q̈ + F_m(q, q̇) + F_int(q) = F_ext(t)   (paper eq. 26; docs/theory.md §5.3)
// of a mesh of CR9 shell elements (architecture.md §4.2).
//
// The Model knows nothing about time integration: it evaluates forces, matrices, energies and momenta
// at states it is given. Matrices are assembled into storage the caller owns, on one fixed CSC pattern
// (assembler()); nothing is allocated per call. Element loops run in parallel over conflict-free
// element colours (OpenMP); results do not depend on the thread count beyond round-off.
//
// Constraints: the Model assembles the unconstrained system; integrators apply the DofMap (identity
// rows/columns, lib/model/assembler.hpp apply_dirichlet). Director-component constraints follow chart
// switches: rechart() re-resolves the DofMap.
#pragma once

#include "elements/cr9_shell.hpp"
#include "lib/model/assembler.hpp"
#include "lib/model/dof_map.hpp"
#include "lib/model/exact_energy_system.hpp"
#include "lib/model/model_multibody.hpp"
#include "lib/mesh/mesh.hpp"
#include "lib/model/semi_discrete_system.hpp"
#include "lib/linalg/sparse_matrix.hpp"
#include "lib/model/state.hpp"
#include "lib/model/surface_loads.hpp"
#include "lib/model/time_function.hpp"

#include <Eigen/Core>
#include <memory>
#include <mutex>
#include <vector>

namespace shelldyn {

// A load on one node: a dead force (global vector) or a dead moment m, whose generalised force on the
// director unknowns is A1ᵀ (m × p) (docs/theory.md §2.3 item 3), both scaled by f(t).
struct NodalLoad {
  enum class Kind { Force, Moment };
  int node = 0;
  Kind kind = Kind::Force;
  Vec3 vector = Vec3::Zero();
  TimeFunction function;
};

// A prescribed displacement history on one constrained translation DOF: u_dof(t) = value · function(t)
// (docs/theory.md §8.6).
struct PrescribedMotion {
  Index dof = 0;
  double value = 0.0;
  TimeFunction function;
};

// The Model offers the em-exact extension of the system interface (lib/model/exact_energy_system.hpp).
class Model final : public ExactEnergySystem {
 public:
  // normals: initial unit nodal normals p_i0 (lib/mesh/nodal_normals.hpp). Throws if an element fails the
  // orientation check or the material is invalid (messages name the element).
  Model(Mesh mesh, std::vector<Vec3> normals, const ShellMaterial& material, DofMap dofs,
        std::vector<NodalLoad> loads = {}, CR9Shell::Options options = {});

  const Mesh& mesh() const { return mesh_; }
  const std::vector<Vec3>& normals() const { return normals_; }
  const ShellMaterial& material() const { return material_; }
  const Assembler& assembler() const { return assembler_; }
  const DofMap& dofs() const override { return dofs_; }
  const std::vector<NodalLoad>& loads() const { return loads_; }
  const CR9Shell& element(int e) const { return elements_[static_cast<size_t>(e)]; }
  Index num_dofs() const override { return assembler_.num_dofs(); }
  std::shared_ptr<const SparsePattern> pattern() const override { return assembler_.pattern(); }
  SparseMatrix make_matrix() const;  // zero matrix on the model's pattern

  // The reference state: t = 0, d = 0, q = minor components of p_i0 in freshly selected charts, v = a = 0.
  State initial_state() const override;

  // F_int(q), K = ∂F_int/∂q (exact, symmetric), returns V = Σ U_e. F or K may be null.
  double internal(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, double* F,
                  SparseMatrix* K) const override;
  // Strain-averaged force F*_int,mid and its symmetric tangent K_mid (docs/theory.md §6.3); returns V(u_np1).
  double algorithmic_internal(const Eigen::VectorXd& u_n, const Eigen::VectorXd& u_np1,
                              const std::vector<DirectorChart>& charts, double alpha_f, double xi, double* F,
                              SparseMatrix* K) const override;
  void mass(const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, SparseMatrix& M) const override;
  void inertial(const Eigen::VectorXd& u, const Eigen::VectorXd& v, const std::vector<DirectorChart>& charts,
                double* Fm) const override;
  void inertia_force(const Eigen::VectorXd& u, const Eigen::VectorXd& v, const Eigen::VectorXd& a,
                     const std::vector<DirectorChart>& charts, double* out) const override;
  // F_ext(t, q) (overwrites F). Moments depend on q through p and A1.
  void external(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                double* F) const override;
  // K += −sym(∂F_ext/∂q): the symmetric part of the load stiffness of dead moments (the curvature
  // term (m × p)_l ∂²p_l/∂q∂q). The skew part A1ᵀ[m]×A1 is left out (it vanishes for moments normal to
  // the plane the director turns in, e.g. the roll-up benchmark), so Newton may converge linearly
  // for general 3-D moments. Forces are dead and contribute nothing.
  void add_load_stiffness(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                          SparseMatrix& K) const override;
  Invariants invariants(const State& s) const override;
  double loads_end() const override;

  // Distributed loads and damping (lib/model/surface_loads.hpp, docs/theory.md §8). Follower pressures act in
  // external() and add_load_stiffness() (their tangent in full, or its symmetric part for symmetric
  // solvers); Rayleigh damping C = a_M M_0 + a_K K_0 (reference state, assembled once) adds C v to
  // inertial() and inertia_force().
  void set_follower_pressures(std::vector<FollowerPressure> loads) { follower_ = std::move(loads); }
  const std::vector<FollowerPressure>& follower_pressures() const { return follower_; }
  void set_unsymmetric_load_stiffness(bool full) { full_load_tangent_ = full; }
  void set_rayleigh_damping(double mass_coefficient, double stiffness_coefficient);
  // Prescribed displacement histories (docs/theory.md §8.6). Every DOF must be a constrained translation of
  // dofs() (throws std::invalid_argument otherwise) and appear once.
  void set_prescribed_motion(std::vector<PrescribedMotion> motion);
  const std::vector<PrescribedMotion>& prescribed_motion() const { return prescribed_; }
  bool has_prescribed_motion() const override { return !prescribed_.empty(); }
  const std::vector<Index>& prescribed_dofs() const override { return prescribed_dofs_; }
  void prescribed_displacement(double t, double* u) const override;
  void prescribed_velocity(double t, double* v) const override;
  bool has_damping() const override { return !damping_.values.empty(); }
  void damping_force(const Eigen::VectorXd& v, double* out) const override;
  void add_damping_matrix(double c, SparseMatrix& J) const override;

  // ---- Rigid bodies and joints (lib/model/model_multibody.hpp; docs/theory/multibody.md §7) ----------------
  // Adds the bodies' 12 unknowns each after the shell's and the joints' constraints; rebuilds the pattern
  // (body blocks, constraint couplings). Call before anything that holds a matrix of the model (damping).
  // Throws std::invalid_argument (one line naming the body or joint) on bad definitions.
  void set_multibody(std::vector<RigidBodyDef> bodies, std::vector<JointDef> joints, const Vec3& gravity);
  // Setup checks at the initial state s (ModelMultibody::check_initial): the joints are not redundant, do not act
  // on supported DOFs, and hold at s (positions and velocities); `advice` replaces the generic advice of a violated
  // joint. No-op without joints.
  void check_constraints(const State& s, const std::string& advice = {}) const {
    if (mb_) mb_->check_initial(s.u, s.v, s.charts, dofs_, 1e-8, advice);
  }
  const ModelMultibody* multibody() const { return mb_.get(); }
  int num_rigid_bodies() const override { return mb_ ? mb_->num_bodies() : 0; }
  RigidBlock rigid_block(int b) const override;
  Index num_constraints() const override { return mb_ ? mb_->num_constraints() : 0; }
  std::vector<ConstraintBlock> constraint_blocks() const override { return mb_ ? mb_->blocks() : std::vector<ConstraintBlock>{}; }
  void constraint_values(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                         Eigen::VectorXd& g) const override;
  void constraint_jacobian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                           ConstraintMatrix& G) const override;
  void constraint_time_derivative(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                                  Eigen::VectorXd& g_t) const override;
  void constraint_discrete_gradient(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                    const std::vector<DirectorChart>& charts, ConstraintMatrix& G_bar,
                                    Eigen::VectorXd& tau) const override;
  void add_constraint_hessian(double t, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts,
                              const Eigen::VectorXd& lambda, double c, SparseMatrix& K) const override;
  void add_constraint_discrete_tangent(double t0, const Eigen::VectorXd& u0, double t1, const Eigen::VectorXd& u1,
                                       const std::vector<DirectorChart>& charts, const Eigen::VectorXd& lambda,
                                       double c, SparseMatrix& K) const override;

  // ---- ExactEnergySystem: the embedded kinematics of em-exact (lib/model/exact_energy_system.hpp) ----
  int num_nodes() const override { return mesh_.num_nodes(); }
  int num_elements() const override { return mesh_.num_elements(); }
  double translational_density() const override { return material_.rho * material_.thickness; }
  double director_density() const override {
    return material_.rho * material_.thickness * material_.thickness * material_.thickness / 12.0;
  }
  bool has_follower_loads() const override { return !follower_.empty(); }
  void scalar_mass_times(const Eigen::VectorXd& x, const Eigen::VectorXd& y, Eigen::VectorXd& mx,
                         Eigen::VectorXd& my) const override;
  void step_energies(const Eigen::VectorXd& u_n, const std::vector<DirectorChart>& charts,
                     std::vector<double>& U) const override;
  CR9Shell::Mat45 reference_local_stiffness(int e) const override;
  double exact_internal(const Eigen::VectorXd& u_n, const Eigen::VectorXd& u_np1, const std::vector<DirectorChart>& charts,
                        const std::vector<double>& U_n, bool correct, double xi,
                        const std::vector<CR9Shell::Mat45>* k0, double* F, SparseMatrix* K,
                        std::vector<double>* U_np1, ExactForceInfo* info, const Eigen::VectorXd* p_mid = nullptr,
                        double director_weight = 0.0) const override;
  void embedded_external(double t, const Eigen::VectorXd& p_mid, Eigen::VectorXd& Fd, Eigen::VectorXd& g) const override;

  // Current director of node i.
  Vec3 director(const State& s, int node) const;

  // Re-selects director charts between increments (docs/theory.md §2.3), converting u, v, a, and
  // re-resolves director constraints. Returns the number of nodes whose chart switched.
  int rechart(State& s, double hysteresis = 1.0) override;
  // Adopts the charts of a state restored from a checkpoint: re-resolves the director constraints for
  // them (what rechart() does after a switch). Throws std::invalid_argument on a count mismatch.
  void adopt_charts(const std::vector<DirectorChart>& charts);
  double chart_margin(const State& s) const override;
  bool kept_matrix_basis(const Eigen::VectorXd& u_ref, const std::vector<DirectorChart>& charts_ref,
                         const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts, bool rotate,
                         std::vector<double>& node_inverse) const override;

 private:
  void gather(int e, const Eigen::VectorXd& global, CR9Shell::Vec45& ue) const;
  CR9Shell::Charts element_charts(int e, const std::vector<DirectorChart>& charts) const;
  void add_damping(const Eigen::VectorXd& v, double* out) const;  // out += C v

  Mesh mesh_;
  std::vector<Vec3> normals_;
  ShellMaterial material_;
  DofMap dofs_;
  std::vector<NodalLoad> loads_;
  Assembler assembler_;
  std::vector<CR9Shell> elements_;
  std::vector<Eigen::Matrix<double, 9, 9>, Eigen::aligned_allocator<Eigen::Matrix<double, 9, 9>>> scalar_masses_;  // m_ij of each element (em-exact)
  std::vector<FollowerPressure> follower_;
  bool full_load_tangent_ = false;
  SparseMatrix damping_;  // empty values: no damping
  std::vector<PrescribedMotion> prescribed_;  // sorted by dof
  std::vector<Index> prescribed_dofs_;

  // Per-step element state at u_n for algorithmic_internal() (CR9Shell::StepState): u_n is fixed during a
  // step's Newton iterations, so its frame, local increments and membrane products are computed at the
  // first call with a new (u_n, charts) and reused by the step's other residuals and tangents. Internal
  // to the Model: results are identical with or without it. The mutex serialises concurrent callers.
  struct StepCache {
    std::mutex mutex;
    Eigen::VectorXd u_n;
    std::vector<DirectorChart> charts;
    std::vector<CR9Shell::StepState> states;
    bool valid = false;
  };
  std::unique_ptr<ModelMultibody> mb_;  // null: no bodies, no joints
  std::unique_ptr<StepCache> step_cache_ = std::make_unique<StepCache>();
  const std::vector<CR9Shell::StepState>& step_states(const Eigen::VectorXd& u_n,
                                                      const std::vector<DirectorChart>& charts) const;
};

}  // namespace shelldyn
