"""Example (c): natural frequencies from K and M with scipy.sparse.linalg.eigsh, checked against `shelldyn modes`.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/modal_analysis.py --cli build/bin/shelldyn --out results/python/modes
"""
import argparse
import csv
import os
import shutil
import subprocess

import numpy as np
import scipy.sparse.linalg as spla

import shelldyn

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--case", default="plate-modes-ss-thin")
ap.add_argument("-n", type=int, default=6, help="number of modes")
ap.add_argument("--cli", default=os.environ.get("SHELLDYN_CLI") or shutil.which("shelldyn"), help="the shelldyn executable")
ap.add_argument("--out", default="results/python/modes")
args = ap.parse_args()

case = shelldyn.load_case(args.case)
system = case.system()
s = system.initial_state()
_, _, K = system.internal(s.u, s.charts, force=False)  # tangent at the reference state = linear stiffness
M = system.mass(s.u, s.charts)
free = system.free_dofs  # Dirichlet DOFs removed: K_ff phi = omega^2 M_ff phi
Kf, Mf = K[free][:, free], M[free][:, free]
lam, phi = spla.eigsh(Kf.tocsc(), k=args.n, M=Mf.tocsc(), sigma=0.0, which="LM")
omega = np.sqrt(np.sort(lam))
print("%s: %d free DOFs; lowest %d angular frequencies from eigsh [rad/s]:" % (case.name, len(free), args.n))

os.makedirs(args.out, exist_ok=True)
subprocess.run([args.cli, "modes", case.path, "-n", str(args.n), "-o", args.out, "--overwrite", "--no-vtu"],
               check=True, stdout=subprocess.DEVNULL)
with open(os.path.join(args.out, "modes.csv")) as f:
    cli = np.array([float(r["omega_rad_s"]) for r in csv.DictReader(f)])
rel = np.abs(omega - cli) / cli
print(" mode   eigsh            shelldyn modes   rel. difference")
for k, (a, b, r) in enumerate(zip(omega, cli, rel), 1):
    print("%5d   %.10g   %.10g   %.1e" % (k, a, b, r))
print("max relative difference %.2e" % rel.max())
assert rel.max() < 1e-8, rel
