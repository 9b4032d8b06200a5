#!/usr/bin/python3
"""Starting from a VTU a run wrote (docs/manual.md §1 `--state FILE.vtu`, §2.6 `initial_velocity`/`initial_displacement: {field: FILE.vtu}`).

usage: check_state_vtu.py SHELLDYN CASES_DIR WORK_DIR

1. static: the Sze cantilever solved to load factor 0.5 (fields/step_000010.vtu), then `static --state` that
   VTU to 1 ends where the solve from 0 ends (tip u, w to 1e-9 relative) and starts at load factor 0.5;
   `modes --state` the VTU gives the frequencies of `modes --state static:0.5` (1e-8 relative).
2. dynamics: a free plate flying and tumbling (rigid initial velocity, director rates non-zero) for 20 steps;
   a second case whose initial velocity is the first run's step_000000.vtu has the same history (every energy,
   momentum and monitor column to 1e-12 of the column's scale).
3. a clamped strip set moving: the run restarted from its VTU at t = 0.1 (initial_displacement and
   initial_velocity from the same file) starts with the K, V, L, J of the first run at t = 0.1 (1e-10).
"""
import csv
import os
import shutil
import subprocess
import sys


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run(args, expect=0):
    p = subprocess.run(args, capture_output=True, text=True)
    if p.returncode != expect:
        fail(f"{' '.join(args)} exited {p.returncode}, expected {expect}\nstdout:\n{p.stdout}\nstderr:\n{p.stderr}")
    return p.stdout


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def modes_table(path):
    return [float(r["omega_rad_s"]) for r in rows(path)]


def main():
    exe, cases, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)

    # --- 1. static and modes from a VTU -------------------------------------------------------------
    full_case = os.path.join(cases, "sze-cantilever-shear.yaml")
    half_case = os.path.join(work, "half.yaml")
    text = open(full_case).read()
    if "t_end: 1.0}" not in text:
        fail("sze-cantilever-shear.yaml changed: expected 't_end: 1.0}'")
    open(half_case, "w").write(text.replace("t_end: 1.0}", "t_end: 0.5}"))
    half, full, cont = (os.path.join(work, d) for d in ("half", "full", "cont"))
    run([exe, "static", half_case, "-o", half])
    run([exe, "static", full_case, "-o", full])
    vtu = os.path.join(half, "fields", "step_000010.vtu")
    out = run([exe, "static", full_case, "-o", cont, "--state", vtu])
    if "at load factor 0.5\n" not in out:
        fail("static --state VTU did not start at load factor 0.5:\n" + out)
    a, b = rows(os.path.join(full, "static.csv"))[-1], rows(os.path.join(cont, "static.csv"))[-1]
    first = rows(os.path.join(cont, "static.csv"))[0]
    if float(first["load_factor"]) != 0.5:
        fail(f"static.csv of the continuation starts at {first['load_factor']}, not 0.5")
    for key in ("load_factor", "u_tip", "w_tip"):
        x, y = float(a[key]), float(b[key])
        if abs(x - y) > 1e-9 * abs(x):
            fail(f"{key}: from 0: {x!r}, from the VTU at 0.5: {y!r}")
        print(f"{key}: from 0 {x!r}, from the VTU {y!r}")
    m_vtu, m_static = os.path.join(work, "modes_vtu"), os.path.join(work, "modes_static")
    run([exe, "modes", full_case, "-n", "4", "--no-vtu", "--state", vtu, "-o", m_vtu])
    run([exe, "modes", full_case, "-n", "4", "--no-vtu", "--state", "static:0.5", "-o", m_static])
    wa, wb = modes_table(os.path.join(m_static, "modes.csv")), modes_table(os.path.join(m_vtu, "modes.csv"))
    if len(wa) != 4 or len(wb) != 4:
        fail(f"expected 4 modes, got {wa} and {wb}")
    for k, (x, y) in enumerate(zip(wa, wb)):
        if abs(x - y) > 1e-8 * abs(x):
            fail(f"mode {k + 1}: static:0.5 {x!r} rad/s, from the VTU {y!r}")
    print("modes about static:0.5 and about the VTU:", wa, wb)

    # --- 2. an initial velocity field from a VTU --------------------------------------------------
    plate = """name: tumbling
mesh: {generator: rectangle, a: 2, b: 1, nx: 2, ny: 2}
material: {E: 1.0e5, nu: 0.3, rho: 10, thickness: 0.05}
integrator: {name: em-galpha}
time: {dt: 0.01, t_end: 0.2, output_interval: 0.01}
output: {vtu_every: 1000}
monitors:
  - {name: uz_max, set: all, quantity: uz, reduce: max}
  - {name: pz_min, set: all, quantity: pz, reduce: min}
"""
    case_a = os.path.join(work, "tumbling_a.yaml")
    open(case_a, "w").write(plate + "initial_velocity: {translation: [0.1, 0, 0.3], angular: [0.4, 1.0, 0.2]}\n")
    run_a = os.path.join(work, "tumbling_a")
    run([exe, "run", case_a, "-q", "-o", run_a])
    step0 = os.path.abspath(os.path.join(run_a, "fields", "step_000000.vtu"))
    case_b = os.path.join(work, "tumbling_b.yaml")
    open(case_b, "w").write(plate.replace("name: tumbling", "name: tumbling-b") + f"initial_velocity: {{field: {step0}}}\n")
    run_b = os.path.join(work, "tumbling_b")
    run([exe, "run", case_b, "-q", "-o", run_b])
    ha, hb = rows(os.path.join(run_a, "history.csv")), rows(os.path.join(run_b, "history.csv"))
    if len(ha) != 21 or len(hb) != len(ha):
        fail(f"history rows: {len(ha)} and {len(hb)}, expected 21")
    for key in ("kinetic", "strain", "total", "Lx", "Ly", "Lz", "Jx", "Jy", "Jz", "uz_max", "pz_min"):
        scale = max(abs(float(r[key])) for r in ha)
        if key == "kinetic" and not scale > 0.05:
            fail(f"the tumbling plate should move: max kinetic {scale}")
        for ra, rb in zip(ha, hb):
            if abs(float(ra[key]) - float(rb[key])) > 1e-12 * max(scale, 1e-300):
                fail(f"{key} at t = {ra['t']}: {ra[key]} (rigid initial velocity) vs {rb[key]} (from the VTU)")
    print(f"history of the tumbling plate reproduced from its VTU: {len(ha)} rows, K(0) = {ha[0]['kinetic']}, "
          f"J(end) = ({hb[-1]['Jx']}, {hb[-1]['Jy']}, {hb[-1]['Jz']})")

    # --- 3. a deformed, moving state: initial_displacement + initial_velocity from one VTU ----------------
    strip = """name: strip
mesh: {generator: rectangle, a: 2, b: 0.5, nx: 4, ny: 1}
material: {E: 1.0e5, nu: 0.3, rho: 10, thickness: 0.05}
boundary_conditions: [{set: left, fix: [ux, uy, uz, director]}]
integrator: {name: em-galpha}
time: {dt: 0.01, t_end: 0.2, output_interval: 0.01}
output: {vtu_every: 1}
"""
    case_c = os.path.join(work, "strip_c.yaml")
    open(case_c, "w").write(strip + "initial_velocity: {set: right, translation: [0, 0, 2]}\n")
    run_c = os.path.join(work, "strip_c")
    run([exe, "run", case_c, "-q", "-o", run_c])
    mid = os.path.abspath(os.path.join(run_c, "fields", "step_000010.vtu"))
    case_d = os.path.join(work, "strip_d.yaml")
    open(case_d, "w").write(strip.replace("name: strip", "name: strip-d").replace("t_end: 0.2", "t_end: 0.1")
                            + f"initial_displacement: {{field: {mid}}}\ninitial_velocity: {{field: {mid}}}\n")
    run_d = os.path.join(work, "strip_d")
    run([exe, "run", case_d, "-q", "-o", run_d])
    hc, hd = rows(os.path.join(run_c, "history.csv")), rows(os.path.join(run_d, "history.csv"))
    at = [r for r in hc if abs(float(r["t"]) - 0.1) < 1e-9]
    if len(at) != 1:
        fail("no row at t = 0.1 in the first strip run")
    for key in ("kinetic", "strain", "Lx", "Ly", "Lz", "Jx", "Jy", "Jz"):
        scale = max(abs(float(r[key])) for r in hc)
        x, y = float(at[0][key]), float(hd[0][key])
        if abs(x - y) > 1e-10 * max(scale, 1e-300):
            fail(f"{key}: the run at t = 0.1: {x!r}; the run started from its VTU, t = 0: {y!r}")
    if not float(at[0]["strain"]) > 0.01 * float(hc[0]["kinetic"]):
        fail("the strip should be deformed at t = 0.1")
    dk = abs(float(hc[-1]["strain"]) - float(hd[-1]["strain"])) / max(float(r["strain"]) for r in hc)
    print(f"strip restarted from its t = 0.1 VTU: K, V, L, J at t = 0.1 reproduced (K {hd[0]['kinetic']}, "
          f"V {hd[0]['strain']}); V at t = 0.2 differs by {dk:.2e} of max V (the integrator restarts its acceleration)")
    print("PASS")


if __name__ == "__main__":
    main()
