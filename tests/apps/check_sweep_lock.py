#!/usr/bin/python3
"""The folders of `compare` and `study` are locked like a run's (docs/guide/result-folders.md).

usage: check_sweep_lock.py SHELLDYN WORK_DIR

  compare   a second `compare` into the folder of a running one is refused (exit != 0, one stderr line naming the
            holder); the first completes with its summary.
  stale     after the first compare is killed (SIGKILL), a plain `compare` into its folder is refused with one line
            (the lock is stale), and `compare --resume` takes it over with a note and completes.
  study     a second `study` into the folder of a running one is refused the same way; the first completes.
"""
import os
import shutil
import signal
import subprocess
import sys
import time


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def wait_for(path, proc, what, timeout=120):
    deadline = time.time() + timeout
    while not os.path.exists(path):
        if proc.poll() is not None:
            fail(f"{what} ended (exit {proc.returncode}) before {path} appeared: {proc.stderr.read()}")
        if time.time() > deadline:
            fail(f"{what}: {path} did not appear in {timeout} s")
        time.sleep(0.01)


def refused_in_one_line(r, what):
    lines = [l for l in r.stderr.splitlines() if l.strip()]
    if r.returncode == 0:
        fail(f"{what}: exit 0 although the folder is in use")
    if len(lines) != 1 or not lines[0].startswith("shelldyn: error:"):
        fail(f"{what}: expected one 'shelldyn: error:' line on stderr, got {lines}")
    return lines[0]


def main():
    exe, work = sys.argv[1:3]
    if os.path.isdir(work):
        shutil.rmtree(work)
    os.makedirs(work)
    lock = ".shelldyn.lock"
    base = ["compare", "flying-plate", "--t-end", "1", "--no-plots", "--jobs", "1", "--threads", "1"]

    # 1. compare + compare
    d = os.path.join(work, "compare")
    a = subprocess.Popen([exe] + base + ["--integrators", "em-galpha,galpha,newmark", "-o", d],
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wait_for(os.path.join(d, lock), a, "first compare")
    b = subprocess.run([exe] + base + ["--integrators", "em-galpha", "-o", d], capture_output=True, text=True, timeout=300)
    line = refused_in_one_line(b, "second compare")
    if "in use by pid" not in line:
        fail(f"second compare: the message does not name the holder: {line}")
    if a.wait(timeout=600) != 0:
        fail(f"first compare failed: {a.stderr.read()}")
    if not os.path.exists(os.path.join(d, "summary.csv")) or os.path.exists(os.path.join(d, lock)):
        fail("first compare: no summary.csv, or its lock file was left behind")
    print(f"compare: the second compare was refused: {line}")

    # 2. a killed compare leaves a stale lock: refused by a plain compare, taken over by --resume
    d = os.path.join(work, "stale")
    a = subprocess.Popen([exe] + base + ["--integrators", "em-galpha,galpha", "-o", d],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while not os.path.exists(os.path.join(d, lock)) and time.time() < deadline:
        time.sleep(0.01)
    a.send_signal(signal.SIGKILL)
    a.wait()
    if not os.path.exists(os.path.join(d, lock)):
        fail("stale: the killed compare left no lock file")
    b = subprocess.run([exe] + base + ["--integrators", "em-galpha,galpha", "-o", d], capture_output=True, text=True,
                       timeout=300)
    line = refused_in_one_line(b, "compare into a stale folder")
    if "no longer running" not in line or "--resume" not in line:
        fail(f"compare into a stale folder: the message does not say the lock is stale and how to continue: {line}")
    c = subprocess.run([exe] + base + ["--integrators", "em-galpha,galpha", "--resume", "-o", d], capture_output=True,
                       text=True, timeout=600)
    if c.returncode != 0 or not os.path.exists(os.path.join(d, "summary.csv")):
        fail(f"compare --resume after a kill: exit {c.returncode}: {c.stderr}")
    if "note:" not in c.stderr:
        fail(f"compare --resume took over the stale lock without a note: {c.stderr}")
    print(f"stale: refused ({line}); --resume took it over")

    # 3. study + study
    d = os.path.join(work, "study")
    sbase = ["study", "flying-plate", "--only", "window", "--max-steps-per-run", "200", "--no-plots", "--jobs", "1"]
    a = subprocess.Popen([exe] + sbase + ["-o", d], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wait_for(os.path.join(d, lock), a, "first study")
    b = subprocess.run([exe] + sbase + ["-o", d], capture_output=True, text=True, timeout=300)
    line = refused_in_one_line(b, "second study")
    if "in use by pid" not in line:
        fail(f"second study: the message does not name the holder: {line}")
    code = a.wait(timeout=900)
    if code not in (0, 3) or not os.path.exists(os.path.join(d, "study.csv")):
        fail(f"first study: exit {code}, study.csv present: {os.path.exists(os.path.join(d, 'study.csv'))}: {a.stderr.read()}")
    print(f"study: the second study was refused: {line}")
    print("sweep folders: locked (compare, stale compare, study)")


if __name__ == "__main__":
    main()
