#!/usr/bin/env bash
# libFuzzer runs of the case-file reader and the Gmsh reader (fuzz/), with AddressSanitizer and
# UndefinedBehaviorSanitizer, in a separate build folder (build-fuzz/, clang from Debian: clang-14 and
# libclang-rt-14-dev).
#
#   bash scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]     # default: 60 s each, both targets
#
# Each target starts from its seed corpus fuzz/corpus/<case|gmsh>/ and keeps what it finds in
# build-fuzz/corpus/<target>/ (not in the source tree). A crash, sanitizer report, leak or timeout
# makes libFuzzer write build-fuzz/artifacts/<target>/crash-* and this script exit non-zero.
# The executions count of each run is the "stat::number_of_executed_units" line at the end of
# build-fuzz/<target>.log.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fuzz_case_file fuzz_gmsh_reader)
CC=${CC:-clang-14}
CXX=${CXX:-clang++-14}
flags="-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g -O1"
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER="$CC" -DCMAKE_CXX_COMPILER="$CXX" \
  -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DSHELLDYN_BUILD_FUZZERS=ON -DSHELLDYN_BUILD_TESTS=OFF -DSHELLDYN_BUILD_APPS=OFF -DSHELLDYN_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz -j2 --target "${targets[@]}"
status=0
for t in "${targets[@]}"; do
  case $t in
    fuzz_case_file) seeds=fuzz/corpus/case dict=fuzz/case_file.dict ;;
    fuzz_gmsh_reader) seeds=fuzz/corpus/gmsh dict=fuzz/gmsh.dict ;;
    *) echo "fuzz.sh: unknown target $t" >&2; exit 2 ;;
  esac
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/artifacts/$t"
  echo "fuzz.sh: $t for $seconds s (log: build-fuzz/$t.log)"
  if ! ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 "build-fuzz/bin/$t" \
      -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=8192 -print_final_stats=1 \
      -dict="$dict" -artifact_prefix="build-fuzz/artifacts/$t/" "build-fuzz/corpus/$t" "$seeds" \
      >"build-fuzz/$t.log" 2>&1; then
    echo "fuzz.sh: $t FOUND A PROBLEM (see build-fuzz/$t.log and build-fuzz/artifacts/$t/)" >&2
    status=1
  fi
  grep -E "stat::number_of_executed_units|stat::new_units_added" "build-fuzz/$t.log" || true
done
exit $status
