// Modal analysis: natural frequencies and mode shapes of the constrained, linearised model
//     K φ = ω² M φ      on the free DOFs (docs/modal.md)
// about a given state (the reference state, or a deformed static state, where K is the tangent
// K(u) + the load stiffness at the state's load factor).
//
// Method: Spectra's shift-invert Lanczos (SymGEigsShiftSolver, GEigsMode::ShiftInvert) for the
// eigenvalues nearest a shift σ. The operator (K − σM)⁻¹ is applied with one sparse factorization of
// the project's LinearSolver (lib/linalg/linear_solver.hpp); nothing is dense except the small Lanczos
// basis. Constrained DOFs are removed (the free-DOF blocks K_ff, M_ff are extracted once on a reduced
// pattern), so no artificial eigenvalues appear.
//
// Shift: by default σ = −σ₀ with σ₀ = 1e-9 · max_i K_ii/M_ii (a tiny negative value), so K − σM is
// positive definite even for a free body and the eigenvalues nearest σ are the lowest ones, rigid-body
// modes first. A user shift (frequency f_s) gives σ = (2π f_s)² and the modes nearest that frequency;
// K − σM is then indefinite and needs an LDLᵀ or LU back-end ("eigen-ldlt" default, "klu").
//
// Rigid-body modes: |ω²| ≤ rigid_tol · max_i K_ii/M_ii (default 1e-13). Their computed ω² is round-off,
// measured at 1e-19 – 1e-17 of max K_ii/M_ii; the lowest elastic ω² of the project's shells is 1e-10 –
// 1e-8 of it (the free hemisphere: 1.3e-10; docs/modal.md), so the threshold sits orders of magnitude
// from both. They are reported with ω = 0 and flagged. Below −threshold
// the mode is flagged unstable (ω² < 0: an indefinite tangent about a state past a critical point).
//
// Completeness: with the default shift, a Sturm-sequence count (negative pivots of LDLᵀ(K − τM), τ just
// below the highest computed ω²) must equal the number of computed modes below τ; Lanczos can miss copies of
// multiple eigenvalues (six rigid modes, symmetric pairs), and then the search is repeated with a
// larger subspace. (With a user shift the count is not checked.)
//
// Mode shapes are mass-normalised (φᵀ M φ = 1) and returned as full-length vectors (zeros at the
// constrained DOFs). Each mode carries its kinetic-energy shares per DOF kind, Σ_{i∈c} φ_i (Mφ)_i for
// c = translations X, Y, Z and director (rotation) DOFs, which sum to 1; the largest names the mode's
// dominant direction.
#pragma once

#include "lib/model/model.hpp"
#include "lib/model/state.hpp"

#include <array>
#include <string>
#include <vector>

namespace shelldyn {

struct ModalOptions {
  int num_modes = 10;                 // modes wanted (rigid ones included)
  double shift_hz = 0.0;              // 0: lowest modes (σ slightly negative); > 0: modes nearest this frequency
  std::string linear_solver = "eigen-ldlt";  // make_linear_solver() name
  double tol = 1e-10;                 // Spectra's relative tolerance on the Ritz values
  int max_restarts = 1000;            // Spectra's maxit
  double rigid_tol = 1e-13;           // rigid if |ω²| ≤ rigid_tol · max_i K_ii/M_ii
  bool load_stiffness = false;        // add −sym(∂F_ext/∂q) at state.t (deformed static states)
};

struct Mode {
  double omega2 = 0.0;     // eigenvalue ω² [rad²/s²] (as computed; may be ±round-off for rigid modes)
  double omega = 0.0;      // √ω² [rad/s], 0 for rigid modes
  double frequency = 0.0;  // ω / 2π [Hz]
  double period = 0.0;     // 2π / ω [s], +inf for rigid modes
  bool rigid = false;
  bool unstable = false;   // ω² < 0 beyond the rigid threshold: the state is not a stable equilibrium
  std::array<double, 4> share{};  // kinetic-energy shares: X, Y, Z translations, director DOFs
  Eigen::VectorXd shape;           // mass-normalised, full length (constrained DOFs zero)
  // "X", "Y", "Z" or "rotation": the largest share.
  std::string dominant() const;
};

struct ModalResult {
  std::vector<Mode> modes;  // ascending ω²
  int rigid_modes = 0;
  int unstable_modes = 0;   // ω² < 0 (only about a deformed state past a limit or bifurcation point)
  double sigma = 0.0;       // shift used [rad²/s²]
  double lambda_scale = 0.0;  // max_i K_ii/M_ii over free DOFs
  Index free_dofs = 0;
  long operator_applications = 0;  // solves with the factorization
  int restarts = 0;
  long sturm_count = -1;    // eigenvalues below the top computed one (−1e-6 relative), from LDLᵀ inertia; -1 if not checked
  double factorize_s = 0.0, total_s = 0.0;  // wall seconds
};

// Throws std::invalid_argument for bad options (num_modes < 1 or ≥ free DOFs, negative shift, ...),
// std::runtime_error when the factorization fails or Spectra does not converge (the message names the
// number of converged modes and suggests fewer modes or a larger tolerance).
ModalResult modal_analysis(const Model& model, const State& state, const ModalOptions& options = {});

// Linearised periods of the elastic modes (rigid modes skipped): the first `count` of them.
std::vector<double> elastic_periods(const ModalResult& r, int count);

// Writes the mode shapes as CSV (`shelldyn modes` -> mode_shapes.csv; docs/manual.md §2.6 and §4):
//     mode,node,ux,uy,uz,pdx,pdy,pdz
// one row per mode (1-based, as in modes.csv) and node (0-based): the mass-normalised shape φ, its
// translations and the director change δp = A1(q) φ_q (a 3-vector tangent to the director, independent of
// the node's chart; docs/theory.md §2.2), all with 17 significant digits. `initial_velocity: {mode: FILE,
// index: k, amplitude: A}` reads it back (v = A φ_k). Throws std::runtime_error if the file cannot be written.
void write_mode_shapes_csv(const std::string& path, const Model& model, const State& state, const ModalResult& r);

}  // namespace shelldyn
