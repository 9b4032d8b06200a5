"""Example (b): a velocity-Verlet scheme written in NumPy (verlet.py), registered by name and compared with
em-galpha and newmark on the flying plate: a work-precision sweep with `shelldyn.compare`.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/verlet_study.py --out results/python/verlet-study
"""
import argparse
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import shelldyn  # noqa: E402
import verlet  # noqa: E402

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--out", default="results/python/verlet-study")
ap.add_argument("--t-end", type=float, default=0.05, help="window [0, t_end] of the sweep [s]")
ap.add_argument("--jobs", type=int, default=2)
args = ap.parse_args()

verlet.register("verlet")
specs = ["em-galpha:dt=%g" % dt for dt in (5e-3, 2.5e-3, 1.25e-3, 5e-4, 2.5e-4)]
specs += ["newmark:dt=%g" % dt for dt in (2.5e-3, 1.25e-3, 5e-4, 2.5e-4)]
specs += ["verlet:dt=%g" % dt for dt in (5e-5, 2.5e-5)]  # explicit: unstable at dt = 1e-4 on this mesh
specs += ["em-galpha:dt=1e-5"]                         # the reference of the displacement errors
r = shelldyn.compare("flying-plate", specs, args.out, t_end=args.t_end, output_interval=0.01, jobs=args.jobs,
                     reference="em-galpha_dt=1e-05", progress=True)
print("%-22s %8s %10s %12s %12s" % ("run", "steps", "CPU [s]", "displ. err", "|H| / (K+V)"))
points = {}
for row in r.rows:
    assert row["status"] == "complete", row
    h = r.history(row["label"])
    balance = np.max(np.abs(h["total"])) / np.max(h["kinetic"] + h["strain"])
    s = r.run_json(row["label"])["summary"]  # as `shelldyn compare` wrote it
    print("%-22s %8d %10.3f %12.3g %12.3g" % (row["label"], s["steps"], s["cpu_s"], row["displacement_error"], balance))
    if row["label"] != r.reference:
        points.setdefault(row["integrator"], []).append((s["cpu_s"], row["displacement_error"]))

fig, ax = plt.subplots(figsize=(6, 4.5))
for name, pts in points.items():
    pts = np.array(sorted(pts))
    ax.loglog(pts[:, 0], pts[:, 1], "o-", label=name)
ax.set_xlabel("CPU time [s]")
ax.set_ylabel("max displacement error vs %s [m]" % r.reference)
ax.set_title("flying plate, t in [0, %g] s" % args.t_end)
ax.legend()
fig.tight_layout()
png = os.path.join(args.out, "work_precision_python.png")
fig.savefig(png, dpi=100)
print("wrote", png, "and", r.summary_md)
