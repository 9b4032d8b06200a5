// DOF numbering with constraints, including director constraints that follow chart switches
// (docs/theory.md §2.3 item 2).
#include "lib/model/dof_map.hpp"

#include <gtest/gtest.h>

namespace shelldyn {
namespace {

TEST(DofMap, FreeNumberingSkipsConstrainedDofs) {
  DofMap dofs(3);
  dofs.fix(1, Fix::Uy);
  dofs.fix(1, Fix::Uy);  // duplicate ignored
  dofs.fix(2, Fix::Director);
  dofs.resolve(std::vector<DirectorChart>(3));
  EXPECT_EQ(dofs.num_dofs(), 15);
  EXPECT_EQ(dofs.num_constrained(), 3);
  EXPECT_EQ(dofs.num_free(), 12);
  EXPECT_EQ(dofs.constrained_dofs(), (std::vector<Index>{6, 13, 14}));
  EXPECT_EQ(dofs.free_index(5), 5);
  EXPECT_EQ(dofs.free_index(6), -1);
  EXPECT_EQ(dofs.free_index(7), 6);
  EXPECT_EQ(dofs.free_index(12), 11);
}

TEST(DofMap, DirectorComponentConstraintFollowsTheChart) {
  DofMap dofs(1);
  dofs.fix(0, Fix::Py);  // symmetry plane Y = 0: p_y = 0 is always a minor component
  DirectorChart z{0, 1, 2, 1.0};  // l = Z: q = (p_x, p_y) -> p_y in slot q_2
  dofs.resolve({z});
  EXPECT_EQ(dofs.constrained_dofs(), (std::vector<Index>{4}));
  DirectorChart x{1, 2, 0, 1.0};  // l = X: q = (p_y, p_z) -> p_y in slot q_1
  dofs.resolve({x});
  EXPECT_EQ(dofs.constrained_dofs(), (std::vector<Index>{3}));
  DirectorChart y{0, 2, 1, 1.0};  // l = Y: p_y is the dependent component -> error
  EXPECT_THROW(dofs.resolve({y}), std::runtime_error);
}

TEST(DofMap, ParsesNamesAndRejectsUnknownOnes) {
  EXPECT_EQ(parse_fix("uz"), Fix::Uz);
  EXPECT_EQ(parse_fix("director"), Fix::Director);
  EXPECT_THROW(parse_fix("rx"), std::invalid_argument);
  DofMap dofs(2);
  EXPECT_THROW(dofs.fix(2, Fix::Ux), std::out_of_range);
}

}  // namespace
}  // namespace shelldyn
