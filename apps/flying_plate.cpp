// flying_plate — the flying L-shaped plate of Li & Qian (2025) §4.1 (docs/benchmarks.md §1), in its
// PROVISIONAL form FLP-prov (§1.3): the paper's figure with the L geometry and the loads is missing, so
// the L = [0,3]x[0,7] ∪ [3,6]x[0,3], the load points A = (6,0,0), B = (0,7,0) and the hat load (peak 5 N
// at 2.5 s, off at 5 s) are our choice. Material, mesh size, dt = 1e-3 s and 20 s are the paper's.
//
// Sample runs:
//   flying_plate                                   # the paper's settings: em-galpha, 20 000 steps
//   flying_plate --t-end 6 -o /tmp/flp             # through the load window and 1 s of free flight
//   flying_plate --integrator galpha --set rho_inf=0.8 --t-end 10
//   flying_plate --dt 0.01 --t-end 6 --threads 1   # coarse and quick (the CTest run)
//
// What to expect: the plate is free, so after the loads end (t = 5 s) the linear momentum is constant
// to round-off for every integrator and equals the load impulse (12.5, 0, 12.5) N·s; with em-galpha
// (rho_inf = 1, xi = 0) the total energy H = K + V and the angular momentum stay constant up to the
// time-discretization error (docs/theory.md §6.7: |ΔH|/H ~ 1e-9 at dt = 1e-3). Results go to
// results/flying-plate/<integrator>/: history.csv, fields.pvd, run.json and energy/momentum plots.
#include "apps/app_common.hpp"

int main(int argc, char** argv) {
  shelldyn::app::BenchmarkApp app("flying_plate", "flying-plate.yaml",
                                  "Flying L-shaped plate, Li & Qian (2025) §4.1, provisional definition FLP-prov");
  app.label = "FLP-prov";
  app.provisional =
      "FLP-prov: L geometry, load points, load vectors and hat function are not the paper's (its figure is "
      "missing; docs/benchmarks.md §1.3); compare conservation, not curves, with Li & Qian Figs. 4-5";
  return app.main(argc, argv);
}
