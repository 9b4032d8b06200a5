#!/usr/bin/python3
"""scripts/plot_study.py on a real, tiny `shelldyn study` (docs/manual.md, `shelldyn study`).

usage: check_plot_study.py SHELLDYN PLOT_STUDY_PY WORK_DIR

The flying-plate study preset (its sweeps, window and reference run) on a one-element, soft free plate
whose loads end at t = 0.1 s and whose full-duration runs last 0.3 s: all runs complete in a few CPU seconds.
Then plot_study.py writes work_precision.png, full_energy.png and full_momentum.png, and each must be a PNG
of a sensible size with coloured curves in it: a figure with axes, labels and grid but no data has almost
no saturated pixels (checked here on such a figure, so the measure can fail), a figure with the study's
curves has thousands. scripts/study_tables.py (next to PLOT_STUDY_PY) must print one complete row per
method and per full-duration run. Exits 77 (ctest: skipped) when matplotlib is not installed.
"""
import importlib.util
import os
import shutil
import struct
import subprocess
import sys

CASE = """name: flying-plate-tiny
description: "one soft element with the flying plate's loads, short: a smoke test of study + plot_study.py"
mesh: {generator: rectangle, a: 2, b: 1, nx: 1, ny: 1}
material: {E: 1.0e2, nu: 0.3, rho: 1.0, thickness: 0.1}
sets:
  A: {point: [2, 0, 0]}
  B: {point: [0, 1, 0]}
loads:
  - {set: A, type: force, direction: [0, 0, 1], amplitude: 0.01, function: {type: hat, t1: 0.05}}
  - {set: B, type: force, direction: [1, 0, 0], amplitude: 0.01, function: {type: hat, t1: 0.05}}
integrator: {name: em-galpha, rho_inf: 1.0}
time: {dt: 1.0e-3, t_end: 0.3, output_interval: 0.01}
output: {vtu: false, history: true}
monitors:
  - {name: uzA, set: A, quantity: uz}
"""

# A curve pixel: saturated (max - min channel > 0.25 of full scale). Axes, text and grid are grey.
SATURATION = 0.25
MIN_COLOURED_FRACTION = 2e-3   # of all pixels; a 1400x900 figure: 2 500 pixels
MIN_COLOURS = 3                # distinct curve colours (quantised), each on >= 100 pixels


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run(args):
    p = subprocess.run(args, capture_output=True, text=True, timeout=1200)
    if p.returncode != 0:
        fail(f"{' '.join(args)} exited {p.returncode}\nstdout:\n{p.stdout}\nstderr:\n{p.stderr}")
    return p.stdout


def png_size(path):
    """(width, height) from the PNG signature and IHDR chunk; fails on anything that is not a PNG."""
    with open(path, "rb") as f:
        head = f.read(24)
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        fail(f"{path} is not a PNG file")
    return struct.unpack(">II", head[16:24])


def curve_content(path):
    """(fraction of saturated pixels, number of distinct saturated colours on >= 100 pixels)."""
    import matplotlib.image as mpimg
    import numpy as np
    img = mpimg.imread(path)[:, :, :3]
    sat = img.max(axis=2) - img.min(axis=2) > SATURATION
    quantised = (img[sat] * 7).round().astype(int)
    _, counts = np.unique(quantised, axis=0, return_counts=True)
    return sat.mean(), int((counts >= 100).sum())


def check_png(path):
    if not os.path.isfile(path):
        fail(f"{path} was not written")
    w, h = png_size(path)
    if w < 800 or h < 600:
        fail(f"{path}: {w}x{h} pixels, expected at least 800x600")
    frac, colours = curve_content(path)
    print(f"{os.path.basename(path)}: {w}x{h}, {frac:.2%} curve pixels, {colours} curve colours")
    return frac, colours


def main():
    exe, plot_script, work = sys.argv[1:4]
    if importlib.util.find_spec("matplotlib") is None:
        print("SKIP: matplotlib is not installed (Debian: python3-matplotlib)")
        sys.exit(77)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)

    # The measure can fail: a figure with axes, labels and a grid but no curve is flagged.
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 2, figsize=(13, 9.5))
    for ax in axes.flat:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("cost: CPU time [s]")
        ax.set_ylabel("energy-balance error [-]")
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle("no data")
    empty = os.path.join(work, "empty.png")
    fig.savefig(empty, dpi=110)
    plt.close(fig)
    frac, colours = check_png(empty)
    if frac >= MIN_COLOURED_FRACTION or colours >= MIN_COLOURS:
        fail(f"the empty figure passes the curve test ({frac:.2%}, {colours} colours): the test cannot fail")

    case = os.path.join(work, "tiny.yaml")
    with open(case, "w") as f:
        f.write(CASE)
    study = os.path.join(work, "study")
    out = run([exe, "study", "flying-plate", "--case", case, "--jobs", "1", "--no-plots", "-o", study])
    if " 0 failed" not in out:
        fail("some study runs failed:\n" + out)
    plots = os.path.join(work, "plots")
    os.makedirs(plots)
    run([sys.executable, plot_script, study, "--out", plots])
    for name in ("work_precision.png", "full_energy.png", "full_momentum.png"):
        frac, colours = check_png(os.path.join(plots, name))
        if frac < MIN_COLOURED_FRACTION or colours < MIN_COLOURS:
            fail(f"{name} has almost no curves: {frac:.2%} coloured pixels (>= {MIN_COLOURED_FRACTION:.1%} expected), "
                 f"{colours} curve colours (>= {MIN_COLOURS} expected)")

    # scripts/study_tables.py (the README's compact tables): one row per method in the window table, every
    # run of this study complete, one row per full-duration run.
    tables = run([sys.executable, os.path.join(os.path.dirname(plot_script), "study_tables.py"), study])
    window, _, full = tables.partition("\n\n")
    wrows = [l for l in window.splitlines()[2:] if l.startswith("| ")]
    frows = [l for l in full.splitlines()[2:] if l.startswith("| ")]
    methods = {l.split(" | ")[0][2:] for l in wrows}
    expected = {"ida-bdf", "arkode-dirk", "arkode-erk", "em-galpha", "em-exact", "galpha ρ∞=1", "galpha ρ∞=0.8",
                "midpoint", "newmark"}
    if methods != expected:
        fail(f"study_tables.py window rows {sorted(methods)}, expected {sorted(expected)}:\n{tables}")
    if any(" 4 of 4 " not in l for l in wrows):
        fail("study_tables.py: a method without 4 of 4 complete runs:\n" + tables)
    if len(frows) != 7 or any(not l.endswith("| complete |") for l in frows):
        fail(f"study_tables.py: {len(frows)} full-duration rows (7 complete expected):\n{tables}")
    print(f"study_tables.py: {len(wrows)} methods, {len(frows)} full-duration runs")
    print("PASS")


if __name__ == "__main__":
    main()
