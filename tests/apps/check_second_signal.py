#!/usr/bin/python3
"""A second SIGINT during the orderly stop exits at once (integrators/runs/run_driver.cpp, docs/architecture.md
"Checkpoints and resume").

usage: check_second_signal.py SHELLDYN CASE WORK_DIR

Runs CASE (the flying plate) on a mesh refined until one time step takes seconds (cell 1/8: 1920 elements),
so that the orderly stop after the first SIGINT -- finish the current step, checkpoint, write run.json
"interrupted" -- is still under way when the second SIGINT comes 0.5 s later. Requires:
  - exit code 130 (128 + SIGINT);
  - nothing of the orderly stop happened: run.json still says "incomplete: running", no checkpoint.cbor,
    nothing on stderr (the "interrupted ..." line is the orderly stop's);
  - no .tmp file left.
If the second signal were ignored (or handled like the first), the run would end in the orderly way and
run.json would say "interrupted: SIGINT ...": this test then fails.
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def data_rows(path):
    try:
        with open(path) as f:
            return max(0, len(f.read().splitlines()) - 1)
    except OSError:
        return 0


def main():
    exe, case, work = sys.argv[1:4]
    if os.path.isdir(work):
        shutil.rmtree(work)
    os.makedirs(work)
    text = open(case).read()
    # cells are counted in units of `cell`: 8x the cells of 1/8 the size is the same L shape.
    fine, n = re.subn(r"\bcells: \[\[0, 0, 3, 7\], \[3, 0, 6, 3\]\]\n  cell: 1\.0\b",
                      "cells: [[0, 0, 24, 56], [24, 0, 48, 24]]\n  cell: 0.125", text)
    if n != 1:
        fail("the case's mesh is not the expected cell_union of 1 m cells")
    fine_case = os.path.join(work, "fine.yaml")
    with open(fine_case, "w") as f:
        f.write(fine)
    out = os.path.join(work, "out")
    p = subprocess.Popen([exe, "run", fine_case, "--set", "newton=full", "--dt", "0.05", "--t-end", "1", "--vtu-every", "0",
                          "--threads", "1", "-q", "-o", out],
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    # The row at t = 0 is written after the initialization: from then on the first step is running.
    deadline = time.time() + 300
    while data_rows(os.path.join(out, "history.csv")) < 1:
        if p.poll() is not None:
            fail("the run ended before the first step: " + p.stderr.read())
        if time.time() > deadline:
            p.kill()
            fail("timeout waiting for the first step")
        time.sleep(0.01)
    p.send_signal(signal.SIGINT)
    time.sleep(0.5)
    if p.poll() is not None:
        fail("the orderly stop ended within 0.5 s, before a second signal could test anything (refine the mesh)")
    rows_at_second = data_rows(os.path.join(out, "history.csv"))
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=300)
    if p.returncode != 130:
        fail(f"exit code {p.returncode}, expected 130; stderr: {err!r}")
    status = json.load(open(os.path.join(out, "run.json"))).get("status", "")
    if status != "incomplete: running":
        fail(f"run.json status {status!r}: the orderly stop went on after the second signal")
    if os.path.exists(os.path.join(out, "checkpoint.cbor")):
        fail("a checkpoint was written after the second signal")
    if err.strip():
        fail(f"stderr {err!r}: the orderly stop's message was printed after the second signal")
    tmp = [f for f in os.listdir(out) if f.endswith(".tmp")]
    if tmp:
        fail("left behind: " + str(tmp))
    print(f"OK: second SIGINT 0.5 s after the first, during step 1 ({rows_at_second} output rows): exit 130 at once, "
          "run.json still 'incomplete: running', no checkpoint, nothing printed")


if __name__ == "__main__":
    main()
