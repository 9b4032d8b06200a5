// Turns a State into the point fields written to VTU (displacement, translational velocity, current
// director), the form every run driver writes.
#pragma once

#include "lib/model.hpp"
#include "lib/state.hpp"
#include "lib/vtu_writer.hpp"

namespace shelldyn {

VtuFields state_fields(const Model& model, const State& state);

// Creates `dir` and `dir/fields` (and parents). Throws std::runtime_error naming the folder when it
// cannot be created or written to.
void prepare_output_folder(const std::string& dir);

}  // namespace shelldyn
