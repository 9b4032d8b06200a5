#!/usr/bin/python3
"""One entry of the bad-input corpus (tests/bad_input/corpus.txt) as a test.

usage: run_bad_input.py CORPUS NAME BIN_DIR SOURCE_DIR OUT_ROOT

corpus.txt lines: NAME | EXIT | PROGRAM | FRAGMENT | ARGS   ('#' starts a comment line). In ARGS,
@cases@ is apps/cases, @bad@ tests/bad_input, @out@ this entry's result folder (OUT_ROOT/NAME),
removed before the run. EXIT 'prefill' runs with a result folder that already holds a complete
earlier result and expects exit 1 with that folder left untouched.

Checks, for every entry:
  - the exit code;
  - stderr is ONE line "PROGRAM: error: ..." (plus detail lines indented by two spaces) containing FRAGMENT, at most 150 characters after the
    "PROGRAM: error: " prefix (paths counted as their file names), without internals
    (KINSOL/KIN_ flags, "spec/" paths, "callback");
  - no complete-looking result: @out@ is absent, empty, or its run.json says neither "complete" nor
    "checked"; no *.tmp file is left in it.
"""
import json
import re
import os
import shutil
import subprocess
import sys

MAX_FIRST_LINE = 150
INTERNALS = ["KIN_", "KINSol", "IDA_", "ARK_", "spec/", "callback"]


def fail(msg, stderr=""):
    print("FAIL: " + msg + ("\nstderr was:\n" + stderr if stderr else ""))
    sys.exit(1)


def entry(corpus, name):
    with open(corpus, encoding="utf-8") as f:
        for line in f:
            if line.strip() and not line.lstrip().startswith("#"):
                fields = [x.strip() for x in line.split("|", 4)]
                if fields[0] == name:
                    return fields
    fail(f"no entry {name!r} in {corpus}")


def main():
    corpus, name, bin_dir, src, out_root = sys.argv[1:6]
    _, code, program, fragment, args = entry(corpus, name)
    out = os.path.join(out_root, name)
    if os.path.isdir(out):
        shutil.rmtree(out)
    prefill = code == "prefill"
    before = None
    if prefill:
        os.makedirs(os.path.join(out, "fields"))
        with open(os.path.join(out, "run.json"), "w") as f:
            json.dump({"status": "complete", "marker": "earlier run"}, f)
        open(os.path.join(out, "history.csv"), "w").write("step,t\n0,0\n")
        open(os.path.join(out, "fields", "step_000000.vtu"), "w").write("<VTKFile/>\n")
        before = sorted((p, open(os.path.join(p, f)).read()) for p, _, fs in os.walk(out) for f in fs)
        code = "1"
    argv = [a.replace("@cases@", os.path.join(src, "apps", "cases")).replace("@bad@", os.path.join(src, "tests", "bad_input"))
            .replace("@out@", out) for a in args.split()]
    exe = os.path.join(bin_dir, "shelldyn" if program == "shelldyn" else program)
    r = subprocess.run([exe] + argv, capture_output=True, text=True, timeout=120)
    # ONE error line; details (e.g. lists of valid names) may follow, indented by two spaces.
    lines = [l for l in r.stderr.splitlines() if not l.startswith("  ")]
    if r.returncode != int(code):
        fail(f"exit code {r.returncode}, expected {code}", r.stderr)
    if len(lines) != 1:
        fail(f"{len(lines)} lines on stderr, expected 1", r.stderr)
    prefix = program + ": error: "
    if not lines[0].startswith(prefix):
        fail(f"stderr does not start with {prefix!r}", r.stderr)
    message = lines[0][len(prefix):]
    if fragment == "?":
        fail("no fragment in the corpus yet; the message is: " + message)
    if fragment not in r.stderr:
        fail(f"message lacks {fragment!r}", r.stderr)
    # Length with every path shortened to its file name: "where" is FILE:LINE, and how deep the folders
    # of a checkout or a result folder are is not the message's doing.
    shown = re.sub(r"(?:[\w.@-]*/)+([\w.@-]+)", r"\1", message)
    # A trailing enumeration of the valid choices counts as details (case-file errors keep it on the
    # first line: tests/lib/test_case_file.cpp requires one-line messages).
    shown = re.sub(r" \((allowed here|expected one of|available|valid): [^)]*\)", "", shown)
    if len(shown) > MAX_FIRST_LINE:
        fail(f"message is {len(shown)} characters with paths as file names (at most {MAX_FIRST_LINE})", r.stderr)
    for word in INTERNALS:
        if word in message:
            fail(f"message shows internals ({word!r})", r.stderr)
    if prefill:
        after = sorted((p, open(os.path.join(p, f)).read()) for p, _, fs in os.walk(out) for f in fs)
        if after != before:
            fail("the earlier result was modified although the command was refused")
    elif os.path.isdir(out):
        run_json = os.path.join(out, "run.json")
        if os.path.isfile(run_json):
            status = json.load(open(run_json)).get("status", "")
            if status in ("complete", "checked"):
                fail(f"{run_json} says {status!r}")
        tmp = [os.path.join(p, f) for p, _, fs in os.walk(out) for f in fs if f.endswith(".tmp")]
        if tmp:
            fail(f"temporary files left: {tmp}")
    print(f"OK ({len(shown)} chars): {lines[0]}")


if __name__ == "__main__":
    main()
