// Passive OpenMP waiting for the project's executables (honest threading, README "Performance").
//
// GCC's libgomp lets idle worker threads spin (busy-wait, up to GOMP_SPINCOUNT = 300 000 spins, a few ms)
// after every parallel region unless OMP_WAIT_POLICY=passive. The element loops of a Newton iteration are
// short (~1–3 ms) and separated by serial work (linear solves, vector updates) of the same length, so a
// second thread spends that time spinning, and on a shared machine it takes the core the working thread
// needs: measured on the pinched hemisphere (bench_step_breakdown --threads 2, load ~13 on 2 cores)
// 6–8x the CPU of one thread and 5x its wall time; with passive waiting, the CPU of one thread.
//
// libgomp reads the variable once, when it is loaded, before main(); setting it later has no effect (and
// glibc discards environment changes made before its own start-up). So including this header in ONE
// translation unit of an executable adds a start-up function that, when OMP_WAIT_POLICY is not set,
// sets it to passive and re-executes the program (same PID, arguments and environment otherwise). An
// OMP_WAIT_POLICY set by the user (e.g. active on a dedicated machine) is respected.
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
__attribute__((constructor)) inline void openmp_wait_passive(int, char** argv, char**) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || argv == nullptr || argv[0] == nullptr) return;
  if (setenv("OMP_WAIT_POLICY", "passive", 0) != 0) return;
  setenv("OPENBLAS_NUM_THREADS", "1", 0);  // keeps a value the user set
  execv("/proc/self/exe", argv);  // returns only on failure: then run on with libgomp's default policy
}
}  // namespace shelldyn::detail
#endif
