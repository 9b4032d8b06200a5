#!/usr/bin/python3
"""Slit annular plate under a lifting line force (Sze, Liu & Lo 2004 §3.3; docs/benchmarks.md §4.3).

usage: check_slit_annulus.py SHELLDYN CASE WORK_DIR TOL [N_RADIAL N_CIRC ...]

Runs `SHELLDYN static CASE` (apps/cases/sze-slit-annulus.yaml) once per mesh (default: the case's own
mesh; otherwise each N_RADIAL N_CIRC pair replaces it), reads W_A, W_B from static.csv at the load levels of
Sze's Table 4 and prints them against the reference. Fails if, on the LAST mesh given, a deflection at
P/P_max >= 0.1 differs from the reference by more than TOL (relative).
"""
import csv
import os
import resource
import shutil
import subprocess
import sys

# Sze, Liu & Lo (2004), Finite Elem. Anal. Des. 40, 1551-1569, Table 4: P/P_max, W_A, W_B
# (ABAQUS S4R, 10 x 80 mesh; P_max = 0.8 per unit length).
REFERENCE = [
    (0.05, 2.455, 3.370), (0.10, 4.277, 5.876), (0.20, 6.725, 9.160), (0.30, 8.340, 11.213),
    (0.40, 9.529, 12.661), (0.50, 10.468, 13.768), (0.60, 11.257, 14.674), (0.70, 11.970, 15.469),
    (0.80, 12.642, 16.202), (0.90, 13.282, 16.886), (1.00, 13.891, 17.528),
]


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run_mesh(exe, case_text, work, nr, nc):
    name = f"{nr}x{nc}" if nr else "case"
    text = case_text
    if nr:
        old = "n_radial: 5, n_circ: 40"
        if old not in text:
            fail(f"the case no longer holds {old!r}")
        text = text.replace(old, f"n_radial: {nr}, n_circ: {nc}")
    text = text.replace("output: {vtu: true", "output: {vtu: false")
    case = os.path.join(work, f"slit_{name}.yaml")
    open(case, "w").write(text)
    out = os.path.join(work, name)
    def children_cpu():
        u = resource.getrusage(resource.RUSAGE_CHILDREN)
        return u.ru_utime + u.ru_stime
    t0 = children_cpu()
    r = subprocess.run([exe, "static", case, "-o", out], capture_output=True, text=True)
    cpu = children_cpu() - t0
    if r.returncode != 0:
        fail(f"{name}: shelldyn static failed:\n{r.stderr}")
    rows = list(csv.DictReader(open(os.path.join(out, "static.csv"))))
    got = {}
    for lam, wa, wb in REFERENCE:
        near = [row for row in rows if abs(float(row["load_factor"]) - lam) < 1e-9]
        if not near:
            fail(f"{name}: no static.csv row at load factor {lam} (the case must use fixed increments of 0.025)")
        got[lam] = (float(near[0]["w_A"]), float(near[0]["w_B"]))
    return name, got, cpu


def main():
    exe, case_path, work, tol = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
    meshes = [(int(a), int(b)) for a, b in zip(sys.argv[5::2], sys.argv[6::2])] or [(0, 0)]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    case_text = open(case_path).read()
    results = [run_mesh(exe, case_text, work, nr, nc) for nr, nc in meshes]
    print("| P/P_max | Sze W_A | Sze W_B | " + " | ".join(f"{n} W_A (err) | {n} W_B (err)" for n, _, _ in results) + " |")
    print("|---" * (3 + 2 * len(results)) + "|")
    worst = 0.0
    for lam, wa, wb in REFERENCE:
        cells = []
        for k, (_, got, _) in enumerate(results):
            ga, gb = got[lam]
            ea, eb = (ga - wa) / wa, (gb - wb) / wb
            cells += [f"{ga:.3f} ({100 * ea:+.2f} %)", f"{gb:.3f} ({100 * eb:+.2f} %)"]
            if k == len(results) - 1 and lam >= 0.1:
                worst = max(worst, abs(ea), abs(eb))
        print(f"| {lam:.2f} | {wa:.3f} | {wb:.3f} | " + " | ".join(cells) + " |")
    for name, _, cpu in results:
        print(f"{name}: {cpu:.1f} s CPU (user + sys of shelldyn static)")
    print(f"largest |relative difference| at P/P_max >= 0.1 on the last mesh: {worst:.4f} (bound {tol})")
    if worst > tol:
        fail(f"the last mesh differs from Sze's reference by {worst:.4f} > {tol}")
    print("PASS")


if __name__ == "__main__":
    main()
