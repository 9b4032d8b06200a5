#!/usr/bin/python3
"""Runs a benchmark app with bad input and checks it fails the promised way: the given exit code,
exactly ONE line on stderr starting with "<app>: error: " and containing a fragment, and no result
folder that looks complete (the -o folder is absent, or its run.json does not say "complete").

usage: expect_app_error.py APP EXIT_CODE FRAGMENT OUT_DIR -- COMMAND [ARGS...]
"""
import json
import os
import shutil
import sys

from expect_error import report, run_failing


def main():
    sep = sys.argv.index("--")
    app, code, fragment, out, cmd = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4], sys.argv[sep + 1:]
    if os.path.isdir(out):
        shutil.rmtree(out)
    r, problems = run_failing(cmd, code, app, fragment, timeout=120)
    run_json = os.path.join(out, "run.json")
    if os.path.isfile(run_json):
        with open(run_json, encoding="utf-8") as f:
            status = json.load(f).get("status", "")
        if status == "complete":
            problems.append(f"{run_json} says complete")
    elif os.path.isdir(out) and os.listdir(out):
        problems.append(f"{out} was created and is not empty: {os.listdir(out)}")
    report(r, problems)


if __name__ == "__main__":
    main()
