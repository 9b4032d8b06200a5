#!/usr/bin/python3
"""Plots of one shelldyn run (history.csv of `shelldyn run` or a benchmark app).

usage: plot_run.py RESULT_DIR [--title TEXT] [--out DIR] [--units SI|none]

Writes into RESULT_DIR (or --out):
  energy.png    top: kinetic K, strain V, external work W_ext (and damping work W_damp); middle: the energy
                balance error H - H(0), H = K + V - W_ext + W_damp; bottom: |rel_drift| of history.csv on a
                log scale (energy-balance error while loads act, conservation error after; docs/manual.md §4)
  momentum.png  the six components of linear momentum L and angular momentum J (about the origin, director
                term included), each on its own axes so that no component hides another
  monitors.png  the case's monitor columns, one panel per monitor, labelled with quantity and set
Axes carry units: SI units with --units SI, otherwise the case's own units named generically
(shelldyn never scales units; docs/manual.md).
If matplotlib is missing, prints one warning line and exits 0 (the run's results are complete anyway).
If matplotlib is missing, prints one warning line and exits 0 (the run's results are complete anyway).
"""
import argparse
import csv
import math
import os
import sys

STANDARD = ["step", "t", "dt", "kinetic", "strain", "external_work", "total", "rel_drift", "Lx", "Ly", "Lz",
            "Jx", "Jy", "Jz", "nonlinear_iters", "linear_setups", "wall_s", "damping_work", "prescribed_work"]

UNITS = {
    "SI": {"t": "s", "E": "J", "L": "kg m/s", "J": "kg m²/s", "u": "m", "v": "m/s", "r": "N", "p": "1"},
    "none": {"t": "time", "E": "energy", "L": "mass·length/time", "J": "mass·length²/time", "u": "length",
             "v": "length/time", "r": "force", "p": "1"},
}
QUANTITY_UNIT = {"ux": "u", "uy": "u", "uz": "u", "ur": "u", "vx": "v", "vy": "v", "vz": "v", "rx": "r", "ry": "r",
                 "rz": "r", "px": "p", "py": "p", "pz": "p"}
QUANTITY_TEXT = {"ux": "displacement x", "uy": "displacement y", "uz": "displacement z", "ur": "radial displacement",
                 "vx": "velocity x", "vy": "velocity y", "vz": "velocity z", "rx": "reaction x", "ry": "reaction y",
                 "rz": "reaction z", "px": "director x", "py": "director y", "pz": "director z"}


def case_info(directory):
    """Monitors (name -> (quantity, set, reduce)) and loads end time from run.json, if readable."""
    import json
    try:
        with open(os.path.join(directory, "run.json"), encoding="utf-8") as f:
            j = json.load(f)
    except (OSError, ValueError):
        return {}, None
    mons = {m.get("name"): (m.get("quantity", ""), m.get("set", ""), m.get("reduce", "none"))
            for m in j.get("case", {}).get("monitors", [])}
    end = j.get("discretization", {}).get("loads_end")
    return mons, end if isinstance(end, (int, float)) else None



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
    ap.add_argument("--units", default="none", choices=sorted(UNITS))
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
    if len(c["t"]) == 0:
        print(f"plot_run.py: error: {hist} has no data rows", file=sys.stderr)
        return 1
    out = a.out or a.dir
    title = a.title or os.path.basename(os.path.normpath(a.dir))
    U = UNITS[a.units]
    mons, loads_end = case_info(a.dir)
    t = c["t"]
    tlabel = f"time t [{U['t']}]"
    damp = c.get("damping_work")
    presc = c.get("prescribed_work")  # work of prescribed displacements (docs/manual.md §2.12)

    def mark_loads(ax):
        if loads_end is not None and math.isfinite(loads_end) and 0 < loads_end <= t[-1]:
            ax.axvline(loads_end, color="0.5", lw=0.8, ls="--")

    # --- energy ------------------------------------------------------------------------------------
    fig, (ax, axb, ax2) = plt.subplots(3, 1, figsize=(8, 8.5), sharex=True, gridspec_kw={"height_ratios": [3, 2, 2]})
    # W_ext first, wide and pale, so that K drawn on top of it stays visible where the two coincide
    # (after the loads of a free body almost all the work done is kinetic energy).
    ax.plot(t, c["external_work"], color="0.6", lw=5, alpha=0.5, label="external work W_ext")
    ax.plot(t, c["kinetic"], color="C0", lw=1.4, label="kinetic K")
    ax.plot(t, c["strain"], color="C1", lw=1.4, ls="-.", label="strain V")
    if damp:
        ax.plot(t, damp, color="C2", lw=1.4, ls="--", label="damping work W_damp")
    if presc:
        ax.plot(t, presc, color="C3", lw=1.4, ls=":", label="prescribed-motion work W_presc")
    ax.set_ylabel(f"energy [{U['E']}]")
    ax.set_title(f"{title}: energy")
    ax.legend(fontsize=8, loc="best")
    ax.grid(alpha=0.3)
    mark_loads(ax)
    # The total H is ~constant (often ~0), so a plot of H itself is a flat line: show its change instead.
    H0 = c["total"][0]
    axb.plot(t, [h - H0 for h in c["total"]], color="k", lw=1.2)
    axb.set_ylabel(f"H − H(0) [{U['E']}]")
    axb.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3))
    axb.text(0.01, 0.95, "H = K + V − W_ext" + (" − W_presc" if presc else "") + (" + W_damp" if damp else "") + ": energy balance error",
             transform=axb.transAxes, fontsize=8, va="top")
    axb.grid(alpha=0.3)
    mark_loads(axb)
    pts = [(ti, abs(d)) for ti, d in zip(t, c["rel_drift"]) if math.isfinite(d) and d != 0.0]
    if pts:
        ax2.semilogy([p[0] for p in pts], [p[1] for p in pts], color="C3", lw=1.2)
        ax2.set_ylabel("|rel_drift| [–]")
        ax2.text(0.01, 0.95, "while loads act: |H − H(0)| / max(K + V, |W_ext|); after: |H − H_ref| / (K + V)_ref",
                 transform=ax2.transAxes, fontsize=8, va="top")
    else:
        ax2.text(0.5, 0.5, "rel_drift is 0 at every output", ha="center", va="center", transform=ax2.transAxes)
    mark_loads(ax2)
    ax2.set_xlabel(tlabel + ("   (dashed line: loads end)" if loads_end and math.isfinite(loads_end) and loads_end <= t[-1] else ""))
    ax2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "energy.png"), dpi=100)
    plt.close(fig)

    # --- momenta: one axes per component ---------------------------------------------------------------
    fig, axs = plt.subplots(2, 3, figsize=(11, 6), sharex=True)
    for row, (sym, name, unit) in enumerate((("L", "linear momentum", U["L"]), ("J", "angular momentum", U["J"]))):
        for col, comp in enumerate("xyz"):
            k = sym + comp
            axk = axs[row][col]
            vals = c[k]
            axk.plot(t, vals, color=f"C{col}", lw=1.3)
            span = max(vals) - min(vals) if vals else 0.0
            axk.set_title(f"{k}  (range {span:.3g})", fontsize=9)
            axk.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4), useOffset=False)
            if col == 0:
                axk.set_ylabel(f"{name}\n{sym} [{unit}]", fontsize=9)
            if row == 1:
                axk.set_xlabel(tlabel)
            axk.grid(alpha=0.3)
            mark_loads(axk)
    fig.suptitle(f"{title}: momenta (J about the origin, director term included)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "momentum.png"), dpi=100)
    plt.close(fig)

    # --- monitors ------------------------------------------------------------------------------------
    monitors = [h for h in header if h not in STANDARD]
    if monitors:
        n = len(monitors)
        fig, axm = plt.subplots(n, 1, figsize=(8, 2.0 + 1.8 * n), sharex=True, squeeze=False)
        for k, m in enumerate(monitors):
            q, st, red = mons.get(m, ("", "", "none"))
            unit = U[QUANTITY_UNIT[q]] if q in QUANTITY_UNIT else "value"
            what = QUANTITY_TEXT.get(q, "monitor")
            where = f"{red} over {st}" if red and red != "none" else st
            axk = axm[k][0]
            axk.plot(t, c[m], color=f"C{k % 10}", lw=1.3)
            axk.set_ylabel(f"{m} [{unit}]")
            axk.set_title(f"{m}: {what}" + (f" ({where})" if where else ""), fontsize=9)
            axk.grid(alpha=0.3)
            mark_loads(axk)
        axm[-1][0].set_xlabel(tlabel)
        fig.suptitle(f"{title}: monitors")
        fig.tight_layout()
        fig.savefig(os.path.join(out, "monitors.png"), dpi=100)
        plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
