// Bounded spinning of idle OpenMP threads for the project's executables (honest threading, docs/performance.md).
//
// GCC's libgomp lets idle worker threads spin (busy-wait) after every parallel region before they sleep:
// GOMP_SPINCOUNT spins, 300 000 by default (about 3 ms at libgomp's estimate of 100 000 spins per ms), 0 with
// OMP_WAIT_POLICY=passive. A Newton iteration's parallel pieces are short (0.1–1 ms: the element loops, the
// split triangular solves) and follow each other closely, so the wake-up of a sleeping thread (a futex round
// trip) is a large part of each; while 3 ms of spinning after every region takes, on a shared machine, the core
// the working thread needs. Measured on the pinched hemisphere (bench_step_breakdown --threads 2 --from 0.0025
// --steps 400, wall ms per step; one thread 2.44 on the quiet machine):
//
//   GOMP_SPINCOUNT              0 (passive)   3 000   10 000
//   quiet machine               2.55          1.68    1.57
//   two CPU-bound processes     9.8           8.5     6.1     (one thread: 4.6)
//
// and the libgomp default of 300 000 spins had cost 6–8x the CPU of one thread at load 13. So the default here is
// 10 000 spins (about 0.1 ms).
//
// libgomp reads its variables once, when it is loaded, before main(); setting them later has no effect (and
// glibc discards environment changes made before its own start-up). So including this header in ONE
// translation unit of an executable adds a start-up function that, when neither OMP_WAIT_POLICY nor
// GOMP_SPINCOUNT is set, sets GOMP_SPINCOUNT=10000 and re-executes the program (same PID, arguments and
// environment otherwise). A policy set by the user (OMP_WAIT_POLICY=passive on a crowded machine, active on a
// dedicated one, or a spin count) is respected.
//
// The same re-execution sets OPENBLAS_NUM_THREADS=1 when it is not set. shelldyn runs BLAS on one thread anyway
// (lib/linalg/linear_solver.cpp limit_blas_threads()), but OpenBLAS's pthread build starts its thread pool when it is
// loaded, and the pool's thread spins (sched_yield) for a while after start-up: ~2 % of a 5 s run's CPU on the
// flying plate. With the variable set, no pool is created.
//
// Never in a library loaded into another program (the Python module, python/CMakeLists.txt): re-executing
// the host process would restart it. Such builds define SHELLDYN_NO_OPENMP_REEXEC.
#pragma once

#if defined(__linux__) && defined(__GNUC__) && !defined(SHELLDYN_NO_OPENMP_REEXEC)
#include <cstdlib>
#include <unistd.h>

namespace shelldyn::detail {
// glibc calls ELF constructors with (argc, argv, envp).
__attribute__((constructor)) inline void openmp_bounded_spin(int, char** argv, char**) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr || argv == nullptr ||
      argv[0] == nullptr)
    return;
  if (setenv("GOMP_SPINCOUNT", "10000", 0) != 0) return;
  setenv("OPENBLAS_NUM_THREADS", "1", 0);  // keeps a value the user set
  execv("/proc/self/exe", argv);  // returns only on failure: then run on with libgomp's default policy
}
}  // namespace shelldyn::detail
#endif
