#!/usr/bin/env python3
"""Conservation table of a constrained run (docs/benchmarks.md "Free-flying pair"): |ΔH|/H, ‖ΔL‖, ‖ΔJ‖, max‖g‖∞ and
max‖G u̇ + ∂g/∂t‖∞ from the history.csv of each result folder given.

    python3 scripts/multibody_conservation_table.py results/free-pair/em-exact results/free-pair/em-galpha ...
    python3 scripts/multibody_conservation_table.py --t-max 3 results/free-pair/ida-bdf   # rows with t <= 3 only
"""
import csv
import math
import os
import sys


def row(folder, t_max):
    with open(os.path.join(folder, "history.csv")) as f:
        r = [x for x in csv.DictReader(f) if float(x["t"]) <= t_max + 1e-12]
    h0 = float(r[0]["total"])
    k0 = abs(float(r[0]["kinetic"])) + abs(float(r[0]["strain"]))
    L0 = [float(r[0][k]) for k in ("Lx", "Ly", "Lz")]
    J0 = [float(r[0][k]) for k in ("Jx", "Jy", "Jz")]
    dH = max(abs(float(x["total"]) - h0) for x in r) / k0
    dL = max(math.dist([float(x[k]) for k in ("Lx", "Ly", "Lz")], L0) for x in r)
    dJ = max(math.dist([float(x[k]) for k in ("Jx", "Jy", "Jz")], J0) for x in r)
    g = max(float(x["g_norm"]) for x in r)
    gd = max(float(x["gdot_norm"]) for x in r)
    return (os.path.basename(folder.rstrip("/")), float(r[-1]["t"]), dH, dL, math.hypot(*L0), dJ, math.hypot(*J0), g, gd,
            int(r[-1]["nonlinear_iters"]))


print("| integrator | t_end | max \\|ΔH\\|/(K+V)₀ | max ‖ΔL‖ (‖L₀‖) | max ‖ΔJ‖ (‖J₀‖) | max ‖g‖∞ | max ‖Gu̇+∂g/∂t‖∞ | Newton its |")
print("|---|---|---|---|---|---|---|---|")
args = sys.argv[1:]
t_max = math.inf
if args[:1] == ["--t-max"]:
    t_max, args = float(args[1]), args[2:]
for folder in args:
    n, t, dH, dL, L0, dJ, J0, g, gd, its = row(folder, t_max)
    print(f"| {n} | {t:g} | {dH:.2e} | {dL:.2e} ({L0:.3g}) | {dJ:.2e} ({J0:.3g}) | {g:.1e} | {gd:.1e} | {its} |")
