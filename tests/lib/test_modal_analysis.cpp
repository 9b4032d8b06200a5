// Modal analysis (lib/analysis/modal_analysis.hpp) against closed forms: simply supported square plates
// (Kirchhoff for t/L = 0.005, Mindlin for t/L = 0.1, docs/modal.md), a free plate (six rigid-body
// modes) and the free hemisphere of the dynamic benchmark (its linearised periods).
#include "lib/analysis/modal_analysis.hpp"
#include "lib/linalg/linear_solver.hpp"
#include "lib/model/problem.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace shelldyn {
namespace {

std::string case_path(const std::string& name) { return std::string(SHELLDYN_SOURCE_DIR) + "/apps/cases/" + name; }

// ω_mn of a simply supported square plate (side L) with Mindlin's theory (rotary inertia and shear,
// factor k), the lower root of (kGt κ − ρt ω²)(Dκ + kGt − I ω²) − (kGt)² κ = 0 with κ = π²(m² + n²)/L²;
// or Kirchhoff's π²(m² + n²)/L² √(D/ρt) when mindlin = false.
std::vector<double> ss_plate_omegas(double E, double nu, double rho, double t, double L, bool mindlin, int count) {
  const double D = E * t * t * t / (12 * (1 - nu * nu)), G = E / (2 * (1 + nu)), k = 5.0 / 6.0, I = rho * t * t * t / 12;
  std::vector<double> w;
  for (int m = 1; m <= 6; ++m)
    for (int n = 1; n <= 6; ++n) {
      const double kap = M_PI * M_PI * (m * m + n * n) / (L * L);
      if (!mindlin) {
        w.push_back(kap * std::sqrt(D / (rho * t)));
        continue;
      }
      const double a = rho * t * I, b = -(rho * t * (D * kap + k * G * t) + I * k * G * t * kap),
                   c = k * G * t * kap * (D * kap + k * G * t) - std::pow(k * G * t, 2) * kap;
      w.push_back(std::sqrt((-b - std::sqrt(b * b - 4 * a * c)) / (2 * a)));
    }
  std::sort(w.begin(), w.end());
  w.resize(static_cast<size_t>(count));
  return w;
}

// The bending modes (Z-dominated) of a result, in order.
std::vector<double> bending_omegas(const ModalResult& r) {
  std::vector<double> w;
  for (const Mode& m : r.modes)
    if (!m.rigid && m.dominant() == "Z") w.push_back(m.omega);
  return w;
}

void expect_plate(const std::string& file, bool mindlin, int count, double tol) {
  Problem p = load_problem(case_path(file));
  ModalOptions o;
  o.num_modes = 12;
  const ModalResult r = modal_analysis(*p.model, p.initial_state(), o);
  EXPECT_EQ(r.rigid_modes, 0);
  const auto& mat = p.spec.material;
  const auto exact = ss_plate_omegas(mat.E, mat.nu, mat.rho, mat.thickness, 1.0, mindlin, count);
  const auto w = bending_omegas(r);
  ASSERT_GE(static_cast<int>(w.size()), count);
  for (int k = 0; k < count; ++k) {
    const double err = w[static_cast<size_t>(k)] / exact[static_cast<size_t>(k)] - 1;
    std::printf("%s mode %d: omega %.6g, %s %.6g, error %+.3f %%\n", file.c_str(), k + 1, w[static_cast<size_t>(k)],
                mindlin ? "Mindlin" : "Kirchhoff", exact[static_cast<size_t>(k)], 100 * err);
    EXPECT_LT(std::abs(err), tol) << "mode " << k + 1;
  }
  // Mass normalisation and the energy shares.
  for (const Mode& m : r.modes) {
    EXPECT_NEAR(m.share[0] + m.share[1] + m.share[2] + m.share[3], 1.0, 1e-10);
    EXPECT_EQ(m.shape.size(), p.model->num_dofs());
    for (Index d : p.model->dofs().constrained_dofs()) EXPECT_EQ(m.shape[d], 0.0);
  }
}

// Issue 12: within 0.5 % on an 8 x 8 mesh. The first eight bending modes ((1,1) … (2,3)) are within
// 0.29 % (thin) / 0.28 % (thick); (1,4) is 1 % off on this mesh, so it is not in the check.
TEST(ModalAnalysis, SimplySupportedThinPlateMatchesKirchhoff) { expect_plate("plate-modes-ss-thin.yaml", false, 8, 0.005); }
TEST(ModalAnalysis, SimplySupportedThickPlateMatchesMindlin) { expect_plate("plate-modes-ss-thick.yaml", true, 8, 0.005); }

TEST(ModalAnalysis, ThickPlateIsNotKirchhoff) {
  // The Mindlin check above can fail: Kirchhoff's frequencies are 3.4 % (mode 1) to 17 % too high at t/L = 0.1.
  Problem p = load_problem(case_path("plate-modes-ss-thick.yaml"));
  ModalOptions o;
  o.num_modes = 4;
  const auto w = bending_omegas(modal_analysis(*p.model, p.initial_state(), o));
  const auto& mat = p.spec.material;
  const auto kirchhoff = ss_plate_omegas(mat.E, mat.nu, mat.rho, mat.thickness, 1.0, false, 1);
  EXPECT_LT(w[0] / kirchhoff[0], 0.97);
}

TEST(ModalAnalysis, FreePlateHasSixRigidModes) {
  Problem p = load_problem(case_path("plate-modes-free.yaml"));
  ModalOptions o;
  o.num_modes = 8;
  const ModalResult r = modal_analysis(*p.model, p.initial_state(), o);
  EXPECT_EQ(r.rigid_modes, 6);
  for (int k = 0; k < 6; ++k) EXPECT_TRUE(r.modes[static_cast<size_t>(k)].rigid);
  // Leissa (1969): first free-plate frequency parameter ω L² √(ρt/D) = 13.49 for ν = 0.3 (a Ritz value).
  const auto& mat = p.spec.material;
  const double D = mat.E * std::pow(mat.thickness, 3) / (12 * (1 - mat.nu * mat.nu));
  const double lambda1 = r.modes[6].omega * std::sqrt(mat.rho * mat.thickness / D);
  std::printf("free plate: %d rigid modes, first elastic omega L^2 sqrt(rho t/D) = %.4f (Leissa 13.49)\n", r.rigid_modes, lambda1);
  EXPECT_NEAR(lambda1, 13.49, 0.01 * 13.49);
  // A rigid mode stores no strain energy: φᵀKφ ≈ 0 next to the elastic ω².
  for (int k = 0; k < 6; ++k) EXPECT_LT(std::abs(r.modes[static_cast<size_t>(k)].omega2), 1e-6 * r.modes[6].omega2);
}

TEST(ModalAnalysis, ShiftFindsTheModesNearAFrequency) {
  Problem p = load_problem(case_path("plate-modes-ss-thin.yaml"));
  ModalOptions o;
  o.num_modes = 6;
  const ModalResult lowest = modal_analysis(*p.model, p.initial_state(), o);
  o.num_modes = 2;
  o.shift_hz = lowest.modes[3].frequency * 1.001;  // next to the (2,2) mode
  const ModalResult near = modal_analysis(*p.model, p.initial_state(), o);
  bool found = false;
  for (const Mode& m : near.modes) found = found || std::abs(m.omega / lowest.modes[3].omega - 1) < 1e-8;
  EXPECT_TRUE(found);
}

TEST(ModalAnalysis, HemispherePeriodsAsTheBenchmarkAppPrintsThem) {
  // The free hemisphere of Li & Qian §4.3 at rho = 1000 (5 440 unknowns): six rigid modes, then the
  // n = 2 pair at 46.2409 s and the next pair at 16.5206 s (docs/results.md, pinched_hemisphere app).
  Problem p = load_problem(case_path("pinched-hemisphere.yaml"));
  ModalOptions o;
  o.num_modes = 10;
  const ModalResult r = modal_analysis(*p.model, p.initial_state(), o);
  EXPECT_EQ(r.rigid_modes, 6);
  const auto T = elastic_periods(r, 4);
  ASSERT_EQ(T.size(), 4u);
  EXPECT_NEAR(T[0], 46.2409, 1e-4);
  EXPECT_NEAR(T[1], 46.2409, 1e-4);
  EXPECT_NEAR(T[2], 16.5206, 1e-4);
  EXPECT_NEAR(T[3], 16.5206, 1e-4);
}

TEST(ModalAnalysis, RejectsBadOptions) {
  Problem p = load_problem(case_path("plate-modes-ss-thin.yaml"));
  ModalOptions o;
  o.num_modes = 0;
  EXPECT_THROW(modal_analysis(*p.model, p.initial_state(), o), std::invalid_argument);
  o.num_modes = static_cast<int>(p.model->dofs().num_free());
  EXPECT_THROW(modal_analysis(*p.model, p.initial_state(), o), std::invalid_argument);
  o.num_modes = 3;
  o.shift_hz = -1;
  EXPECT_THROW(modal_analysis(*p.model, p.initial_state(), o), std::invalid_argument);
}

}  // namespace
}  // namespace shelldyn

namespace shelldyn {
namespace {

// LinearSolver::negative_pivots(): the inertia behind the Sturm count and the path follower's
// limit-point detection. diag(3, −1, 2, −4) coupled symmetrically still has two negative eigenvalues.
TEST(LinearSolverInertia, NegativePivotsCountNegativeEigenvalues) {
  SparsePattern p;
  p.n = 4;
  p.colptr = {0, 2, 4, 6, 8};
  p.rowind = {0, 1, 0, 1, 2, 3, 2, 3};
  const std::vector<double> v = {3.0, 0.5, 0.5, -1.0, 2.0, 0.3, 0.3, -4.0};
  const CscView A{p.n, p.colptr.data(), p.rowind.data(), v.data()};
  for (const char* name : {"eigen-ldlt", "cholmod", "mumps"}) {
    auto s = make_linear_solver(name);
    s->factorize(A);
    EXPECT_EQ(s->negative_pivots(), 2) << name;
  }
  const std::vector<double> pd = {3.0, 0.5, 0.5, 1.0, 2.0, 0.3, 0.3, 4.0};
  for (const char* name : {"eigen-ldlt", "cholmod", "mumps"}) {
    auto s = make_linear_solver(name);
    s->factorize({p.n, p.colptr.data(), p.rowind.data(), pd.data()});
    EXPECT_EQ(s->negative_pivots(), 0) << name;
  }
  auto klu = make_linear_solver("klu");
  klu->factorize(A);
  EXPECT_EQ(klu->negative_pivots(), -1);  // LU pivots are no inertia
}

}  // namespace
}  // namespace shelldyn

namespace shelldyn {
namespace {

// The new generators build valid free shells: six rigid-body modes each (orientation and seam merging;
// an unmerged cylinder seam or an inconsistent element would add mechanisms or fail to build).
TEST(ModalAnalysis, GeneratedFreeShellsHaveSixRigidModes) {
  for (const char* mesh : {"{generator: closed_cylinder, radius: 100.0, length: 200.0, n_circ: 8, n_axial: 4}",
                           "{generator: slit_annulus, r_inner: 6.0, r_outer: 10.0, n_radial: 2, n_circ: 12}",
                           "{generator: cylinder_patch, radius: 2540.0, angle: 0.1, length: 254.0, n_arc: 2, n_axial: 2}"}) {
    const std::string text = std::string("mesh: ") + mesh +
                             "\nmaterial: {E: 3.0e4, nu: 0.3, rho: 1.0, thickness: 1.0}\n"
                             "integrator: {name: em-galpha}\ntime: {dt: 1.0e-3, t_end: 0.01}\n";
    Problem p = make_problem(load_case_from_string(text, "generated.yaml"));
    ModalOptions o;
    o.num_modes = 8;
    const ModalResult r = modal_analysis(*p.model, p.initial_state(), o);
    EXPECT_EQ(r.rigid_modes, 6) << mesh;
  }
}

}  // namespace
}  // namespace shelldyn
