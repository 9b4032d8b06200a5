"""Helpers shared by the plotting scripts (plot_compare.py, plot_study.py): CSV columns as floats, and
the row where a run's after-the-loads reference lies (docs/manual.md §4: the run driver takes H_ref,
L_ref, J_ref at the first output time at or after the loads end; rel_drift is finite on every row, so
it cannot mark that row)."""
import csv
import json
import math
import os


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


def loads_end(run_dir):
    """The loads' end time from RUN_DIR/run.json (discretization.loads_end), or None if unreadable."""
    try:
        with open(os.path.join(run_dir, "run.json"), encoding="utf-8") as f:
            end = json.load(f).get("discretization", {}).get("loads_end")
    except (OSError, ValueError):
        return None
    return float(end) if isinstance(end, (int, float)) else None


def after_loads_row(h, end):
    """Index of the first output row at or after the loads end (the run driver's reference row), or
    None when the run ends before the loads do or the end is unknown."""
    if end is None or not math.isfinite(end):
        return None
    t = h.get("t", [])
    tol = 1e-9 * max(1.0, abs(end))
    return next((i for i, ti in enumerate(t) if ti >= end - tol), None)
