"""Example (a): load the flying plate, print its energies, run em-galpha briefly, plot the energy history.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/flying_plate_energy.py --out results/python/energy
"""
import argparse
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import shelldyn  # noqa: E402

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--out", default="results/python/flying-plate-energy", help="result folder")
ap.add_argument("--t-end", type=float, default=1.0, help="end time of the run [s]")
args = ap.parse_args()

case = shelldyn.load_case("flying-plate")
system = case.system()
s = system.initial_state()
inv = system.invariants(s)
print("%s: %d nodes, %d DOFs, mass %.3g kg, loads end at t = %g s" % (
    case.name, system.num_nodes, system.num_dofs, case.check()["total_mass"], system.loads_end))
print("t = 0: kinetic %.3g, strain %.3g (at rest, undeformed)" % (inv["kinetic"], inv["strain"]))

run = shelldyn.run(case, "em-galpha", t_end=args.t_end, out_dir=args.out, overwrite=True, vtu_every=0)
h = run.history
print("em-galpha to t = %g s: %d steps, %s, CPU %.2f s" % (
    args.t_end, run.summary["steps"], run.status, run.summary["cpu_s"]))
print("t = %g: kinetic %.6g, strain %.6g, external work %.6g, H = K + V - W_ext = %.3g" % (
    h["t"][-1], h["kinetic"][-1], h["strain"][-1], h["external_work"][-1], h["total"][-1]))
balance = np.max(np.abs(h["total"])) / np.max(h["kinetic"] + h["strain"])
print("energy balance max |H| / max (K + V) = %.3g" % balance)
assert run.status == "complete" and balance < 1e-6, balance

fig, ax = plt.subplots(figsize=(6, 4))
for col, label in (("kinetic", "K"), ("strain", "V"), ("external_work", "W_ext"), ("total", "H = K + V - W_ext")):
    ax.plot(h["t"], h[col], label=label)
ax.set_xlabel("t [s]")
ax.set_ylabel("energy [J]")
ax.set_title("flying plate (FLP-prov), em-galpha, dt = %g" % case.dt)
ax.legend()
fig.tight_layout()
png = os.path.join(args.out, "energy_python.png")
fig.savefig(png, dpi=100)
print("wrote", png)
