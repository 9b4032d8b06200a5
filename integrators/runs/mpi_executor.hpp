// The ranks of an MPI job as sweep workers (the RunExecutor contract of integrators/runs/executor.hpp;
// usage and cluster set-up: docs/cluster-sweeps.md). Built only when CMake finds MPI and
// SHELLDYN_WITH_MPI is ON (it defines SHELLDYN_HAVE_MPI for the targets that link shelldyn_mpi).
//
// Every rank runs the same command, so every rank expands the same list of runs; the ranks check this
// (a hash of the labels) before anything runs. Rank 0 hands out run indices on request, longest expected
// run first; every rank, rank 0 included (in a second thread, so that MPI calls stay on its main
// thread: MPI_THREAD_FUNNELED), executes one run at a time with `threads` OpenMP threads (0 → 1) and
// sends back (index, ok, status, payload). Rank 0 receives every outcome and is the only rank that
// collects (RunExecutor::collects()).
//
// Failures: a run that throws is a failed outcome like in a local pool. A rank that dies (crash, kill,
// node loss) makes mpirun/srun terminate the job; rank 0 catches the SIGTERM it then gets, reports every
// run not yet finished as "failed: job terminated ..." through on_outcome (naming the rank it was running
// on, or "never started") and exits with status 143 — so the summary the caller writes from on_outcome
// lists every run, and a rerun with --resume executes only those.
#pragma once

#include "integrators/runs/executor.hpp"

#include <memory>

namespace shelldyn {

// Initializes MPI (MPI_Init_thread, FUNNELED) and returns the executor over MPI_COMM_WORLD; MPI is
// finalized when it is destroyed. Call only when launched_by_mpi(), once per process.
std::unique_ptr<RunExecutor> make_mpi_executor(int threads);

}  // namespace shelldyn
