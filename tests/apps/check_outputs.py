#!/usr/bin/python3
"""Checks what `shelldyn check` wrote (architecture.md §5) with independent readers.

usage: check_outputs.py RESULT_DIR NUM_POINTS NUM_CELLS

- fields/step_000000.vtu read by meshio: point and cell counts, one block of quad9 cells, raw VTK cell
  type 28 in the XML, point data displacement/velocity/director with 3 components, unit directors;
- fields.pvd: valid XML listing that VTU at time 0;
- run.json: valid JSON with status "checked" and matching node/element counts.
"""
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

import meshio


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def main():
    if len(sys.argv) != 4:
        fail("usage: check_outputs.py RESULT_DIR NUM_POINTS NUM_CELLS")
    out, npts, ncells = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    vtu = os.path.join(out, "fields", "step_000000.vtu")

    mesh = meshio.read(vtu)
    if mesh.points.shape != (npts, 3):
        fail(f"{vtu}: points {mesh.points.shape}, expected ({npts}, 3)")
    if len(mesh.cells) != 1 or mesh.cells[0].type != "quad9":
        fail(f"{vtu}: cell blocks {[(c.type, len(c.data)) for c in mesh.cells]}, expected one quad9 block")
    if mesh.cells[0].data.shape != (ncells, 9):
        fail(f"{vtu}: connectivity {mesh.cells[0].data.shape}, expected ({ncells}, 9)")
    if mesh.cells[0].data.min() < 0 or mesh.cells[0].data.max() >= npts:
        fail(f"{vtu}: connectivity out of range")
    for name in ("displacement", "velocity", "director"):
        if name not in mesh.point_data:
            fail(f"{vtu}: point data '{name}' missing")
        if mesh.point_data[name].shape != (npts, 3):
            fail(f"{vtu}: '{name}' has shape {mesh.point_data[name].shape}")
    for p in mesh.point_data["director"]:
        if abs(math.sqrt(sum(x * x for x in p)) - 1.0) > 1e-12:
            fail(f"{vtu}: director {p} is not a unit vector")

    # meshio maps several VTK types; check the raw type code too (28 = VTK_BIQUADRATIC_QUAD).
    root = ET.parse(vtu).getroot()
    types = [a for a in root.iter("DataArray") if a.get("Name") == "types"]
    if len(types) != 1 or [int(t) for t in types[0].text.split()] != [28] * ncells:
        fail(f"{vtu}: cell types are not all 28")

    # Every vector/tensor array names its components (ComponentName0.. attributes: ParaView's labels).
    for a in root.iter("DataArray"):
        n = int(a.get("NumberOfComponents", "1"))
        if a.get("Name") and n > 1:
            missing = [c for c in range(n) if not a.get(f"ComponentName{c}")]
            if missing:
                fail(f"{vtu}: DataArray '{a.get('Name')}' has no ComponentName{missing[0]}")

    pvd = ET.parse(os.path.join(out, "fields.pvd")).getroot()
    sets = pvd.findall("./Collection/DataSet")
    if len(sets) != 1 or float(sets[0].get("timestep")) != 0.0:
        fail("fields.pvd: expected one DataSet at time 0")
    if not os.path.isfile(os.path.join(out, sets[0].get("file"))):
        fail("fields.pvd: listed file does not exist: " + sets[0].get("file"))

    with open(os.path.join(out, "run.json"), encoding="utf-8") as f:
        info = json.load(f)
    if info.get("status") != "checked":
        fail(f"run.json: status {info.get('status')!r}, expected 'checked'")
    disc = info.get("discretization", {})
    if disc.get("nodes") != npts or disc.get("elements") != ncells:
        fail(f"run.json: discretization {disc}")
    if not info.get("versions", {}).get("shelldyn"):
        fail("run.json: versions.shelldyn missing")
    if not info.get("versions", {}).get("blas"):  # its kernels set the round-off (docs/dependencies.md §5.6)
        fail("run.json: versions.blas missing")
    print(f"OK: {out}: {npts} points, {ncells} quad9 cells (VTK 28), pvd and run.json valid")


if __name__ == "__main__":
    main()
