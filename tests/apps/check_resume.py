#!/usr/bin/python3
"""Checkpoint/restart end to end (integrators/runs/run_driver.hpp, `shelldyn resume`).

usage: check_resume.py SHELLDYN WORK_DIR MODE -- RUN_ARGS...

Runs `SHELLDYN run RUN_ARGS -o WORK_DIR/ref` uninterrupted, then the same run into WORK_DIR/cut,
stopped once history.csv has passed half of the end time (t_end is read from the reference), by
  MODE = kill      SIGKILL (the last periodic checkpoint is the restart point; pass --checkpoint-every)
  MODE = int       SIGINT  (exit code 130, run.json "interrupted: SIGINT at t = ...", a checkpoint)
  MODE = term      SIGTERM (exit code 143, likewise)
  MODE = maxsteps  --max-steps N given in RUN_ARGS (exit code 4, run.json "stopped: ...")
then `SHELLDYN resume WORK_DIR/cut` and requires:
  - resume exits 0 and run.json says "complete" with no checkpoint, no run.json.reserve and no *.tmp left
    (a SIGKILL leaves the reserve and possibly a temporary, planted here if it did not; an orderly stop must
    leave neither);
  - history.csv of the resumed run equals the reference row for row, in every column but wall_s,
    as text (the numbers are written with 17 digits: equal text = equal doubles, bitwise);
  - fields.pvd lists the same times and files as the reference.
Prints the number of rows compared and where the cut happened.
"""
import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def rows(path):
    with open(path, newline="") as f:
        r = list(csv.reader(f))
    header = r[0]
    wall = header.index("wall_s")
    return header, [[v for i, v in enumerate(row) if i != wall] for row in r[1:]]


def pvd(path):
    if not os.path.exists(path):
        return []
    return [(e.get("timestep"), e.get("file")) for e in ET.parse(path).getroot().iter("DataSet")]


def last_t(path):
    try:
        with open(path) as f:
            lines = f.read().splitlines()
        return float(lines[-1].split(",")[1]) if len(lines) > 1 else 0.0
    except (OSError, ValueError, IndexError):
        return 0.0


def main():
    sep = sys.argv.index("--")
    exe, work, mode = sys.argv[1:4]
    args = sys.argv[sep + 1:]
    if os.path.isdir(work):
        shutil.rmtree(work)
    os.makedirs(work)
    ref, cut = os.path.join(work, "ref"), os.path.join(work, "cut")
    ref_args = [a for a in args]
    if mode == "maxsteps":  # the reference runs without the limit
        i = ref_args.index("--max-steps")
        del ref_args[i:i + 2]
    r = subprocess.run([exe, "run"] + ref_args + ["-o", ref], capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        fail("reference run failed: " + r.stderr)
    header, ref_rows = rows(os.path.join(ref, "history.csv"))
    t_end = float(ref_rows[-1][1])

    p = subprocess.Popen([exe, "run"] + args + ["-o", cut], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if mode in ("kill", "int", "term"):
        deadline = time.time() + 600
        while last_t(os.path.join(cut, "history.csv")) < 0.5 * t_end:
            if p.poll() is not None:
                fail("the run ended before it could be interrupted at half time (make it longer)")
            if time.time() > deadline:
                p.kill()
                fail("timeout waiting for half time")
            time.sleep(0.01)
        p.send_signal({"kill": signal.SIGKILL, "int": signal.SIGINT, "term": signal.SIGTERM}[mode])
    _, err = p.communicate(timeout=600)
    expected = {"kill": -signal.SIGKILL, "int": 130, "term": 143, "maxsteps": 4}[mode]
    if p.returncode != expected:
        fail(f"interrupted run exited with {p.returncode}, expected {expected}; stderr: {err}")
    info = json.load(open(os.path.join(cut, "run.json")))
    status = info.get("status", "")
    want = {"kill": "incomplete: running", "int": "interrupted: SIGINT at t = ", "term": "interrupted: SIGTERM at t = ",
            "maxsteps": "stopped: --max-steps"}[mode]
    if not status.startswith(want):
        fail(f"run.json status {status!r}, expected it to start with {want!r}")
    if mode != "kill" and len(err.splitlines()) != 1:
        fail(f"expected one line on stderr, got: {err!r}")
    if not os.path.exists(os.path.join(cut, "checkpoint.cbor")):
        fail("no checkpoint.cbor after the interruption")
    # An orderly stop leaves no temporary. A SIGKILL can land while an output's temporary is being written
    # (run.json.tmp, fields.pvd.tmp, checkpoint.cbor.tmp are written whole, then renamed); resume must clear
    # such leftovers. So that this is checked on every run, not only when the kill happens to land mid-write,
    # plant one of each where the kill left none.
    def temporaries():
        found = [f for f in os.listdir(cut) if f.endswith(".tmp")]
        fields = os.path.join(cut, "fields")
        if os.path.isdir(fields):
            found += ["fields/" + f for f in os.listdir(fields) if f.endswith(".tmp")]
        return found
    if mode != "kill" and temporaries():
        fail("a .tmp file was left behind: " + str(temporaries()))
    if mode == "kill":
        for name in ("run.json.tmp", "fields.pvd.tmp", "checkpoint.cbor.tmp"):
            path = os.path.join(cut, name)
            if not os.path.exists(path):
                with open(path, "w") as f:
                    f.write("<half-written")
    cut_t = last_t(os.path.join(cut, "history.csv"))
    ckpt_t = info.get("checkpoint", {}).get("t")
    # The disk reserve (room for the last run.json on a full disk) survives only a SIGKILL; an orderly stop
    # frees it. After the resume it must be gone in every mode.
    reserve = os.path.join(cut, "run.json.reserve")
    if mode == "kill" and not os.path.exists(reserve):
        print("note: no run.json.reserve after SIGKILL (the file system could not allocate it)")
    if mode != "kill" and os.path.exists(reserve):
        fail("run.json.reserve left after an orderly stop")

    r = subprocess.run([exe, "resume", cut, "-q"], capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        fail("resume failed: " + r.stderr)
    info = json.load(open(os.path.join(cut, "run.json")))
    if info.get("status") != "complete":
        fail("resumed run.json status " + repr(info.get("status")))
    if os.path.exists(os.path.join(cut, "checkpoint.cbor")):
        fail("checkpoint.cbor left after the run completed")
    if os.path.exists(reserve):
        fail("run.json.reserve left after the resumed run completed")
    if temporaries():
        fail("a .tmp file was left behind after the resume: " + str(temporaries()))
    h2, cut_rows = rows(os.path.join(cut, "history.csv"))
    if h2 != header:
        fail("history.csv headers differ")
    if len(cut_rows) != len(ref_rows):
        fail(f"{len(cut_rows)} rows after resume, {len(ref_rows)} in the reference")
    for i, (a, b) in enumerate(zip(ref_rows, cut_rows)):
        if a != b:
            cols = [header[j] for j in range(len(a)) if a[j] != b[j]]
            fail(f"row {i + 1} (t = {a[1]}) differs in {cols}:\n  ref {a}\n  got {b}")
    bodies = os.path.join(ref, "bodies.csv")  # runs with rigid bodies: their states per output, row for row
    if os.path.exists(bodies):
        with open(bodies) as f_ref, open(os.path.join(cut, "bodies.csv")) as f_cut:
            b_ref, b_cut = f_ref.read().splitlines(), f_cut.read().splitlines()
        if b_ref != b_cut:
            i = next((k for k, (a, b) in enumerate(zip(b_ref, b_cut)) if a != b), min(len(b_ref), len(b_cut)))
            fail(f"bodies.csv differs from the reference at line {i + 1} ({len(b_cut)} lines, reference {len(b_ref)})")
    if pvd(os.path.join(ref, "fields.pvd")) != pvd(os.path.join(cut, "fields.pvd")):
        fail("fields.pvd differs from the reference")
    print(f"OK: {mode}: history.csv identical to the uninterrupted run in {len(ref_rows)} rows x {len(header) - 1} "
          f"columns (wall_s excluded); stopped at t = {cut_t} of {t_end}, checkpoint at t = {ckpt_t}")


if __name__ == "__main__":
    main()
