// Test plugins for the bad-plugin checks of tests/plugins/CMakeLists.txt (integrators/runs/plugin.hpp): one
// source, one shared library per BAD_KIND. Built without linking shelldyn's libraries: every shelldyn symbol
// is resolved from the host executable at dlopen (the shelldyn executable exports its symbols).
//   1 no_entry         no shelldyn_plugin_register (a library that is not a plugin)
//   2 duplicate        registers "em-galpha", a built-in name
//   3 factory_throws   registers "throwing-factory", whose factory throws
//   4 step_throws      registers "throwing-step", whose advance() throws at t >= 0.005 (no save/restore either)
//   5 nothing          an entry point that registers nothing
#include "integrators/integrator.hpp"
#include "integrators/runs/plugin.hpp"

#include <memory>
#include <stdexcept>

namespace {
// A do-nothing "integrator": the state stays at rest, time advances in steps of dt.
class Idle final : public shelldyn::Integrator {
 public:
  explicit Idle(double dt) : dt_(dt) {}
  std::string name() const override { return "throwing-step"; }
  std::vector<std::pair<std::string, std::string>> settings() const override { return {}; }
  void initialize(shelldyn::SemiDiscreteSystem&, shelldyn::State&) override {}
  shelldyn::StepReport advance(shelldyn::SemiDiscreteSystem&, shelldyn::State& s, double t_out) override {
    shelldyn::StepReport r;
    while (s.t < t_out - 1e-12) {
      if (s.t >= 0.005) throw std::runtime_error("deliberate failure in advance() at t = 0.005");
      s.t = std::min(t_out, s.t + dt_);
      ++r.steps;
    }
    return r;
  }
  double external_work() const override { return 0.0; }

 private:
  double dt_;
};
}  // namespace

#if BAD_KIND == 1
extern "C" __attribute__((visibility("default"))) int not_a_shelldyn_plugin() { return 1; }
#elif BAD_KIND == 2
SHELLDYN_PLUGIN("dup-1") {
  shelldyn::register_integrator("em-galpha", "a second em-galpha",
                                [](shelldyn::IntegratorSettings&, double dt) { return std::make_unique<Idle>(dt); });
}
#elif BAD_KIND == 3
SHELLDYN_PLUGIN("factory-1") {
  shelldyn::register_integrator("throwing-factory", "factory throws", [](shelldyn::IntegratorSettings&, double)
                                                                          -> std::unique_ptr<shelldyn::Integrator> {
    throw std::runtime_error("deliberate failure in the factory");
  });
}
#elif BAD_KIND == 4
SHELLDYN_PLUGIN("step-1") {
  shelldyn::register_integrator("throwing-step", "advance throws",
                                [](shelldyn::IntegratorSettings&, double dt) { return std::make_unique<Idle>(dt); });
}
#elif BAD_KIND == 5
SHELLDYN_PLUGIN("empty-1") {}
#endif
