#!/usr/bin/python3
"""Plots of one shelldyn run (history.csv of `shelldyn run` or a benchmark app).

usage: plot_run.py RESULT_DIR [--title TEXT] [--out DIR]

Writes into RESULT_DIR (or --out):
  energy.png    kinetic K, strain V, external work W_ext and total H = K + V - W_ext; below, the relative
                drift |H - H_ref|/(K_ref + V_ref) after the loads end (log scale)
  momentum.png  linear momentum L and angular momentum J (about the origin, director term included)
  monitors.png  the case's monitor columns (displacements of named points)
If matplotlib is missing, prints one warning line and exits 0 (the run's results are complete anyway).
"""
import argparse
import csv
import math
import os
import sys

STANDARD = ["step", "t", "dt", "kinetic", "strain", "external_work", "total", "rel_drift", "Lx", "Ly", "Lz",
            "Jx", "Jy", "Jz", "nonlinear_iters", "linear_setups", "wall_s"]


def read_history(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise SystemExit(f"plot_run.py: error: {path}: empty file")
    header, cols = rows[0], {}
    for k, name in enumerate(header):
        cols[name] = []
        for r in rows[1:]:
            if len(r) != len(header):
                continue  # truncated last row of an interrupted run
            try:
                cols[name].append(float(r[k]))
            except ValueError:
                cols[name].append(math.nan)
    return header, cols


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--title", default="")
    ap.add_argument("--out", default="")
    a = ap.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("warning: matplotlib is not installed (Debian: apt-get install python3-matplotlib); no plots written")
        return 0
    hist = os.path.join(a.dir, "history.csv")
    if not os.path.isfile(hist):
        print(f"plot_run.py: error: {hist} not found (is {a.dir} a shelldyn result folder?)", file=sys.stderr)
        return 1
    header, c = read_history(hist)
    out = a.out or a.dir
    title = a.title or os.path.basename(os.path.normpath(a.dir))
    t = c["t"]

    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    ax.plot(t, c["kinetic"], label="kinetic K")
    ax.plot(t, c["strain"], label="strain V")
    ax.plot(t, c["external_work"], label="external work W_ext", ls=":")
    ax.plot(t, c["total"], label="total H = K + V - W_ext", color="k", lw=1.5)
    ax.set_ylabel("energy")
    ax.set_title(f"{title}: energy")
    ax.legend(fontsize=8, loc="best")
    ax.grid(alpha=0.3)
    # Drift normalised by the mechanical energy K + V at the reference time (the first row with a finite
    # rel_drift): H = K + V - W_ext itself is ~0 for a body set in motion by loads.
    ref = next((i for i, d in enumerate(c["rel_drift"]) if math.isfinite(d)), None)
    pts = []
    if ref is not None and c["kinetic"][ref] + c["strain"][ref] > 0:
        scale = c["kinetic"][ref] + c["strain"][ref]
        pts = [(t[i], abs(c["total"][i] - c["total"][ref]) / scale) for i in range(ref, len(t))
               if c["total"][i] != c["total"][ref]]
    if pts:
        ax2.semilogy([p[0] for p in pts], [p[1] for p in pts], color="C3")
        ax2.set_ylabel("|H - H_ref| / (K_ref + V_ref)")
    else:
        ax2.text(0.5, 0.5, "no drift after the loads end in this window", ha="center", va="center", transform=ax2.transAxes)
    ax2.set_xlabel("t [s]")
    ax2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "energy.png"), dpi=90)
    plt.close(fig)

    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for k in ("Lx", "Ly", "Lz"):
        a1.plot(t, c[k], label=k)
    a1.set_ylabel("linear momentum L")
    a1.set_title(f"{title}: momenta")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3)
    for k in ("Jx", "Jy", "Jz"):
        a2.plot(t, c[k], label=k)
    a2.set_ylabel("angular momentum J")
    a2.set_xlabel("t [s]")
    a2.legend(fontsize=8)
    a2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "momentum.png"), dpi=90)
    plt.close(fig)

    monitors = [h for h in header if h not in STANDARD]
    if monitors:
        fig, axm = plt.subplots(figsize=(7, 3.5))
        for m in monitors:
            axm.plot(t, c[m], label=m)
        axm.set_xlabel("t [s]")
        axm.set_ylabel("monitor")
        axm.set_title(f"{title}: monitors")
        axm.legend(fontsize=8, ncol=3)
        axm.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "monitors.png"), dpi=90)
        plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
