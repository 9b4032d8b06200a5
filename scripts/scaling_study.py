#!/usr/bin/env python3
"""The scaling study of docs/scaling.md: runs build/bin/bench_scaling over a series of meshes (one process
per configuration, so peak memory is that configuration's), writes the CSV, fits the exponents and plots.

usage: scaling_study.py [--bin build/bin/bench_scaling] [--csv docs/scaling.csv] [--png docs/img/scaling.png]
                        [--plot-only] [--quick] [--series hemisphere|plate]

--plot-only: read the CSV instead of running. --quick: the two smallest meshes only (smoke test).
Exponents: least-squares slope of log(quantity) against log(unknowns) over the three largest meshes of
each series (the small ones are dominated by fixed costs). Prints the markdown table of docs/scaling.md.
"""
import argparse
import csv
import math
import os
import subprocess
import sys

SERIES = {"hemisphere": [4, 8, 12, 16, 24, 32], "plate": [16, 24, 32, 48, 64]}
THREADS = [1, 2]


def run_series(exe, quick, only):
    rows = []
    header = subprocess.run([exe, "--header"], check=True, capture_output=True, text=True).stdout.strip().split(",")
    for mesh, ns in SERIES.items():
        if only and mesh != only:
            continue
        for n in ns[:2] if quick else ns:
            for t in THREADS:
                env = dict(os.environ, OPENBLAS_NUM_THREADS=str(t), OMP_NUM_THREADS=str(t))
                out = subprocess.run([exe, mesh, str(n), "--threads", str(t)], check=True, capture_output=True, text=True,
                                     env=env, timeout=3600).stdout.strip()
                print(out, flush=True)
                rows.append(dict(zip(header, out.split(","))))
    return header, rows


def slope(xs, ys):
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


QUANTITIES = [("assembly_cpu_s", "assembly (CPU)"), ("cholmod_nnz_L", "nnz(L)"), ("cholmod_flops", "factor flops"),
              ("factor_eigen-ldlt_cpu_s", "factor eigen-ldlt (CPU)"), ("factor_cholmod_cpu_s", "factor cholmod (CPU)"),
              ("step_cpu_s", "em-galpha step (CPU)"), ("peak_rss_mb", "peak memory")]


def fits(rows):
    res = {}
    for mesh in SERIES:
        for t in THREADS:
            sel = sorted((r for r in rows if r["mesh"] == mesh and int(r["threads"]) == t), key=lambda r: int(r["unknowns"]))
            if len(sel) < 3:
                continue
            big = sel[-3:]
            for q, _ in QUANTITIES:
                try:
                    res[(mesh, t, q)] = slope([float(r["unknowns"]) for r in big], [float(r[q]) for r in big])
                except (ValueError, ZeroDivisionError):
                    pass
    return res


def table(rows, res):
    print("| mesh | unknowns | threads | nnz(K) | nnz(L) | fill nnz(L)/nnz(K)/2 | peak memory [MB] | assembly [ms] wall / CPU "
          "| factorization CPU eigen-ldlt / cholmod [s] | em-galpha step [s] wall / CPU | Newton its |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in sorted(rows, key=lambda r: (r["mesh"], int(r["unknowns"]), int(r["threads"]))):
        nnzK, nnzL = float(r["nnz_K"]), float(r["cholmod_nnz_L"])
        print(f"| {r['mesh']} | {int(r['unknowns'])} | {r['threads']} | {int(nnzK)} | {int(nnzL)} | "
              f"{nnzL / (nnzK / 2):.1f} | {float(r['peak_rss_mb']):.0f} | "
              f"{1e3 * float(r['assembly_s']):.1f} / {1e3 * float(r['assembly_cpu_s']):.1f} | "
              f"{float(r['factor_eigen-ldlt_cpu_s']):.3g} / {float(r['factor_cholmod_cpu_s']):.3g} | "
              f"{float(r['step_s']):.3g} / {float(r['step_cpu_s']):.3g} | {r['newton_per_step']} |")
    print()
    print("| series | " + " | ".join(label for _, label in QUANTITIES) + " |")
    print("|---|" + "---|" * len(QUANTITIES))
    for mesh in SERIES:
        for t in THREADS:
            vals = [res.get((mesh, t, q)) for q, _ in QUANTITIES]
            if any(v is not None for v in vals):
                print(f"| {mesh}, {t} thread(s) | " + " | ".join("–" if v is None else f"{v:.2f}" for v in vals) + " |")


def plot(rows, png):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("scaling_study: matplotlib not available, no plot")
        return
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5))
    panels = [(axes[0][0], [("peak_rss_mb", "peak memory [MB]")], "memory"),
              (axes[0][1], [("assembly_s", "assembly wall [s]"), ("assembly_cpu_s", "assembly CPU [s]")], "assembly of F_int + K"),
              (axes[1][0], [("factor_eigen-ldlt_cpu_s", "eigen-ldlt CPU [s]"), ("factor_cholmod_cpu_s", "cholmod CPU [s]")],
               "one factorization of K̄ (nnz(L) dashed, right axis)"),
              (axes[1][1], [("step_s", "step wall [s]"), ("step_cpu_s", "step CPU [s]")], "em-galpha step, full Newton")]
    markers = {"hemisphere": "o", "plate": "s"}
    for ax, qs, title in panels:
        for mesh in SERIES:
            for t in THREADS:
                sel = sorted((r for r in rows if r["mesh"] == mesh and int(r["threads"]) == t), key=lambda r: int(r["unknowns"]))
                if not sel:
                    continue
                x = [int(r["unknowns"]) for r in sel]
                for k, (q, lab) in enumerate(qs):
                    ax.loglog(x, [float(r[q]) for r in sel], marker=markers[mesh], linestyle="-" if t == 1 else ":",
                              label=f"{mesh}, {t} thr: {lab}", alpha=0.9 if k == 0 else 0.6)
        if title.startswith("one factorization"):
            ax2 = ax.twinx()
            for mesh in SERIES:
                sel = sorted((r for r in rows if r["mesh"] == mesh and int(r["threads"]) == 1), key=lambda r: int(r["unknowns"]))
                if sel:
                    ax2.loglog([int(r["unknowns"]) for r in sel], [float(r["cholmod_nnz_L"]) for r in sel], "k--",
                               marker=markers[mesh], alpha=0.4, label=f"{mesh}: nnz(L)")
            ax2.set_ylabel("nnz(L)")
            ax2.legend(fontsize=7, loc="lower right")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("unknowns")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, loc="upper left")
    fig.suptitle("shelldyn cost against mesh size (bench_scaling; solid: 1 thread, dotted: 2 threads)")
    fig.tight_layout()
    os.makedirs(os.path.dirname(png) or ".", exist_ok=True)
    fig.savefig(png, dpi=110)
    print("wrote " + png)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="build/bin/bench_scaling")
    ap.add_argument("--csv", default="docs/scaling.csv")
    ap.add_argument("--png", default="docs/img/scaling.png")
    ap.add_argument("--plot-only", action="store_true")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--series", choices=sorted(SERIES), help="run one series only")
    a = ap.parse_args()
    if a.plot_only:
        with open(a.csv, newline="") as f:
            rows = list(csv.DictReader(f))
    else:
        header, rows = run_series(a.bin, a.quick, a.series)
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=header)
            w.writeheader()
            w.writerows(rows)
        print("wrote " + a.csv)
    res = fits(rows)
    table(rows, res)
    plot(rows, a.png)


if __name__ == "__main__":
    sys.exit(main())
