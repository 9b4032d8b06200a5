// Nodal director (unit normal) parametrised by its two minor components (spec/element.md §2).
// Owned by the element kernels; this header is extended with p(q), A1, A2 and the re-charting maps.
#pragma once

namespace shelldyn {

// Choice record ch = (n, m, l, s) of spec/element.md §2.1: n < m are the global components stored
// as the nodal unknowns q = (p_n, p_m); l is the dependent (largest) component, s = sign(p_l).
struct DirectorChart {
  int n = 0;
  int m = 1;
  int l = 2;
  double s = 1.0;
};

}  // namespace shelldyn
