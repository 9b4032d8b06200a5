// Turns a State into the point fields written to VTU (displacement, translational velocity, current
// director), the form every run driver writes.
#pragma once

#include "lib/model.hpp"
#include "lib/state.hpp"
#include "lib/vtu_writer.hpp"

namespace shelldyn {

// With `reactions` (lib/reactions.hpp) the point field "reaction" (3 components) is added. Cell data:
// membrane_force, bending_moment, shear_force, membrane_strain, curvature, shear_strain and
// strain_energy_density, element averages of docs/theory.md §9.1 (docs/manual.md §4).
VtuFields state_fields(const Model& model, const State& state, const Eigen::VectorXd* reactions = nullptr);

// Creates `dir` and `dir/fields` (and parents). Throws std::runtime_error naming the folder when it
// cannot be created or written to.
void prepare_output_folder(const std::string& dir);

}  // namespace shelldyn
