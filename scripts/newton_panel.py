#!/usr/bin/env python3
"""Runs em-exact and em-galpha (or any integrators) on a panel of cases with the integrators' defaults and prints
one table row per case: iterations per step, factorizations, rejected steps, CPU time, the energy error after the
loads, and the CPU ratio of the first integrator to the second (docs/theory/newton-iteration.md).

    python3 scripts/newton_panel.py [--shelldyn build/bin/shelldyn] [--cases NAME,...] [--integrators A,B]
                                    [--set KEY=VALUE ...] [--threads 1] [--work DIR]

The cases are written into --work from the templates below: case files whose integrator block names only the
integrator, so each run gets the integrator's defaults. Every run uses one thread (CPU times comparable).
"""
import argparse
import json
import os
import subprocess
import sys

PLATE = """name: plate-{n}
mesh: {{generator: rectangle, a: 1.0, b: 1.0, nx: {n}, ny: {n}, x0: -0.5, y0: -0.5}}
material: {{E: {E}, nu: 0.3, rho: 1000.0, thickness: 0.01}}
initial_velocity: {{translation: [0.1, 0, 0], angular: [0, -2, 0]}}
integrator: {{name: em-galpha}}
time: {{dt: 0.01, t_end: {t_end}, output_interval: 0.1}}
output: {{vtu: false, history: true}}
"""
TUMBLING = """name: tumbling-{tag}
mesh: {{generator: rectangle, a: 2.0, b: 1.0, nx: 4, ny: 2, x0: -1.0, y0: -0.5}}
material: {{E: {E}, nu: 0.3, rho: 1.0, thickness: 0.1}}
initial_velocity: {{angular: [0.01, 1.0, 0.01]}}
integrator: {{name: em-galpha}}
time: {{dt: {dt}, t_end: {t_end}, output_interval: 0.1}}
output: {{vtu: false, history: true}}
"""
FREE_FLIGHT = """name: stiff-free-flight
mesh: {{generator: rectangle, a: 2.0, b: 1.0, nx: 2, ny: 1, x0: -1.0, y0: -0.5}}
material: {{E: 1.0e9, nu: 0.3, rho: 1.0, thickness: 0.1}}
initial_velocity: {{translation: [0.1, 0, 0.2], angular: [0.3, 0.5, 1.0]}}
integrator: {{name: em-galpha}}
time: {{dt: 0.02, t_end: 4.0, output_interval: 0.02}}
output: {{vtu: false, history: true}}
"""
CANTILEVER = """name: loaded-cantilever
mesh: {{generator: rectangle, a: 10, b: 1, nx: 16, ny: 2}}
material: {{E: 1.2e6, nu: 0, rho: 1.0, thickness: 0.1}}
boundary_conditions:
  - {{set: left, fix: [ux, uy, uz, director]}}
loads:
  - {{set: right, type: force, direction: [0, 0, 1], amplitude: 4.0, distribution: edge_total,
     function: {{type: ramp, t1: 1.0}}}}
integrator: {{name: em-galpha}}
time: {{dt: 0.01, t_end: 5.0, output_interval: 0.05}}
output: {{vtu: false, history: true}}
"""


def cases(root):
    c = {}
    for n in (4, 8, 16, 32):
        c[f"plate-{n}"] = (PLATE.format(n=n, E="1.0e7", t_end=2.0), [])
    c["tumbling-1e8"] = (TUMBLING.format(tag="1e8", E="1.0e8", dt=0.01, t_end=20.0), [])
    c["tumbling-1e10"] = (TUMBLING.format(tag="1e10", E="1.0e10", dt=0.01, t_end=20.0), [])
    c["stiff-free-flight"] = (FREE_FLIGHT.format(), [])
    c["loaded-cantilever"] = (CANTILEVER.format(), [])
    # The benchmark's own case file, its first 1 000 steps (its integrator block asks for modified Newton etc.).
    c["hemisphere-1000"] = (os.path.join(root, "apps/cases/pinched-hemisphere.yaml"), ["--t-end", "0.125"])
    return c


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--shelldyn", default=os.path.join(root, "build/bin/shelldyn"))
    ap.add_argument("--cases", default="")
    ap.add_argument("--integrators", default="em-exact,em-galpha")
    ap.add_argument("--set", action="append", default=[], help="KEY=VALUE for every run (integrator setting)")
    ap.add_argument("--threads", default="1")
    ap.add_argument("--work", default="/tmp/newton_panel")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    all_cases = cases(root)
    names = a.cases.split(",") if a.cases else list(all_cases)
    integrators = a.integrators.split(",")
    print("| case | " + " | ".join(f"{i}: it/step, fact., rejected, CPU s, max dH" for i in integrators) +
          (" | CPU ratio |" if len(integrators) == 2 else " |"))
    print("|---|" + "---|" * len(integrators) + ("---|" if len(integrators) == 2 else ""))
    for name in names:
        text, extra = all_cases[name]
        if text.endswith(".yaml"):
            path = text
        else:
            path = os.path.join(a.work, name + ".yaml")
            with open(path, "w") as f:
                f.write(text)
        cells, cpus = [], []
        for integ in integrators:
            out = os.path.join(a.work, name + "-" + integ)
            cmd = [a.shelldyn, "run", path, "--integrator", integ, "-o", out, "--overwrite", "-q", "--threads",
                   a.threads, "--checkpoint-every", "off", "--vtu-every", "0"] + extra
            for kv in a.set:
                cmd += ["--set", kv]
            p = subprocess.run(cmd, capture_output=True, text=True)
            try:
                with open(os.path.join(out, "run.json")) as f:
                    j = json.load(f)
                s = j.get("summary", j)
                steps = s["steps"]
                ok = p.returncode == 0
                drift = s.get("max_rel_energy_drift_after_loads")
                dh = "–" if drift is None else f"{drift:.2e}"  # a load acting until the end: no after-the-loads window
                cell = (f"{s['nonlinear_iterations'] / max(steps, 1):.2f}, {s['factorizations']}, {s['rejected_steps']}, "
                        f"{s['cpu_s']:.2f}, {dh}")
                if not ok:
                    cell = "FAILED after %d steps: %s" % (steps, (p.stderr.strip().splitlines() or ["?"])[-1][:160])
                cpus.append(s["cpu_s"] if ok else None)
            except (OSError, KeyError, ValueError):
                cell = "FAILED: " + ((p.stderr.strip().splitlines() or ["?"])[-1][:160])
                cpus.append(None)
            cells.append(cell)
        ratio = ""
        if len(integrators) == 2:
            ratio = f" {cpus[0] / cpus[1]:.2f} |" if cpus[0] and cpus[1] else " – |"
        print(f"| {name} | " + " | ".join(cells) + " |" + ratio, flush=True)


if __name__ == "__main__":
    sys.exit(main())
