#!/usr/bin/python3
"""A case file's Newton settings reproduce the converged scheme (docs/results.md §2.1).

usage: check_converged_settings.py WORK_DIR TOL MONITOR -- APP ARGS...
example: python3 scripts/check_converged_settings.py /tmp/conv 3e-11 uzC --
             build/bin/shelldyn run apps/cases/cylindrical-panel.yaml --t-end 0.03 --vtu-every 0 -q
(APP ARGS: a `shelldyn run CASE ...` or a benchmark app command line without -o; MONITOR: a monitor column of
the case's history.csv. Exit 0 if both distances are within TOL, 1 if not or if a run fails, 2 on bad usage.)

Runs APP ARGS twice: as given (the case file's settings) into WORK_DIR/case, and with the iteration driven
much deeper (`--set floor_test=correction --set e_floor=1e-26 --set cc_tol=1e-30`, each step iterated until
the energy of its correction is 1e-26 of the system's) into WORK_DIR/deep. The deep run stands for the
converged scheme: on the full cylindrical panel such settings stay within 1.1e-11 of full Newton iterated to
cc 1e-20. Requires, over all output rows,
  max |H - H_deep| / max(K + V)  <= TOL   (H = K + V - W_ext, the history's `total` column)
  max |m - m_deep| / max |m_deep| <= TOL  (m = the monitor column MONITOR)
and prints both, so that a stopping rule which leaves algebraic error in the trajectory fails even when the
energy error after the loads looks small.
"""
import csv
import os
import shutil
import subprocess
import sys


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def history(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def usage(msg):
    print("error: " + msg, file=sys.stderr)
    print("usage: check_converged_settings.py WORK_DIR TOL MONITOR -- APP ARGS...  (--help for more)", file=sys.stderr)
    sys.exit(2)


def main():
    if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return
    if "--" not in sys.argv or sys.argv.index("--") != 4 or len(sys.argv) < 6:
        usage("expected WORK_DIR TOL MONITOR, then --, then the command to run")
    sep = sys.argv.index("--")
    work, monitor = sys.argv[1], sys.argv[3]
    try:
        tol = float(sys.argv[2])
    except ValueError:
        usage(f"TOL {sys.argv[2]!r} is not a number (e.g. 3e-11)")
    cmd = sys.argv[sep + 1:]
    if os.path.isdir(work):
        shutil.rmtree(work)
    os.makedirs(work)
    deep = ["--set", "floor_test=correction", "--set", "e_floor=1e-26", "--set", "cc_tol=1e-30"]
    rows = {}
    for name, extra in (("case", []), ("deep", deep)):
        out = os.path.join(work, name)
        r = subprocess.run(cmd + extra + ["-o", out], capture_output=True, text=True, timeout=900)
        if r.returncode != 0:
            fail(f"{name} run failed ({r.returncode}): {r.stderr.strip()}")
        rows[name] = history(os.path.join(out, "history.csv"))
    a, b = rows["case"], rows["deep"]
    if len(a) != len(b) or len(a) < 2:
        fail(f"{len(a)} rows against {len(b)}")
    if monitor not in b[0]:
        fail(f"no monitor column {monitor!r} in history.csv")
    kv = max(float(x["kinetic"]) + float(x["strain"]) for x in b)
    mmax = max(abs(float(x[monitor])) for x in b)
    dh = max(abs(float(x["total"]) - float(y["total"])) for x, y in zip(a, b)) / kv
    dm = max(abs(float(x[monitor]) - float(y[monitor])) for x, y in zip(a, b)) / mmax
    its = (int(a[-1]["nonlinear_iters"]), int(b[-1]["nonlinear_iters"]))
    print(f"{len(a)} rows to t = {a[-1]['t']}: max|H - H_deep|/(K+V) = {dh:.2e}, max|{monitor} - deep|/max|{monitor}| = "
          f"{dm:.2e} (bound {tol:.1e}); iterations {its[0]} (case) against {its[1]} (deep)")
    if not dh <= tol:
        fail(f"energy trajectory {dh:.2e} from the deeply iterated run (bound {tol:.1e})")
    if not dm <= tol:
        fail(f"{monitor} {dm:.2e} from the deeply iterated run (bound {tol:.1e})")
    print("OK")


if __name__ == "__main__":
    main()
