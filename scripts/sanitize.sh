#!/usr/bin/env bash
# The test suite under AddressSanitizer + UndefinedBehaviorSanitizer (gcc), in build-asan/. gcc's
# -fsanitize=undefined leaves out float-cast-overflow (a double out of an integer's range converted to it,
# e.g. a step count from t_end/dt), so it is named as well.
#
#   bash scripts/sanitize.sh [CTEST_ARGS...]     # e.g. -R bad_input, or -L lib
#
# Every sanitizer finding aborts the process (-fno-sanitize-recover), so it fails its test. Excluded:
# the disabled full-length benchmarks and the install test (it rebuilds the library without the
# sanitizers). Expect 3-10x the normal test time. Run by .ci/run when SHELLDYN_CI_SANITIZE=1.
#
# LeakSanitizer reads scripts/lsan.supp, which suppresses Open MPI's own start-up allocations and
# nothing else (the reason and the stacks are in that file). Processes that Open MPI's mpiexec starts get
# the same LSAN_OPTIONS plus fast_unwind_on_malloc=0 through Open MPI's mca_base_env_list: the full
# stack is what lets those leaks be matched by the Open MPI library's name. Other processes keep the fast
# unwinder.
set -euo pipefail
cd "$(dirname "$0")/.."
flags="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer -g -O1"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined,float-cast-overflow" -DSHELLDYN_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-asan -j2
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
export OMPI_MCA_mca_base_env_list="LSAN_OPTIONS=$LSAN_OPTIONS:fast_unwind_on_malloc=0"
export OPENBLAS_NUM_THREADS=1
ctest --test-dir build-asan -j2 --output-on-failure -LE "benchmark|install" --timeout 1800 "$@"
