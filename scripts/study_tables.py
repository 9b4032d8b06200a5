#!/usr/bin/python3
"""Compact tables of a `shelldyn study` folder, as the README shows them.

usage: study_tables.py STUDY_DIR

Reads STUDY_DIR/study.csv (no matplotlib needed) and prints two Markdown tables:
  work-precision window: one row per method, its sweep, how many runs completed (and how many stopped at the
                         per-run budget), CPU seconds, energy-balance error and displacement error from the
                         loosest to the tightest completed run;
  full duration:         one row per run: steps, CPU seconds, the time reached, the energy error after the
                         loads and max |dL|, |dJ| after the loads (with |L|, |J| at the loads' end).
Numbers are printed with two significant digits (CPU seconds with one decimal), as in study.md.
"""
import argparse
import os
import sys

from plot_common import fnum, read_csv
from plot_study import method_of, sweep_value


def g(x, digits=2):
    """Two significant digits, '–' for NaN/missing."""
    v = fnum(x)
    if v != v:
        return "–"
    return f"{v:.{digits}g}"


def cpu(x):
    v = fnum(x)
    return "–" if v != v else f"{v:.1f}"


def window_table(rows):
    out = ["| method | sweep | complete | CPU s, loosest → tightest complete run | energy-balance error (same runs) "
           "| displ. error (same runs) |", "|---|---|---|---|---|---|"]
    methods = []
    for r in rows:
        m = method_of(r["label"])
        if r["group"] == "window" and r["kind"] in ("fixed", "adaptive") and m not in methods:
            methods.append(m)
    for m in methods:
        mine = [r for r in rows if r["group"] == "window" and r["kind"] in ("fixed", "adaptive") and method_of(r["label"]) == m]
        # loosest first: largest rtol / largest dt
        mine.sort(key=lambda r: -sweep_value(r))
        done = [r for r in mine if r["status"] == "complete"]
        stopped = [r for r in mine if r["status"].startswith("stopped at budget")]
        kind = mine[0]["kind"]
        par = "rtol" if kind == "adaptive" else "Δt"
        sweep = f"{par} {g(sweep_value(mine[0]), 3)} … {g(sweep_value(mine[-1]), 3)}"
        count = f"{len(done)} of {len(mine)}" + (f" ({len(stopped)} stopped at budget)" if stopped else "")
        if done:
            a, b = done[0], done[-1]
            out.append(f"| {m} | {sweep} | {count} | {cpu(a['cpu_s'])} → {cpu(b['cpu_s'])} | "
                       f"{g(a['energy_error'])} → {g(b['energy_error'])} | "
                       f"{g(a['displacement_error'])} → {g(b['displacement_error'])} |")
        else:
            out.append(f"| {m} | {sweep} | {count} | – | – | – |")
    return "\n".join(out)


def full_table(rows):
    full = [r for r in rows if r["group"] == "full"]
    if not full:
        return ""
    out = ["| run | steps | CPU s | t reached | energy error after the loads | max ‖ΔL‖ (‖L‖) | max ‖ΔJ‖ (‖J‖) | status |",
           "|---|---|---|---|---|---|---|---|"]
    for r in full:
        status = "complete" if r["status"] == "complete" else r["status"].split(" (")[0]
        if status == "complete":
            measures = (f"{g(r['energy_error_after_loads'])} | {g(r['max_dL'])} ({g(r['norm_L_ref'])}) | "
                        f"{g(r['max_dJ'])} ({g(r['norm_J_ref'])})")
        else:  # stopped or failed: no after-the-loads measures
            measures = "– | – | –"
        out.append(f"| {r['label']} | {r['steps']} | {cpu(r['cpu_s'])} | {g(r['t_reached'], 4)} of {g(r['t_end'], 4)} | "
                   f"{measures} | {status} |")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    a = ap.parse_args()
    path = os.path.join(a.dir, "study.csv")
    if not os.path.isfile(path):
        print(f"study_tables.py: {path} not found (run `shelldyn study BENCHMARK -o {a.dir}` first)", file=sys.stderr)
        return 1
    rows = read_csv(path)
    print(window_table(rows))
    t = full_table(rows)
    if t:
        print()
        print(t)
    return 0


if __name__ == "__main__":
    sys.exit(main())
