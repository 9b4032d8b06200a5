#!/usr/bin/env bash
# Installs the build tree into a scratch prefix and builds a separate CMake project against it with
# find_package(shelldyn): the exported-target contract of the foundation issue.
set -euo pipefail
build_dir=$1 src_dir=$2 work=$3
rm -rf "$work"
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
for s in flying-plate cylindrical-panel pinched-hemisphere; do  # the shipped study files (shelldyn study NAME)
  test -f "$work/prefix/share/shelldyn/studies/$s.yaml" || { echo "not installed: share/shelldyn/studies/$s.yaml"; exit 1; }
done
cmake -S "$src_dir" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/consumer" -j2 >/dev/null
"$work/consumer/consumer"
