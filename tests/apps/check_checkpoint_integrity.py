#!/usr/bin/python3
"""Checkpoints with integrity (integrators/checkpoint/checkpoint.hpp, docs/guide/result-folders.md).

usage: check_checkpoint_integrity.py SHELLDYN CASE WORK_DIR MODE [N]

MODE = kill   N (default 20) runs with a checkpoint after every output, each killed with SIGKILL while it
              writes a checkpoint (at the first checkpoint.cbor.tmp seen after a random delay), then `resume` (again after every further
              kill-free attempt, until complete): every history.csv must equal the uninterrupted run's, row for
              row in every column but wall_s. Prints how many kills hit a checkpoint write (its .tmp left).
MODE = flips  N (default 100) copies of a stopped run (--max-steps), each with one random bit of
              checkpoint.cbor flipped, each resumed: every resume must either be refused (exit 1, one line
              "damaged checkpoint", run.json keeps "stopped: ..." and records "resume_failed") or be harmless
              (exit 0, history identical to the uninterrupted run). Prints the counts.
"""
import csv
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def rows(path):
    with open(path, newline="") as f:
        r = list(csv.reader(f))
    wall = r[0].index("wall_s")
    return [[v for i, v in enumerate(row) if i != wall] for row in r]


def main():
    exe, case, work, mode = sys.argv[1:5]
    n = int(sys.argv[5]) if len(sys.argv) > 5 else (20 if mode == "kill" else 100)
    random.seed(3939)
    if os.path.isdir(work):
        shutil.rmtree(work)
    os.makedirs(work)
    args = [case, "--dt", "0.01", "--t-end", "1", "--output-every", "0.02", "--vtu-every", "10", "--threads", "1", "-q"]
    ref = os.path.join(work, "ref")
    t0 = time.time()
    r = subprocess.run([exe, "run"] + args + ["-o", ref], capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        fail("reference run failed: " + r.stderr)
    run_time = time.time() - t0
    ref_rows = rows(os.path.join(ref, "history.csv"))

    if mode == "kill":
        hit_write = 0
        for k in range(n):
            d = os.path.join(work, f"kill-{k}")
            for attempt in range(10):  # a kill before the first checkpoint: the run starts over
                p = subprocess.Popen([exe, "run"] + args + ["--checkpoint-every", "1", "--overwrite", "-o", d],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                deadline = time.time() + 120
                while not os.path.exists(os.path.join(d, "checkpoint.cbor")) and p.poll() is None and time.time() < deadline:
                    time.sleep(0.001)
                time.sleep(random.uniform(0.0, 0.5 * run_time))
                # Then at the next checkpoint write (its temporary exists while it is written and synced).
                tmp = os.path.join(d, "checkpoint.cbor.tmp")
                deadline = time.time() + 5
                while not os.path.exists(tmp) and p.poll() is None and time.time() < deadline:
                    pass
                p.send_signal(signal.SIGKILL)
                p.wait()
                if os.path.exists(os.path.join(d, "checkpoint.cbor")):
                    break
            if os.path.exists(os.path.join(d, "checkpoint.cbor.tmp")):
                hit_write += 1
            r = subprocess.run([exe, "resume", d, "-q"], capture_output=True, text=True, timeout=600)
            if r.returncode != 0:
                if "the run is complete" in r.stderr:  # the kill came after the end
                    pass
                else:
                    fail(f"kill {k}: resume failed: {r.stderr}")
            if json.load(open(os.path.join(d, "run.json"))).get("status") != "complete":
                fail(f"kill {k}: run.json not complete after resume")
            if rows(os.path.join(d, "history.csv")) != ref_rows:
                fail(f"kill {k}: history.csv differs from the uninterrupted run")
            shutil.rmtree(d)
        print(f"kill: {n} runs killed with SIGKILL and resumed, every history identical to the uninterrupted run; "
              f"{hit_write} kills interrupted a checkpoint write (checkpoint.cbor.tmp left)")
        print("OK")
        return

    stopped = os.path.join(work, "stopped")
    r = subprocess.run([exe, "run"] + args + ["--max-steps", "50", "-o", stopped], capture_output=True, text=True, timeout=600)
    if r.returncode != 4:
        fail(f"--max-steps run: exit {r.returncode}: {r.stderr}")
    status0 = json.load(open(os.path.join(stopped, "run.json")))["status"]
    data = open(os.path.join(stopped, "checkpoint.cbor"), "rb").read()
    refused = harmless = 0
    for k in range(n):
        d = os.path.join(work, f"flip-{k}")
        shutil.copytree(stopped, d)
        bit = random.randrange(8 * len(data))
        b = bytearray(data)
        b[bit // 8] ^= 1 << (bit % 8)
        open(os.path.join(d, "checkpoint.cbor"), "wb").write(bytes(b))
        r = subprocess.run([exe, "resume", d, "-q"], capture_output=True, text=True, timeout=600)
        where = f"flip {k} (byte {bit // 8} of {len(data)}, bit {bit % 8})"
        if r.returncode == 0:
            if rows(os.path.join(d, "history.csv")) != ref_rows:
                fail(f"{where}: resumed without complaint and the history differs from the uninterrupted run")
            harmless += 1
        else:
            lines = [l for l in r.stderr.splitlines() if l and not l.startswith("  ")]
            if r.returncode != 1 or len(lines) != 1 or "damaged checkpoint" not in lines[0]:
                fail(f"{where}: expected exit 1 and one line 'damaged checkpoint', got {r.returncode}: {r.stderr!r}")
            j = json.load(open(os.path.join(d, "run.json")))
            if j.get("status") != status0 or "damaged checkpoint" not in j.get("resume_failed", ""):
                fail(f"{where}: run.json must keep {status0!r} and record resume_failed, has {j.get('status')!r}, "
                     f"{j.get('resume_failed')!r}")
            refused += 1
        shutil.rmtree(d)
    print(f"flips: {n} single-bit flips of a {len(data)}-byte checkpoint: {refused} refused, {harmless} harmless "
          f"(resumed to the uninterrupted history), 0 resumed wrongly")
    print("OK")


if __name__ == "__main__":
    main()
