#!/usr/bin/python3
"""Plots of a `shelldyn study` folder.

usage: plot_study.py STUDY_DIR [--out DIR] [--title TEXT]

Reads STUDY_DIR/study.csv and the runs' STUDY_DIR/<group>/<label>/history.csv and writes:
  work_precision.png  work-precision diagram of the window sweep, log-log, one curve per method, its
                      points joined in sweep order (fixed-step schemes over dt: solid, circles; SUNDIALS
                      baselines over rtol: dashed, squares): energy-balance error and displacement error
                      against the reference run, each against CPU seconds and against residual/RHS
                      evaluations. Runs stopped at the study's per-run budget are not points (they did
                      not cover the window); the figure names how many there are.
  full_energy.png     full-duration runs: running maximum of |H - H_ref|/(K + V)_ref after the loads (log
                      axis; the table's measure at every time) and K + V over time
  full_momentum.png   full-duration runs: running maxima of |L - L_ref| and |J - J_ref| after the loads
Runs stopped at the budget appear in the full-duration plots up to the time they reached (legend says so).
Errors below 1e-16 (energy) / 1e-18 (momentum) are drawn at that floor, and the figure says so.
If matplotlib is missing, prints one warning line and exits 0.
"""
import argparse
import math
import os
import sys

from plot_common import after_loads_row, columns, fnum, loads_end, read_csv

FLOOR = 1e-16




def method_of(label):
    """'galpha_rho_inf=0.8_dt=0.002' -> 'galpha ρ∞=0.8'; 'ida-bdf_rtol=1e-05' -> 'ida-bdf'."""
    parts = [p for p in label.split("_") if not (p.startswith("dt=") or p.startswith("rtol="))]
    name = parts[0]
    rest = " ".join(parts[1:]).replace("rho inf=", "ρ∞=")
    return (name + " " + rest).strip()


def study_title(study_dir):
    """The benchmark's name from study.md's first line ('# Integrator study: NAME'), else the folder name."""
    try:
        with open(os.path.join(study_dir, "study.md"), encoding="utf-8") as f:
            first = f.readline().strip()
        if ":" in first:
            return first.split(":", 1)[1].strip()
    except OSError:
        pass
    return os.path.basename(os.path.abspath(study_dir))


def sweep_value(r):
    """The swept parameter of a window row (rtol for adaptive runs, dt for fixed-step runs)."""
    return fnum(r["rtol"]) if r["kind"] == "adaptive" else fnum(r["dt"])


def running_max(values):
    out, m = [], 0.0
    for v in values:
        if math.isfinite(v):
            m = max(m, v)
        out.append(m)
    return out


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
    title = a.title or study_title(a.dir)
    done = [r for r in rows if r["status"] == "complete"]
    stopped = [r for r in rows if r["status"].startswith("stopped at budget")]
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
                # joined in sweep order, loosest rtol / largest dt first
                runs = sorted((r for r in window if method_of(r["label"]) == m), key=sweep_value, reverse=True)
                pts = [(fnum(r[xk]), fnum(r[yk])) for r in runs]
                pts = [(x, y) for x, y in pts if x > 0 and math.isfinite(y)]
                if not pts:
                    continue
                if yk == "energy_error" and any(y < FLOOR for _, y in pts):
                    floored = True
                pts = [(x, max(y, FLOOR)) for x, y in pts]
                adaptive = any(r["kind"] == "adaptive" for r in window if method_of(r["label"]) == m)
                swept = [sweep_value(r) for r in runs if r["status"] == "complete"]
                sweep = f"{'rtol' if adaptive else 'Δt'} {max(swept):.3g} → {min(swept):.3g}" + ("" if adaptive else " s")
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], ("s--" if adaptive else "o-"), color=colour[m],
                          label=f"{m} ({sweep})", ms=5, lw=1.4)
            ax.set_xlabel(xlabels[xk])
            ax.set_ylabel(ylabels[yk])
            ax.grid(True, which="both", alpha=0.3)
        if floored:
            for ax in axes[0]:
                ax.axhline(FLOOR, color="0.5", lw=0.8, ls=":")
                ax.text(0.99, 0.02, "errors < 1e-16 drawn at 1e-16", transform=ax.transAxes, ha="right", va="bottom",
                        fontsize=8, color="0.4")
        handles, labels = axes[0][0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=10, frameon=False,
                   bbox_to_anchor=(0.5, 0.025))
        w_stopped = [r for r in stopped if r["group"] == "window"]
        if w_stopped:
            names = ", ".join(r["label"] for r in w_stopped)
            if len(names) > 110:  # keep the line inside the figure; study.md lists every run
                names = names[:107] + "..."
            fig.text(0.5, 0.005, f"not plotted: {len(w_stopped)} run(s) stopped at the per-run budget (study.md): {names}",
                     ha="center", va="bottom", fontsize=8.5, color="0.3")
        t_end = max(fnum(r["t_end"]) for r in window)
        fig.suptitle(f"{title}: work–precision on 0 ≤ t ≤ {t_end:g} s (lower left is better)", fontsize=13)
        fig.tight_layout(rect=(0, 0.1, 1, 0.96))
        fig.savefig(os.path.join(out, "work_precision.png"), dpi=110)
        plt.close(fig)

    # --- full-duration histories -----------------------------------------------------------------------
    full = [r for r in done + stopped if r["group"] == "full"]
    hist = {}
    refs = {}  # label -> row of the after-the-loads reference (None: the run ends before the loads do)
    for r in full:
        try:
            run_dir = os.path.join(a.dir, "full", r["label"])
            hist[r["label"]] = columns(read_csv(os.path.join(run_dir, "history.csv")))
            refs[r["label"]] = after_loads_row(hist[r["label"]], loads_end(run_dir))
        except OSError:
            pass
    def legend_name(r):
        name = r["label"].replace("_", " ") if r["kind"] == "baseline" else method_of(r["label"])
        if r["status"] != "complete":
            name += f" (stopped at budget, t = {fnum(r['t_reached']):.4g} s)"
        return name

    for r in full:
        if r["kind"] == "baseline":
            colour.setdefault(method_of(r["label"]), cmap(len(colour) % 10))
    # earlier curves drawn wider, so that curves that coincide (e.g. two schemes with the same drift) stay visible
    width = {r["label"]: max(1.1, 3.0 - 0.3 * i) for i, r in enumerate(full)}
    if hist:
        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(13.5, 8.5), sharex=True)
        for r in full:
            h = hist.get(r["label"])
            if not h:
                continue
            m = method_of(r["label"])
            c = colour.get(m, "k")
            ref = refs[r["label"]]
            ls = "--" if r["kind"] == "baseline" else "-"
            lw = width[r["label"]]
            ax2.plot(h["t"], [k + v for k, v in zip(h["kinetic"], h["strain"])], ls, color=c, lw=lw, label=legend_name(r))
            if ref is not None and ref + 1 < len(h["t"]):
                scale = h["kinetic"][ref] + h["strain"][ref]
                err = running_max([abs(x - h["total"][ref]) / scale for x in h["total"][ref + 1:]])
                ax1.semilogy(h["t"][ref + 1:], [max(v, FLOOR) for v in err], ls, color=c, lw=lw, label=legend_name(r))
        ax1.set_ylabel("max over [t_ref, t] of\n|H − H_ref| / (K+V)_ref  [–]")
        ax1.grid(True, which="both", alpha=0.3)
        ax1.legend(fontsize=9, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        ax1.set_title(f"{title}: energy error after the loads (running maximum; < 1e-16 drawn at 1e-16)")
        ax2.set_ylabel("mechanical energy K + V  [energy unit of the case]")
        ax2.set_xlabel("time t [s]")
        ax2.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "full_energy.png"), dpi=110)
        plt.close(fig)

        fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(13.5, 8), sharex=True)
        for r in full:
            h = hist.get(r["label"])
            if not h:
                continue
            c = colour.get(method_of(r["label"]), "k")
            ref = refs[r["label"]]
            if ref is None:
                continue
            ls = "--" if r["kind"] == "baseline" else "-"
            for ax, key in ((ax1, "L"), (ax2, "J")):
                d = running_max([math.sqrt(sum((h[key + x][i] - h[key + x][ref]) ** 2 for x in "xyz"))
                                 for i in range(ref + 1, len(h["t"]))])
                ax.semilogy(h["t"][ref + 1:], [max(v, 1e-18) for v in d], ls, color=c, lw=width[r["label"]],
                            label=legend_name(r))
        ax1.set_ylabel("max over [t_ref, t] of ‖L − L_ref‖\n[momentum unit of the case]")
        ax2.set_ylabel("max over [t_ref, t] of ‖J − J_ref‖\n[angular momentum unit of the case]")
        ax2.set_xlabel("time t [s]")
        for ax in (ax1, ax2):
            ax.grid(True, which="both", alpha=0.3)
        ax1.legend(fontsize=9, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        ax1.set_title(f"{title}: momentum changes after the loads (running maxima; < 1e-18 drawn at 1e-18)")
        fig.tight_layout()
        fig.savefig(os.path.join(out, "full_momentum.png"), dpi=110)
        plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
