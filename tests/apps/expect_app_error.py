#!/usr/bin/python3
"""Runs a benchmark app with bad input and checks it fails the promised way: the given exit code,
exactly ONE line on stderr starting with "<app>: error: " and containing a fragment, and no result
folder that looks complete (the -o folder is absent, or its run.json does not say "complete").

usage: expect_app_error.py APP EXIT_CODE FRAGMENT OUT_DIR -- COMMAND [ARGS...]
"""
import json
import os
import shutil
import subprocess
import sys


def main():
    sep = sys.argv.index("--")
    app, code, fragment, out, cmd = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[sep + 1:]
    if os.path.isdir(out):
        shutil.rmtree(out)
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    # ONE error line; details (lists of valid names) may follow on lines indented by two spaces.
    lines = [l for l in r.stderr.splitlines() if not l.startswith("  ")]
    problems = []
    if r.returncode != code:
        problems.append(f"exit code {r.returncode}, expected {code}")
    if len(lines) != 1:
        problems.append(f"{len(lines)} unindented lines on stderr, expected 1")
    elif not lines[0].startswith(app + ": error: "):
        problems.append(f"stderr does not start with '{app}: error: '")
    if fragment not in r.stderr:
        problems.append(f"stderr lacks {fragment!r}")
    run_json = os.path.join(out, "run.json")
    if os.path.isfile(run_json):
        with open(run_json, encoding="utf-8") as f:
            status = json.load(f).get("status", "")
        if status == "complete":
            problems.append(f"{run_json} says complete")
    elif os.path.isdir(out) and os.listdir(out):
        problems.append(f"{out} was created and is not empty: {os.listdir(out)}")
    if problems:
        print("FAIL: " + "; ".join(problems) + "\nstderr was:\n" + r.stderr)
        sys.exit(1)
    print("OK: " + lines[0])


if __name__ == "__main__":
    main()
