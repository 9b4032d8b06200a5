// Structured quad9 meshes (docs/benchmarks.md §§1.3, 2.3, 3.2, 4.4).
//
// Every generator works on a grid of "half-cell" node indices (I, J): element (i, j) owns the nodes
// (2i + dI_k, 2j + dJ_k) for its 9 local nodes k (Gmsh type-10 order). Shared nodes are merged by
// construction through the index map (I, J) -> node, never by a coordinate tolerance search, and
// every node is placed on the exact surface (mid-side and centre nodes included), not on chords.
// The parameter direction I (-> xi) and J (-> eta) are chosen so that X,xi x X,eta points to the
// documented normal side, i.e. corners run counter-clockwise seen from there (docs/theory.md §2.4).
#include "lib/mesh/mesh_generators.hpp"
#include "lib/io/result_folder.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>

namespace shelldyn {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Half-cell offsets of the 9 local nodes (docs/theory.md §1: (xi, eta) = (dI - 1, dJ - 1)).
constexpr int kDI[9] = {0, 2, 2, 0, 1, 2, 1, 0, 1};
constexpr int kDJ[9] = {0, 0, 2, 2, 0, 1, 2, 1, 1};

[[noreturn]] void bad_parameter(const std::string& generator, const std::string& what) {
  throw std::invalid_argument(generator + ": " + what);
}

std::string str(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

void require_positive(const std::string& gen, const char* name, double v) {
  if (!(std::isfinite(v) && v > 0.0))
    bad_parameter(gen, std::string("parameter '") + name + "' = " + str(v) +
                           " is invalid; it must be a finite number > 0");
}

void require_finite(const std::string& gen, const char* name, double v) {
  if (!std::isfinite(v))
    bad_parameter(gen, std::string("parameter '") + name + "' = " + str(v) + " must be finite");
}

void require_count(const std::string& gen, const char* name, int v) {
  if (v < 1)
    bad_parameter(gen, std::string("parameter '") + name + "' = " + std::to_string(v) +
                           " is invalid; it must be an integer >= 1");
}

// Node indices are int (Mesh contract); reject grids whose node count would overflow.
void require_int_nodes(const std::string& gen, std::int64_t nodes) {
  if (nodes > static_cast<std::int64_t>(INT_MAX) / 8)
    bad_parameter(gen, "the requested mesh would have " + std::to_string(nodes) +
                           " nodes, more than the supported " + std::to_string(INT_MAX / 8) +
                           "; reduce the element counts");
  // Before the node arrays are allocated (lib/io/result_folder.hpp): a grid of quad9 elements has ~nodes/4 elements.
  try {
    check_memory_estimate(nodes, nodes / 4, "", "reduce the element counts");
  } catch (const std::runtime_error& e) {
    bad_parameter(gen, e.what());
  }
}

// (1 - t) a + t b: returns a at t = 0 and b at t = 1 exactly (boundary coordinates are exact).
double lerp(double a, double b, double t) {
  return (1.0 - t) * a + t * b;
}

// cos and sin of an angle in degrees, exact at multiples of 90 deg so that nodes on the symmetry
// planes, the equator and the axes have exact zero coordinates.
void cos_sin_deg(double deg, double& c, double& s) {
  const double q = deg / 90.0;
  if (q == std::floor(q) && std::fabs(q) < 1e9) {
    static constexpr double kC[4] = {1.0, 0.0, -1.0, 0.0};
    static constexpr double kS[4] = {0.0, 1.0, 0.0, -1.0};
    const int k = ((static_cast<int>(q) % 4) + 4) % 4;
    c = kC[k];
    s = kS[k];
    return;
  }
  const double r = deg * (kPi / 180.0);
  c = std::cos(r);
  s = std::sin(r);
}

std::vector<int> iota_vector(int n) {
  std::vector<int> v(static_cast<size_t>(n));
  std::iota(v.begin(), v.end(), 0);
  return v;
}

void sort_unique(std::vector<int>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// Elements of an ne_i x ne_j structured patch; node_id(I, J) maps half-cell indices to nodes.
template <class NodeId>
void add_grid_elements(Mesh& m, int ne_i, int ne_j, NodeId node_id) {
  for (int j = 0; j < ne_j; ++j)
    for (int i = 0; i < ne_i; ++i) {
      Quad9 q;
      for (int k = 0; k < 9; ++k) q[k] = node_id(2 * i + kDI[k], 2 * j + kDJ[k]);
      m.elements.push_back(q);
    }
}

void add_all_sets(Mesh& m) {
  m.node_sets["all"] = iota_vector(m.num_nodes());
  m.element_sets["all"] = iota_vector(m.num_elements());
}

}  // namespace

Mesh make_rectangle(double a, double b, int nx, int ny, double x0, double y0) {
  const std::string gen = "make_rectangle";
  require_positive(gen, "a", a);
  require_positive(gen, "b", b);
  require_count(gen, "nx", nx);
  require_count(gen, "ny", ny);
  require_finite(gen, "x0", x0);
  require_finite(gen, "y0", y0);
  const std::int64_t NI = 2 * static_cast<std::int64_t>(nx) + 1;
  const std::int64_t NJ = 2 * static_cast<std::int64_t>(ny) + 1;
  require_int_nodes(gen, NI * NJ);

  Mesh m;
  const int ni = static_cast<int>(NI), nj = static_cast<int>(NJ);
  auto id = [ni](int I, int J) { return J * ni + I; };
  m.X.resize(static_cast<size_t>(ni) * nj);
  // I runs along +X (xi), J along +Y (eta): X,xi x X,eta = +Z, the documented normal.
  for (int J = 0; J < nj; ++J)
    for (int I = 0; I < ni; ++I)
      m.X[id(I, J)] =
          Vec3(lerp(x0, x0 + a, double(I) / (ni - 1)), lerp(y0, y0 + b, double(J) / (nj - 1)), 0.0);
  add_grid_elements(m, nx, ny, id);

  auto& left = m.node_sets["left"];
  auto& right = m.node_sets["right"];
  for (int J = 0; J < nj; ++J) {
    left.push_back(id(0, J));
    right.push_back(id(ni - 1, J));
  }
  auto& bottom = m.node_sets["bottom"];
  auto& top = m.node_sets["top"];
  for (int I = 0; I < ni; ++I) {
    bottom.push_back(id(I, 0));
    top.push_back(id(I, nj - 1));
  }
  m.node_sets["corner_ll"] = {id(0, 0)};
  m.node_sets["corner_lr"] = {id(ni - 1, 0)};
  m.node_sets["corner_ur"] = {id(ni - 1, nj - 1)};
  m.node_sets["corner_ul"] = {id(0, nj - 1)};
  for (auto& kv : m.node_sets) sort_unique(kv.second);
  add_all_sets(m);
  return m;
}

Mesh make_cell_union(const std::vector<std::array<int, 4>>& rectangles, double cell) {
  const std::string gen = "make_cell_union";
  require_positive(gen, "cell", cell);
  if (rectangles.empty())
    bad_parameter(gen, "parameter 'rectangles' is empty; give at least one cell rectangle {i0, j0, i1, j1}");
  std::int64_t i_min = INT64_MAX, j_min = INT64_MAX, i_max = INT64_MIN, j_max = INT64_MIN;
  for (size_t r = 0; r < rectangles.size(); ++r) {
    const auto& R = rectangles[r];
    if (!(R[2] > R[0] && R[3] > R[1]))
      bad_parameter(gen, "rectangles[" + std::to_string(r) + "] = {" + std::to_string(R[0]) + ", " +
                             std::to_string(R[1]) + ", " + std::to_string(R[2]) + ", " +
                             std::to_string(R[3]) + "} is empty; it must satisfy i1 > i0 and j1 > j0");
    i_min = std::min<std::int64_t>(i_min, R[0]);
    j_min = std::min<std::int64_t>(j_min, R[1]);
    i_max = std::max<std::int64_t>(i_max, R[2]);
    j_max = std::max<std::int64_t>(j_max, R[3]);
  }
  const std::int64_t nci64 = i_max - i_min, ncj64 = j_max - j_min;  // bounding box in cells
  if (nci64 * ncj64 > 10'000'000)
    bad_parameter(gen, "the bounding box of 'rectangles' spans " + std::to_string(nci64) + " x " +
                           std::to_string(ncj64) + " cells, more than the supported 1e7 cells");
  const int nci = static_cast<int>(nci64), ncj = static_cast<int>(ncj64);

  // Cell occupancy: owner rectangle index, -1 = empty. Overlaps are detected cell by cell.
  std::vector<int> owner(static_cast<size_t>(nci) * ncj, -1);
  auto cell_at = [&](int i, int j) -> int& { return owner[static_cast<size_t>(j) * nci + i]; };
  for (size_t r = 0; r < rectangles.size(); ++r) {
    const auto& R = rectangles[r];
    for (int j = int(R[1] - j_min); j < int(R[3] - j_min); ++j)
      for (int i = int(R[0] - i_min); i < int(R[2] - i_min); ++i) {
        int& o = cell_at(i, j);
        if (o >= 0)
          bad_parameter(gen, "rectangles[" + std::to_string(o) + "] and rectangles[" + std::to_string(r) +
                                 "] overlap (both contain cell (" + std::to_string(i + i_min) + ", " +
                                 std::to_string(j + j_min) + ")); rectangles must be disjoint");
        o = static_cast<int>(r);
      }
  }

  // Edge connectivity of the union (breadth-first search over occupied cells).
  {
    std::vector<char> seen(owner.size(), 0);
    std::vector<int> queue;
    int start = -1, n_occupied = 0;
    for (size_t c = 0; c < owner.size(); ++c)
      if (owner[c] >= 0) {
        ++n_occupied;
        if (start < 0) start = static_cast<int>(c);
      }
    queue.push_back(start);
    seen[start] = 1;
    int reached = 0;
    for (size_t head = 0; head < queue.size(); ++head) {
      const int c = queue[head];
      ++reached;
      const int i = c % nci, j = c / nci;
      const int ni[4] = {i - 1, i + 1, i, i};
      const int nj[4] = {j, j, j - 1, j + 1};
      for (int k = 0; k < 4; ++k) {
        if (ni[k] < 0 || ni[k] >= nci || nj[k] < 0 || nj[k] >= ncj) continue;
        const int d = nj[k] * nci + ni[k];
        if (owner[d] >= 0 && !seen[d]) {
          seen[d] = 1;
          queue.push_back(d);
        }
      }
    }
    if (reached != n_occupied) {
      int lost = -1;
      for (size_t c = 0; c < owner.size() && lost < 0; ++c)
        if (owner[c] >= 0 && !seen[c]) lost = owner[c];
      bad_parameter(gen, "the rectangles do not form one edge-connected region (rectangles[" +
                             std::to_string(lost) + "] is not connected to rectangles[" +
                             std::to_string(owner[start]) +
                             "] through shared cell edges); meshes must be connected");
    }
  }

  // Half-cell node grid: a node exists iff one of the (up to 4) cells touching it is occupied.
  const int NI = 2 * nci + 1, NJ = 2 * ncj + 1;
  std::vector<int> node_of(static_cast<size_t>(NI) * NJ, -1);
  auto occupied = [&](int i, int j) { return i >= 0 && i < nci && j >= 0 && j < ncj && cell_at(i, j) >= 0; };
  Mesh m;
  for (int J = 0; J < NJ; ++J)
    for (int I = 0; I < NI; ++I) {
      // Cells touching half-cell node (I, J): i in {floor((I-1)/2), floor(I/2)}, likewise j.
      const int ia = (I - 1) >= 0 ? (I - 1) / 2 : -1, ib = I / 2;
      const int ja = (J - 1) >= 0 ? (J - 1) / 2 : -1, jb = J / 2;
      if (occupied(ia, ja) || occupied(ia, jb) || occupied(ib, ja) || occupied(ib, jb)) {
        node_of[static_cast<size_t>(J) * NI + I] = m.num_nodes();
        m.X.emplace_back((double(i_min) + 0.5 * I) * cell, (double(j_min) + 0.5 * J) * cell, 0.0);
      }
    }
  auto id = [&](int I, int J) { return node_of[static_cast<size_t>(J) * NI + I]; };
  // One element per occupied cell, in row-major cell order; normal +Z as for make_rectangle.
  for (int j = 0; j < ncj; ++j)
    for (int i = 0; i < nci; ++i) {
      if (!occupied(i, j)) continue;
      Quad9 q;
      for (int k = 0; k < 9; ++k) q[k] = id(2 * i + kDI[k], 2 * j + kDJ[k]);
      m.elements.push_back(q);
    }

  // "boundary": the 3 nodes of every cell edge that has no occupied neighbour across it.
  auto& boundary = m.node_sets["boundary"];
  for (int j = 0; j < ncj; ++j)
    for (int i = 0; i < nci; ++i) {
      if (!occupied(i, j)) continue;
      const int I = 2 * i, J = 2 * j;
      if (!occupied(i, j - 1))
        for (int d = 0; d <= 2; ++d) boundary.push_back(id(I + d, J));
      if (!occupied(i, j + 1))
        for (int d = 0; d <= 2; ++d) boundary.push_back(id(I + d, J + 2));
      if (!occupied(i - 1, j))
        for (int d = 0; d <= 2; ++d) boundary.push_back(id(I, J + d));
      if (!occupied(i + 1, j))
        for (int d = 0; d <= 2; ++d) boundary.push_back(id(I + 2, J + d));
    }
  sort_unique(boundary);
  add_all_sets(m);
  return m;
}

Mesh make_cylindrical_panel(double radius, double angle, double length, int n_arc, int n_axial) {
  const std::string gen = "make_cylindrical_panel";
  require_positive(gen, "radius", radius);
  require_positive(gen, "length", length);
  require_count(gen, "n_arc", n_arc);
  require_count(gen, "n_axial", n_axial);
  if (!(std::isfinite(angle) && angle > 0.0 && angle < 2.0 * kPi))
    bad_parameter(gen, "parameter 'angle' = " + str(angle) + " rad is invalid; it must lie in (0, 2*pi)");
  // Each element must be far from folded for the diagonal triad (docs/theory.md §2.4).
  if (!(angle / n_arc < kPi))
    bad_parameter(gen, "each element spans angle/n_arc = " + str(angle / n_arc) +
                           " rad; it must be < pi: increase 'n_arc'");
  const std::int64_t NI = 2 * static_cast<std::int64_t>(n_axial) + 1;
  const std::int64_t NJ = 2 * static_cast<std::int64_t>(n_arc) + 1;
  require_int_nodes(gen, NI * NJ);

  Mesh m;
  const int ni = static_cast<int>(NI), nj = static_cast<int>(NJ);
  auto id = [ni](int I, int J) { return J * ni + I; };
  m.X.resize(static_cast<size_t>(ni) * nj);
  // I -> X (xi), J -> psi (eta): e_X x d/dpsi (0, cos psi, -sin psi) = (0, sin psi, cos psi), i.e.
  // the outward radial direction, away from the axis at (x, 0, -R) (docs/benchmarks.md §2.3).
  for (int J = 0; J < nj; ++J) {
    // psi = angle (2J - (nj-1)) / (2 (nj-1)): exact 0 at the apex and exactly antisymmetric.
    const double psi = angle * double(2 * J - (nj - 1)) / double(2 * (nj - 1));
    const double y = radius * std::sin(psi);
    const double z = radius * std::cos(psi) - radius;
    for (int I = 0; I < ni; ++I) m.X[id(I, J)] = Vec3(lerp(0.0, length, double(I) / (ni - 1)), y, z);
  }
  add_grid_elements(m, n_axial, n_arc, id);

  auto& x0 = m.node_sets["x0"];
  auto& x1 = m.node_sets["x1"];
  for (int J = 0; J < nj; ++J) {
    x0.push_back(id(0, J));
    x1.push_back(id(ni - 1, J));
  }
  auto& amin = m.node_sets["arc_min"];
  auto& amax = m.node_sets["arc_max"];
  for (int I = 0; I < ni; ++I) {
    amin.push_back(id(I, 0));
    amax.push_back(id(I, nj - 1));
  }
  m.node_sets["corner_x0_arcmin"] = {id(0, 0)};
  m.node_sets["corner_x0_arcmax"] = {id(0, nj - 1)};
  m.node_sets["corner_x1_arcmin"] = {id(ni - 1, 0)};
  m.node_sets["corner_x1_arcmax"] = {id(ni - 1, nj - 1)};
  for (auto& kv : m.node_sets) sort_unique(kv.second);
  add_all_sets(m);
  return m;
}

Mesh make_hemisphere(double radius, double hole_deg, bool quarter, int n) {
  const std::string gen = "make_hemisphere";
  require_positive(gen, "radius", radius);
  require_count(gen, "n", n);
  // hole = 0 would collapse the first element row into the pole (degenerate quads, no normal).
  if (!(std::isfinite(hole_deg) && hole_deg > 0.0 && hole_deg < 90.0))
    bad_parameter(gen, "parameter 'hole_deg' = " + str(hole_deg) +
                           " is invalid; it must lie in (0, 90) degrees (a closed pole is not supported)");
  const int n_phi_el = quarter ? n : 4 * n;                                               // elements around
  const std::int64_t NI64 = 2 * static_cast<std::int64_t>(n) + 1;                         // nodes along chi
  const std::int64_t NJ64 = 2 * static_cast<std::int64_t>(n_phi_el) + (quarter ? 1 : 0);  // nodes along phi
  require_int_nodes(gen, NI64 * NJ64);
  const int ni = static_cast<int>(NI64), nj = static_cast<int>(NJ64);
  const int n_phi_steps = 2 * n_phi_el;  // half-cell steps around
  const double phi_span = quarter ? 90.0 : 360.0;

  Mesh m;
  // Full model: phi is periodic, half-cell index J = n_phi_steps is the node at J = 0.
  auto id = [ni, nj](int I, int J) { return (J % nj) * ni + I; };
  m.X.resize(static_cast<size_t>(ni) * nj);
  // I -> chi from the hole to the equator (xi), J -> phi (eta): e_chi x e_phi = +e_r (outward).
  for (int J = 0; J < nj; ++J) {
    double cp, sp;
    cos_sin_deg(phi_span * double(J) / double(n_phi_steps), cp, sp);  // exact at multiples of 90 deg
    for (int I = 0; I < ni; ++I) {
      double cc, sc;
      cos_sin_deg(lerp(hole_deg, 90.0, double(I) / (ni - 1)), cc, sc);
      m.X[id(I, J)] = Vec3(radius * sc * cp, radius * sc * sp, radius * cc);
    }
  }
  add_grid_elements(m, n, n_phi_el, id);

  const int eq = ni - 1;
  auto& equator = m.node_sets["equator"];
  auto& hole = m.node_sets["hole"];
  for (int J = 0; J < nj; ++J) {
    equator.push_back(id(eq, J));
    hole.push_back(id(0, J));
  }
  // phi = 90 deg sits at half-cell index n_phi_steps / 4 (full) or at the end (quarter).
  const int J90 = quarter ? nj - 1 : n_phi_steps / 4;
  m.node_sets["point_xpos"] = {id(eq, 0)};
  m.node_sets["point_ypos"] = {id(eq, J90)};
  if (quarter) {
    auto& sy = m.node_sets["sym_y0"];
    auto& sx = m.node_sets["sym_x0"];
    for (int I = 0; I < ni; ++I) {
      sy.push_back(id(I, 0));
      sx.push_back(id(I, J90));
    }
  } else {
    m.node_sets["point_xneg"] = {id(eq, 2 * J90)};
    m.node_sets["point_yneg"] = {id(eq, 3 * J90)};
  }
  for (auto& kv : m.node_sets) sort_unique(kv.second);
  add_all_sets(m);
  return m;
}

}  // namespace shelldyn

namespace shelldyn {

Mesh make_cylinder_patch(double radius, double angle, double length, int n_arc, int n_axial) {
  const std::string gen = "make_cylinder_patch";
  require_positive(gen, "radius", radius);
  require_positive(gen, "length", length);
  require_count(gen, "n_arc", n_arc);
  require_count(gen, "n_axial", n_axial);
  if (!(std::isfinite(angle) && angle > 0.0 && angle <= kPi))
    bad_parameter(gen, "parameter 'angle' = " + str(angle) + " rad is invalid; it must lie in (0, pi]");
  if (!(angle / n_arc < kPi / 2))
    bad_parameter(gen, "each element spans angle/n_arc = " + str(angle / n_arc) + " rad; it must be < pi/2: increase 'n_arc'");
  const std::int64_t NI = 2 * static_cast<std::int64_t>(n_axial) + 1, NJ = 2 * static_cast<std::int64_t>(n_arc) + 1;
  require_int_nodes(gen, NI * NJ);
  Mesh m;
  const int ni = static_cast<int>(NI), nj = static_cast<int>(NJ);
  auto id = [ni](int I, int J) { return J * ni + I; };
  m.X.resize(static_cast<size_t>(ni) * nj);
  // I -> X, J -> psi: e_X x (0, cos psi, -sin psi) = (0, sin psi, cos psi), the outward radial direction.
  for (int J = 0; J < nj; ++J) {
    const double psi = angle * double(J) / double(nj - 1);
    const double y = J == 0 ? 0.0 : radius * std::sin(psi), z = radius * std::cos(psi);
    for (int I = 0; I < ni; ++I) m.X[id(I, J)] = Vec3(lerp(0.0, length, double(I) / (ni - 1)), y, z);
  }
  add_grid_elements(m, n_axial, n_arc, id);
  auto& x0 = m.node_sets["x0"];
  auto& x1 = m.node_sets["x1"];
  for (int J = 0; J < nj; ++J) {
    x0.push_back(id(0, J));
    x1.push_back(id(ni - 1, J));
  }
  auto& a0 = m.node_sets["arc0"];
  auto& a1 = m.node_sets["arc1"];
  for (int I = 0; I < ni; ++I) {
    a0.push_back(id(I, 0));
    a1.push_back(id(I, nj - 1));
  }
  m.node_sets["corner_x0_arc0"] = {id(0, 0)};
  m.node_sets["corner_x0_arc1"] = {id(0, nj - 1)};
  m.node_sets["corner_x1_arc0"] = {id(ni - 1, 0)};
  m.node_sets["corner_x1_arc1"] = {id(ni - 1, nj - 1)};
  for (auto& kv : m.node_sets) sort_unique(kv.second);
  add_all_sets(m);
  return m;
}

Mesh make_closed_cylinder(double radius, double length, int n_circ, int n_axial) {
  const std::string gen = "make_closed_cylinder";
  require_positive(gen, "radius", radius);
  require_positive(gen, "length", length);
  require_count(gen, "n_axial", n_axial);
  if (n_circ < 4) bad_parameter(gen, "parameter 'n_circ' = " + std::to_string(n_circ) + " is invalid; it must be >= 4");
  const std::int64_t NI = 2 * static_cast<std::int64_t>(n_axial) + 1, NJ = 2 * static_cast<std::int64_t>(n_circ);
  require_int_nodes(gen, NI * NJ);
  Mesh m;
  const int ni = static_cast<int>(NI), nj = static_cast<int>(NJ);
  auto id = [ni, nj](int I, int J) { return (J % nj) * ni + I; };  // the seam theta = 2 pi is theta = 0
  m.X.resize(static_cast<size_t>(ni) * nj);
  for (int J = 0; J < nj; ++J) {
    const double th = 2.0 * kPi * double(J) / double(nj);
    for (int I = 0; I < ni; ++I)
      m.X[id(I, J)] = Vec3(lerp(0.0, length, double(I) / (ni - 1)), radius * std::sin(th), radius * std::cos(th));
  }
  add_grid_elements(m, n_axial, n_circ, id);
  auto& x0 = m.node_sets["x0"];
  auto& x1 = m.node_sets["x1"];
  for (int J = 0; J < nj; ++J) {
    x0.push_back(id(0, J));
    x1.push_back(id(ni - 1, J));
  }
  auto& top = m.node_sets["top"];
  for (int I = 0; I < ni; ++I) top.push_back(id(I, 0));
  if (nj % 2 == 0) {
    auto& bottom = m.node_sets["bottom"];
    for (int I = 0; I < ni; ++I) bottom.push_back(id(I, nj / 2));
  }
  for (auto& kv : m.node_sets) sort_unique(kv.second);
  add_all_sets(m);
  return m;
}

Mesh make_slit_annulus(double r_inner, double r_outer, int n_radial, int n_circ) {
  const std::string gen = "make_slit_annulus";
  require_positive(gen, "r_inner", r_inner);
  require_positive(gen, "r_outer", r_outer);
  require_count(gen, "n_radial", n_radial);
  if (!(r_outer > r_inner)) bad_parameter(gen, "needs r_outer > r_inner (got " + str(r_inner) + ", " + str(r_outer) + ")");
  if (n_circ < 3) bad_parameter(gen, "parameter 'n_circ' = " + std::to_string(n_circ) + " is invalid; it must be >= 3");
  const std::int64_t NI = 2 * static_cast<std::int64_t>(n_radial) + 1, NJ = 2 * static_cast<std::int64_t>(n_circ) + 1;
  require_int_nodes(gen, NI * NJ);
  Mesh m;
  const int ni = static_cast<int>(NI), nj = static_cast<int>(NJ);
  auto id = [ni](int I, int J) { return J * ni + I; };
  m.X.resize(static_cast<size_t>(ni) * nj);
  // I -> r, J -> theta in [0, 2 pi]: e_r x e_theta = +Z. The slit edges theta = 0 and 2 pi are separate nodes.
  for (int J = 0; J < nj; ++J) {
    const double th = 2.0 * kPi * double(J) / double(nj - 1);
    const double c = J == nj - 1 ? 1.0 : std::cos(th), s = (J == 0 || J == nj - 1) ? 0.0 : std::sin(th);
    for (int I = 0; I < ni; ++I) {
      const double r = lerp(r_inner, r_outer, double(I) / (ni - 1));
      m.X[id(I, J)] = Vec3(r * c, r * s, 0.0);
    }
  }
  add_grid_elements(m, n_radial, n_circ, id);
  auto& s0 = m.node_sets["slit_start"];
  auto& s1 = m.node_sets["slit_end"];
  for (int I = 0; I < ni; ++I) {
    s0.push_back(id(I, 0));
    s1.push_back(id(I, nj - 1));
  }
  auto& in = m.node_sets["inner"];
  auto& out = m.node_sets["outer"];
  for (int J = 0; J < nj; ++J) {
    in.push_back(id(0, J));
    out.push_back(id(ni - 1, J));
  }
  m.node_sets["point_A"] = {id(0, nj - 1)};
  m.node_sets["point_B"] = {id(ni - 1, nj - 1)};
  for (auto& kv : m.node_sets) sort_unique(kv.second);
  add_all_sets(m);
  return m;
}

}  // namespace shelldyn
