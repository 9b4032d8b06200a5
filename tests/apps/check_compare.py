#!/usr/bin/python3
"""Checks what `shelldyn compare` wrote.

usage: check_compare.py COMPARE_DIR [--conserving LABEL,...] [--failed LABEL,...] EXPECTED_LABEL...

--before-loads-end: the study ends before the loads do, so every energy error must be NaN ("n/a").
--failed: these runs must be rows with status "failed: <reason>" (not dropped); the others complete.

- summary.csv: one row per expected label (in order), status complete, steps > 0, wall_s > 0, finite energy
  error, linear momentum change max_dL below 1e-9 |L_ref| for the --conserving runs (rho_inf = 1; with
  rho_inf < 1 the generalized-alpha L relaxes towards the impulse after the loads end), exactly one
  reference run with displacement_error 0 and the others finite;
- each run folder has history.csv and run.json with status complete;
- summary.md: a table row per label;
- PNGs exist when matplotlib is importable.
"""
import csv
import importlib.util
import json
import math
import os
import sys


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def main():
    d, labels, conserving = sys.argv[1], sys.argv[2:], []
    failed, energy = [], True
    while labels and labels[0] in ("--conserving", "--failed", "--before-loads-end"):
        if labels[0] == "--before-loads-end":  # t_end before the loads end: energy error is n/a (NaN)
            energy, labels = False, labels[1:]
            continue
        (conserving if labels[0] == "--conserving" else failed).extend(labels[1].split(","))
        labels = labels[2:]
    with open(os.path.join(d, "summary.csv"), newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    if [r["label"] for r in rows] != labels:
        fail(f"summary.csv labels {[r['label'] for r in rows]}, expected {labels}")
    refs = set()
    for r in rows:
        lab = r["label"]
        if lab in failed:
            if not r["status"].startswith("failed: ") or len(r["status"]) < 20:
                fail(f"{lab}: status {r['status']!r}, expected 'failed: <reason>'")
            continue
        if r["status"] != "complete":
            fail(f"{lab}: status {r['status']!r}")
        if int(r["steps"]) <= 0 or float(r["wall_s"]) <= 0:
            fail(f"{lab}: steps {r['steps']}, wall_s {r['wall_s']}")
        if math.isfinite(float(r["energy_error"])) != energy:
            fail(f"{lab}: energy_error {r['energy_error']}")
        if lab in conserving and float(r["max_dL"]) > 1e-9 * max(1.0, float(r["norm_L_ref"])):
            fail(f"{lab}: linear momentum not conserved after the loads: max_dL {r['max_dL']}")
        de = float(r["displacement_error"])
        if not math.isfinite(de):
            fail(f"{lab}: displacement_error {r['displacement_error']}")
        if de == 0.0:
            refs.add(lab)
        with open(os.path.join(d, lab, "run.json"), encoding="utf-8") as f:
            if json.load(f).get("status") != "complete":
                fail(f"{lab}/run.json: not complete")
        if not os.path.isfile(os.path.join(d, lab, "history.csv")):
            fail(f"{lab}/history.csv missing")
    if refs != {rows[0]["reference"]}:
        fail(f"runs with zero displacement error {refs}, reference {rows[0]['reference']!r}")
    with open(os.path.join(d, "summary.md"), encoding="utf-8") as f:
        md = f.read()
    for lab in failed:
        if f"| `{lab}` |" not in md or "failed: " not in md:
            fail(f"summary.md lacks the failed row {lab}")
    for lab in labels:
        if f"| `{lab}` |" not in md:
            fail(f"summary.md lacks a row for {lab}")
    if importlib.util.find_spec("matplotlib"):
        for png in ("energy.png", "momentum.png", "work_precision.png"):
            if not os.path.isfile(os.path.join(d, png)):
                fail(f"{png} missing although matplotlib is installed")
    print(f"OK: {d}: {len(rows)} runs complete, reference {rows[0]['reference']}")


if __name__ == "__main__":
    main()
