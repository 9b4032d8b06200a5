// How the independent runs of a sweep are executed (docs/architecture.md, "Layers": runs/): the one boundary
// between "what a sweep runs" (compare, study) and "where it runs" (worker threads of this process, or
// the ranks of an MPI job; docs/cluster-sweeps.md).
//
//   std::vector<RunJob> jobs = ...;              // one per run: label + expected cost
//   auto outcomes = execute_runs(jobs, run_one, executor, on_outcome);
//
// Contract, for every executor:
//   - run_one(k, threads) executes run k (its own folder, its own Problem) and returns a PAYLOAD string
//     (the caller's serialized result of the run); if it throws, the run is a failed outcome with status
//     "failed: <what()>". It is called concurrently from several threads (local pool) or processes (MPI):
//     it must not share mutable state between runs.
//   - Runs start longest expected first (RunJob::expected_cost, ties in list order) and are handed out
//     dynamically: a worker that finishes takes the next waiting run.
//   - On the COLLECTING process (the only process of a local pool; rank 0 of an MPI job), the result
//     has one outcome per job, in job order, none missing: a run that did not finish — its worker's
//     process died, the job was terminated, the run was never started — is a failed outcome saying so.
//     on_outcome(k, outcome, more) is called there, from the calling thread only, as each run finishes (so
//     a caller can rewrite its summary incrementally and a job killed later still leaves every row);
//     more = true when further outcomes follow at once (a terminated job reports all unfinished runs
//     together): the caller may defer expensive work, e.g. rewriting its summary, to the last one.
//   - On the other processes of an MPI job (collects() == false) the result is empty and on_outcome is
//     never called: they must not write summaries.
//
// Local pool: `jobs` worker threads; each run gets `threads` OpenMP threads (0: the OpenMP default when
// jobs == 1, 1 when jobs > 1). MPI: integrators/runs/mpi_executor.hpp (built when SHELLDYN_WITH_MPI).
#pragma once

#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace shelldyn {

struct RunJob {
  std::string label;           // for log lines
  double expected_cost = 0.0;  // any consistent unit (e.g. number of steps); larger runs start first
};

struct RunOutcome {
  bool ok = false;
  std::string status;          // "complete" or "failed: <reason>"
  std::string payload;         // run_one's return value when ok
  std::string worker;          // who ran it, e.g. "thread 2" or "rank 3" (empty if it never started)
};

using RunFunction = std::function<std::string(size_t index, int threads)>;
using OutcomeCallback = std::function<void(size_t index, const RunOutcome& outcome, bool more)>;

class RunExecutor {
 public:
  virtual ~RunExecutor() = default;
  // Executes every job; see the contract above. `log` (may be null) gets one line per start and finish.
  virtual std::vector<RunOutcome> execute(const std::vector<RunJob>& jobs, const RunFunction& run_one,
                                          const OutcomeCallback& on_outcome, std::ostream* log) = 0;
  // True on the process that receives the outcomes and writes summaries.
  virtual bool collects() const { return true; }
  // Number of runs that can execute at once.
  virtual int workers() const = 0;
  // e.g. "2 worker threads" or "4 MPI ranks".
  virtual std::string describe() const = 0;
};

// Worker threads of this process; jobs >= 1, threads >= 0 (see above).
std::unique_ptr<RunExecutor> make_local_executor(int jobs, int threads);

// The order in which runs start: by decreasing expected_cost, stable.
std::vector<size_t> longest_first(const std::vector<RunJob>& jobs);

// True when this process was started by an MPI launcher (mpirun/mpiexec/srun: Open MPI, PMI or PMIx
// environment variables). Does not need MPI itself.
bool launched_by_mpi();

// execute_runs(jobs, run_one, executor, on_outcome, log) = executor.execute(...).
std::vector<RunOutcome> execute_runs(const std::vector<RunJob>& jobs, const RunFunction& run_one, RunExecutor& executor,
                                     const OutcomeCallback& on_outcome = {}, std::ostream* log = nullptr);

}  // namespace shelldyn
