// Small shell cases with exact or well-understood answers for the SUNDIALS baselines (ida-bdf,
// arkode-erk, arkode-dirk): the rigid spins of docs/benchmarks.md §6 and the free flight of
// docs/theory.md §7 item 12. Header-only; shared by tests/integrators/test_*.cpp and
// benchmarks/bench_sundials_baselines.cpp.
#pragma once

#include "integrators/integrator.hpp"
#include "tests/integrators/dynamics_fixtures.hpp"
#include "lib/mesh/mesh_generators.hpp"
#include "lib/model/model.hpp"
#include "lib/mesh/nodal_normals.hpp"

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace shelldyn {
namespace baseline_cases {

// A free rectangular plate a × b (centroid at the origin, normal +Z) of nx × ny CR9 elements.
using testing::free_plate;

// Sets the velocity of node i from a translational velocity d and a director rate pdot (converted
// to the two minor-component rates of the node's chart: q̇ = S ṗ, docs/theory.md §2.3).
inline void set_node_velocity(const Model& model, State& s, int i, const Vec3& d, const Vec3& pdot) {
  s.v.segment<3>(DofMap::dof(i, 0)) = d;
  s.v.segment<2>(DofMap::dof(i, 3)) = chart_coordinates(pdot, s.charts[static_cast<size_t>(i)]);
  (void)model;
}

// Rigid spin of docs/benchmarks.md §6: plate 2 × 1, h 0.1, ρ 1, E 1e8, ν 0.3, 4 × 2 mesh,
// v = ω × X, ṗ = ω × p. R2: ω = (1, 0, 0), K = 0.00841667, ‖J‖ = 0.0168333.
// E may be lowered for short tests (the centrifugal strain, ~ρω²a²/E, then grows accordingly).
inline std::unique_ptr<Model> spin_plate(double E = 1e8) {
  return free_plate(2.0, 1.0, 4, 2, ShellMaterial{E, 0.3, 1.0, 0.1});
}
inline State spin_state(const Model& model, const Vec3& omega) {
  State s = model.initial_state();
  for (int i = 0; i < model.mesh().num_nodes(); ++i) {
    const Vec3& X = model.mesh().X[static_cast<size_t>(i)];
    const Vec3 p = model.director(s, i);
    set_node_velocity(model, s, i, omega.cross(X), omega.cross(p));
  }
  return s;
}
constexpr double kR2Kinetic = 0.5 * 0.2 * (1.0 + 0.01) / 12.0;  // ½ I_X ω², I_X = m(b² + h²)/12
constexpr double kR2AngularMomentum = 0.2 * (1.0 + 0.01) / 12.0;

// Free flight of docs/theory.md §7 item 12: two 1 × 1 elements (2 × 1 plate), h 0.1, E 1e6, ν 0.3, ρ 1,
// c = centroid (the origin here), ω = (0.3, 0.5, 1), v₀ = (0.1, 0, 0.2), β = 0.5:
//   ḋ_i = v₀ + ω × (X_i − c) + (0, 0, β((X_i − c)_x² − 0.3)),
//   ṗ_i = ω × p_i + (−2β (X_i − c)_x, 0, 0) projected onto the plane ⊥ p_i.
inline std::unique_ptr<Model> flight_plate() { return free_plate(2.0, 1.0, 2, 1, ShellMaterial{1e6, 0.3, 1.0, 0.1}); }
inline State flight_state(const Model& model, const Vec3& omega = Vec3(0.3, 0.5, 1.0),
                          const Vec3& v0 = Vec3(0.1, 0.0, 0.2), double beta = 0.5) {
  State s = model.initial_state();
  for (int i = 0; i < model.mesh().num_nodes(); ++i) {
    const Vec3& X = model.mesh().X[static_cast<size_t>(i)];
    const Vec3 p = model.director(s, i);
    const Vec3 d = v0 + omega.cross(X) + Vec3(0.0, 0.0, beta * (X.x() * X.x() - 0.3));
    Vec3 pd = omega.cross(p) + Vec3(-2.0 * beta * X.x(), 0.0, 0.0);
    pd -= pd.dot(p) * p;
    set_node_velocity(model, s, i, d, pd);
  }
  return s;
}

// H = K + V − W_ext of a state.
inline double total_energy(const SemiDiscreteSystem& sys, const State& s, double w_ext) {
  const Invariants inv = sys.invariants(s);
  return inv.kinetic + inv.strain - w_ext;
}

}  // namespace baseline_cases
}  // namespace shelldyn
