#!/usr/bin/env python3
"""Tip deflection of the spin-up case (apps/cases/spin-up.yaml, docs/benchmarks.md "Spin-up") in the hub's rotating
frame, from history.csv (monitors ux_tip, uz_tip) and the prescribed angle θ(t) of the case's spin-up profile.

The hub turns about +Y through the root, so the rigid strip's axis is e1 = (cos θ, 0, −sin θ) and its normal
e3 = (sin θ, 0, cos θ). With p the tip's position relative to the root, the flapwise deflection is w = p · e3 and
the axial one u = p · e1 − L.

The rigid limit: the driver's work equals the kinetic energy of the rigid rotation, W = ½ I θ̇², with I the
inertia about the axis (default: the strip, m (L²/3 + h²/12) with m = 12 kg, h = 0.02 m, plus the hub's 0.01).

    python3 scripts/spin_up_tip.py RESULT_DIR [RESULT_DIR ...] [--ws 6] [--Ts 15] [--L 10] [--I 400.0104] [--every 1.0]
"""
import argparse
import csv
import math
import os


def theta(t, ws, Ts):
    # Kane, Ryan & Banerjee (1987); lib/model/time_function.hpp TimeFunction::spin_up.
    if t <= 0:
        return 0.0
    if t >= Ts:
        return ws * (t - Ts / 2)
    c = Ts / (2 * math.pi)
    return ws * (t * t / 2 + c * c * (math.cos(t / c) - 1)) / Ts


def theta_dot(t, ws, Ts):
    if t <= 0:
        return 0.0
    if t >= Ts:
        return ws
    c = Ts / (2 * math.pi)
    return ws * (t - c * math.sin(t / c)) / Ts


def tip(folder, ws, Ts, L):
    with open(os.path.join(folder, "history.csv")) as f:
        rows = list(csv.DictReader(f))
    out = []
    for r in rows:
        t = float(r["t"])
        th = theta(t, ws, Ts)
        px, pz = L + float(r["ux_tip"]), float(r["uz_tip"])
        w = px * math.sin(th) + pz * math.cos(th)
        u = px * math.cos(th) - pz * math.sin(th) - L
        out.append((t, w, u, r))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("folders", nargs="+")
    ap.add_argument("--ws", type=float, default=6.0)
    ap.add_argument("--Ts", type=float, default=15.0)
    ap.add_argument("--L", type=float, default=10.0)
    ap.add_argument("--I", type=float, default=12 * (100 / 3 + 0.02 ** 2 / 12) + 0.01)
    ap.add_argument("--every", type=float, default=1.0, help="print the history every this many seconds")
    a = ap.parse_args()
    runs = [tip(f, a.ws, a.Ts, a.L) for f in a.folders]
    print("| t | " + " | ".join(f"w_tip {os.path.basename(f.rstrip('/'))}" for f in a.folders) + " |")
    print("|---|" + "---|" * len(a.folders))
    for k, (t, _, _, _) in enumerate(runs[0]):
        if abs(t / a.every - round(t / a.every)) < 1e-9:
            cells = []
            for run in runs:
                m = [x for x in run if abs(x[0] - t) < 1e-9]
                cells.append(f"{m[0][1]:.6g}" if m else "–")
            print(f"| {t:g} | " + " | ".join(cells) + " |")
    print()
    print("| run | max \\|w_tip\\| (at t) | w_tip(t_end) | u_tip(t_end) | max \\|H − H₀\\| / max\\|W_presc\\| | W_presc(t_end) | W_presc / (½ I θ̇²) − 1 at t_end | max ‖g‖∞ | Newton its |")
    print("|---|---|---|---|---|---|---|---|---|")
    for f, run in zip(a.folders, runs):
        wmax = max(run, key=lambda x: abs(x[1]))
        h0 = float(run[0][3]["total"])
        W = [float(x[3]["prescribed_work"]) for x in run]
        dH = max(abs(float(x[3]["total"]) - h0) for x in run) / max(abs(w) for w in W)
        g = max(float(x[3]["g_norm"]) for x in run)
        its = run[-1][3].get("nonlinear_iters", "–")
        Kr = 0.5 * a.I * theta_dot(run[-1][0], a.ws, a.Ts) ** 2
        print(f"| {os.path.basename(f.rstrip('/'))} | {abs(wmax[1]):.4g} ({wmax[0]:g}) | {run[-1][1]:.4g} | {run[-1][2]:.3g} | "
              f"{dH:.2e} | {W[-1]:.6g} | {W[-1] / Kr - 1 if Kr else float('nan'):.2e} | {g:.1e} | {its} |")


if __name__ == "__main__":
    main()
