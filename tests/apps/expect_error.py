#!/usr/bin/python3
"""Runs a command and checks that it fails the way the CLI promises: the given exit code, nothing
but ONE line on stderr starting with "shelldyn: error:", containing an expected fragment.

usage: expect_error.py EXIT_CODE FRAGMENT -- COMMAND [ARGS...]
"""
import subprocess
import sys


def main():
    sep = sys.argv.index("--")
    code, fragment, cmd = int(sys.argv[1]), sys.argv[2], sys.argv[sep + 1:]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    # ONE error line; details (lists of valid names) may follow on lines indented by two spaces.
    lines = [l for l in r.stderr.splitlines() if not l.startswith("  ")]
    problems = []
    if r.returncode != code:
        problems.append(f"exit code {r.returncode}, expected {code}")
    if len(lines) != 1:
        problems.append(f"{len(lines)} unindented lines on stderr, expected 1")
    elif not lines[0].startswith("shelldyn: error: "):
        problems.append("stderr does not start with 'shelldyn: error: '")
    if fragment not in r.stderr:
        problems.append(f"stderr lacks {fragment!r}")
    if problems:
        print("FAIL: " + "; ".join(problems) + "\nstderr was:\n" + r.stderr)
        sys.exit(1)
    print("OK: " + lines[0])


if __name__ == "__main__":
    main()
