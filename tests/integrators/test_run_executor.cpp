// The local RunExecutor (integrators/runs/executor.hpp): order of starts, one outcome per job in job
// order, failures as outcomes, the outcome callback. The MPI executor is checked end to end by
// tests/apps/check_mpi_compare.py.
#include "integrators/runs/executor.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>

namespace shelldyn {
namespace {

std::vector<RunJob> make_jobs() {
  return {{"a", 1.0}, {"b", 30.0}, {"c", 5.0}, {"d", 30.0}, {"e", 0.0}};
}

TEST(RunExecutor, LongestFirstIsStableByDecreasingCost) {
  EXPECT_EQ(longest_first(make_jobs()), (std::vector<size_t>{1, 3, 2, 0, 4}));
}

TEST(RunExecutor, OneWorkerStartsRunsLongestFirst) {
  auto ex = make_local_executor(1, 0);
  std::vector<size_t> started;
  ex->execute(make_jobs(), [&](size_t k, int) { started.push_back(k); return std::string(); }, {}, nullptr);
  EXPECT_EQ(started, (std::vector<size_t>{1, 3, 2, 0, 4}));
}

TEST(RunExecutor, EveryJobHasItsOutcomeInJobOrderAndFailuresAreOutcomes) {
  for (int jobs : {1, 2, 4}) {
    auto ex = make_local_executor(jobs, 0);
    std::mutex m;
    std::set<size_t> called;
    std::atomic<int> threads_seen{-1};
    const auto out = ex->execute(
        make_jobs(),
        [&](size_t k, int threads) -> std::string {
          threads_seen = threads;
          std::this_thread::sleep_for(std::chrono::milliseconds(2));
          if (k == 2) throw std::runtime_error("step 7 failed\nsecond line");
          return "payload " + std::to_string(k);
        },
        [&](size_t k, const RunOutcome& o, bool more) {
          std::lock_guard<std::mutex> lock(m);
          EXPECT_FALSE(more);
          EXPECT_TRUE(called.insert(k).second) << "outcome " << k << " reported twice";
          EXPECT_EQ(o.ok, k != 2);
        },
        nullptr);
    ASSERT_EQ(out.size(), 5u);
    EXPECT_EQ(called.size(), 5u);
    for (size_t k = 0; k < out.size(); ++k) {
      if (k == 2) {
        EXPECT_FALSE(out[k].ok);
        EXPECT_EQ(out[k].status, "failed: step 7 failed second line");  // one line
      } else {
        EXPECT_TRUE(out[k].ok);
        EXPECT_EQ(out[k].status, "complete");
        EXPECT_EQ(out[k].payload, "payload " + std::to_string(k));
      }
      EXPECT_FALSE(out[k].worker.empty());
    }
    EXPECT_EQ(threads_seen.load(), jobs > 1 ? 1 : 0) << "runs of a pool are single-threaded";
    EXPECT_TRUE(ex->collects());
    EXPECT_EQ(ex->workers(), jobs);
  }
}

TEST(RunExecutor, PoolRunsJobsConcurrently) {
  auto ex = make_local_executor(2, 0);
  std::atomic<int> running{0}, peak{0};
  ex->execute(make_jobs(),
              [&](size_t, int) {
                const int r = ++running;
                int p = peak.load();
                while (r > p && !peak.compare_exchange_weak(p, r)) {
                }
                // wait (at most 5 s) for a second run to be in progress at the same time
                for (int i = 0; i < 500 && peak.load() < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
                --running;
                return std::string();
              },
              {}, nullptr);
  EXPECT_EQ(peak.load(), 2);
}

}  // namespace
}  // namespace shelldyn
