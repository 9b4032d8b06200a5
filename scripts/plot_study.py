#!/usr/bin/python3
"""Plots of a `shelldyn study` folder.

usage: plot_study.py STUDY_DIR [--out DIR] [--title TEXT]

Reads STUDY_DIR/study.csv and the runs' STUDY_DIR/<group>/<label>/history.csv and writes:
  work_precision.png  work-precision diagram of the window sweep, log-log, one curve per method
                      (fixed-step schemes over dt: solid, circles; SUNDIALS baselines over rtol: dashed,
                      squares): energy-balance error and displacement error against the reference
                      run, each against CPU seconds and against residual/RHS evaluations
  full_energy.png     full-duration runs: relative energy error (H - H_ref)/(K + V)_ref after the loads
                      (symmetric-log axis) and K + V over time
  full_momentum.png   full-duration runs: |L - L_ref| and |J - J_ref| after the loads (log axis)
Energy errors below 1e-16 are drawn at 1e-16 (round-off level) and marked as such in the legend.
If matplotlib is missing, prints one warning line and exits 0.
"""
import argparse
import csv
import math
import os
import sys

FLOOR = 1e-16


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def fnum(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return math.nan


def columns(rows):
    out = {}
    for r in rows:
        for k, v in r.items():
            out.setdefault(k, []).append(fnum(v))
    return out


def method_of(label):
    """'galpha_rho_inf=0.8_dt=0.002' -> 'galpha ρ∞=0.8'; 'ida-bdf_rtol=1e-05' -> 'ida-bdf'."""
    parts = [p for p in label.split("_") if not (p.startswith("dt=") or p.startswith("rtol="))]
    name = parts[0]
    rest = " ".join(parts[1:]).replace("rho inf=", "ρ∞=")
    return (name + " " + rest).strip()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--out", default="")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("plot_study.py: matplotlib not installed; no plots (apt-get install python3-matplotlib)")
        return 0
    out = a.out or a.dir
    rows = read_csv(os.path.join(a.dir, "study.csv"))
    title = a.title or os.path.basename(os.path.dirname(os.path.abspath(a.dir))) or a.dir
    done = [r for r in rows if r["status"] == "complete"]
    methods = []
    for r in done:
        m = method_of(r["label"])
        if m not in methods and r["kind"] != "reference":
            methods.append(m)
    cmap = plt.get_cmap("tab10")
    colour = {m: cmap(i % 10) for i, m in enumerate(methods)}

    # --- work-precision ---------------------------------------------------------------------------------
    window = [r for r in done if r["group"] == "window" and r["kind"] in ("fixed", "adaptive")]
    if window:
        fig, axes = plt.subplots(2, 2, figsize=(13, 9.5))
        panels = [("energy_error", "cpu_s"), ("energy_error", "rhs_evaluations"),
                  ("displacement_error", "cpu_s"), ("displacement_error", "rhs_evaluations")]
        ylabels = {"energy_error": "energy-balance error  max|H(t) − H(0)| / max(K+V)  [–]",
                   "displacement_error": "displacement error vs reference  [length unit]"}
        xlabels = {"cpu_s": "cost: CPU time [s]", "rhs_evaluations": "cost: residual / RHS evaluations [–]"}
        floored = False
        for ax, (yk, xk) in zip(axes.flat, panels):
            for m in methods:
                pts = sorted((fnum(r[xk]), fnum(r[yk])) for r in window if method_of(r["label"]) == m)
                pts = [(x, y) for x, y in pts if x > 0 and math.isfinite(y)]
                if not pts:
                    continue
                if yk == "energy_error" and any(y < FLOOR for _, y in pts):
                    floored = True
                pts = [(x, max(y, FLOOR)) for x, y in pts]
                adaptive = any(r["kind"] == "adaptive" for r in window if method_of(r["label"]) == m)
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], ("s--" if adaptive else "o-"), color=colour[m],
                          label=m + (" (rtol sweep)" if adaptive else " (Δt sweep)"), ms=5, lw=1.4)
            ax.set_xlabel(xlabels[xk])
            ax.set_ylabel(ylabels[yk])
            ax.grid(True, which="both", alpha=0.3)
        if floored:
            for ax in axes[0]:
                ax.axhline(FLOOR, color="0.5", lw=0.8, ls=":")
                ax.text(0.99, 0.02, "errors < 1e-16 drawn at 1e-16", transform=ax.transAxes, ha="right", va="bottom",
                        fontsize=8, color="0.4")
        handles, labels = axes[0][0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=9, frameon=False)
        t_end = max(fnum(r["t_end"]) for r in window)
        fig.suptitle(f"{title}: work–precision on 0 ≤ t ≤ {t_end:g} s (lower left is better)", fontsize=13)
        fig.tight_layout(rect=(0, 0.1, 1, 0.96))
        fig.savefig(os.path.join(out, "work_precision.png"), dpi=110)
        plt.close(fig)

    # --- full-duration histories -----------------------------------------------------------------------
    full = [r for r in done if r["group"] == "full"]
    hist = {}
    for r in full:
        try:
            hist[r["label"]] = columns(read_csv(os.path.join(a.dir, "full", r["label"], "history.csv")))
        except OSError:
            pass
    if hist:
        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(11, 8.5), sharex=True)
        for r in full:
            h = hist.get(r["label"])
            if not h:
                continue
            m = method_of(r["label"])
            c = colour.get(m, "k")
            ref = next((i for i, d in enumerate(h["rel_drift"]) if math.isfinite(d)), None)
            ls = "--" if r["kind"] == "baseline" else "-"
            ax2.plot(h["t"], [k + v for k, v in zip(h["kinetic"], h["strain"])], ls, color=c, lw=1.1, label=r["label"])
            if ref is not None:
                scale = h["kinetic"][ref] + h["strain"][ref]
                ax1.plot(h["t"][ref:], [(x - h["total"][ref]) / scale for x in h["total"][ref:]], ls, color=c, lw=1.1,
                         label=r["label"])
        ax1.set_yscale("symlog", linthresh=1e-12)
        ax1.set_ylabel("(H − H_ref) / (K+V)_ref  [–]\n(symlog, linear below 1e-12)")
        ax1.grid(True, which="both", alpha=0.3)
        ax1.legend(fontsize=8, ncol=2)
        ax1.set_title(f"{title}: energy after the loads, full duration")
        ax2.set_ylabel("mechanical energy K + V  [energy unit]")
        ax2.set_xlabel("time t [s]")
        ax2.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "full_energy.png"), dpi=110)
        plt.close(fig)

        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(11, 8), sharex=True)
        for r in full:
            h = hist.get(r["label"])
            if not h:
                continue
            c = colour.get(method_of(r["label"]), "k")
            ref = next((i for i, d in enumerate(h["rel_drift"]) if math.isfinite(d)), None)
            if ref is None:
                continue
            ls = "--" if r["kind"] == "baseline" else "-"
            for ax, key in ((ax1, "L"), (ax2, "J")):
                d = [math.sqrt(sum((h[key + x][i] - h[key + x][ref]) ** 2 for x in "xyz")) for i in range(ref, len(h["t"]))]
                ax.semilogy(h["t"][ref:], [max(v, 1e-18) for v in d], ls, color=c, lw=1.1, label=r["label"])
        ax1.set_ylabel("‖L − L_ref‖  [momentum unit]")
        ax2.set_ylabel("‖J − J_ref‖  [angular momentum unit]")
        ax2.set_xlabel("time t [s]")
        for ax in (ax1, ax2):
            ax.grid(True, which="both", alpha=0.3)
        ax1.legend(fontsize=8, ncol=2)
        ax1.set_title(f"{title}: momentum changes after the loads (values < 1e-18 drawn at 1e-18)")
        fig.tight_layout()
        fig.savefig(os.path.join(out, "full_momentum.png"), dpi=110)
        plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
