// The example integrator of examples/velocity-verlet compiled into this program (not loaded as a plugin): runs a
// case the way one run of `shelldyn compare` does (the case settings the integrator understands, --threads 1),
// so that tests/install/run_example_test.sh can check that the installed plugin gives identical results.
//   usage: example_in_tree_runner CASE.yaml T_END OUT_DIR
#include "integrators/runs/registry.hpp"
#include "integrators/runs/run_driver.hpp"
#include "lib/model/problem.hpp"

#include <cstdlib>
#include <iostream>

extern "C" void shelldyn_plugin_register();  // examples/velocity-verlet/velocity_verlet.cpp (SHELLDYN_PLUGIN)

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: example_in_tree_runner CASE.yaml T_END OUT_DIR\n";
    return 2;
  }
  try {
    shelldyn::register_builtin_integrators();
    shelldyn::DefaultOriginScope origin("in-tree copy");
    shelldyn_plugin_register();
    shelldyn::Problem problem = shelldyn::load_problem(argv[1]);
    shelldyn::RunOptions ro;
    ro.out_dir = argv[3];
    ro.integrator = "velocity-verlet";
    ro.settings = shelldyn::settings_understood_by("velocity-verlet", problem.spec.integrator.settings);
    ro.t_end = std::atof(argv[2]);
    ro.vtu_every = 0;
    ro.threads = 1;
    const shelldyn::RunSummary s = shelldyn::run_dynamic(problem, ro);
    std::cout << "in-tree velocity-verlet (" << shelldyn::integrator_origin("velocity-verlet") << "): " << s.status << ", "
              << s.totals.steps << " steps\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "example_in_tree_runner: error: " << e.what() << "\n";
    return 1;
  }
}
