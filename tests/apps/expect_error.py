#!/usr/bin/python3
"""Runs a command and checks that it fails the way the CLI promises: the given exit code, nothing
but ONE line on stderr starting with "shelldyn: error:", containing an expected fragment.

usage: expect_error.py EXIT_CODE FRAGMENT -- COMMAND [ARGS...]
"""
import subprocess
import sys


def run_failing(cmd, code, program, fragment, timeout):
    """Runs cmd; returns (the result, the list of ways it did not fail as promised: exit code, ONE
    unindented stderr line starting with "<program>: error: ", the fragment somewhere in stderr)."""
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    # ONE error line; details (lists of valid names) may follow on lines indented by two spaces.
    lines = [l for l in r.stderr.splitlines() if not l.startswith("  ")]
    problems = []
    if r.returncode != code:
        problems.append(f"exit code {r.returncode}, expected {code}")
    if len(lines) != 1:
        problems.append(f"{len(lines)} unindented lines on stderr, expected 1")
    elif not lines[0].startswith(program + ": error: "):
        problems.append(f"stderr does not start with '{program}: error: '")
    if fragment not in r.stderr:
        problems.append(f"stderr lacks {fragment!r}")
    return r, problems


def report(r, problems):
    """Prints FAIL with the problems and stderr and exits 1, or prints OK with the error line."""
    if problems:
        print("FAIL: " + "; ".join(problems) + "\nstderr was:\n" + r.stderr)
        sys.exit(1)
    print("OK: " + [l for l in r.stderr.splitlines() if not l.startswith("  ")][0])


def main():
    sep = sys.argv.index("--")
    code, fragment, cmd = int(sys.argv[1]), sys.argv[2], sys.argv[sep + 1:]
    report(*run_failing(cmd, code, "shelldyn", fragment, timeout=60))


if __name__ == "__main__":
    main()
