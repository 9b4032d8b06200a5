// Timing of the CR9 element kernels (docs/theory.md §3.4, §4, §6.3). Target: internal() with F and K
// <= 50 µs per element. Run: build/bin/bench_element [--benchmark_filter=Internal]
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <array>
#include <random>
#include <vector>

#include "elements/cr9_shell.hpp"
#include "elements/exact_energy.hpp"
#include "elements/shape_functions.hpp"

namespace {

using namespace shelldyn;

struct Setup {
  std::array<Eigen::Vector3d, 9> X0, p0;
  CR9Shell::Charts charts;
  CR9Shell::Vec45 u, u1;
};

// Cylindrical element (R = 2, 0.5 rad x 1) in a deformed state: translations ~0.05, directors turned.
Setup make_setup() {
  Setup s;
  for (int k = 0; k < 9; ++k) {
    const double phi = 0.25 * kNodeXi[k];
    s.X0[k] = Eigen::Vector3d(2.0 * std::sin(phi), 0.5 * kNodeEta[k], 2.0 * std::cos(phi) - 2.0);
    s.p0[k] = Eigen::Vector3d(std::sin(phi), 0.0, std::cos(phi));
  }
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int k = 0; k < 9; ++k) {
    s.charts[k] = select_chart(s.p0[k]);
    const Eigen::Vector3d p =
        Eigen::AngleAxisd(0.1 * U(rng), Eigen::Vector3d(U(rng), U(rng), U(rng)).normalized()) * s.p0[k];
    s.u.segment<3>(5 * k) = 0.05 * Eigen::Vector3d(U(rng), U(rng), U(rng));
    s.u.segment<2>(5 * k + 3) = chart_coordinates(p, s.charts[k]);
  }
  s.u1 = s.u;
  for (int k = 0; k < 9; ++k) s.u1.segment<3>(5 * k) += 0.001 * Eigen::Vector3d(U(rng), U(rng), U(rng));
  return s;
}

const ShellMaterial kMat{1e6, 0.3, 1.0, 0.05};

void BM_InternalForceAndTangent(benchmark::State& state) {
  const Setup s = make_setup();
  const CR9Shell e(s.X0, s.p0, kMat);
  CR9Shell::Vec45 F;
  CR9Shell::Mat45 K;
  for (auto _ : state) {
    benchmark::DoNotOptimize(e.internal(s.u, s.charts, &F, &K));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_InternalForceAndTangent)->Unit(benchmark::kMicrosecond);

void BM_InternalForceOnly(benchmark::State& state) {
  const Setup s = make_setup();
  const CR9Shell e(s.X0, s.p0, kMat);
  CR9Shell::Vec45 F;
  for (auto _ : state) {
    benchmark::DoNotOptimize(e.internal(s.u, s.charts, &F, nullptr));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_InternalForceOnly)->Unit(benchmark::kMicrosecond);

void BM_AlgorithmicForceAndTangent(benchmark::State& state) {
  const Setup s = make_setup();
  const CR9Shell e(s.X0, s.p0, kMat);
  CR9Shell::Vec45 F;
  CR9Shell::Mat45 K;
  for (auto _ : state) {
    benchmark::DoNotOptimize(e.algorithmic_internal(s.u, s.u1, s.charts, 0.5, 0.0, &F, &K));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_AlgorithmicForceAndTangent)->Unit(benchmark::kMicrosecond);

// The element's step state at the setup's u_n (what a model caches once per step).
CR9Shell::StepState state_at_un(const CR9Shell& e, const Setup& s) {
  CR9Shell::StepState sn;
  e.step_state(s.u, s.charts, &sn);
  return sn;
}

// What a residual of em-galpha costs per element: the strain-averaged force with the step's state at u_n
// (computed once per step, outside the loop) and without a tangent.
void BM_AlgorithmicForceStepState(benchmark::State& state) {
  const Setup s = make_setup();
  const CR9Shell e(s.X0, s.p0, kMat);
  const CR9Shell::StepState sn = state_at_un(e, s);
  CR9Shell::Vec45 F;
  for (auto _ : state) {
    benchmark::DoNotOptimize(e.algorithmic_internal(sn, s.u, s.u1, s.charts, 0.5, 0.0, &F, nullptr));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_AlgorithmicForceStepState)->Unit(benchmark::kMicrosecond);

// The same over 256 element copies in turn (the hemisphere's count): element data streamed from memory as
// in a model's residual, not hot in the cache. Time per element.
void BM_AlgorithmicForceStepState256(benchmark::State& state) {
  const Setup s = make_setup();
  const std::vector<CR9Shell> els(256, CR9Shell(s.X0, s.p0, kMat));
  std::vector<CR9Shell::StepState> sn(els.size());
  for (size_t k = 0; k < els.size(); ++k) els[k].step_state(s.u, s.charts, &sn[k]);
  CR9Shell::Vec45 F;
  for (auto _ : state) {
    for (size_t k = 0; k < els.size(); ++k)
      benchmark::DoNotOptimize(els[k].algorithmic_internal(sn[k], s.u, s.u1, s.charts, 0.5, 0.0, &F, nullptr));
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(els.size()));
}
BENCHMARK(BM_AlgorithmicForceStepState256)->Unit(benchmark::kMillisecond);

// What em-exact adds per element and residual to em-galpha's force (docs/theory/exact-energy-momentum.md §3):
// the midpoint rigid rows from the nodal vectors and the correction (one 6 × 6 solve for both right-hand sides).
void BM_ExactCorrection(benchmark::State& state) {
  const Setup s = make_setup();
  const CR9Shell e(s.X0, s.p0, kMat);
  const CR9Shell::StepState sn = state_at_un(e, s);
  CR9Shell::Vec45 F;
  const double U1 = e.algorithmic_internal(sn, s.u, s.u1, s.charts, 0.5, 0.0, &F, nullptr);
  const double dU = U1 - e.step_energy(sn);
  NodeVectors xm, pm;
  for (int a = 0; a < 9; ++a) {
    xm[a] = s.X0[a] + 0.5 * (s.u.segment<3>(5 * a) + s.u1.segment<3>(5 * a));
    pm[a] = 0.5 * (director(s.u.segment<2>(5 * a + 3), s.charts[a]) + director(s.u1.segment<2>(5 * a + 3), s.charts[a]));
  }
  const CR9Shell::Vec45 du = s.u1 - s.u;
  for (auto _ : state) {
    CR9Shell::Vec45 f = F;
    const MidpointRigidRows R(xm, pm, s.charts);
    benchmark::DoNotOptimize(energy_momentum_correction(R, du, dU, f));
    benchmark::DoNotOptimize(f.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_ExactCorrection)->Unit(benchmark::kMicrosecond);

void BM_StepState(benchmark::State& state) {
  const Setup s = make_setup();
  const CR9Shell e(s.X0, s.p0, kMat);
  CR9Shell::StepState sn;
  for (auto _ : state) {
    e.step_state(s.u, s.charts, &sn);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_StepState)->Unit(benchmark::kMicrosecond);

// M(u) a + F_m(u, v) as a residual needs it (no mass matrix formed).
void BM_InertiaForce(benchmark::State& state) {
  const Setup s = make_setup();
  const CR9Shell e(s.X0, s.p0, kMat);
  CR9Shell::Vec45 f;
  for (auto _ : state) {
    e.inertia_force(s.u, s.u1, s.u1, s.charts, &f);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_InertiaForce)->Unit(benchmark::kMicrosecond);

void BM_MassAndInertial(benchmark::State& state) {
  const Setup s = make_setup();
  const CR9Shell e(s.X0, s.p0, kMat);
  CR9Shell::Mat45 M;
  CR9Shell::Vec45 Fm;
  for (auto _ : state) {
    e.mass(s.u, s.charts, &M);
    e.inertial(s.u, s.u1, s.charts, &Fm);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_MassAndInertial)->Unit(benchmark::kMicrosecond);

void BM_Construct(benchmark::State& state) {
  const Setup s = make_setup();
  for (auto _ : state) {
    CR9Shell e(s.X0, s.p0, kMat);
    benchmark::DoNotOptimize(e.area());
  }
}
BENCHMARK(BM_Construct)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
