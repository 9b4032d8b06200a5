// Fixed-count driver of the CR9 element kernels for instruction counting (valgrind --tool=callgrind): runs one
// kernel exactly N times on bench_element's cylindrical element, so that instructions / N is the cost of one
// call. Run: valgrind --tool=callgrind --toggle-collect='shelldyn::CR9Shell::algorithmic_internal*'
// build/bin/count_element residual 2000
// (scripts/element_icount.sh does that for every kernel). A third argument "sphere" runs the patch on a sphere. Kernels: residual (algorithmic_internal with the step
// state, F only: what one em-galpha residual costs per element), internal_f (internal(), F only), tangent
// (algorithmic_internal with F and K), step_state.
#include <Eigen/Geometry>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "elements/cr9_shell.hpp"
#include "elements/shape_functions.hpp"

using namespace shelldyn;

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::printf("usage: count_element residual|internal_f|tangent|step_state [N=1000] [cylinder|sphere]\n");
    return argc < 2 ? 1 : 0;
  }
  const std::string shape = argc > 3 ? argv[3] : "cylinder";
  if (shape != "cylinder" && shape != "sphere") {
    std::fprintf(stderr, "count_element: unknown geometry '%s' (cylinder, sphere)\n", shape.c_str());
    return 1;
  }
  const std::string which = argv[1];
  const long n = argc > 2 ? std::atol(argv[2]) : 1000;
  if (n <= 0) {
    std::fprintf(stderr, "count_element: N = %s must be a positive integer\n", argv[2]);
    return 1;
  }
  // The element of bench_element.cpp's make_setup() (cylindrical, R = 2, 0.5 rad x 1, deformed), or the same
  // patch on a sphere of radius 2 (doubly curved: K_bs has no zero rows, as on the pinched hemisphere).
  std::array<Eigen::Vector3d, 9> X0, p0;
  CR9Shell::Charts charts;
  CR9Shell::Vec45 u, u1;
  for (int k = 0; k < 9; ++k) {
    const double phi = 0.25 * kNodeXi[k], psi = 0.25 * kNodeEta[k];
    if (shape == "cylinder") {
      X0[k] = Eigen::Vector3d(2.0 * std::sin(phi), 0.5 * kNodeEta[k], 2.0 * std::cos(phi) - 2.0);
      p0[k] = Eigen::Vector3d(std::sin(phi), 0.0, std::cos(phi));
    } else {
      p0[k] = Eigen::Vector3d(std::tan(phi), std::tan(psi), 1.0).normalized();
      X0[k] = 2.0 * p0[k] - Eigen::Vector3d(0.0, 0.0, 2.0);
    }
  }
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int k = 0; k < 9; ++k) {
    charts[k] = select_chart(p0[k]);
    const Eigen::Vector3d p = Eigen::AngleAxisd(0.1 * U(rng), Eigen::Vector3d(U(rng), U(rng), U(rng)).normalized()) * p0[k];
    u.segment<3>(5 * k) = 0.05 * Eigen::Vector3d(U(rng), U(rng), U(rng));
    u.segment<2>(5 * k + 3) = chart_coordinates(p, charts[k]);
  }
  u1 = u;
  for (int k = 0; k < 9; ++k) u1.segment<3>(5 * k) += 0.001 * Eigen::Vector3d(U(rng), U(rng), U(rng));
  const CR9Shell e(X0, p0, ShellMaterial{1e6, 0.3, 1.0, 0.05});
  CR9Shell::StepState sn;
  e.step_state(u, charts, &sn);
  CR9Shell::Vec45 F = CR9Shell::Vec45::Zero();
  static CR9Shell::Mat45 K;
  double sum = 0.0;
  for (long it = 0; it < n; ++it) {
    if (which == "residual") sum += e.algorithmic_internal(sn, u, u1, charts, 0.5, 0.0, &F, nullptr);
    else if (which == "internal_f") sum += e.internal(u1, charts, &F, nullptr);
    else if (which == "tangent") sum += e.algorithmic_internal(sn, u, u1, charts, 0.5, 0.0, &F, &K);
    else if (which == "step_state") e.step_state(u1, charts, &sn), sum += sn.w(0);
    else {
      std::fprintf(stderr, "count_element: unknown kernel '%s' (residual, internal_f, tangent, step_state)\n", which.c_str());
      return 1;
    }
  }
  std::printf("%s x %ld: checksum %.17g %.17g\n", which.c_str(), n, sum, F.sum());
  return 0;
}
