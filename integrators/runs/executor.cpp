#include "integrators/runs/executor.hpp"

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <numeric>
#include <thread>

namespace shelldyn {
namespace {

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

class LocalExecutor final : public RunExecutor {
 public:
  LocalExecutor(int jobs, int threads) : jobs_(std::max(1, jobs)), threads_(std::max(0, threads)) {}

  int workers() const override { return jobs_; }
  std::string describe() const override {
    return std::to_string(jobs_) + (jobs_ == 1 ? " worker thread" : " worker threads");
  }

  std::vector<RunOutcome> execute(const std::vector<RunJob>& jobs, const RunFunction& run_one,
                                  const OutcomeCallback& on_outcome, std::ostream* log) override {
    const std::vector<size_t> order = longest_first(jobs);
    std::vector<RunOutcome> out(jobs.size());
    std::vector<bool> done(jobs.size(), false);
    const int pool = std::max(1, std::min<int>(jobs_, static_cast<int>(jobs.size())));
    const int threads = pool > 1 ? 1 : threads_;
    std::mutex m;  // guards next, out, done, log and on_outcome (called under the lock: one at a time)
    size_t next = 0;
    std::exception_ptr callback_error;
    auto say = [&](const std::string& line) {
      if (log) *log << line << std::endl;
    };
    auto worker = [&](int id) {
      for (;;) {
        size_t k;
        {
          std::lock_guard<std::mutex> lock(m);
          if (next == order.size() || callback_error) return;
          k = order[next++];
          say("[" + std::to_string(k + 1) + "/" + std::to_string(jobs.size()) + "] " + jobs[k].label + ": started (thread " +
              std::to_string(id) + ")");
        }
        RunOutcome o;
        o.worker = "thread " + std::to_string(id);
        try {
          o.payload = run_one(k, threads);
          o.ok = true;
          o.status = "complete";
        } catch (const std::exception& e) {
          o.status = "failed: " + one_line(e.what());
        } catch (...) {
          o.status = "failed: unknown exception";
        }
        std::lock_guard<std::mutex> lock(m);
        out[k] = o;
        done[k] = true;
        say("[" + std::to_string(k + 1) + "/" + std::to_string(jobs.size()) + "] " + jobs[k].label + ": " + o.status);
        if (on_outcome && !callback_error) {
          try {
            on_outcome(k, out[k], false);
          } catch (...) {
            callback_error = std::current_exception();
          }
        }
      }
    };
    std::vector<std::thread> threads_pool;
    for (int j = 1; j < pool; ++j) threads_pool.emplace_back(worker, j + 1);
    worker(1);  // the calling thread is worker 1
    for (auto& t : threads_pool) t.join();
    if (callback_error) std::rethrow_exception(callback_error);
    for (size_t k = 0; k < jobs.size(); ++k)
      if (!done[k]) out[k].status = "failed: not run";
    return out;
  }

 private:
  int jobs_, threads_;
};

}  // namespace

std::unique_ptr<RunExecutor> make_local_executor(int jobs, int threads) {
  return std::make_unique<LocalExecutor>(jobs, threads);
}

std::vector<size_t> longest_first(const std::vector<RunJob>& jobs) {
  std::vector<size_t> order(jobs.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return jobs[a].expected_cost > jobs[b].expected_cost; });
  return order;
}

bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "MPI_LOCALNRANKS"})
    if (std::getenv(v)) return true;
  return false;
}

std::vector<RunOutcome> execute_runs(const std::vector<RunJob>& jobs, const RunFunction& run_one, RunExecutor& executor,
                                     const OutcomeCallback& on_outcome, std::ostream* log) {
  return executor.execute(jobs, run_one, on_outcome, log);
}

}  // namespace shelldyn
