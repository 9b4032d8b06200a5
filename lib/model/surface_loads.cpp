// Consistent nodal forces of distributed loads (docs/theory.md §8.2–8.4); see lib/model/surface_loads.hpp.
#include "lib/model/surface_loads.hpp"

#include "elements/shape_functions.hpp"
#include "lib/model/assembler.hpp"
#include "lib/model/dof_map.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <set>

namespace shelldyn {
namespace {

Eigen::Matrix3d skew(const Vec3& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

std::array<Vec3, 9> element_nodes(const Mesh& mesh, int e) {
  std::array<Vec3, 9> x;
  const Quad9& el = mesh.elements[static_cast<size_t>(e)];
  for (size_t a = 0; a < 9; ++a) x[a] = mesh.X[static_cast<size_t>(el[a])];
  return x;
}

}  // namespace

void element_pressure(const std::array<Vec3, 9>& x, double p, Eigen::Matrix<double, 27, 1>& f,
                      Eigen::Matrix<double, 27, 27>* K) {
  f.setZero();
  if (K) K->setZero();
  const auto& gp = gauss3_points();
  const auto& gw = gauss3_weights();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double w = p * gw[static_cast<size_t>(i)] * gw[static_cast<size_t>(j)];
      const auto N = shape_functions(gp[static_cast<size_t>(i)], gp[static_cast<size_t>(j)]);
      const auto dN = shape_derivatives(gp[static_cast<size_t>(i)], gp[static_cast<size_t>(j)]);
      Vec3 xs = Vec3::Zero(), xe = Vec3::Zero();
      for (int b = 0; b < 9; ++b) {
        xs += dN(b, 0) * x[static_cast<size_t>(b)];
        xe += dN(b, 1) * x[static_cast<size_t>(b)];
      }
      const Vec3 n = xs.cross(xe);  // unit normal times the area element (§8.2)
      for (int a = 0; a < 9; ++a) f.segment<3>(3 * a) += w * N(a) * n;
      if (K) {
        const Eigen::Matrix3d Ss = skew(xs), Se = skew(xe);
        for (int b = 0; b < 9; ++b) {
          const Eigen::Matrix3d dn = dN(b, 1) * Ss - dN(b, 0) * Se;  // ∂(x,ξ × x,η)/∂x_b
          for (int a = 0; a < 9; ++a) K->block<3, 3>(3 * a, 3 * b) += w * N(a) * dn;
        }
      }
    }
}

std::map<int, Vec3> dead_pressure_forces(const Mesh& mesh, const std::vector<int>& elements, double p) {
  std::map<int, Vec3> out;
  Eigen::Matrix<double, 27, 1> f;
  for (int e : elements) {
    element_pressure(element_nodes(mesh, e), p, f);
    const Quad9& el = mesh.elements[static_cast<size_t>(e)];
    for (size_t a = 0; a < 9; ++a) {
      auto it = out.try_emplace(el[a], Vec3::Zero()).first;
      it->second += f.segment<3>(static_cast<Eigen::Index>(3 * a));
    }
  }
  return out;
}

std::map<int, Vec3> body_forces(const Mesh& mesh, const std::vector<int>& elements, const Vec3& b, double h) {
  std::map<int, Vec3> out;
  const auto& gp = gauss3_points();
  const auto& gw = gauss3_weights();
  for (int e : elements) {
    const auto x = element_nodes(mesh, e);
    const Quad9& el = mesh.elements[static_cast<size_t>(e)];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const auto N = shape_functions(gp[static_cast<size_t>(i)], gp[static_cast<size_t>(j)]);
        const auto dN = shape_derivatives(gp[static_cast<size_t>(i)], gp[static_cast<size_t>(j)]);
        Vec3 xs = Vec3::Zero(), xe = Vec3::Zero();
        for (int a = 0; a < 9; ++a) {
          xs += dN(a, 0) * x[static_cast<size_t>(a)];
          xe += dN(a, 1) * x[static_cast<size_t>(a)];
        }
        const double dA = xs.cross(xe).norm() * gw[static_cast<size_t>(i)] * gw[static_cast<size_t>(j)];
        for (size_t a = 0; a < 9; ++a) {
          auto it = out.try_emplace(el[a], Vec3::Zero()).first;
          it->second += N(static_cast<Eigen::Index>(a)) * dA * h * b;
        }
      }
  }
  return out;
}

std::map<int, Vec3> edge_line_forces(const Mesh& mesh, const std::vector<int>& nodes, const Vec3& t) {
  static const int kEdges[4][3] = {{0, 4, 1}, {1, 5, 2}, {2, 6, 3}, {3, 7, 0}};  // corner, mid, corner
  static const double gs[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                               0.9061798459386640};
  static const double gw[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                               0.2369268850561891};
  const std::set<int> in(nodes.begin(), nodes.end());
  std::set<std::array<int, 3>> done;
  std::map<int, Vec3> out;
  for (const Quad9& el : mesh.elements)
    for (const auto& e : kEdges) {
      const int a = el[static_cast<size_t>(e[0])], m = el[static_cast<size_t>(e[1])], b = el[static_cast<size_t>(e[2])];
      if (!in.count(a) || !in.count(m) || !in.count(b)) continue;
      if (!done.insert({std::min(a, b), m, std::max(a, b)}).second) continue;  // shared edge: once
      const Vec3 &Xa = mesh.X[static_cast<size_t>(a)], &Xm = mesh.X[static_cast<size_t>(m)],
                 &Xb = mesh.X[static_cast<size_t>(b)];
      for (int g = 0; g < 5; ++g) {
        const double s = gs[g];
        const double Na = 0.5 * s * (s - 1.0), Nm = 1.0 - s * s, Nb = 0.5 * s * (s + 1.0);
        const double ds = ((s - 0.5) * Xa - 2.0 * s * Xm + (s + 0.5) * Xb).norm() * gw[g];
        for (auto [node, Nn] : {std::pair<int, double>{a, Na}, {m, Nm}, {b, Nb}}) {
          auto it = out.try_emplace(node, Vec3::Zero()).first;
          it->second += Nn * ds * t;
        }
      }
    }
  return out;
}

std::vector<int> elements_within(const Mesh& mesh, const std::vector<int>& nodes) {
  const std::set<int> in(nodes.begin(), nodes.end());
  std::vector<int> out;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const Quad9& el = mesh.elements[static_cast<size_t>(e)];
    if (std::all_of(el.begin(), el.end(), [&](int i) { return in.count(i) > 0; })) out.push_back(e);
  }
  return out;
}

void add_follower_pressures(const std::vector<FollowerPressure>& loads, const Mesh& mesh, const Assembler& assembler,
                            double t, const Eigen::VectorXd& u, double* F, SparseMatrix* K, bool symmetric) {
  Eigen::Matrix<double, 27, 1> f;
  Eigen::Matrix<double, 27, 27> k;
  ElementMatrix ke;
  ElementVector fe;
  for (const FollowerPressure& load : loads) {
    const double p = load.pressure * load.function(t);
    if (p == 0.0) continue;
    for (int e : load.elements) {
      std::array<Vec3, 9> x = element_nodes(mesh, e);
      const Quad9& el = mesh.elements[static_cast<size_t>(e)];
      for (size_t a = 0; a < 9; ++a) x[a] += u.segment<3>(DofMap::dof(el[a], 0));  // current geometry
      element_pressure(x, p, f, K ? &k : nullptr);
      if (F) {
        fe.setZero();
        for (int a = 0; a < 9; ++a) fe.segment<3>(5 * a) = f.segment<3>(3 * a);
        assembler.add_vector(e, fe, F);
      }
      if (K) {
        if (symmetric) k = (0.5 * (k + k.transpose())).eval();
        ke.setZero();
        for (int a = 0; a < 9; ++a)
          for (int b = 0; b < 9; ++b) ke.block<3, 3>(5 * a, 5 * b) = -k.block<3, 3>(3 * a, 3 * b);
        assembler.add_matrix(e, ke, K->values.data());
      }
    }
  }
}

}  // namespace shelldyn
