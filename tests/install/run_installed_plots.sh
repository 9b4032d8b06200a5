#!/usr/bin/env bash
# An installed shelldyn plots with the installed scripts: installs the build tree into a scratch prefix
# (as a non-root user would, no root needed), marks the installed plot_compare.py so that running it leaves
# a file, and runs the installed `shelldyn compare` on a short run. Fails when the installed binary takes
# the source tree's scripts (no marker) or when an installed script cannot import what it needs
# (plot_common.py not installed: no compare_energy.png).
set -euo pipefail
build_dir=$1 work=$2
rm -rf "$work"
cmake --install "$build_dir" --prefix "$work/prefix" >/dev/null
scripts="$work/prefix/share/shelldyn/scripts"
marker="$work/installed-script-ran"
python3 - "$scripts/plot_compare.py" "$marker" <<'PY'
import sys
path, marker = sys.argv[1], sys.argv[2]
lines = open(path, encoding="utf-8").read().split("\n")
first_import = next(k for k, line in enumerate(lines) if line.startswith("import "))  # after the docstring
lines.insert(first_import, f"open({marker!r}, 'w').close()  # test marker")
open(path, "w", encoding="utf-8").write("\n".join(lines))
PY
cd "$work"
OPENBLAS_NUM_THREADS=1 "$work/prefix/bin/shelldyn" compare flying-plate --integrators em-galpha,galpha --t-end 0.02 \
    -o "$work/cmp" > "$work/compare.log" 2>&1 || { cat "$work/compare.log"; exit 1; }
[ -f "$marker" ] || { echo "FAIL: the installed shelldyn did not run the installed plot_compare.py"; cat "$work/compare.log"; exit 1; }
ls "$work/cmp"/*.png >/dev/null 2>&1 || { echo "FAIL: no plots in $work/cmp"; cat "$work/compare.log"; exit 1; }
if grep -qi 'traceback\|warning: plot' "$work/compare.log"; then echo "FAIL: plotting failed"; cat "$work/compare.log"; exit 1; fi
echo "installed compare plotted with the installed scripts: $(cd "$work/cmp" && ls *.png | tr '\n' ' ')"
