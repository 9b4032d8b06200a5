#!/usr/bin/python3
"""Checks scripts/newton_accuracy.py's equal-accuracy interpolation on made-up points (ctest newton_accuracy_interpolation).

em-galpha's runs enter the interpolation only if no other run has both fewer iterations and a smaller accepted
residual (front()); between two of them the iterations are linear in log10(residual) (interpolate()). Exits 1 with
the first failed check."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
import newton_accuracy as na  # noqa: E402


def check(ok, what):
    if not ok:
        print(f"check_newton_accuracy: FAILED: {what}")
        sys.exit(1)


# The cylindrical panel's shape: a tighter e_floor only adds iterations at the same residual -> dropped.
panel = [(5.41e-11, 3.132), (6.68e-11, 3.993), (6.28e-11, 4.058)]
check(na.front(panel) == [(5.41e-11, 3.132)], f"front(panel) = {na.front(panel)}")
check(na.interpolate(panel, 7.96e-11) is None, "a residual outside the front interpolates to None")
check(na.interpolate(panel, 5.41e-11) == 3.132, "a single-point front at exactly its residual")

# A monotone sweep: 1e-10 -> 4 it, 1e-8 -> 3 it; at 1e-9 (the geometric mean) 3.5.
sweep = [(1e-8, 3.0), (1e-9 * 3.0, 3.2), (1e-10, 4.0)]
check(len(na.front(sweep)) == 3, "no point of a monotone sweep is dominated")
v = na.interpolate([(1e-8, 3.0), (1e-10, 4.0)], 1e-9)
check(v is not None and abs(v - 3.5) < 1e-12, f"log-linear interpolation gives {v}, expected 3.5")
v = na.interpolate(sweep, 3e-9)
check(v is not None and abs(v - 3.2) < 1e-12, f"at a swept point the interpolation returns its value, got {v}")
check(na.interpolate(sweep, 1e-7) is None and na.interpolate(sweep, 1e-11) is None, "outside the sweep: None")

# em-exact's two runs of a case: its own settings, and em-galpha's stopping rule (certify=energy).
rows = [{"case": "c", "integrator": "em-exact", "setting": "default"},
        {"case": "c", "integrator": "em-exact", "setting": "predictor=newmark certify=energy"},
        {"case": "c", "integrator": "em-galpha", "setting": "certify=energy"}]
own, same = na.exact_runs(rows, "c")
check(own is rows[0] and same is rows[1], f"exact_runs picks {own}, {same}")
own, same = na.exact_runs(rows[:1], "c")
check(own is rows[0] and same is None, "without a same-rule run (an older CSV) the second is None")
print("check_newton_accuracy: 10 checks passed")
