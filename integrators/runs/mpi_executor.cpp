#include "integrators/runs/mpi_executor.hpp"

#include <mpi.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace shelldyn {
namespace {

constexpr int kTagReady = 11;   // worker -> 0: free for a run; carries the previous run's outcome, if any
constexpr int kTagAssign = 12;  // 0 -> worker: int64 run index, or -1: no more runs

std::atomic<int> g_signal{0};
extern "C" void on_terminate(int sig) { g_signal.store(sig); }

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

// Message of a worker: int64 index (-1: none), int32 ok, uint64 status length, status, payload.
std::string pack(int64_t index, const RunOutcome& o) {
  std::string s(sizeof(int64_t) + sizeof(int32_t) + sizeof(uint64_t), '\0');
  const int32_t ok = o.ok ? 1 : 0;
  const uint64_t n = o.status.size();
  std::memcpy(&s[0], &index, sizeof index);
  std::memcpy(&s[sizeof index], &ok, sizeof ok);
  std::memcpy(&s[sizeof index + sizeof ok], &n, sizeof n);
  return s + o.status + o.payload;
}

int64_t unpack(const std::string& s, RunOutcome& o) {
  int64_t index;
  int32_t ok;
  uint64_t n;
  const size_t head = sizeof index + sizeof ok + sizeof n;
  if (s.size() < head) throw std::runtime_error("MPI sweep: truncated message from a worker rank");
  std::memcpy(&index, &s[0], sizeof index);
  std::memcpy(&ok, &s[sizeof index], sizeof ok);
  std::memcpy(&n, &s[sizeof index + sizeof ok], sizeof n);
  if (s.size() < head + n) throw std::runtime_error("MPI sweep: truncated message from a worker rank");
  o.ok = ok != 0;
  o.status = s.substr(head, n);
  o.payload = s.substr(head + n);
  return index;
}

void check(int rc, const char* what) {
  if (rc != MPI_SUCCESS) {
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    MPI_Error_string(rc, text, &len);
    throw std::runtime_error(std::string("MPI sweep: ") + what + " failed: " + std::string(text, static_cast<size_t>(len)));
  }
}

RunOutcome run_guarded(const RunFunction& run_one, size_t k, int threads) {
  RunOutcome o;
  try {
    o.payload = run_one(k, threads);
    o.ok = true;
    o.status = "complete";
  } catch (const std::exception& e) {
    o.status = "failed: " + one_line(e.what());
  } catch (...) {
    o.status = "failed: unknown exception";
  }
  return o;
}

uint64_t list_hash(const std::vector<RunJob>& jobs) {  // FNV-1a over the labels
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](unsigned char c) { h = (h ^ c) * 1099511628211ull; };
  for (const auto& j : jobs) {
    for (char c : j.label) mix(static_cast<unsigned char>(c));
    mix(0);
  }
  return h ^ jobs.size();
}

class MpiExecutor final : public RunExecutor {
 public:
  explicit MpiExecutor(int threads) : threads_(threads > 0 ? threads : 1) {
    int provided = 0;
    check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    if (provided < MPI_THREAD_FUNNELED)
      throw std::runtime_error("MPI sweep: the MPI library does not provide MPI_THREAD_FUNNELED");
  }
  ~MpiExecutor() override {
    // A rank that leaves while the others may still wait for it (an exception in the middle of a sweep)
    // must take the job down rather than leave it hanging.
    if (in_sweep_ && size_ > 1) MPI_Abort(MPI_COMM_WORLD, 1);
    MPI_Finalize();
  }

  bool collects() const override { return rank_ == 0; }
  int workers() const override { return size_; }
  std::string describe() const override {
    return std::to_string(size_) + (size_ == 1 ? " MPI rank" : " MPI ranks") + " (" + std::to_string(threads_) +
           " thread" + (threads_ == 1 ? "" : "s") + " per run)";
  }

  std::vector<RunOutcome> execute(const std::vector<RunJob>& jobs, const RunFunction& run_one,
                                  const OutcomeCallback& on_outcome, std::ostream* log) override {
    in_sweep_ = true;
    uint64_t h = list_hash(jobs), h0 = h;
    check(MPI_Bcast(&h0, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD), "MPI_Bcast");
    int mismatch = h != h0 ? 1 : 0, any = 0;
    check(MPI_Allreduce(&mismatch, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD), "MPI_Allreduce");
    if (any) {
      in_sweep_ = false;
      throw std::runtime_error("MPI sweep: the ranks expanded different run lists (same command, case files and "
                               "working folder on every node?)");
    }
    std::vector<RunOutcome> out = rank_ == 0 ? coordinate(jobs, run_one, on_outcome, log) : work(run_one);
    in_sweep_ = false;
    return out;
  }

 private:
  std::vector<RunOutcome> work(const RunFunction& run_one) {
    int64_t done = -1;
    RunOutcome last;
    for (;;) {
      const std::string msg = pack(done, last);
      check(MPI_Send(msg.data(), static_cast<int>(msg.size()), MPI_CHAR, 0, kTagReady, MPI_COMM_WORLD), "MPI_Send");
      int64_t k = -1;
      check(MPI_Recv(&k, 1, MPI_INT64_T, 0, kTagAssign, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "MPI_Recv");
      if (k < 0) return {};
      last = run_guarded(run_one, static_cast<size_t>(k), threads_);
      done = k;
    }
  }

  std::vector<RunOutcome> coordinate(const std::vector<RunJob>& jobs, const RunFunction& run_one,
                                     const OutcomeCallback& on_outcome, std::ostream* log) {
    const size_t n = jobs.size();
    const std::vector<size_t> order = longest_first(jobs);
    std::vector<RunOutcome> out(n);
    std::vector<int> state(n, 0);  // 0 waiting, 1 running, 2 finished
    std::vector<int> where(n, -1);
    std::mutex m;                  // next, state, where, local_done, log
    size_t next = 0;
    std::deque<std::pair<size_t, RunOutcome>> local_done;
    bool local_running = true;
    auto tag = [&](size_t k) { return "[" + std::to_string(k + 1) + "/" + std::to_string(n) + "] " + jobs[k].label; };
    auto say = [&](const std::string& line) {  // callers hold m
      if (log) *log << line << std::endl;
    };
    auto take = [&](int r) -> int64_t {  // callers hold m
      if (next == n) return -1;
      const size_t k = order[next++];
      state[k] = 1;
      where[k] = r;
      say(tag(k) + ": started on rank " + std::to_string(r));
      return static_cast<int64_t>(k);
    };
    std::atomic<bool> stop_local{false};
    std::thread local([&] {  // rank 0's own runs; no MPI calls here
      for (;;) {
        int64_t k;
        {
          std::lock_guard<std::mutex> lock(m);
          k = stop_local ? -1 : take(0);
          if (k < 0) {
            local_running = false;
            return;
          }
        }
        RunOutcome o = run_guarded(run_one, static_cast<size_t>(k), threads_);
        std::lock_guard<std::mutex> lock(m);
        local_done.emplace_back(static_cast<size_t>(k), std::move(o));
      }
    });

    auto finish = [&](size_t k, RunOutcome o, int r) {  // main thread, without m
      o.worker = "rank " + std::to_string(r);
      {
        std::lock_guard<std::mutex> lock(m);
        state[k] = 2;
        say(tag(k) + ": " + o.status + " (rank " + std::to_string(r) + ")");
      }
      out[k] = o;
      if (on_outcome) on_outcome(k, out[k], false);
    };

    struct sigaction sa {}, old_term {}, old_int {};
    sa.sa_handler = on_terminate;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, &old_term);
    sigaction(SIGINT, &sa, &old_int);
    g_signal.store(0);

    try {
      int workers_left = size_ - 1;
      int idle_ms = 0;
      for (;;) {
        if (g_signal.load()) interrupted(jobs, out, state, where, m, on_outcome, log, stop_local);
        bool progress = false;
        int flag = 0;
        MPI_Status st;
        if (workers_left > 0) check(MPI_Iprobe(MPI_ANY_SOURCE, kTagReady, MPI_COMM_WORLD, &flag, &st), "MPI_Iprobe");
        if (flag) {
          int count = 0;
          MPI_Get_count(&st, MPI_CHAR, &count);
          std::string msg(static_cast<size_t>(count), '\0');
          check(MPI_Recv(&msg[0], count, MPI_CHAR, st.MPI_SOURCE, kTagReady, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "MPI_Recv");
          RunOutcome o;
          const int64_t k = unpack(msg, o);
          if (k >= static_cast<int64_t>(n)) throw std::runtime_error("MPI sweep: a worker reported an unknown run");
          if (k >= 0) finish(static_cast<size_t>(k), std::move(o), st.MPI_SOURCE);
          int64_t assign;
          {
            std::lock_guard<std::mutex> lock(m);
            assign = take(st.MPI_SOURCE);
          }
          check(MPI_Send(&assign, 1, MPI_INT64_T, st.MPI_SOURCE, kTagAssign, MPI_COMM_WORLD), "MPI_Send");
          if (assign < 0) --workers_left;
          progress = true;
        }
        std::deque<std::pair<size_t, RunOutcome>> mine;
        bool local_alive;
        {
          std::lock_guard<std::mutex> lock(m);
          mine.swap(local_done);
          local_alive = local_running;
        }
        for (auto& [k, o] : mine) finish(k, std::move(o), 0);
        progress = progress || !mine.empty();
        if (workers_left == 0 && !local_alive && mine.empty()) break;
        idle_ms = progress ? 0 : std::min(idle_ms + 1, 20);
        if (idle_ms) std::this_thread::sleep_for(std::chrono::milliseconds(idle_ms));
      }
    } catch (...) {
      stop_local = true;
      local.detach();  // it may be inside a run; the destructor aborts the job
      sigaction(SIGTERM, &old_term, nullptr);
      sigaction(SIGINT, &old_int, nullptr);
      throw;
    }
    local.join();
    sigaction(SIGTERM, &old_term, nullptr);
    sigaction(SIGINT, &old_int, nullptr);
    return out;
  }

  // The job is being terminated (a rank died, the scheduler's time limit, Ctrl-C): report every run not
  // finished, then leave at once — the launcher kills what is left within seconds.
  [[noreturn]] void interrupted(const std::vector<RunJob>& jobs, std::vector<RunOutcome>& out, const std::vector<int>& state,
                                const std::vector<int>& where, std::mutex& m, const OutcomeCallback& on_outcome,
                                std::ostream* log, std::atomic<bool>& stop_local) {
    stop_local = true;
    const int sig = g_signal.load();
    std::vector<size_t> unfinished;
    {
      std::lock_guard<std::mutex> lock(m);
      for (size_t k = 0; k < jobs.size(); ++k) {
        if (state[k] == 2) continue;
        unfinished.push_back(k);
        out[k].ok = false;
        out[k].status = state[k] == 1 ? "failed: job terminated (signal " + std::to_string(sig) + ") while running on rank " +
                                            std::to_string(where[k])
                                      : "failed: job terminated (signal " + std::to_string(sig) + ") before the run started";
        if (state[k] == 1) out[k].worker = "rank " + std::to_string(where[k]);
      }
    }
    try {  // first the summary (the launcher's SIGKILL follows within about a second), then the log
      if (on_outcome)
        for (size_t i = 0; i < unfinished.size(); ++i) on_outcome(unfinished[i], out[unfinished[i]], i + 1 < unfinished.size());
    } catch (const std::exception& e) {
      if (log) *log << "shelldyn: error: " << one_line(e.what()) << std::endl;
    }
    if (log)
      for (size_t k : unfinished) *log << "[" << k + 1 << "/" << jobs.size() << "] " << jobs[k].label << ": " << out[k].status << "\n";
    if (log) log->flush();
    std::_Exit(128 + sig);
  }

  int threads_;
  int rank_ = 0, size_ = 1;
  bool in_sweep_ = false;
};

}  // namespace

std::unique_ptr<RunExecutor> make_mpi_executor(int threads) { return std::make_unique<MpiExecutor>(threads); }

}  // namespace shelldyn
