#!/usr/bin/python3
"""Result folders as transactions: concurrent commands into one folder (docs/guide/result-folders.md).

usage: check_folder_lock.py SHELLDYN CASE WORK_DIR [TRIALS]

Three scenarios, TRIALS (default 20) trials each, every trial into a fresh folder, the second command
started at a random delay (0-150 ms) after the first:
  two       `run` and `run` (same arguments)
  overwrite `run`, then `run --overwrite` (same arguments) while the first may still run
  resume    `run --checkpoint-every 1`, then `resume` once the first checkpoint exists
Requires in every trial: exactly one command wins (exit 0), the other exits non-zero with ONE line on stderr
("shelldyn: error: ..."), and the folder's history.csv equals a reference run's history row for row in every
column but wall_s (no torn row, no foreign row, nothing missing), with run.json "complete". Prints how many
trials actually overlapped (the loser was refused because the folder was in use).
"""
import csv
import json
import os
import random
import shutil
import subprocess
import sys
import time


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def rows(path):
    with open(path, newline="") as f:
        text = f.read()
    if not text.endswith("\n"):
        fail(f"{path}: last row is torn (no line end)")
    r = list(csv.reader(text.splitlines()))
    header = r[0]
    for k, row in enumerate(r[1:]):
        if len(row) != len(header):
            fail(f"{path}: row {k + 1} has {len(row)} fields, the header {len(header)} (torn row)")
    wall = header.index("wall_s")
    return [[v for i, v in enumerate(row) if i != wall] for row in r[1:]]


def main():
    exe, case, work = sys.argv[1:4]
    trials = int(sys.argv[4]) if len(sys.argv) > 4 else 20
    random.seed(39)
    if os.path.isdir(work):
        shutil.rmtree(work)
    os.makedirs(work)
    args = [case, "--dt", "0.01", "--t-end", "2.0", "--output-every", "0.02", "--vtu-every", "10", "--threads", "1", "-q"]
    ref = os.path.join(work, "ref")
    r = subprocess.run([exe, "run"] + args + ["-o", ref], capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        fail("reference run failed: " + r.stderr)
    ref_rows = rows(os.path.join(ref, "history.csv"))

    def start(cmd):
        return subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)

    overlapped = {}
    for scenario in ("two", "overwrite", "resume"):
        overlapped[scenario] = 0
        for trial in range(trials):
            d = os.path.join(work, f"{scenario}-{trial}")
            if scenario == "resume":
                a = start([exe, "run"] + args + ["--checkpoint-every", "1", "-o", d])
                deadline = time.time() + 120
                while not os.path.exists(os.path.join(d, "checkpoint.cbor")) and a.poll() is None and time.time() < deadline:
                    time.sleep(0.002)
                time.sleep(random.uniform(0.0, 0.05))
                b = start([exe, "resume", d, "-q"])
            else:
                a = start([exe, "run"] + args + ["-o", d])
                time.sleep(random.uniform(0.0, 0.15))
                b = start([exe, "run"] + args + (["--overwrite"] if scenario == "overwrite" else []) + ["-o", d])
            ea, eb = a.wait(timeout=600), b.wait(timeout=600)
            errs = (a.stderr.read(), b.stderr.read())
            codes = (ea, eb)
            where = f"{scenario} trial {trial}: exit codes {codes}"
            # Both won: the first ended before the second took the folder (it starts up before it locks), so the
            # overwrite replaced a finished run, as it should; the result must still be one whole run.
            if scenario == "overwrite" and codes == (0, 0):
                if rows(os.path.join(d, "history.csv")) != ref_rows:
                    fail(f"{where}: history.csv of the sequential overwrite differs from the reference")
                shutil.rmtree(d)
                continue
            if sorted(c == 0 for c in codes) != [False, True]:
                fail(f"{where}: exactly one command must win\nstderr: {errs}")
            loser = 0 if codes[0] != 0 else 1
            lines = [l for l in errs[loser].splitlines() if l and not l.startswith("  ")]
            if len(lines) != 1 or not lines[0].startswith("shelldyn: error: "):
                fail(f"{where}: the refused command must print one error line, printed: {errs[loser]!r}")
            if "in use by" in lines[0]:
                overlapped[scenario] += 1
            status = json.load(open(os.path.join(d, "run.json"))).get("status")
            if status != "complete":
                fail(f"{where}: run.json status {status!r}")
            got = rows(os.path.join(d, "history.csv"))
            if got != ref_rows:
                n = next((k for k, (x, y) in enumerate(zip(got, ref_rows)) if x != y), min(len(got), len(ref_rows)))
                fail(f"{where}: history.csv differs from the reference at row {n + 1} ({len(got)} vs {len(ref_rows)} rows)")
            if os.path.exists(os.path.join(d, ".shelldyn.lock")):
                fail(f"{where}: the lock file was left behind")
            shutil.rmtree(d)
        print(f"{scenario}: {trials} trials, one winner each, history identical to the reference; "
              f"{overlapped[scenario]} overlapped (the second command refused as 'in use')")
    if min(overlapped.values()) < trials // 2:
        fail(f"too few trials overlapped to test the lock: {overlapped}")
    print("OK")


if __name__ == "__main__":
    main()
