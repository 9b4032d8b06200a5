// Initial nodal normals, consistent orientation and the orientation check (docs/theory.md §2.4).
#include "lib/mesh/mesh_generators.hpp"
#include "lib/mesh/nodal_normals.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace shelldyn {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The reversal documented in lib/mesh/nodal_normals.hpp: corners (1,2,3,4) -> (1,4,3,2).
Quad9 reverse(const Quad9& q) {
  return {q[0], q[3], q[2], q[1], q[7], q[6], q[5], q[4], q[8]};
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<no exception>";
}

TEST(InitialNormals, ReversedElementHasOppositeNormalAndStaysAQuad9) {
  // Reversal must be a re-numbering of the same quad9 geometry: the area is unchanged and the normal
  // flips at every node.
  Mesh m = make_rectangle(2.0, 1.0, 1, 1);
  m.elements[0] = reverse(m.elements[0]);
  EXPECT_NEAR(surface_area(m), 2.0, 1e-14);
  for (const Vec3& p : initial_normals(m)) EXPECT_NEAR((p + Vec3::UnitZ()).norm(), 0.0, 1e-15);
  EXPECT_NO_THROW(check_orientation(m, initial_normals(m)));  // clockwise seen from +Z, normal -Z
}

TEST(InitialNormals, AveragesNormalisedElementNormalsAtACrease) {
  // Two unit squares hinged along X = 0 with a 90 deg crease: left element in the plane Z = 0
  // (normal +Z), right element in the plane X = 0 going down (normal +X). Crease nodes get the
  // normalised mean (1, 0, 1)/sqrt(2); the other nodes keep their element normal.
  Mesh m;
  // Crease nodes 0..2 at X = 0, Y = 0, 0.5, 1.
  for (int j = 0; j < 3; ++j) m.X.emplace_back(0.0, 0.5 * j, 0.0);
  for (int i = 1; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m.X.emplace_back(-0.5 * i, 0.5 * j, 0.0);  // 3..8: left
  for (int i = 1; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m.X.emplace_back(0.0, 0.5 * j, -0.5 * i);  // 9..14: down
  // Left element: xi along +X (from X=-1 to 0), eta along +Y -> normal +Z.
  m.elements.push_back({6, 0, 2, 8, 3, 1, 5, 7, 4});
  // Down element: xi along -Z (from Z=0 to -1)... corners 0 (Z=0,Y=0), 12 (Z=-1,Y=0), 14, 2:
  // X,xi = -Z, X,eta = +Y, (-Z) x (+Y) = +X.
  m.elements.push_back({0, 12, 14, 2, 9, 13, 11, 1, 10});
  const auto p = initial_normals(m);
  const Vec3 mean = Vec3(1, 0, 1) / std::sqrt(2.0);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR((p[i] - mean).norm(), 0.0, 1e-15) << i;
  for (int i = 3; i < 9; ++i) EXPECT_NEAR((p[i] - Vec3::UnitZ()).norm(), 0.0, 1e-15) << i;
  for (int i = 9; i < 15; ++i) EXPECT_NEAR((p[i] - Vec3::UnitX()).norm(), 0.0, 1e-15) << i;
  // A 90 deg crease still passes the orientation check (e_z0 . p = cos 45 deg at the crease).
  EXPECT_NO_THROW(check_orientation(m, p));
}

TEST(InitialNormals, RejectsDegenerateUnusedAndOutOfRange) {
  Mesh m = make_rectangle(1.0, 1.0, 1, 1);
  Mesh collapsed = m;
  for (int k : {1, 5, 2}) collapsed.X[collapsed.elements[0][k]] = collapsed.X[collapsed.elements[0][0]];
  EXPECT_NE(message_of([&] { initial_normals(collapsed); }).find("vanishes"), std::string::npos);
  Mesh unused = m;
  unused.X.emplace_back(5, 5, 5);
  EXPECT_NE(message_of([&] { initial_normals(unused); }).find("mesh node 9 belongs to no element"),
            std::string::npos);
  Mesh bad = m;
  bad.elements[0][4] = 42;
  EXPECT_NE(message_of([&] { initial_normals(bad); }).find("local node 5, mesh node 42"), std::string::npos);
}

TEST(OrientConsistently, FixesOneFlippedElement) {
  const Mesh ref = make_rectangle(3.0, 3.0, 3, 3);
  Mesh m = ref;
  m.elements[4] = reverse(m.elements[4]);  // centre element flipped
  // Mid-side nodes shared with the flipped element get cancelling normals.
  EXPECT_NE(message_of([&] { initial_normals(m); }).find("orient_consistently"), std::string::npos);
  EXPECT_EQ(orient_consistently(m), 1);
  EXPECT_EQ(m.elements, ref.elements);
  EXPECT_EQ(m.node_sets, ref.node_sets);
  const auto p = initial_normals(m);
  for (const Vec3& n : p) EXPECT_NEAR((n - Vec3::UnitZ()).norm(), 0.0, 1e-15);
  EXPECT_NO_THROW(check_orientation(m, p));
  EXPECT_EQ(orient_consistently(m), 0);  // idempotent
}

TEST(OrientConsistently, KeepsTheFirstElementOfEachComponent) {
  // Flipping element 0 makes it the odd one out: all other 8 are reversed to agree with it.
  Mesh m = make_rectangle(3.0, 3.0, 3, 3);
  m.elements[0] = reverse(m.elements[0]);
  EXPECT_EQ(orient_consistently(m), 8);
  for (const Vec3& n : initial_normals(m)) EXPECT_NEAR((n + Vec3::UnitZ()).norm(), 0.0, 1e-15);
  // Two disconnected components: each keeps the orientation of its own first element.
  Mesh two = make_rectangle(1.0, 1.0, 1, 1);
  const Mesh other = make_rectangle(1.0, 1.0, 2, 1, 5.0);
  const int off = two.num_nodes();
  for (const Vec3& x : other.X) two.X.push_back(x);
  for (Quad9 q : other.elements) {
    for (int& n : q) n += off;
    two.elements.push_back(reverse(q));
  }
  two.elements.back() = reverse(two.elements.back());  // second component: element 1 reversed, 2 not
  EXPECT_EQ(orient_consistently(two), 1);
  const auto p = initial_normals(two);
  EXPECT_NEAR((p[0] - Vec3::UnitZ()).norm(), 0.0, 1e-15);
  EXPECT_NEAR((p[off] + Vec3::UnitZ()).norm(), 0.0, 1e-15);
  EXPECT_NO_THROW(check_orientation(two, p));
}

TEST(OrientConsistently, RejectsMoebiusStripAndNonManifoldEdges) {
  // Moebius strip: 6 elements around, half-cell grid I = 0..12 (periodic with a twist), J = 0..2.
  const int ne = 6, NI = 2 * ne;
  Mesh m;
  auto id = [&](int I, int J) {
    if (I == NI) return 0 * 3 + (2 - J);  // the seam is glued with the width reversed
    return I * 3 + J;
  };
  for (int I = 0; I < NI; ++I)
    for (int J = 0; J < 3; ++J) {
      const double t = 2 * kPi * I / NI, w = 0.5 * (J - 1);
      m.X.emplace_back((3 + w * std::cos(t / 2)) * std::cos(t), (3 + w * std::cos(t / 2)) * std::sin(t),
                       w * std::sin(t / 2));
    }
  constexpr int dI[9] = {0, 2, 2, 0, 1, 2, 1, 0, 1}, dJ[9] = {0, 0, 2, 2, 0, 1, 2, 1, 1};
  for (int e = 0; e < ne; ++e) {
    Quad9 q;
    for (int k = 0; k < 9; ++k) q[k] = id(2 * e + dI[k], dJ[k]);
    m.elements.push_back(q);
  }
  EXPECT_NE(message_of([&] { orient_consistently(m); }).find("not orientable"), std::string::npos);

  Mesh fan = make_rectangle(2.0, 1.0, 2, 1);  // a third element on the shared edge
  Quad9 extra = fan.elements[0];
  fan.elements.push_back(extra);
  EXPECT_NE(message_of([&] { orient_consistently(fan); }).find("non-manifold"), std::string::npos);
}

TEST(CheckOrientation, ThrowsForAFoldedMesh) {
  // A flat 2x1 strip whose right element is folded over onto itself: its free edge 2-3 (mid-side
  // node 6) is pulled back across the element centre, X = 1.2 < 1.5. The quad9 map then reverses
  // orientation near that edge: X,xi at node 6 = 0.5 X8 - 2 X9 + 1.5 X6 = (1 - 3 + 1.8, 0, 0) points
  // along -X, so the nodal normal there is -Z while the diagonal triad still gives e_z0 = +Z.
  Mesh m = make_rectangle(2.0, 1.0, 2, 1);
  const int node6 = m.elements[1][5];
  m.X[node6] = Vec3(1.2, 0.5, 0.0);
  const auto p = initial_normals(m);
  EXPECT_NEAR((p[node6] + Vec3::UnitZ()).norm(), 0.0, 1e-15);
  const std::string msg = message_of([&] { check_orientation(m, p); });
  EXPECT_NE(msg.find("element 1 (0-based), local node 6, mesh node " + std::to_string(node6)),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("e_z0 . p_i0 = -1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("folded"), std::string::npos) << msg;
  // The same node only moved inward to X = 1.8 keeps a positive Jacobian: accepted.
  m.X[node6] = Vec3(1.8, 0.5, 0.0);
  EXPECT_NO_THROW(check_orientation(m, initial_normals(m)));
}

TEST(CheckOrientation, AcceptsStronglyCurvedElementsAndRejectsWrongInput) {
  // One quad9 on a 160 deg arc (radius 1, axis along X): the end normals make 80 deg with e_z0,
  // still positive; the check must not be over-strict for coarse curved meshes.
  Mesh m;
  for (int J = 0; J < 3; ++J)
    for (int I = 0; I < 3; ++I) {
      const double psi = 80.0 * kPi / 180.0 * (J - 1);
      m.X.emplace_back(0.5 * I, std::sin(psi), std::cos(psi));
    }
  auto id = [](int I, int J) { return 3 * J + I; };
  m.elements.push_back(
      {id(0, 0), id(2, 0), id(2, 2), id(0, 2), id(1, 0), id(2, 1), id(1, 2), id(0, 1), id(1, 1)});
  const auto p = initial_normals(m);
  EXPECT_NO_THROW(check_orientation(m, p));
  EXPECT_NE(message_of([&] { check_orientation(m, {}); }).find("got 0 normals"), std::string::npos);
  Mesh flipped = m;
  flipped.elements[0] = reverse(flipped.elements[0]);
  // Normals of the original numbering against the reversed element: every node fails, first node 1.
  EXPECT_NE(message_of([&] { check_orientation(flipped, p); }).find("local node 1"), std::string::npos);
}

}  // namespace
}  // namespace shelldyn
