// docs/theory.md §7.8: linear membrane and bending patch tests (K_0 u = 0 with boundary nodes prescribed
// by the exact field) on a skewed parallelogram mesh and on the MacNeal-Harder 5-element trapezoidal
// patch; h = 0.001, E = 1e6, nu = 0.25. MITC9 passes exactly on parallelograms; on trapezoids its
// membrane error is ~1 % (§4.4 known property), and the plain displacement element is exact.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdio>
#include <functional>
#include <map>
#include <vector>

#include "elements/cr9_shell.hpp"

namespace shelldyn {
namespace {

struct PatchMesh {
  std::vector<Eigen::Vector3d> X;
  std::vector<std::array<int, 9>> elements;
  std::vector<bool> boundary;
};

int find_or_add(std::vector<Eigen::Vector3d>& X, const Eigen::Vector3d& p) {
  for (size_t i = 0; i < X.size(); ++i)
    if ((X[i] - p).norm() < 1e-12) return static_cast<int>(i);
  X.push_back(p);
  return static_cast<int>(X.size()) - 1;
}

// Straight-sided 9-node elements from corner quads (CCW): mid-side nodes at edge midpoints, centre node
// at the corner average. Boundary = nodes of edges used by one element only.
PatchMesh build_mesh(const std::vector<std::array<Eigen::Vector2d, 4>>& quads) {
  PatchMesh m;
  std::map<std::pair<int, int>, int> edge_count;
  std::vector<std::array<int, 3>> edges;
  for (const auto& qd : quads) {
    std::array<Eigen::Vector3d, 4> c;
    for (int k = 0; k < 4; ++k) c[k] = Eigen::Vector3d(qd[k](0), qd[k](1), 0.0);
    std::array<int, 9> e;
    for (int k = 0; k < 4; ++k) e[k] = find_or_add(m.X, c[k]);
    for (int k = 0; k < 4; ++k) e[4 + k] = find_or_add(m.X, 0.5 * (c[k] + c[(k + 1) % 4]));
    e[8] = find_or_add(m.X, 0.25 * (c[0] + c[1] + c[2] + c[3]));
    m.elements.push_back(e);
    for (int k = 0; k < 4; ++k) {
      const int a = e[k], b = e[(k + 1) % 4];
      ++edge_count[{std::min(a, b), std::max(a, b)}];
      edges.push_back({a, e[4 + k], b});
    }
  }
  m.boundary.assign(m.X.size(), false);
  for (const auto& ed : edges)
    if (edge_count[{std::min(ed[0], ed[2]), std::max(ed[0], ed[2])}] == 1)
      for (int n : ed) m.boundary[n] = true;
  return m;
}

using Field = std::function<Eigen::Matrix<double, 5, 1>(const Eigen::Vector3d&)>;

struct PatchError {
  double d, q;  // max interior error of translations / director components, relative to field maxima
};

PatchError run_patch(const PatchMesh& m, const Field& exact, bool mitc) {
  const ShellMaterial mat{1.0e6, 0.25, 1.0, 0.001};
  const int n = static_cast<int>(m.X.size()), ndof = 5 * n;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(ndof, ndof);
  CR9Shell::Charts ch;
  ch.fill(DirectorChart{0, 1, 2, 1.0});
  for (const auto& e : m.elements) {
    std::array<Eigen::Vector3d, 9> X, p;
    for (int k = 0; k < 9; ++k) X[k] = m.X[e[k]], p[k] = Eigen::Vector3d::UnitZ();
    const CR9Shell el(X, p, mat, CR9Shell::Options{mitc, true});
    CR9Shell::Mat45 Ke;
    el.internal(CR9Shell::Vec45::Zero(), ch, nullptr, &Ke);
    for (int a = 0; a < 9; ++a)
      for (int b = 0; b < 9; ++b) K.block(5 * e[a], 5 * e[b], 5, 5) += Ke.block<5, 5>(5 * a, 5 * b);
  }
  std::vector<int> I, B;
  Eigen::VectorXd uex(ndof);
  for (int i = 0; i < n; ++i) {
    uex.segment<5>(5 * i) = exact(m.X[i]);
    for (int c = 0; c < 5; ++c) (m.boundary[i] ? B : I).push_back(5 * i + c);
  }
  Eigen::MatrixXd KII(I.size(), I.size()), KIB(I.size(), B.size());
  Eigen::VectorXd uB(B.size());
  for (size_t a = 0; a < I.size(); ++a) {
    for (size_t b = 0; b < I.size(); ++b) KII(a, b) = K(I[a], I[b]);
    for (size_t b = 0; b < B.size(); ++b) KIB(a, b) = K(I[a], B[b]);
  }
  for (size_t b = 0; b < B.size(); ++b) uB(b) = uex(B[b]);
  const Eigen::VectorXd uI = KII.ldlt().solve(-KIB * uB);
  double maxd = 0, maxq = 0, errd = 0, errq = 0;
  for (int i = 0; i < ndof; ++i) (i % 5 < 3 ? maxd : maxq) = std::max(i % 5 < 3 ? maxd : maxq, std::abs(uex(i)));
  for (size_t a = 0; a < I.size(); ++a) {
    const double err = std::abs(uI(a) - uex(I[a]));
    (I[a] % 5 < 3 ? errd : errq) = std::max(I[a] % 5 < 3 ? errd : errq, err);
  }
  return {errd / maxd, maxq > 0 ? errq / maxq : errq / maxd};
}

// Membrane: u = 1e-3(x + y/2), v = 1e-3(y + x/2), flat directors.
Eigen::Matrix<double, 5, 1> membrane_field(const Eigen::Vector3d& X) {
  Eigen::Matrix<double, 5, 1> u;
  u << 1e-3 * (X(0) + 0.5 * X(1)), 1e-3 * (X(1) + 0.5 * X(0)), 0, 0, 0;
  return u;
}
// Bending: w = 1e-3(x^2 + xy + y^2)/2 with Kirchhoff normals q = (-w_x, -w_y).
Eigen::Matrix<double, 5, 1> bending_field(const Eigen::Vector3d& X) {
  const double x = X(0), y = X(1);
  Eigen::Matrix<double, 5, 1> u;
  u << 0, 0, 0.5e-3 * (x * x + x * y + y * y), -1e-3 * (x + 0.5 * y), -1e-3 * (y + 0.5 * x);
  return u;
}

std::vector<std::array<Eigen::Vector2d, 4>> parallelogram_quads() {
  // Skewed 3x2 structured mesh of parallelograms.
  const double a = 0.08, b = 0.06, s = 0.025;
  auto P = [&](int i, int j) { return Eigen::Vector2d(i * a + j * s, j * b); };
  std::vector<std::array<Eigen::Vector2d, 4>> q;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 3; ++i) q.push_back({P(i, j), P(i + 1, j), P(i + 1, j + 1), P(i, j + 1)});
  return q;
}

std::vector<std::array<Eigen::Vector2d, 4>> macneal_harder_quads() {
  const Eigen::Vector2d o1(0, 0), o2(0.24, 0), o3(0.24, 0.12), o4(0, 0.12);
  const Eigen::Vector2d i1(0.04, 0.02), i2(0.18, 0.03), i3(0.16, 0.08), i4(0.08, 0.08);
  return {{o1, o2, i2, i1}, {o2, o3, i3, i2}, {i4, i3, o3, o4}, {o1, i1, i4, o4}, {i1, i2, i3, i4}};
}

TEST(PatchTest, ParallelogramMeshIsExactForMembraneAndBending) {
  const PatchMesh m = build_mesh(parallelogram_quads());
  for (bool mitc : {true, false}) {
    const PatchError em = run_patch(m, membrane_field, mitc), eb = run_patch(m, bending_field, mitc);
    std::printf("  parallelogram mitc=%d: membrane d %.1e q %.1e | bending d %.1e q %.1e\n", mitc, em.d, em.q, eb.d,
                eb.q);
    EXPECT_LT(std::max(em.d, em.q), 1e-10);
    EXPECT_LT(std::max(eb.d, eb.q), 1e-10);
  }
}

TEST(PatchTest, MacNealHarderTrapezoids) {
  const PatchMesh m = build_mesh(macneal_harder_quads());
  ASSERT_EQ(m.X.size(), 25u);  // 8 corners + 12 edge mid-nodes + 5 centres
  const PatchError bm = run_patch(m, bending_field, true), mm = run_patch(m, membrane_field, true);
  const PatchError bd = run_patch(m, bending_field, false), md = run_patch(m, membrane_field, false);
  std::printf("  MacNeal-Harder MITC9: membrane d %.3e q %.1e | bending d %.1e q %.1e\n", mm.d, mm.q, bm.d, bm.q);
  std::printf("  MacNeal-Harder plain: membrane d %.1e q %.1e | bending d %.1e q %.1e\n", md.d, md.q, bd.d, bd.q);
  EXPECT_LT(std::max(bm.d, bm.q), 1e-10);
  EXPECT_LT(std::max(bd.d, bd.q), 1e-10);
  EXPECT_LT(std::max(md.d, md.q), 1e-10);
  EXPECT_LT(mm.q, 1e-10);
  // Measured 0.9445 % (max interior translation error / max |u|), docs/theory.md §4.4 quotes 0.94 %: MITC9's 2x2
  // tying of e_xieta on trapezoids. Bound it on both sides so a change of the tying scheme is noticed.
  EXPECT_GT(mm.d, 0.0090);
  EXPECT_LT(mm.d, 0.0100);
}

}  // namespace
}  // namespace shelldyn
