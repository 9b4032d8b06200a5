#!/usr/bin/env bash
# The example integrator plugin of examples/velocity-verlet, built only against the installed package:
#   1. cmake --install into a scratch prefix;
#   2. configure and build examples/velocity-verlet with find_package(shelldyn) from that prefix;
#   3. the installed `shelldyn compare flying-plate --plugin ... --integrators em-galpha,velocity-verlet`;
#   4. tests/install/check_example.py: both runs complete, same history.csv columns, and the in-tree copy of the
#      same source (example_in_tree_runner) gives the same history, number for number (wall_s aside);
#   5. the installed `shelldyn study` on a study file whose methods include the plugin's integrator
#      (tests/install/example-study.yaml): its window rows are complete, with displacement errors against the
#      reference, beside em-galpha's.
set -euo pipefail
build_dir=$1 src_dir=$2 work=$3 in_tree=$4
rm -rf "$work"
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
cmake -S "$src_dir/examples/velocity-verlet" -B "$work/vv" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/vv" -j2 >/dev/null
plugin="$work/vv/libvelocity_verlet.so"
"$work/prefix/bin/shelldyn" compare flying-plate --plugin "$plugin" --integrators em-galpha,velocity-verlet \
  --t-end 0.05 --jobs 1 --threads 1 --no-plots --progress-every 0 -o "$work/compare"
"$in_tree" "$src_dir/apps/cases/flying-plate.yaml" 0.05 "$work/in-tree"
/usr/bin/python3 "$src_dir/tests/install/check_example.py" "$work/compare" "$work/in-tree" "$plugin"
cp "$src_dir/tests/install/example-study.yaml" "$work/example-study.yaml"
"$work/prefix/bin/shelldyn" study "$work/example-study.yaml" --plugin "$plugin" --jobs 1 --no-plots -o "$work/study"
/usr/bin/python3 "$src_dir/tests/install/check_example.py" --study "$work/study"
