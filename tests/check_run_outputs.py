#!/usr/bin/env python3
"""Checks the result folder of `shelldyn run`: run.json complete, history.csv consistent, PVD/VTU present.

usage: check_run_outputs.py DIR T_END [ENERGY_TOL]

ENERGY_TOL (default 1e-6) bounds |H| / (K + V) for a body started at rest, H = K + V - W_ext: em-galpha
keeps that balance to its time-discretization error; adaptive SUNDIALS schemes only to their accumulated
local error (pass a looser bound for them).
"""
import csv
import json
import math
import os
import sys
import xml.etree.ElementTree as ET


def fail(msg):
    print("check_run_outputs: " + msg)
    sys.exit(1)


def main():
    d, t_end = sys.argv[1], float(sys.argv[2])
    energy_tol = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-6
    info = json.load(open(os.path.join(d, "run.json")))
    if info.get("status") != "complete":
        fail("run.json status is %r" % info.get("status"))
    rows = list(csv.DictReader(open(os.path.join(d, "history.csv"))))
    required = "step,t,dt,kinetic,strain,external_work,total,rel_drift,Lx,Ly,Lz,Jx,Jy,Jz,nonlinear_iters,linear_setups,wall_s"
    for col in required.split(","):
        if col not in rows[0]:
            fail("history.csv lacks column " + col)
    if abs(float(rows[-1]["t"]) - t_end) > 1e-12:
        fail("last row at t = %s, expected %g" % (rows[-1]["t"], t_end))
    times = [float(r["t"]) for r in rows]
    if any(b <= a for a, b in zip(times, times[1:])):
        fail("times not increasing")
    # Energy balance of the scheme: H = K + V - W_ext stays ~0 for a body starting at rest (paper §3).
    for r in rows:
        if not math.isfinite(float(r["rel_drift"])):  # defined while loads act too (docs/manual.md §4)
            fail("rel_drift = %s at t = %s" % (r["rel_drift"], r["t"]))
        kv = float(r["kinetic"]) + float(r["strain"])
        if not math.isfinite(kv) or abs(float(r["total"])) > energy_tol * max(kv, 1e-300) + 1e-14:
            fail("energy balance violated at t = %s: total %s, K+V %g" % (r["t"], r["total"], kv))
    root = ET.parse(os.path.join(d, "fields.pvd")).getroot()
    files = [ds.get("file") for ds in root.iter("DataSet")]
    if not files or not all(os.path.exists(os.path.join(d, f)) for f in files):
        fail("fields.pvd lists missing files")
    # The VTU carries reactions (point data) and stress resultants (cell data) (docs/manual.md §4).
    names = {a.get("Name") for a in ET.parse(os.path.join(d, files[-1])).getroot().iter("DataArray")}
    for want in ("reaction", "membrane_force", "bending_moment", "shear_force", "membrane_strain", "curvature",
                 "shear_strain", "strain_energy_density"):
        if want not in names:
            fail("%s lacks the field %s" % (files[-1], want))
    print("ok: %d history rows, %d VTU files, final H = %s" % (len(rows), len(files), rows[-1]["total"]))


main()
