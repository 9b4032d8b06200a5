"""The Python velocity Verlet (verlet.py) against its C++ copy (python/tests/verlet_cpp.cpp) on the flying plate:
same steps, the energy histories' difference, CPU per step.

    PYTHONPATH=build/python OMP_NUM_THREADS=1 /usr/bin/python3 python/examples/verlet_vs_cpp.py --t-end 2
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import shelldyn  # noqa: E402
import verlet  # noqa: E402

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--t-end", type=float, default=2.0)
ap.add_argument("--dt", type=float, default=5e-5)
ap.add_argument("--out", default=None, help="keep the two run folders here")
args = ap.parse_args()

verlet.register("verlet")
shelldyn._register_verlet_cpp("verlet-cpp")
runs = {}
for name in ("verlet", "verlet-cpp"):
    out = os.path.join(args.out, name) if args.out else None
    runs[name] = shelldyn.run("flying-plate", name, dt=args.dt, t_end=args.t_end, out_dir=out, overwrite=True, vtu_every=0)
py, cpp = runs["verlet"], runs["verlet-cpp"]
H_py, H_cpp = py.history["total"], cpp.history["total"]
E = np.max(cpp.history["kinetic"] + cpp.history["strain"])
for name, r in runs.items():
    s = r.summary
    print("%-10s %s, %d steps, CPU %.2f s = %.1f us/step, max |H| = %.3g (max K+V = %.4g)" % (
        name, s["status"], s["steps"], s["cpu_s"], 1e6 * s["cpu_s"] / s["steps"], np.max(np.abs(r.history["total"])), E))
print("same output times: %s; max |H_py - H_cpp| = %.3g (%.2g of max K+V); max |uzA_py - uzA_cpp| = %.3g" % (
    np.array_equal(py.history["t"], cpp.history["t"]), np.max(np.abs(H_py - H_cpp)), np.max(np.abs(H_py - H_cpp)) / E,
    np.max(np.abs(py.history["uzA"] - cpp.history["uzA"]))))
print("CPU per step, Python / C++: %.2f" % ((py.summary["cpu_s"] / py.summary["steps"]) / (cpp.summary["cpu_s"] / cpp.summary["steps"])))
