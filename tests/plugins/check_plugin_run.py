#!/usr/bin/python3
"""A plugin integrator behaves like a built-in in `shelldyn run` and `resume` (integrators/runs/plugin.hpp):

- run.json records the plugin (path, version, FNV-1a hash of its bytes) and the integrator's origin;
- history.csv has the columns of a built-in's (em-galpha);
- a run stopped by --max-steps resumes without --plugin (the recorded plugin is loaded again) and continues
  bitwise: its history equals an uninterrupted run's in every column but wall_s;
- resuming when the recorded plugin file is gone fails with one line naming it.

usage: check_plugin_run.py SHELLDYN PLUGIN.so CASE.yaml WORKDIR
"""
import csv
import json
import os
import shutil
import subprocess
import sys

cli, plugin, case, work = sys.argv[1:5]
plugin = os.path.realpath(plugin)


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run(args, code=0):
    r = subprocess.run([cli] + args, capture_output=True, text=True, timeout=300)
    if r.returncode != code:
        fail(f"{' '.join(args)}: exit {r.returncode}, expected {code}\nstdout:\n{r.stdout}\nstderr:\n{r.stderr}")
    return r


def fnv1a64(path):
    h = 1469598103934665603
    with open(path, "rb") as f:
        for b in f.read():
            h = ((h ^ b) * 1099511628211) % (1 << 64)
    return f"fnv1a64:{h:016x}"


def rows(path):
    with open(path, newline="") as f:
        return list(csv.reader(f))


shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
common = [case, "--t-end", "0.05", "--vtu-every", "0", "-q", "--integrator", "velocity-verlet"]
full, cut, ref = (os.path.join(work, d) for d in ("full", "cut", "em-galpha"))
run(["run"] + common + ["--plugin", plugin, "-o", full, "--checkpoint-every", "off"])
run(["run"] + common + ["--plugin", plugin, "-o", cut, "--max-steps", "400", "--checkpoint-every", "100"], code=4)
with open(os.path.join(cut, "run.json")) as f:
    j = json.load(f)
if j.get("integrator_origin") != plugin:
    fail(f"run.json integrator_origin {j.get('integrator_origin')!r}, expected {plugin!r}")
p = (j.get("plugins") or [{}])[0]
if p.get("path") != plugin or p.get("version") != "1.0" or p.get("hash") != fnv1a64(plugin):
    fail(f"run.json plugins[0] = {p}, expected path {plugin}, version 1.0, hash {fnv1a64(plugin)}")
run(["resume", cut, "-q"])
a, b = rows(os.path.join(full, "history.csv")), rows(os.path.join(cut, "history.csv"))
wall = a[0].index("wall_s")
strip = lambda t: [r[:wall] + r[wall + 1:] for r in t]
if strip(a) != strip(b):
    fail(f"resumed history ({len(b)} rows) differs from the uninterrupted one ({len(a)} rows)")
run(["run", case, "--t-end", "0.02", "--vtu-every", "0", "-q", "--integrator", "em-galpha", "-o", ref])
if rows(os.path.join(ref, "history.csv"))[0] != a[0]:
    fail(f"history.csv columns {a[0]} differ from em-galpha's {rows(os.path.join(ref, 'history.csv'))[0]}")

# The recorded plugin is gone: resume refuses with one line naming it.
copy = os.path.join(work, "copy-of-plugin.so")
shutil.copy(plugin, copy)
gone = os.path.join(work, "gone")
run(["run"] + common + ["--plugin", copy, "-o", gone, "--max-steps", "200", "--checkpoint-every", "100"], code=4)
os.remove(copy)
r = run(["resume", gone, "-q"], code=1)
err = [l for l in r.stderr.splitlines() if not l.startswith("  ")]
if len(err) != 1 or not err[0].startswith("shelldyn: error: resume: plugin " + os.path.realpath(copy)) or "is missing" not in err[0]:
    fail("resume without its plugin: stderr " + repr(r.stderr))
print(f"plugin run checks passed: run.json names {plugin} ({p['hash']}), resume continues bitwise "
      f"({len(a) - 1} rows), columns as em-galpha's, a missing plugin is refused: {err[0]}")
