#!/usr/bin/env python3
"""Period of the plate-hinge case (apps/cases/plate-hinge.yaml) from the downward zero crossings of the tip's uz
monitor, against the compound pendulum's closed form T = 4 K(sin(θ0/2)) sqrt(I_p/(m g l)) (docs/theory/multibody.md
(6.1)), θ0 from the initial angular velocity: ½ I_p θ̇0² = m g l (1 − cos θ0).

    python3 scripts/hinge_period.py RESULT_DIR [RESULT_DIR ...]
"""
import csv
import math
import os
import sys

a, h, rho, g, w0 = 0.3, 0.01, 7810.0, 9.81, 2.0   # the case's plate, gravity and θ̇(0)
m_hub, J_hub = 0.01, 1.0e-6                       # the hub: on the axis, adds only its inertia
m = a * a * h * rho
Ip = m * (a * a / 3 + h * h / 12) + J_hub   # about the edge, the thickness included (the directors carry it)
mgl = m * g * a / 2
th0 = math.acos(1 - 0.5 * Ip * w0 * w0 / mgl)


def agm(x, y):
    for _ in range(60):
        x, y = (x + y) / 2, math.sqrt(x * y)
    return x


k = math.sin(th0 / 2)
T = 4 * math.pi / (2 * agm(1.0, math.sqrt(1 - k * k))) * math.sqrt(Ip / mgl)
print(f"closed form: theta0 = {th0:.6f} rad, T = {T:.9f} s")
for folder in sys.argv[1:]:
    with open(os.path.join(folder, "history.csv")) as f:
        r = list(csv.DictReader(f))
    t = [float(x["t"]) for x in r]
    z = [float(x["uz_tip"]) for x in r]
    # uz starts at 0 going up: the first downward crossing after a full swing is at T.
    cross = [t[i - 1] + (t[i] - t[i - 1]) * z[i - 1] / (z[i - 1] - z[i]) for i in range(1, len(z)) if z[i - 1] > 0 >= z[i]]
    gmax = max(float(x["g_norm"]) for x in r)
    h0 = float(r[0]["total"])
    dH = max(abs(float(x["total"]) - h0) for x in r) / float(r[0]["kinetic"])
    if cross:
        print(f"{folder}: T = {cross[0]:.9f} s, relative error {abs(cross[0] / T - 1):.3e}; max |dH|/K0 {dH:.2e}; max|g| {gmax:.1e}")
    else:
        print(f"{folder}: no full swing in the run")
