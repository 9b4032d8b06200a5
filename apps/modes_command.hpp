// `shelldyn modes CASE [-n N] [--shift HZ] [--state initial|static] [--dt DT] [-o DIR]`: natural
// frequencies and mode shapes of a case (lib/analysis/modal_analysis.hpp, docs/modal.md).
//
// Prints a table (mode, ω [rad/s], f [Hz], T [s], dominant direction with its kinetic-energy share,
// Δt for 20 steps per period; with --dt the steps per period at that Δt) and writes to DIR (default
// results/<case>/modes): modes.csv (the table with every share), mode_shapes.csv (the mass-normalised shapes,
// mode,node,ux,uy,uz,pdx,pdy,pdz: lib/analysis/modal_analysis.hpp; input of initial_velocity: {mode: ...}), modes.pvd + fields/mode_NNN.vtu (one
// VTU per mode, the mode number as the "time" of the collection, shapes scaled so that the largest
// translation is 10 % of the model's largest extent; point data "mode_translation" is the unscaled
// mass-normalised shape) and run.json.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <string>

namespace shelldyn::app {

// Registers the subcommand; its callback stores the action to run in `action` (the pattern of
// apps/shelldyn.cpp).
void add_modes_command(CLI::App& app, std::function<int()>& action, const std::string& command);

}  // namespace shelldyn::app
