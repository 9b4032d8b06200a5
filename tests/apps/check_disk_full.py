#!/usr/bin/python3
"""A run whose outputs fill the disk (docs/architecture.md "Checkpoints and resume", lib/io/run_info.hpp DiskReserve).

usage: check_disk_full.py SHELLDYN CASE WORK_DIR

Mounts a small tmpfs (needs root and a working `mount`; otherwise prints SKIP and exits 77, which ctest
reports as skipped) and runs CASE into it, once for each file that is to fill the disk first:
  vtu         VTU every output (fields/step_*.vtu is the largest file)
  history     no VTU, many output rows (history.csv grows until the disk is full)
  checkpoint  no VTU, a checkpoint every step (checkpoint.cbor.tmp)
  static_vtu  `shelldyn static` of apps/cases/sze-cantilever-shear.yaml, a VTU every increment
  static_csv  the same without VTU and with 2000 increments (static.csv grows until the disk is full)
Each run must exit 1 with a first stderr line "shelldyn: error: PATH: ... the disk is full ..." naming
the file named for the scenario, and leave:
  - run.json with status "incomplete: " + that same message (not "incomplete: running", not "complete");
  - no *.tmp file and no run.json.reserve anywhere in the folder;
  - history.csv with whole rows only (every row has as many fields as the header);
  - only complete VTU files, each listed in fields.pvd (when there is one).
"""
import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

STATIC_CASE = "sze-cantilever-shear.yaml"  # beside CASE in apps/cases
SCENARIOS = {
    # name: (tmpfs size, extra run arguments, failing file must contain); "static_*": `shelldyn static` on
    # STATIC_CASE, the extra "arguments" are (old, new) replacements of its text.
    "vtu": ("160k", ["--t-end", "2", "--output-every", "0.01", "--vtu-every", "1"], "/fields/step_"),
    "history": ("160k", ["--t-end", "20", "--output-every", "0.01", "--vtu-every", "0"], "/history.csv"),
    "checkpoint": ("160k", ["--t-end", "2", "--output-every", "0.01", "--vtu-every", "0", "--checkpoint-every", "1"],
                   "/checkpoint.cbor"),
    "static_vtu": ("160k", [], "/fields"),  # a VTU or fields.pvd, whichever meets the full disk
    "static_csv": ("160k", [("output: {vtu: true, vtu_every: 1, history: false}", "output: {vtu: false}"),
                            ("integrator: {name: static}", "integrator: {name: static, increment: 0.0005, growth: 1.0, max_steps: 5000}")],
                   "/static.csv"),
}


def skip(msg):
    print("SKIP: " + msg)
    sys.exit(77)


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def check(exe, case, mnt, name):
    size, extra, failing = SCENARIOS[name]
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=" + size, "tmpfs", mnt], capture_output=True).returncode != 0:
        skip("cannot mount a tmpfs here")
    try:
        out = os.path.join(mnt, "out")
        if name.startswith("static"):
            text = open(os.path.join(os.path.dirname(case), STATIC_CASE)).read()
            for old, new in extra:
                if old not in text:
                    fail(f"{name}: {STATIC_CASE} no longer holds {old!r}")
                text = text.replace(old, new)
            static_case = os.path.join(os.path.dirname(mnt), "static_case.yaml")
            open(static_case, "w").write(text)
            cmd = [exe, "static", static_case, "-o", out]
        else:
            cmd = [exe, "run", case, "--dt", "0.01", "--threads", "1", "-q", "-o", out] + extra
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        first = r.stderr.splitlines()[0] if r.stderr else ""
        if r.returncode != 1:
            fail(f"{name}: exit code {r.returncode}, expected 1; stderr: {r.stderr!r}")
        prefix = "shelldyn: error: "
        if not first.startswith(prefix) or "the disk is full" not in first or failing not in first:
            fail(f"{name}: first stderr line {first!r} does not say that the disk is full while writing {failing}")
        message = first[len(prefix):]
        status = json.load(open(os.path.join(out, "run.json"))).get("status", "")
        if status != "incomplete: " + message:
            fail(f"{name}: run.json status {status!r}, expected 'incomplete: ' + {message!r}")
        left = []
        for root, _, files in os.walk(out):
            left += [os.path.join(root, f) for f in files if f.endswith(".tmp") or f == "run.json.reserve"]
        if left:
            fail(f"{name}: left behind: {left}")
        for table in ("history.csv", "static.csv"):
            hist = os.path.join(out, table)
            if not os.path.exists(hist):
                continue
            lines = open(hist).read().split("\n")
            if name != "static_csv" and lines[-1] != "":  # a full disk may cut static.csv's last row
                fail(f"{name}: {table} ends in a half row: {lines[-1][:80]!r}")
            width = lines[0].count(",")
            bad = [i for i, l in enumerate(lines[1:-1], 2) if l.count(",") != width]
            if bad:
                fail(f"{name}: {table} rows {bad[:5]} are not whole")
        listed = set()
        pvd = os.path.join(out, "fields.pvd")
        if os.path.exists(pvd):
            listed = {e.get("file") for e in ET.parse(pvd).getroot().iter("DataSet")}
        fields = os.path.join(out, "fields")
        vtus = sorted(os.listdir(fields)) if os.path.isdir(fields) else []
        for v in vtus:
            ET.parse(os.path.join(fields, v))  # raises on a truncated file
            if "fields/" + v not in listed:
                fail(f"{name}: fields/{v} is not listed in fields.pvd")
        for f in listed:
            if not os.path.exists(os.path.join(out, f)):
                fail(f"{name}: fields.pvd lists {f}, which does not exist")
        print(f"OK: {name}: {message}; run.json says so; {len(vtus)} complete VTU files, no .tmp, no reserve left")
    finally:
        subprocess.run(["umount", mnt])


def main():
    exe, case, work = sys.argv[1:4]
    if os.geteuid() != 0:
        skip("needs root to mount a small tmpfs")
    mnt = os.path.join(work, "mnt")
    if os.path.ismount(mnt):  # left mounted by an interrupted earlier run
        subprocess.run(["umount", mnt])
    if os.path.isdir(work):
        shutil.rmtree(work)
    os.makedirs(mnt)
    for name in SCENARIOS:
        check(exe, case, mnt, name)


if __name__ == "__main__":
    main()
