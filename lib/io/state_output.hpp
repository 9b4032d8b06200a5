// Turns a State into the point fields written to VTU (displacement, translational velocity, current
// director), the form every run driver writes.
#pragma once

#include "lib/model/model.hpp"
#include "lib/model/state.hpp"
#include "lib/io/vtu_writer.hpp"

#include <ostream>
#include <string>
#include <utility>

namespace shelldyn {

// With `reactions` (lib/model/reactions.hpp) the point field "reaction" (3 components) is added. Cell data:
// membrane_force, bending_moment, shear_force, membrane_strain, curvature, shear_strain and
// strain_energy_density, element averages of docs/theory.md §9.1 (docs/manual.md §4).
VtuFields state_fields(const Model& model, const State& state, const Eigen::VectorXd* reactions = nullptr);

// The state a VTU of this writer holds (docs/manual.md §1, `--state FILE.vtu`), as a State of `model`:
// d from `displacement`, the director from `director` (charts selected afresh for it, docs/theory.md §2.3),
// v from `velocity` and, if present, `director_rate` (projected normal to p), a = 0; t from the fields.pvd
// of the run folder that lists the file (*has_time = false and t = 0 when none does). The caller adopts
// the charts (Model::adopt_charts). Throws std::runtime_error "PATH: reason" for a file of another mesh,
// a missing/non-finite array, a director that is not a unit vector, or a displaced fixed DOF.
State state_from_vtu(const Model& model, const std::string& path, bool* has_time);

// Constraint drift at a state (docs/manual.md "Rigid bodies and joints"): (‖g(u, t)‖∞, ‖G(u, t) u̇ + ∂g/∂t‖∞),
// the history.csv columns g_norm and gdot_norm; (0, 0) without constraints.
std::pair<double, double> constraint_drift(const SemiDiscreteSystem& system, const State& state);

// bodies.csv: one row per rigid body per output, "t,body,phi_x,phi_y,phi_z,d1_x,..,d3_z,v_x,v_y,v_z,omega_x,
// omega_y,omega_z" with the centre of mass φ, the body axes d_i, φ̇ and the spatial angular velocity
// ω = ½ Σ d_i × ḋ_i (exact for an orthonormal frame with ḋ_i = ω × d_i).
std::string body_state_header();
// One row per body (each ending in "\n"), for one AppendFile::append (lib/io/append_file.hpp).
std::string body_state_rows(const Model& model, const State& state);

// Creates `dir` and `dir/fields` (and parents). Throws std::runtime_error naming the folder when it
// cannot be created or written to.
void prepare_output_folder(const std::string& dir);

}  // namespace shelldyn
