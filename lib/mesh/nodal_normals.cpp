// Initial nodal normals, orientation and area of quad9 meshes (docs/theory.md §§1, 2.4, 3.1).
#include "lib/mesh/nodal_normals.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace shelldyn {
namespace {

// Natural coordinates of the 9 nodes (docs/theory.md §1).
constexpr double kXi[9] = {-1, 1, 1, -1, 0, 1, 0, -1, 0};
constexpr double kEta[9] = {-1, -1, 1, 1, -1, 0, 1, 0, 0};

// 1D quadratic Lagrange polynomials on nodes -1, 0, 1 (index 0, 1, 2) and their derivatives.
inline void lagrange3(double s, double L[3], double dL[3]) {
  L[0] = 0.5 * s * (s - 1.0);
  L[1] = 1.0 - s * s;
  L[2] = 0.5 * s * (s + 1.0);
  dL[0] = s - 0.5;
  dL[1] = -2.0 * s;
  dL[2] = s + 0.5;
}

// 1D index (0: -1, 1: 0, 2: +1) of each local node along xi and eta.
constexpr int kIx[9] = {0, 2, 2, 0, 1, 2, 1, 0, 1};
constexpr int kIy[9] = {0, 0, 2, 2, 0, 1, 2, 1, 1};

// Tangent vectors X,xi and X,eta of the quad9 geometry at (xi, eta) (tensor-product shape functions).
void tangents(const Mesh& mesh, const Quad9& el, double xi, double eta, Vec3& g1, Vec3& g2) {
  double Lx[3], dLx[3], Ly[3], dLy[3];
  lagrange3(xi, Lx, dLx);
  lagrange3(eta, Ly, dLy);
  g1.setZero();
  g2.setZero();
  for (int k = 0; k < 9; ++k) {
    const Vec3& X = mesh.X[static_cast<size_t>(el[k])];
    g1 += (dLx[kIx[k]] * Ly[kIy[k]]) * X;
    g2 += (Lx[kIx[k]] * dLy[kIy[k]]) * X;
  }
}

std::string where(int e, int k, int node) {
  std::ostringstream os;
  os << "element " << e << " (0-based), local node " << (k + 1) << ", mesh node " << node;
  return os.str();
}

void check_connectivity(const Mesh& mesh, const char* fn) {
  const int nn = mesh.num_nodes();
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int k = 0; k < 9; ++k) {
      const int n = mesh.elements[static_cast<size_t>(e)][k];
      if (n < 0 || n >= nn)
        throw std::invalid_argument(std::string(fn) + ": " + where(e, k, n) + " is out of range [0, " +
                                    std::to_string(nn) + "); fix the connectivity");
    }
}

// Reversed element: corners (1,2,3,4) -> (1,4,3,2); this swaps xi and eta, so mid-sides
// (5,6,7,8) -> (8,7,6,5) and the centre stays.
Quad9 reversed(const Quad9& q) {
  return {q[0], q[3], q[2], q[1], q[7], q[6], q[5], q[4], q[8]};
}

}  // namespace

std::vector<Vec3> initial_normals(const Mesh& mesh) {
  check_connectivity(mesh, "initial_normals");
  std::vector<Vec3> sum(mesh.X.size(), Vec3::Zero());
  std::vector<int> count(mesh.X.size(), 0);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const Quad9& el = mesh.elements[static_cast<size_t>(e)];
    for (int k = 0; k < 9; ++k) {
      Vec3 g1, g2;
      tangents(mesh, el, kXi[k], kEta[k], g1, g2);
      const Vec3 n = g1.cross(g2);  // paper eq. 7 / docs/theory.md §2.4 step 1
      const double len = n.norm();
      // Relative test: |g1 x g2| against |g1||g2| (scale-free degeneracy check).
      if (!(len > 1e-12 * g1.norm() * g2.norm()) || !std::isfinite(len))
        throw std::invalid_argument("initial_normals: " + where(e, k, el[k]) +
                                    ": X,xi x X,eta vanishes (degenerate or collapsed element); fix the "
                                    "mesh geometry");
      sum[static_cast<size_t>(el[k])] += n / len;  // normalise first (docs/theory.md §2.4 recommendation)
      ++count[static_cast<size_t>(el[k])];
    }
  }
  for (size_t i = 0; i < sum.size(); ++i) {
    if (count[i] == 0)
      throw std::invalid_argument("initial_normals: mesh node " + std::to_string(i) +
                                  " belongs to no element; remove unused nodes from the mesh");
    const double len = sum[i].norm();
    // Unit vectors that cancel to well below 1 per contributor mean opposite element orientations.
    if (!(len > 1e-8 * count[i]))
      throw std::invalid_argument("initial_normals: the element normals at mesh node " + std::to_string(i) +
                                  " cancel: adjacent elements are oriented oppositely (call "
                                  "orient_consistently() first) or the mesh is folded there (out of "
                                  "scope, docs/theory.md §2.4)");
    sum[i] /= len;  // docs/theory.md §2.4 step 2
  }
  return sum;
}

int orient_consistently(Mesh& mesh) {
  check_connectivity(mesh, "orient_consistently");
  const int ne = mesh.num_elements();
  // Edge (sorted corner pair) -> list of (element, direction): direction +1 if the element traverses
  // the edge from the smaller to the larger corner index.
  std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> edges;
  for (int e = 0; e < ne; ++e) {
    const Quad9& q = mesh.elements[static_cast<size_t>(e)];
    for (int k = 0; k < 4; ++k) {
      const int a = q[k], b = q[(k + 1) % 4];
      auto& list = edges[{std::min(a, b), std::max(a, b)}];
      list.emplace_back(e, a < b ? 1 : -1);
      if (list.size() > 2)
        throw std::invalid_argument("orient_consistently: the edge between mesh nodes " + std::to_string(a) +
                                    " and " + std::to_string(b) + " is shared by elements " +
                                    std::to_string(list[0].first) + ", " + std::to_string(list[1].first) +
                                    " and " + std::to_string(e) +
                                    " (non-manifold mesh); a shell mesh edge may have at most 2 elements");
    }
  }
  // neighbours[e] = (neighbour g, same) where same = true if e and g traverse the shared edge in the
  // same direction in their current numbering (so exactly one of them must be reversed).
  std::vector<std::vector<std::pair<int, bool>>> neighbours(static_cast<size_t>(ne));
  for (const auto& kv : edges) {
    const auto& l = kv.second;
    if (l.size() != 2 || l[0].first == l[1].first) continue;
    const bool same = l[0].second == l[1].second;
    neighbours[static_cast<size_t>(l[0].first)].emplace_back(l[1].first, same);
    neighbours[static_cast<size_t>(l[1].first)].emplace_back(l[0].first, same);
  }
  std::vector<int> flip(static_cast<size_t>(ne), -1);  // -1 unvisited, 0 keep, 1 reverse
  std::vector<int> queue;
  queue.reserve(static_cast<size_t>(ne));
  for (int root = 0; root < ne; ++root) {
    if (flip[static_cast<size_t>(root)] >= 0) continue;
    flip[static_cast<size_t>(root)] = 0;  // first element of the component keeps its orientation
    queue.assign(1, root);
    for (size_t head = 0; head < queue.size(); ++head) {
      const int e = queue[head];
      for (const auto& nb : neighbours[static_cast<size_t>(e)]) {
        const int want = nb.second ? 1 - flip[static_cast<size_t>(e)] : flip[static_cast<size_t>(e)];
        int& f = flip[static_cast<size_t>(nb.first)];
        if (f < 0) {
          f = want;
          queue.push_back(nb.first);
        } else if (f != want) {
          throw std::invalid_argument("orient_consistently: the mesh is not orientable (elements " +
                                      std::to_string(e) + " and " + std::to_string(nb.first) +
                                      " cannot be oriented consistently, e.g. a Moebius strip); "
                                      "shells must be orientable");
        }
      }
    }
  }
  int reversed_count = 0;
  for (int e = 0; e < ne; ++e)
    if (flip[static_cast<size_t>(e)] == 1) {
      mesh.elements[static_cast<size_t>(e)] = reversed(mesh.elements[static_cast<size_t>(e)]);
      ++reversed_count;
    }
  return reversed_count;
}

void check_orientation(const Mesh& mesh, const std::vector<Vec3>& normals) {
  check_connectivity(mesh, "check_orientation");
  if (normals.size() != mesh.X.size())
    throw std::invalid_argument("check_orientation: got " + std::to_string(normals.size()) +
                                " normals for a mesh of " + std::to_string(mesh.num_nodes()) +
                                " nodes; pass initial_normals(mesh)");
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const Quad9& q = mesh.elements[static_cast<size_t>(e)];
    // docs/theory.md §3.1 (paper eqs. 3-6) at the initial geometry.
    const Vec3 a = mesh.X[static_cast<size_t>(q[2])] - mesh.X[static_cast<size_t>(q[0])];
    const Vec3 b = mesh.X[static_cast<size_t>(q[3])] - mesh.X[static_cast<size_t>(q[1])];
    const double la = a.norm(), lb = b.norm();
    if (!(la > 0.0) || !(lb > 0.0))
      throw std::invalid_argument("check_orientation: element " + std::to_string(e) +
                                  " has a zero-length diagonal (corners coincide); fix the mesh");
    const Vec3 s = a / la - b / lb, c = a / la + b / lb;
    const double ls = s.norm(), lc = c.norm();
    if (!(ls > 1e-12) || !(lc > 1e-12))
      throw std::invalid_argument("check_orientation: element " + std::to_string(e) +
                                  " has parallel diagonals (degenerate corners); fix the mesh");
    const Vec3 ez = (s / ls).cross(c / lc);
    for (int k = 0; k < 9; ++k) {
      const double r = ez.dot(normals[static_cast<size_t>(q[k])]);
      if (!(r > 0.0)) {
        std::ostringstream os;
        os << "check_orientation: " << where(e, k, q[k]) << ": e_z0 . p_i0 = " << r
           << " <= 0 (docs/theory.md §2.4). The element is numbered clockwise with respect to the "
              "nodal normal (call orient_consistently(), or reverse it) or the shell is folded / "
              "non-smooth there, which is out of scope";
        throw std::invalid_argument(os.str());
      }
    }
  }
}

double surface_area(const Mesh& mesh) {
  check_connectivity(mesh, "surface_area");
  const double g = std::sqrt(0.6);
  const double pts[3] = {-g, 0.0, g};
  const double wts[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  double area = 0.0;
  for (const Quad9& el : mesh.elements)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        Vec3 g1, g2;
        tangents(mesh, el, pts[i], pts[j], g1, g2);
        area += wts[i] * wts[j] * g1.cross(g2).norm();
      }
  return area;
}

}  // namespace shelldyn
