// Bad input is rejected with exceptions that say what and where (docs/theory.md §2.1 guard, §2.4 orientation).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "element_fixtures.hpp"
#include "elements/corotational_frame.hpp"

namespace shelldyn::testing {
namespace {

template <class Ex, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const Ex& e) {
    return e.what();
  }
  return "<no exception>";
}

// A frame built without the directors' derivatives (end points of a strain-averaged step) gives the same local
// variables as a full frame, and refuses what needs its derivatives instead of using unset data.
TEST(CR9Errors, FrameWithoutDirectorDerivativesRefusesDerivatives) {
  const Geometry g = make_geometry(Shape::Distorted, Facing::Y);
  std::array<DirectorChart, 9> ch;
  std::array<Eigen::Matrix<double, 3, 2>, 9> A1;
  std::array<Eigen::Matrix2d, 9> d2;
  for (int i = 0; i < 9; ++i) {
    ch[static_cast<size_t>(i)] = select_chart(g.p0[static_cast<size_t>(i)]);
    const Eigen::Vector2d q = chart_coordinates(g.p0[static_cast<size_t>(i)], ch[static_cast<size_t>(i)]);
    A1[static_cast<size_t>(i)] = director_A1(q, ch[static_cast<size_t>(i)]);
    d2[static_cast<size_t>(i)] = director_d2pl(q, ch[static_cast<size_t>(i)]);
  }
  const CorotationalFrame full(g.X0, g.p0, A1, d2, ch), light(g.X0, g.p0, ch);
  EXPECT_EQ((full.local_variables(g.X0) - light.local_variables(g.X0)).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NO_THROW(full.matrix());
  const std::string msg = message_of<std::logic_error>([&] { light.matrix(); });
  EXPECT_NE(msg.find("local_variables() only"), std::string::npos) << msg;
  EXPECT_THROW(light.apply_transpose(CorotationalFrame::Vec45::Ones()), std::logic_error);
}

TEST(CR9Errors, OrientationCheckNamesTheNode) {
  Geometry g = make_geometry(Shape::Cylinder, Facing::Z);
  g.p0[6] = -g.p0[6];  // node 7 normal flipped
  const std::string msg = message_of<std::invalid_argument>([&] { CR9Shell e(g.X0, g.p0, test_material()); });
  EXPECT_NE(msg.find("node 7"), std::string::npos) << msg;
  EXPECT_NE(msg.find("orientation"), std::string::npos) << msg;
  // Clockwise numbering: all normals point against e_z0.
  Geometry c = make_geometry(Shape::Flat, Facing::Z);
  for (auto& p : c.p0) p = -p;
  EXPECT_THROW(CR9Shell(c.X0, c.p0, test_material()), std::invalid_argument);
}

TEST(CR9Errors, BadMaterialAndNormalsAreRejected) {
  const Geometry g = make_geometry(Shape::Flat, Facing::Z);
  ShellMaterial m = test_material();
  m.nu = 0.5;
  EXPECT_NE(message_of<std::invalid_argument>([&] { CR9Shell e(g.X0, g.p0, m); }).find("nu"), std::string::npos);
  m = test_material();
  m.thickness = 0.0;
  EXPECT_NE(message_of<std::invalid_argument>([&] { CR9Shell e(g.X0, g.p0, m); }).find("thickness"),
            std::string::npos);
  Geometry h = g;
  h.p0[2] *= 1.1;
  EXPECT_NE(message_of<std::invalid_argument>([&] { CR9Shell e(h.X0, h.p0, test_material()); }).find("node 3"),
            std::string::npos);
  Geometry d = g;
  d.X0[2] = d.X0[0];  // collapsed diagonal
  EXPECT_THROW(CR9Shell(d.X0, d.p0, test_material()), std::invalid_argument);
}

TEST(CR9Errors, OvershootingDirectorThrowsDomainError) {
  const Geometry g = make_geometry(Shape::Flat, Facing::Z);
  const CR9Shell e(g.X0, g.p0, test_material());
  const Charts ch = initial_charts(g);
  Vec45 u = Vec45::Zero();
  for (int k = 0; k < 9; ++k) u.segment<2>(5 * k + 3) = chart_coordinates(g.p0[k], ch[k]);
  u.segment<2>(5 * 4 + 3) = Eigen::Vector2d(0.9, 0.6);  // 1 - |q|^2 < 0 at node 5
  Vec45 F;
  EXPECT_THROW(e.internal(u, ch, &F, nullptr), std::domain_error);
  EXPECT_THROW(e.algorithmic_internal(u, u, ch, 0.5, 0.0, &F, nullptr), std::domain_error);
  EXPECT_THROW(e.algorithmic_internal(Vec45::Zero(), Vec45::Zero(), ch, 1.5, 0.0, &F, nullptr),
               std::invalid_argument);
}

}  // namespace
}  // namespace shelldyn::testing
