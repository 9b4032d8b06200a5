#!/bin/bash
# Instructions per call of the CR9 element kernels (valgrind callgrind over a fixed number of calls of
# build/bin/count_element): independent of the machine's load, unlike bench_element's times.
# Usage: scripts/element_icount.sh [build/bin] [N=2000] [cylinder|sphere]
# (sphere: the doubly curved patch, whose K_bs has no zero rows, as on the pinched hemisphere)
set -euo pipefail
BIN=${1:-build/bin}; N=${2:-2000}; SHAPE=${3:-cylinder}
command -v valgrind >/dev/null || { echo "element_icount.sh: valgrind not found (apt-get install valgrind)" >&2; exit 1; }
[ -x "$BIN/count_element" ] || { echo "element_icount.sh: $BIN/count_element missing (cmake --build build --target count_element)" >&2; exit 1; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
# The kernel's top-level method only (a nested match would toggle the collection off inside it).
declare -A fn=([residual]='shelldyn::CR9Shell::algorithmic_internal*' [tangent]='shelldyn::CR9Shell::algorithmic_internal*'
              [internal_f]='shelldyn::CR9Shell::internal(*' [step_state]='shelldyn::CR9Shell::step_state*')
for k in residual internal_f step_state tangent; do
  valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$k" --toggle-collect="${fn[$k]}" \
    "$BIN/count_element" "$k" "$N" "$SHAPE" >"$tmp/log.$k" 2>&1
  ir=$(grep -E "Collected" "$tmp/log.$k" | awk '{print $NF}' | tr -d ,)
  echo "$k: $((ir / N)) instructions per call ($(grep checksum "$tmp/log.$k"))"
done
