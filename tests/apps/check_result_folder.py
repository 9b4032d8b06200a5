#!/usr/bin/python3
"""Result folders and inputs that cannot mislead (docs/guide/result-folders.md), one check per defect.

usage: check_result_folder.py SHELLDYN SOURCE_DIR WORK_DIR CHECK

CHECK is one of
  fifo            a FIFO as case file, as mesh file and as checkpoint: one error line within 20 s (no hang)
  symlink         --overwrite of a folder whose fields/ is a symbolic link: the files behind the link stay,
                  and a file shelldyn did not write stays
  stale           a lock file left by a dead process: `run` is refused naming it; `run --overwrite` takes it
                  over with a note and completes
  failed-resume   a resume that fails (history.csv shorter than the checkpoint says) keeps run.json's
                  "stopped: ..." status and records the reason as "resume_failed"
  complete        `resume` of a finished run says the run is complete (not "no checkpoint here")
  changed-case    `resume` after the case file was edited is refused; with --allow-changed-case it continues
  coincident      a mesh with coincident unmerged nodes: `check` warns, naming the nodes
  failed-run      a run that fails before its first step (history.csv cannot be created) records the reason in
                  run.json instead of "incomplete: running"
"""
import json
import os
import shutil
import socket
import subprocess
import sys


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run(exe, args, timeout=300, code=None):
    try:
        r = subprocess.run([exe] + args, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        fail(f"{' '.join(args)}: still running after {timeout} s (it hangs)")
    if code is not None and r.returncode != code:
        fail(f"{' '.join(args)}: exit {r.returncode}, expected {code}\nstderr: {r.stderr}")
    return r


def one_error_line(r, fragment):
    lines = [l for l in r.stderr.splitlines() if l and not l.startswith("  ") and not l.startswith("note: ")]
    if len(lines) != 1 or not lines[0].startswith("shelldyn: error: ") or fragment not in lines[0]:
        fail(f"expected one error line with {fragment!r}, stderr: {r.stderr!r}")
    return lines[0]


def main():
    exe, src, work, check = sys.argv[1:5]
    if os.path.isdir(work):
        shutil.rmtree(work)
    os.makedirs(work)
    case = os.path.join(src, "apps", "cases", "flying-plate.yaml")
    short = ["--dt", "0.01", "--t-end", "0.4", "--output-every", "0.02", "--threads", "1", "-q"]

    if check == "fifo":
        fifo = os.path.join(work, "pipe.yaml")
        os.mkfifo(fifo)
        print(one_error_line(run(exe, ["check", fifo, "-o", os.path.join(work, "a")], timeout=20, code=1), "is a FIFO"))
        mesh_fifo = os.path.join(work, "pipe.msh")
        os.mkfifo(mesh_fifo)
        c = os.path.join(work, "mesh-fifo.yaml")
        open(c, "w").write("mesh: {file: pipe.msh}\nmaterial: {E: 1.0e6, nu: 0.3, rho: 2.0, thickness: 0.1}\n"
                           "integrator: {name: em-galpha}\ntime: {dt: 0.1, t_end: 1.0}\n")
        print(one_error_line(run(exe, ["check", c, "-o", os.path.join(work, "b")], timeout=20, code=1), "not a regular file"))
        d = os.path.join(work, "run")
        run(exe, ["run", case] + short + ["--max-steps", "10", "-o", d], code=4)
        os.remove(os.path.join(d, "checkpoint.cbor"))
        os.mkfifo(os.path.join(d, "checkpoint.cbor"))
        print(one_error_line(run(exe, ["resume", d], timeout=20, code=1), "is a FIFO"))
    elif check == "symlink":
        d = os.path.join(work, "run")
        run(exe, ["run", case] + short + ["--vtu-every", "5", "-o", d], code=0)
        outside = os.path.join(work, "outside")
        os.makedirs(outside)
        for f in ("step_000000.vtu", "mine.vtu"):
            open(os.path.join(outside, f), "w").write("not shelldyn's\n")
        shutil.rmtree(os.path.join(d, "fields"))
        os.symlink(outside, os.path.join(d, "fields"))
        open(os.path.join(d, "notes.txt"), "w").write("the user's notes\n")
        run(exe, ["run", case] + short + ["--vtu-every", "0", "--overwrite", "-o", d], code=0)
        for f in ("step_000000.vtu", "mine.vtu"):
            if not os.path.exists(os.path.join(outside, f)):
                fail(f"--overwrite deleted {f} behind the fields symlink")
        if not os.path.exists(os.path.join(d, "notes.txt")):
            fail("--overwrite deleted a file shelldyn did not write")
        print("OK: --overwrite kept the files behind the fields/ link and the user's notes.txt")
    elif check == "stale":
        d = os.path.join(work, "run")
        os.makedirs(d)
        open(os.path.join(d, ".shelldyn.lock"), "w").write(
            f"pid=2147483 host={socket.gethostname()} start=2026-01-01T00:00:00Z command=shelldyn run x.yaml\n")
        print(one_error_line(run(exe, ["run", case] + short + ["-o", d], code=1), "left locked by pid 2147483"))
        r = run(exe, ["run", case] + short + ["--overwrite", "-o", d], code=0)
        if "note: " not in r.stderr or "taking over the lock of pid 2147483" not in r.stderr:
            fail(f"--overwrite must report the stale lock it takes over, stderr: {r.stderr!r}")
        if os.path.exists(os.path.join(d, ".shelldyn.lock")):
            fail("the lock file was left behind")
        print("OK: " + r.stderr.strip())
    elif check == "failed-resume":
        d = os.path.join(work, "run")
        run(exe, ["run", case] + short + ["--max-steps", "20", "-o", d], code=4)
        before = json.load(open(os.path.join(d, "run.json")))["status"]
        h = os.path.join(d, "history.csv")
        os.truncate(h, os.path.getsize(h) // 2)
        line = one_error_line(run(exe, ["resume", d], code=1), "shorter than at the checkpoint")
        j = json.load(open(os.path.join(d, "run.json")))
        if j.get("status") != before:
            fail(f"run.json status {j.get('status')!r} after the failed resume, expected {before!r}")
        if "shorter than at the checkpoint" not in j.get("resume_failed", ""):
            fail(f"run.json does not record the failed resume's reason: {j.get('resume_failed')!r}")
        print(f"OK: {line}; run.json keeps {before!r} and records resume_failed")
    elif check == "complete":
        d = os.path.join(work, "run")
        run(exe, ["run", case] + short + ["-o", d], code=0)
        print(one_error_line(run(exe, ["resume", d], code=1), "the run is complete, nothing to resume"))
        if "resume_failed" in json.load(open(os.path.join(d, "run.json"))):
            fail("resume of a complete run changed its run.json")
    elif check == "changed-case":
        mine = os.path.join(work, "case.yaml")
        text = open(case).read()
        open(mine, "w").write(text)
        d = os.path.join(work, "run")
        run(exe, ["run", mine] + short + ["--max-steps", "20", "-o", d], code=4)
        open(mine, "w").write(text + "# edited after the run started\n")
        print(one_error_line(run(exe, ["resume", d], code=1), "the case file was edited after the run"))
        if json.load(open(os.path.join(d, "run.json")))["status"].startswith("incomplete"):
            fail("the refused resume changed the folder's status")
        r = run(exe, ["resume", d, "-q", "--allow-changed-case"], code=0)
        if "note: " not in r.stderr:
            fail(f"--allow-changed-case must say what it does, stderr: {r.stderr!r}")
        print("OK: with --allow-changed-case: " + r.stderr.strip())
    elif check == "coincident":
        c = os.path.join(src, "tests", "data", "case_two_plates_unmerged.yaml")
        r = run(exe, ["check", c, "-o", os.path.join(work, "c")], code=0)
        w = [l for l in r.stderr.splitlines() if l.startswith("warning: ")]
        if len(w) != 1 or "(1 & 9, 2 & 12, 5 & 16, first at (2, 0, 0))" not in w[0]:
            fail(f"expected one warning naming the coincident nodes, stderr: {r.stderr!r}")
        print("OK: " + w[0])
    elif check == "failed-run":
        d = os.path.join(work, "run")
        os.makedirs(os.path.join(d, "history.csv"))  # a folder where the file should go (not empty)
        open(os.path.join(d, "history.csv", "keep"), "w").write("x")
        open(os.path.join(d, "run.json"), "w").write('{"status": "complete"}\n')
        line = one_error_line(run(exe, ["run", case] + short + ["--overwrite", "-o", d], code=1), "history")
        status = json.load(open(os.path.join(d, "run.json")))["status"]
        if not status.startswith("incomplete: ") or "history" not in status:
            fail(f"run.json status {status!r} does not say why the run failed")
        print(f"OK: {line}; run.json: {status!r}")
    else:
        fail("unknown check " + check)


if __name__ == "__main__":
    main()
