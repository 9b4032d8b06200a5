#!/usr/bin/python3
"""Plots of a `shelldyn compare` study.

usage: plot_compare.py COMPARE_DIR [--out DIR]

Reads COMPARE_DIR/summary.csv and each run's COMPARE_DIR/<label>/history.csv and writes:
  energy.png          total energy H of every run overlaid, and |H - H_ref|/(K_ref + V_ref) after the loads end
  momentum.png        |L - L(t_ref)| and |J - J(t_ref)| of every run after the loads end (log scale)
  work_precision.png  wall time vs max energy error, and wall time vs displacement error against the
                      reference run (summary.csv's displacement_error); failed runs are listed, not plotted
If matplotlib is missing, prints one warning line and exits 0.
"""
import argparse
import math
import os
import sys

from plot_common import after_loads_row, columns, fnum, loads_end, read_csv




def mechanical_drift(h, ref):
    """(t, |H - H_ref| / (K_ref + V_ref)) after the loads end; ref = the row of the run driver's reference
    time (plot_common.after_loads_row). H_ref itself is ~0 for a body set in motion by loads."""
    if ref is None:
        return []
    scale = h["kinetic"][ref] + h["strain"][ref]
    if not scale > 0:
        return []
    return [(h["t"][i], abs(h["total"][i] - h["total"][ref]) / scale) for i in range(ref, len(h["t"]))
            if h["total"][i] != h["total"][ref]]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--out", default="")
    a = ap.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("warning: matplotlib is not installed (Debian: apt-get install python3-matplotlib); no plots written")
        return 0
    summary = os.path.join(a.dir, "summary.csv")
    if not os.path.isfile(summary):
        print(f"plot_compare.py: error: {summary} not found", file=sys.stderr)
        return 1
    runs = read_csv(summary)
    out = a.out or a.dir
    case = os.path.basename(os.path.normpath(a.dir))
    md = os.path.join(a.dir, "summary.md")
    if os.path.isfile(md):  # first line: "# Integrator comparison: CASE"
        with open(md, encoding="utf-8") as f:
            first = f.readline()
        if ":" in first:
            case = first.split(":", 1)[1].strip()
    color = {r["label"]: f"C{i % 10}" for i, r in enumerate(runs)}  # one colour per run in every panel
    hists = {}
    refs = {}  # label -> row of the after-the-loads reference (None: the run ends before the loads do)
    for r in runs:
        p = os.path.join(a.dir, r["label"], "history.csv")
        if r["status"] == "complete" and os.path.isfile(p):
            h = columns(read_csv(p))
            refs[r["label"]] = after_loads_row(h, loads_end(os.path.dirname(p)))
            hists[r["label"]] = h

    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for label, h in hists.items():
        ax.plot(h["t"], h["total"], label=label, lw=1, color=color[label])
        pts = mechanical_drift(h, refs[label])
        if pts:
            ax2.semilogy([p[0] for p in pts], [p[1] for p in pts], lw=1, label=label, color=color[label])
    ax.set_ylabel("total energy H")
    ax.set_title(f"{case}: energy of each run")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    ax2.set_ylabel("|H - H_ref| / (K_ref + V_ref)")
    ax2.set_xlabel("t [s]")
    ax2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "energy.png"), dpi=90)
    plt.close(fig)

    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for label, h in hists.items():
        t = h["t"]
        ref = refs[label]
        if ref is None:
            continue
        for axis, keys in ((a1, ("Lx", "Ly", "Lz")), (a2, ("Jx", "Jy", "Jz"))):
            d = [math.sqrt(sum((h[k][i] - h[k][ref]) ** 2 for k in keys)) for i in range(ref, len(t))]
            pts = [(t[ref + i], x) for i, x in enumerate(d) if x > 0]
            if pts:
                axis.semilogy([p[0] for p in pts], [p[1] for p in pts], lw=1, label=label, color=color[label])
    a1.set_ylabel("|L - L_ref|")
    a1.set_title(f"{case}: momentum changes after the loads end")
    a1.legend(fontsize=7)
    a1.grid(alpha=0.3, which="both")
    a2.set_ylabel("|J - J_ref|")
    a2.set_xlabel("t [s]")
    a2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "momentum.png"), dpi=90)
    plt.close(fig)

    fig, (w1, w2) = plt.subplots(1, 2, figsize=(10, 4))
    failed = []
    for r in runs:
        if r["status"] != "complete":
            failed.append(r["label"])
            continue
        wall, e, d = fnum(r["wall_s"]), fnum(r["energy_error"]), fnum(r["displacement_error"])
        if math.isfinite(e) and e > 0:
            w1.loglog(e, wall, "o", color=color[r["label"]])
            w1.annotate(r["label"], (e, wall), fontsize=7)
        if math.isfinite(d) and d > 0:
            w2.loglog(d, wall, "s", color=color[r["label"]])
            w2.annotate(r["label"], (d, wall), fontsize=7)
    ref = runs[0]["reference"] if runs else ""
    w1.set_xlabel("max |H - H_ref| / (K_ref + V_ref) after the loads")
    w1.set_ylabel("wall time [s]")
    w1.set_title("energy error")
    w1.grid(alpha=0.3, which="both")
    w2.set_xlabel(f"max displacement error vs {ref}")
    w2.set_title("displacement error")
    w2.grid(alpha=0.3, which="both")
    if failed:
        fig.text(0.01, 0.01, "failed: " + ", ".join(failed), fontsize=7, color="C3")
    fig.suptitle(f"{case}: work-precision")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "work_precision.png"), dpi=90)
    plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
