#!/usr/bin/python3
"""Progress and quiet output of `shelldyn run` when stdout is not a terminal (docs/manual.md §1).

usage: check_progress.py SHELLDYN CASE T_END OUT_DIR

- without -q: at most 12 progress lines (one per 10 % of the simulated time, plus the first and last),
  none containing 'nan' or '-0.000000', each with a 'balance' (loads on) or 'drift' figure;
- with -q: no progress line and no summary table: exactly one result line after the header line;
- with --plots: energy.png, momentum.png, monitors.png exist and are non-empty PNG files.
"""
import os
import subprocess
import sys


def fail(msg):
    print("check_progress.py: FAIL: " + msg)
    sys.exit(1)


def main():
    exe, case, t_end, out = sys.argv[1:5]
    r = subprocess.run([exe, "run", case, "--t-end", t_end, "--vtu-every", "0", "--overwrite", "-o", out], capture_output=True,
                       text=True, timeout=300)
    if r.returncode != 0:
        fail("run failed: " + r.stdout + r.stderr)
    progress = [l for l in r.stdout.splitlines() if l.startswith("t = ")]
    if not 2 <= len(progress) <= 12:
        fail(f"{len(progress)} progress lines (expected 2..12):\n" + "\n".join(progress))
    for l in progress:
        if "nan" in l or "-0.000000" in l or not ("balance" in l or "drift" in l) or "\r" in l:
            fail("bad progress line: " + repr(l))
    r = subprocess.run([exe, "run", case, "--t-end", t_end, "--vtu-every", "0", "-q", "--plots", "--overwrite", "-o", out],
                       capture_output=True, text=True, timeout=300)
    lines = [l for l in r.stdout.splitlines() if l.strip()]
    if r.returncode != 0 or len(lines) != 2 or "complete" not in lines[1]:
        fail("-q output (expected a header and one result line):\n" + r.stdout + r.stderr)
    for png in ("energy.png", "momentum.png", "monitors.png"):
        p = os.path.join(out, png)
        if not os.path.isfile(p) or open(p, "rb").read(8) != b"\x89PNG\r\n\x1a\n":
            fail(p + " missing or not a PNG")
    print(f"ok: {len(progress)} progress lines, quiet output {len(lines)} lines, 3 plots")


main()
