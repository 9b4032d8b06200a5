#!/usr/bin/python3
"""Checks the result folder of a benchmark app run (apps/flying_plate.cpp & co.) with invariant checks.

usage: check_app_run.py RESULT_DIR T_END [--loads-end T] [--impulse LX,LY,LZ] [--max-energy-error E]
                        [--zero-momentum SCALE] [--log-contains TEXT ...] -- COMMAND [ARGS...]

Runs COMMAND (the app, writing into RESULT_DIR; must exit 0 within 300 s), then checks:

- run.json: valid JSON, status "complete", summary.t_end == T_END;
- history.csv: header with the standard columns, last t == T_END, every value finite (rel_drift too: it is
  the energy-balance error while loads act, docs/manual.md §4), K >= 0;
- --impulse: after the loads end, L equals the load impulse (computed from the case's load functions by
  the caller) to 1e-9 relative, and stays constant to 1e-10 relative (linear momentum is conserved to
  round-off by every integrator; docs/theory.md §6.7);
- --max-energy-error: max |H - H_ref| / (K_ref + V_ref) after the loads end is below E;
- --zero-momentum: |L| and |J| stay below 1e-9 * SCALE (self-equilibrated loads);
- PNG plots exist when matplotlib is importable;
- --log-contains: the app's stdout contains each TEXT.
"""
import argparse
import csv
import importlib.util
import json
import math
import os
import shutil
import subprocess
import sys

STANDARD = ["step", "t", "dt", "kinetic", "strain", "external_work", "total", "rel_drift", "Lx", "Ly", "Lz",
            "Jx", "Jy", "Jz", "nonlinear_iters", "linear_setups", "wall_s"]


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("t_end", type=float)
    ap.add_argument("--loads-end", type=float, default=0.0)
    ap.add_argument("--impulse", default="")
    ap.add_argument("--max-energy-error", type=float, default=None)
    ap.add_argument("--zero-momentum", type=float, default=None)
    ap.add_argument("--log-contains", action="append", default=[])
    sep = sys.argv.index("--")
    a = ap.parse_args(sys.argv[1:sep])
    if os.path.isdir(a.dir):
        shutil.rmtree(a.dir)
    r = subprocess.run(sys.argv[sep + 1:], capture_output=True, text=True, timeout=300)
    sys.stdout.write(r.stdout[-3000:])
    if r.returncode != 0:
        fail(f"exit code {r.returncode}; stderr: {r.stderr}")

    with open(os.path.join(a.dir, "run.json"), encoding="utf-8") as f:
        info = json.load(f)
    if info.get("status") != "complete":
        fail(f"run.json: status {info.get('status')!r}, expected 'complete'")
    if abs(info.get("summary", {}).get("t_end", -1) - a.t_end) > 1e-12:
        fail(f"run.json: summary.t_end {info.get('summary', {}).get('t_end')} != {a.t_end}")

    with open(os.path.join(a.dir, "history.csv"), newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        fail("history.csv: no rows")
    missing = [c for c in STANDARD if c not in rows[0]]
    if missing:
        fail(f"history.csv: missing columns {missing}")
    h = {k: [float(r[k]) for r in rows] for k in rows[0]}
    if abs(h["t"][-1] - a.t_end) > 1e-9 * max(1.0, a.t_end):
        fail(f"history.csv: last t = {h['t'][-1]}, expected {a.t_end}")
    for k, col in h.items():
        for i, x in enumerate(col):
            if not math.isfinite(x):
                fail(f"history.csv: {k} = {x} at t = {h['t'][i]}")
    if min(h["kinetic"]) < 0:
        fail("history.csv: negative kinetic energy")

    after = [i for i, t in enumerate(h["t"]) if t >= a.loads_end - 1e-12]
    if (a.impulse or a.max_energy_error is not None) and len(after) < 2:
        fail(f"history.csv: fewer than 2 rows after the loads end at {a.loads_end}")
    if a.impulse:
        want = [float(x) for x in a.impulse.split(",")]
        scale = math.sqrt(sum(x * x for x in want))
        for i in after:
            L = [h["Lx"][i], h["Ly"][i], h["Lz"][i]]
            err = math.sqrt(sum((x - y) ** 2 for x, y in zip(L, want)))
            if err > 1e-9 * scale:
                fail(f"L = {L} at t = {h['t'][i]}, expected the load impulse {want} (error {err:.3g})")
        L0 = [h[k][after[0]] for k in ("Lx", "Ly", "Lz")]
        dL = max(math.sqrt(sum((h[k][i] - L0[j]) ** 2 for j, k in enumerate(("Lx", "Ly", "Lz")))) for i in after)
        if dL > 1e-10 * scale:
            fail(f"linear momentum changes by {dL:.3g} after the loads end (|L| = {scale})")
    drift = None
    if a.max_energy_error is not None:
        ref = after[0]
        mech = h["kinetic"][ref] + h["strain"][ref]
        if not mech > 0:
            fail(f"K + V = {mech} at the end of the loads")
        drift = max(abs(h["total"][i] - h["total"][ref]) / mech for i in after)
        if drift > a.max_energy_error:
            fail(f"energy error max |H - H_ref|/(K_ref + V_ref) = {drift:.3g} > {a.max_energy_error}")
    if a.zero_momentum is not None:
        worst = max(math.sqrt(h[x][i] ** 2 + h[y][i] ** 2 + h[z][i] ** 2)
                    for i in range(len(rows)) for x, y, z in (("Lx", "Ly", "Lz"), ("Jx", "Jy", "Jz")))
        if worst > 1e-9 * a.zero_momentum:
            fail(f"momentum {worst:.3g} is not zero (loads are self-equilibrated)")
    if importlib.util.find_spec("matplotlib"):
        for png in ("energy.png", "momentum.png"):
            p = os.path.join(a.dir, png)
            if not os.path.isfile(p) or os.path.getsize(p) < 1000:
                fail(f"{p} missing or empty although matplotlib is installed")
    for want in a.log_contains:
        if want not in r.stdout:
            fail(f"the app's output lacks {want!r}")
    print(f"OK: {a.dir}: complete to t = {a.t_end}, {len(rows)} rows" +
          (f", energy error {drift:.3g}" if drift is not None else ""))


if __name__ == "__main__":
    main()
