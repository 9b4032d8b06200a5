// The open integrator registry (integrators/runs/registry.hpp): built-ins registered like user integrators,
// registration, origins, duplicates, removal, settings checks and thread safety.
#include "integrators/runs/registry.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <string>
#include <thread>
#include <vector>

namespace shelldyn {
namespace {

// A minimal integrator: reads one setting so that unknown keys can be refused.
class Still final : public Integrator {
 public:
  Still(IntegratorSettings& s, double) : gain_(s.get("gain", 2.0)) {}
  std::string name() const override { return "still"; }
  std::vector<std::pair<std::string, std::string>> settings() const override { return {{"gain", std::to_string(gain_)}}; }
  void initialize(SemiDiscreteSystem&, State&) override {}
  StepReport advance(SemiDiscreteSystem&, State& s, double t_out) override {
    s.t = t_out;
    return {};
  }
  double external_work() const override { return 0.0; }
  double gain_;
};

IntegratorFactory still_factory() {
  return [](IntegratorSettings& s, double dt) { return std::make_unique<Still>(s, dt); };
}

bool listed(const std::string& name) {
  const auto names = integrator_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

TEST(Registry, BuiltinsAreRegisteredOnceWithTheirOrigin) {
  register_builtin_integrators();
  register_builtin_integrators();  // idempotent
  for (const char* n : {"em-galpha", "em-exact", "galpha", "midpoint", "newmark", "ida-bdf", "arkode-erk", "arkode-dirk"}) {
    EXPECT_TRUE(listed(n)) << n;
    EXPECT_EQ(integrator_origin(n), "built-in") << n;
  }
  auto names = integrator_names();
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));
}

TEST(Registry, UserIntegratorIsMadeCheckedAndListed) {
  register_integrator("test-still", "does nothing", still_factory(), "test code");
  EXPECT_TRUE(listed("test-still"));
  EXPECT_EQ(integrator_origin("test-still"), "test code");
  IntegratorSettings ok("test-still", {{"gain", "3"}});
  const auto made = make_integrator(ok, 1e-3);
  EXPECT_EQ(dynamic_cast<Still&>(*made).gain_, 3.0);
  IntegratorSettings typo("test-still", {{"gian", "3"}});  // unknown keys are refused with the valid names
  try {
    make_integrator(typo, 1e-3);
    ADD_FAILURE() << "a misspelt setting was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gian"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gain"), std::string::npos) << e.what();
  }
  bool in_catalogue = false;
  for (const auto& [name, text] : integrator_catalogue())
    if (name == "test-still") in_catalogue = text.find("does nothing") != std::string::npos && text.find("gain=2") != std::string::npos;
  EXPECT_TRUE(in_catalogue);
  EXPECT_EQ(settings_understood_by("test-still", {{"gain", "5"}, {"rho_inf", "0.8"}}),
            (std::vector<std::pair<std::string, std::string>>{{"gain", "5"}}));
  EXPECT_TRUE(unregister_integrator("test-still"));
  EXPECT_FALSE(unregister_integrator("test-still"));
  EXPECT_FALSE(listed("test-still"));
  EXPECT_THROW(integrator_origin("test-still"), std::invalid_argument);
}

TEST(Registry, DuplicateNameIsRefusedNamingTheExistingOrigin) {
  try {
    register_integrator("em-galpha", "again", still_factory(), "plugin /tmp/x.so");
    ADD_FAILURE() << "a second em-galpha was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'em-galpha' is already registered (by built-in)"), std::string::npos) << e.what();
  }
  EXPECT_EQ(integrator_origin("em-galpha"), "built-in");
}

TEST(Registry, BadNamesAndEmptyFactoriesAreRefused) {
  for (const char* bad : {"", "a b", "a,b", "a:b", "a=b"})
    EXPECT_THROW(register_integrator(bad, "x", still_factory()), std::invalid_argument) << "'" << bad << "'";
  EXPECT_THROW(register_integrator("test-null", "x", IntegratorFactory{}), std::invalid_argument);
  EXPECT_FALSE(listed("test-null"));
}

TEST(Registry, DefaultOriginAndFailingFactoriesNameTheOrigin) {
  {
    DefaultOriginScope scope("plugin-under-test.so");
    register_integrator("test-failing", "throws", [](IntegratorSettings&, double) -> std::unique_ptr<Integrator> {
      throw std::runtime_error("boom");
    });
  }
  register_integrator("test-user", "no origin", still_factory());
  EXPECT_EQ(integrator_origin("test-failing"), "plugin-under-test.so");
  EXPECT_EQ(integrator_origin("test-user"), "user code");
  IntegratorSettings s("test-failing", {});
  try {
    make_integrator(s, 1e-3);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "integrator 'test-failing' from plugin-under-test.so: factory failed: boom");
  }
  unregister_integrator("test-failing");
  unregister_integrator("test-user");
}

TEST(Registry, ConcurrentRegistrationsAllArrive) {
  std::vector<std::thread> threads;
  std::atomic<int> failures{0};
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([t, &failures] {
      try {
        for (int k = 0; k < 25; ++k) {
          register_integrator("test-par-" + std::to_string(t) + "-" + std::to_string(k), "x", still_factory());
          (void)integrator_names();
        }
      } catch (...) {
        ++failures;
      }
    });
  for (auto& th : threads) th.join();
  EXPECT_EQ(failures.load(), 0);
  int found = 0;
  for (const auto& n : integrator_names())
    if (n.rfind("test-par-", 0) == 0) ++found;
  EXPECT_EQ(found, 200);
  for (int t = 0; t < 8; ++t)
    for (int k = 0; k < 25; ++k) EXPECT_TRUE(unregister_integrator("test-par-" + std::to_string(t) + "-" + std::to_string(k)));
}

}  // namespace
}  // namespace shelldyn
