#!/usr/bin/python3
"""The shipped study file of a benchmark makes exactly the runs of the study it replaces.

usage: check_study_file.py SHELLDYN BENCHMARK WORK_DIR

Until the study files (apps/studies/*.yaml, docs/reference/study-files.md), `shelldyn study BENCHMARK` ran a
table compiled into integrators/runs/study.cpp. That table is written out below (PRESETS) as the `shelldyn
compare` commands it amounted to: the window (the fixed-step schemes over the Δt list, the adaptive baselines
over the rtol list, the reference run) and the full-duration runs. This script runs

    shelldyn study BENCHMARK --case tiny.yaml          (the shipped study file)
    shelldyn compare tiny.yaml ...                     (the old table, one compare per group)

on a one-element soft plate (the case of check_plot_study.py: loads end at 0.1 s, 0.3 s in all; a few CPU
seconds for all runs), then checks that both made the same runs (labels per group) with the same t_end,
steps, RHS evaluations, factorizations, nonlinear iterations and history rows (output times). A study file
that drops, adds or changes one run, one sweep value, the window, an output interval or the full runs' Δt
fails it. Then `--add-method galpha:rho_inf=0.5` into the same folder makes only that method's 5 runs.
"""
import csv
import json
import os
import shutil
import subprocess
import sys

CASE = """name: flying-plate-tiny
description: "one soft element with the flying plate's loads, short"
mesh: {generator: rectangle, a: 2, b: 1, nx: 1, ny: 1}
material: {E: 1.0e2, nu: 0.3, rho: 1.0, thickness: 0.1}
sets:
  A: {point: [2, 0, 0]}
  B: {point: [0, 1, 0]}
loads:
  - {set: A, type: force, direction: [0, 0, 1], amplitude: 0.01, function: {type: hat, t1: 0.05}}
  - {set: B, type: force, direction: [1, 0, 0], amplitude: 0.01, function: {type: hat, t1: 0.05}}
integrator: {name: em-galpha, rho_inf: 1.0}
time: {dt: 1.0e-3, t_end: 0.3, output_interval: 0.01}
output: {vtu: false, history: true}
monitors:
  - {name: uzA, set: A, quantity: uz}
"""

FIXED = ["em-galpha", "em-exact", "galpha:rho_inf=1", "galpha:rho_inf=0.8", "midpoint", "newmark"]
ADAPTIVE = ["ida-bdf", "arkode-dirk", "arkode-erk"]
RTOLS = "1e-3,1e-4,1e-5,1e-6"
BASELINE = "ida-bdf:rtol=0.0001:atol=1e-06"
# The compiled-in presets of integrators/runs/study.cpp before the study files (window t_end, window output
# interval, Δt sweep, reference, full-duration Δt and output interval: None = the case's).
PRESETS = {
    "flying-plate": dict(t_end="0.5", output="0.005", dts="4e-3,2e-3,1e-3,5e-4", reference="em-galpha:dt=0.000125",
                         full_dt=None, full_output=None, dt_labels=["0.004", "0.002", "0.001", "0.0005"]),
    "cylindrical-panel": dict(t_end="0.004", output="4e-5", dts="4e-5,2e-5,1e-5,5e-6", reference="em-galpha:dt=1.25e-06",
                              full_dt=None, full_output=None, dt_labels=["4e-05", "2e-05", "1e-05", "5e-06"]),
    "pinched-hemisphere": dict(t_end="0.0025", output="1.25e-4", dts="5e-4,2.5e-4,1.25e-4,6.25e-5",
                               reference="em-galpha:dt=1.5625e-05", full_dt="1.25e-3", full_output="1.25e-3",
                               full_dt_label="0.00125", dt_labels=["0.0005", "0.00025", "0.000125", "6.25e-05"]),
}
COUNTS = ["t_end", "steps", "rhs_evaluations", "factorizations", "nonlinear_iterations"]


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run(args):
    p = subprocess.run(args, capture_output=True, text=True, timeout=600)
    if p.returncode != 0:
        fail(f"{' '.join(args)} exited {p.returncode}\nstdout:\n{p.stdout}\nstderr:\n{p.stderr}")
    return p.stdout


def history_rows(run_dir):
    with open(os.path.join(run_dir, "history.csv")) as f:
        return sum(1 for _ in f)


def main():
    exe, bench, work = sys.argv[1:4]
    preset = PRESETS[bench]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    case = os.path.join(work, "tiny.yaml")
    with open(case, "w") as f:
        f.write(CASE)

    study = os.path.join(work, "study")
    out = run([exe, "study", bench, "--case", case, "--jobs", "2", "--no-plots", "-o", study])
    if " 0 failed" not in out:
        fail("some study runs failed:\n" + out)

    compare = {"window": os.path.join(work, "compare-window"), "full": os.path.join(work, "compare-full")}
    run([exe, "compare", case, "--integrators", ",".join(FIXED + ADAPTIVE + [preset["reference"]]), "--dt", preset["dts"],
         "--rtol", RTOLS, "--t-end", preset["t_end"], "--output-every", preset["output"], "--jobs", "2", "--no-plots",
         "-o", compare["window"]])
    full = [exe, "compare", case, "--integrators", ",".join([BASELINE] + FIXED), "--jobs", "2", "--no-plots", "-o", compare["full"]]
    if preset["full_dt"]:
        full += ["--dt", preset["full_dt"]]
    if preset["full_output"]:
        full += ["--output-every", preset["full_output"]]
    run(full)

    with open(os.path.join(study, "study.csv")) as f:
        rows = list(csv.DictReader(f))
    for group, folder in compare.items():
        want = sorted(d for d in os.listdir(folder) if os.path.isfile(os.path.join(folder, d, "run.json")))
        got = sorted(r["label"] for r in rows if r["group"] == group)
        if got != want:
            fail(f"{group}: the study file's runs\n  {got}\nare not the old preset's\n  {want}")
    checked = 0
    for r in rows:
        if r["status"] != "complete":
            fail(f"{r['group']}/{r['label']}: {r['status']}")
        ref_dir = os.path.join(compare[r["group"]], r["label"])
        with open(os.path.join(ref_dir, "run.json")) as f:
            summary = json.load(f)["summary"]
        for key in COUNTS:
            if float(r[key]) != float(summary[key]):
                fail(f"{r['group']}/{r['label']}: {key} = {r[key]} from the study file, {summary[key]} from the old preset")
        a, b = history_rows(os.path.join(study, r["group"], r["label"])), history_rows(ref_dir)
        if a != b:
            fail(f"{r['group']}/{r['label']}: {a} history rows from the study file, {b} from the old preset")
        checked += 1
    # A method added to the shipped study (--add-method, any registered integrator) joins its Δt sweep and its
    # full-duration runs; into the same folder only the new runs are made, the others are kept.
    out = run([exe, "study", bench, "--case", case, "--add-method", "galpha:rho_inf=0.5", "--jobs", "2", "--no-plots", "-o", study])
    expect = f"study {bench}: 5 runs made, {checked} kept from earlier, 0 stopped at the per-run budget, 0 failed"
    if expect not in out:
        fail(f"--add-method: expected '{expect}' in\n{out}")
    with open(os.path.join(study, "study.csv")) as f:
        added = sorted(r["group"] + "/" + r["label"] for r in csv.DictReader(f) if r["label"].startswith("galpha_rho_inf=0.5"))
    want = sorted([f"window/galpha_rho_inf=0.5_dt={d}" for d in preset["dt_labels"]] +
                  ["full/galpha_rho_inf=0.5" + (f"_dt={preset['full_dt_label']}" if preset["full_dt"] else "")])
    if added != want:
        fail(f"--add-method: rows {added}, expected {want}")
    print(f"{bench}: {checked} runs, the same labels, t_end, steps, RHS evaluations, factorizations, nonlinear "
          f"iterations and output times as the old preset")


if __name__ == "__main__":
    main()
