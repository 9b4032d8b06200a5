#!/usr/bin/python3
"""Checks of tests/install/run_example_test.sh: COMPARE_DIR has complete rows em-galpha and velocity-verlet; their
history.csv have the same columns; the velocity-verlet run.json names the plugin; IN_TREE_DIR/history.csv (the
same source compiled into a test program) equals the plugin's in every column but wall_s.
With --study STUDY_DIR: study.csv has complete window rows of em-galpha and velocity-verlet, each with a finite
displacement error against the reference run.
usage: check_example.py COMPARE_DIR IN_TREE_DIR PLUGIN.so | check_example.py --study STUDY_DIR"""
import csv
import json
import math
import os
import sys


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


if sys.argv[1] == "--study":
    with open(os.path.join(sys.argv[2], "study.csv"), newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["group"] == "window" and r["kind"] != "reference"]
    for name in ("em-galpha", "velocity-verlet"):
        mine = [r for r in rows if r["integrator"] == name]
        if not mine or any(r["status"] != "complete" for r in mine):
            fail(f"study.csv: window rows of {name} missing or not complete: {mine}")
        bad = [r["label"] for r in mine if not math.isfinite(float(r["displacement_error"]))]
        if bad:
            fail(f"study.csv: no displacement error for {bad}")
    vv = [r for r in rows if r["integrator"] == "velocity-verlet"]
    print(f"example plugin in a study file: {len(rows)} window rows complete, velocity-verlet "
          f"displacement error {float(vv[0]['displacement_error']):.3g}")
    sys.exit(0)

cmp_dir, in_tree, plugin = sys.argv[1:4]


def table(path):
    with open(path, newline="") as f:
        return list(csv.reader(f))


with open(os.path.join(cmp_dir, "summary.csv"), newline="") as f:
    rows = {r["label"]: r for r in csv.DictReader(f)}
for lab in ("em-galpha", "velocity-verlet"):
    if lab not in rows or rows[lab]["status"] != "complete":
        fail(f"summary.csv: row {lab} missing or not complete: {rows.get(lab)}")
ref = table(os.path.join(cmp_dir, "em-galpha", "history.csv"))
vv = table(os.path.join(cmp_dir, "velocity-verlet", "history.csv"))
if ref[0] != vv[0]:
    fail(f"history.csv columns differ:\n em-galpha       {ref[0]}\n velocity-verlet {vv[0]}")
if len(ref) != len(vv):
    fail(f"history.csv rows: em-galpha {len(ref)}, velocity-verlet {len(vv)} (same output times expected)")
with open(os.path.join(cmp_dir, "velocity-verlet", "run.json")) as f:
    j = json.load(f)
if j.get("integrator_origin") != os.path.realpath(plugin) or j["plugins"][0]["version"] != "1.0":
    fail(f"run.json: integrator_origin {j.get('integrator_origin')}, plugins {j.get('plugins')}")
it = table(os.path.join(in_tree, "history.csv"))
w = vv[0].index("wall_s")
strip = lambda t: [r[:w] + r[w + 1:] for r in t]
if strip(it) != strip(vv):
    diff = next(i for i, (a, b) in enumerate(zip(strip(it), strip(vv))) if a != b) if len(it) == len(vv) else "count"
    fail(f"in-tree copy differs from the installed plugin (first differing row {diff})")
print(f"example plugin checks passed: {len(vv) - 1} output rows, columns as em-galpha's ({len(vv[0])}), "
      f"in-tree copy identical, steps {rows['velocity-verlet']['steps']} vs em-galpha {rows['em-galpha']['steps']}")
