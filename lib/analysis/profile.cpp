#include "lib/analysis/profile.hpp"

#include <atomic>
#include <chrono>
#include <ctime>

namespace shelldyn::profile {
namespace {
std::atomic<bool> g_enabled{false};
std::array<Totals, kSections> g_totals{};
}  // namespace

const char* name(Section s) {
  switch (s) {
    case Section::factorize: return "factorization";
    case Section::analyze: return "symbolic analysis";
    case Section::solve: return "triangular solves";
    case Section::krylov: return "Krylov products";
    case Section::tangent: return "tangent assembly";
    case Section::internal_force: return "internal force";
    case Section::inertia: return "inertial force (M a + F_m)";
    case Section::mass: return "mass assembly";
    case Section::combine: return "K-bar combine + Dirichlet";
    case Section::external: return "external loads";
    case Section::step_state: return "per-step element state";
    case Section::count_: break;
  }
  return "?";
}

void enable(bool on) { g_enabled.store(on, std::memory_order_relaxed); }
bool enabled() { return g_enabled.load(std::memory_order_relaxed); }
void reset() { g_totals.fill(Totals{}); }
Totals totals(Section s) { return g_totals[static_cast<size_t>(s)]; }

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

Scope::Scope(Section s) : s_(s), on_(enabled()) {
  if (on_) {
    cpu0_ = process_cpu_seconds();
    wall0_ = wall_seconds();
  }
}
Scope::~Scope() {
  if (!on_) return;
  Totals& t = g_totals[static_cast<size_t>(s_)];
  t.cpu_s += process_cpu_seconds() - cpu0_;
  t.wall_s += wall_seconds() - wall0_;
  ++t.calls;
}

}  // namespace shelldyn::profile
