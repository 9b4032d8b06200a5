#!/usr/bin/env python3
"""Regenerates the README's headline tables and the docs' validation page from runs (docs/performance.md: make_performance.py).

    python3 scripts/make_results.py --full      # the paper's durations and time steps; rewrites README.md,
                                                # docs/validation.md, docs/img/headline-*.png (the runs'
                                                # cost tables: --out's integrator-costs.md)
    python3 scripts/make_results.py --short     # a few hundred steps per run (ctest make_results_short);
                                                # writes into --out (default build/make-results-short) only

Every table states the command that made it. The runs are `shelldyn compare` (em-galpha, em-exact, galpha,
midpoint at the case files' settings, two runs at a time), `shelldyn static` of the Sze benchmarks and
`shelldyn modes` of a simply supported plate. Each mode also checks what the tables claim (em-exact's energy
error after the loads, the static and modal errors against their references) and exits 1 naming the check
that failed, so the short mode is a test. Needs a built tree (--bin, default build/bin) and python3-matplotlib
for the figures.
"""

import argparse
import csv
import json
import math
import os
import platform
import re
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

INTEGRATORS = ["em-galpha", "em-exact", "galpha", "midpoint"]
# The full hemisphere runs only the two energy-momentum schemes: galpha and midpoint advanced several times
# more slowly than they do there (the short mode runs all four).
FULL_INTEGRATORS = {"pinched-hemisphere": ["em-galpha", "em-exact"]}

# Benchmark: title, and the short mode's overrides (the full mode runs the case file as it is).
BENCHMARKS = [
    ("flying-plate", "Flying L-shaped plate (FLP-prov), loads until 5 s", {"t_end": "5.25", "dt": "0.025"}),
    ("cylindrical-panel", "Free cylindrical panel (CYP-prov), loads until 0.02 s", {"t_end": "0.025", "dt": "1e-4"}),
    ("pinched-hemisphere", "Pinched hemisphere, ρ = 1000, loads until 0.03 s", {"t_end": "0.035", "dt": "5e-4"}),
]

# Static benchmarks (docs/benchmarks.md §4): case, what, monitors -> reference at the last load level.
STATICS = [
    ("sze-cantilever-shear", "Sze 3.1 cantilever, end shear, 8×1", [("−u_tip", "u_tip", -1.0, 3.2894, "elastica"),
                                                                    ("w_tip", "w_tip", 1.0, 6.6996, "elastica")]),
    ("sze-slit-annulus", "Sze 3.3 slit annulus, 5×40", [("w_A", "w_A", 1.0, 13.891, "S4R"), ("w_B", "w_B", 1.0, 17.528, "S4R")]),
    ("sze-hemisphere", "Sze 3.4 hemisphere, 8×8 quarter", [("outward", "outward", 1.0, 4.067, "S4R"),
                                                          ("inward", "inward_neg", -1.0, 8.178, "S4R")]),
]
SHORT_STATICS = ["sze-cantilever-shear"]
STATIC_TOLERANCE = 0.02  # relative error the check accepts (measured errors: docs/validation.md)

MODES_CASE = "plate-modes-ss-thin"
MODES_TOLERANCE = 0.01   # first eight bending frequencies against Kirchhoff


class CheckFailed(Exception):
    pass


def fmt(x, digits=2):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    return f"{x:.{digits}e}" if (x != 0 and (abs(x) < 1e-3 or abs(x) >= 1e4)) else f"{x:.{digits + 2}g}"


def run(cmd, log):
    """Runs cmd (a list), appends its output to log; raises CheckFailed with the tail on failure."""
    text = " ".join(cmd)
    t0 = time.time()
    p = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    with open(log, "a", encoding="utf-8") as f:
        f.write(f"$ {text}\n{p.stdout}\n")
    if p.returncode != 0:
        tail = "\n".join(p.stdout.strip().splitlines()[-5:])
        raise CheckFailed(f"command failed (exit {p.returncode}): {text}\n{tail}")
    return p.stdout, time.time() - t0


def display(cmd, binary_dir):
    """The command as a reader types it from the repository root."""
    out = []
    for c in cmd:
        if c.startswith(binary_dir + os.sep):
            c = "build/bin/" + os.path.relpath(c, binary_dir)
        elif c.startswith(ROOT + os.sep):
            c = os.path.relpath(c, ROOT)
        out.append(c)
    return " ".join(out)


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def num(row, key):
    try:
        return float(row.get(key, "nan"))
    except (TypeError, ValueError):
        return float("nan")


def find_number(obj, key):
    """First value of `key` anywhere in a JSON document (run.json's layout may grow)."""
    if isinstance(obj, dict):
        if key in obj and isinstance(obj[key], (int, float)):
            return float(obj[key])
        for v in obj.values():
            r = find_number(v, key)
            if r is not None:
                return r
    elif isinstance(obj, list):
        for v in obj:
            r = find_number(v, key)
            if r is not None:
                return r
    return None


def machine():
    model = ""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{model or platform.processor()}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"


def load_average():
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")


# --- dynamic benchmarks -----------------------------------------------------------------------------------
def compare_benchmark(args, name, short_overrides, out_dir, log):
    integrators = INTEGRATORS if args.short else FULL_INTEGRATORS.get(name, INTEGRATORS)
    cmd = [os.path.join(args.bin, "shelldyn"), "compare", name, "--integrators", ",".join(integrators),
           "-o", os.path.join(out_dir, "runs", name), "--jobs", "2"]
    if args.short:
        cmd += ["--t-end", short_overrides["t_end"], "--dt", short_overrides["dt"]]
        if name != "flying-plate":
            cmd.append("--no-plots")
    load_file = os.path.join(out_dir, "runs", name + "-load.json")
    if not args.report_only:
        if os.path.isdir(os.path.join(out_dir, "runs", name)):
            shutil.rmtree(os.path.join(out_dir, "runs", name))
        load0 = load_average()
        run(cmd, log)
        load1 = load_average()
        with open(load_file, "w", encoding="utf-8") as f:
            json.dump([load0, load1], f)
    with open(load_file, encoding="utf-8") as f:
        load0, load1 = json.load(f)
    rows = []
    for r in read_csv(os.path.join(out_dir, "runs", name, "summary.csv")):
        if not r.get("status", "").startswith("complete"):
            raise CheckFailed(f"{name}: run {r.get('label')} did not complete: {r.get('status')}")
        info_path = os.path.join(out_dir, "runs", name, r["label"], "run.json")
        cpu = None
        if os.path.isfile(info_path):
            with open(info_path, encoding="utf-8") as f:
                cpu = find_number(json.load(f), "cpu_s")
        steps = num(r, "steps")
        rows.append({
            "integrator": r["integrator"], "label": r["label"], "dt": num(r, "dt"), "t_end": num(r, "t_end"),
            "steps": steps, "iterations": num(r, "nonlinear_iterations") / steps if steps else float("nan"),
            "factorizations": num(r, "factorizations"),
            "energy": num(r, "energy_error"),
            "dL": num(r, "max_dL") / num(r, "norm_L_ref") if num(r, "norm_L_ref") > 1e-6 else float("nan"),
            "dL_abs": num(r, "max_dL"), "L": num(r, "norm_L_ref"),
            "dJ": num(r, "max_dJ") / num(r, "norm_J_ref") if num(r, "norm_J_ref") > 1e-6 else float("nan"),
            "dJ_abs": num(r, "max_dJ"), "J": num(r, "norm_J_ref"),
            "wall": num(r, "wall_s"), "cpu": cpu,
        })
    by = {r["integrator"]: r for r in rows}
    exact = by.get("em-exact")
    if exact is None or not (exact["energy"] < 1e-9):
        raise CheckFailed(f"{name}: em-exact's energy error after the loads is {exact and exact['energy']}, expected < 1e-9")
    for r in rows:
        if not math.isfinite(r["energy"]):
            raise CheckFailed(f"{name}: {r['label']} has no energy error after the loads (the run ends before they do?)")
    figure = os.path.join(out_dir, "runs", name, "energy.png")
    return {"name": name, "command": display(cmd, args.bin), "rows": rows, "figure": figure if os.path.isfile(figure) else None,
            "load": (load0, load1)}


def momentum_cell(rel, absval, ref):
    if math.isfinite(rel):
        return fmt(rel)
    return f"{fmt(absval)} absolute (‖·‖ ≈ 0)"


def headline_table(b):
    lines = ["| integrator | energy error after the loads | ‖ΔL‖/‖L‖ | ‖ΔJ‖/‖J‖ | Newton iterations / step |",
             "|---|---|---|---|---|"]
    for r in b["rows"]:
        lines.append(f"| `{r['integrator']}` | {fmt(r['energy'])} | {momentum_cell(r['dL'], r['dL_abs'], r['L'])} | "
                     f"{momentum_cell(r['dJ'], r['dJ_abs'], r['J'])} | {r['iterations']:.3f} |")
    return "\n".join(lines)


def performance_table(b):
    lines = ["| integrator | Δt | steps | iterations / step | factorizations | CPU s | CPU ms / step | CPU / em-galpha |",
             "|---|---|---|---|---|---|---|---|"]
    ref = next((r["cpu"] for r in b["rows"] if r["integrator"] == "em-galpha"), None)
    for r in b["rows"]:
        cpu = r["cpu"]
        per = 1e3 * cpu / r["steps"] if cpu and r["steps"] else None
        ratio = cpu / ref if cpu and ref else None
        lines.append(f"| `{r['integrator']}` | {fmt(r['dt'])} | {int(r['steps'])} | {r['iterations']:.3f} | "
                     f"{int(r['factorizations'])} | {fmt(cpu, 1) if cpu else 'n/a'} | {fmt(per, 2) if per else 'n/a'} | "
                     f"{f'{ratio:.2f}' if ratio else 'n/a'} |")
    return "\n".join(lines)


# --- statics and modes ------------------------------------------------------------------------------------
def static_validation(args, out_dir, log):
    results = []
    for case, title, checks in STATICS:
        if args.short and case not in SHORT_STATICS:
            continue
        cmd = [os.path.join(args.bin, "shelldyn"), "static", os.path.join(ROOT, "apps", "cases", case + ".yaml"),
               "-o", os.path.join(out_dir, "static", case), "--overwrite"]
        _, wall = run(cmd, log)
        rows = read_csv(os.path.join(out_dir, "static", case, "static.csv"))
        last = rows[-1]
        cells = []
        for label, column, sign, ref, source in checks:
            if column not in last:
                raise CheckFailed(f"{case}: static.csv has no column {column}")
            value = sign * float(last[column])
            err = value / ref - 1.0
            if abs(err) > STATIC_TOLERANCE:
                raise CheckFailed(f"{case}: {label} = {value:.5g}, {100 * err:+.2f} % from {source} {ref}; "
                                  f"the check allows {100 * STATIC_TOLERANCE:.0f} %")
            cells.append((label, value, ref, source, err))
        results.append({"case": case, "title": title, "command": display(cmd, args.bin), "cells": cells})
    return results


def kirchhoff_frequencies(case_path, count):
    import yaml  # python3-yaml
    with open(case_path, encoding="utf-8") as f:
        c = yaml.safe_load(f)
    a, b = float(c["mesh"]["a"]), float(c["mesh"]["b"])
    m = c["material"]
    E, nu, rho, h = float(m["E"]), float(m["nu"]), float(m["rho"]), float(m["thickness"])
    D = E * h ** 3 / (12 * (1 - nu ** 2))
    # Simply supported rectangle: ω_mn = π² (m²/a² + n²/b²) √(D / (ρ h)).
    w = sorted(math.pi ** 2 * ((i / a) ** 2 + (j / b) ** 2) * math.sqrt(D / (rho * h))
               for i in range(1, 8) for j in range(1, 8))
    return [x / (2 * math.pi) for x in w[:count]]


def modal_validation(args, out_dir, log):
    count = 8
    case_path = os.path.join(ROOT, "apps", "cases", MODES_CASE + ".yaml")
    cmd = [os.path.join(args.bin, "shelldyn"), "modes", case_path, "-n", str(count), "-o",
           os.path.join(out_dir, "modes"), "--overwrite"]
    run(cmd, log)
    rows = [r for r in read_csv(os.path.join(out_dir, "modes", "modes.csv")) if r.get("rigid", "0") in ("0", "false")]
    computed = [float(r["frequency_hz"]) for r in rows][:count]
    ref = kirchhoff_frequencies(case_path, count)
    errs = [c / r - 1.0 for c, r in zip(computed, ref)]
    if len(computed) < count or max(abs(e) for e in errs) > MODES_TOLERANCE:
        raise CheckFailed(f"{MODES_CASE}: frequencies {computed} against Kirchhoff {ref}: largest error "
                          f"{100 * max(abs(e) for e in errs):.2f} %, the check allows {100 * MODES_TOLERANCE:.0f} %")
    return {"command": display(cmd, args.bin), "computed": computed, "reference": ref, "errors": errs}


# --- pages ------------------------------------------------------------------------------------------------
GENERATED = ("<!-- Generated by scripts/make_results.py {mode}; do not edit by hand: rerun it "
             "(python3 scripts/make_results.py --full). -->")


def validation_page(mode, dyn, statics, modes, env):
    out = [GENERATED.format(mode=mode), "", "# Validation", "",
           "What the tables below claim is also checked by the script that made them "
           "(`python3 scripts/make_results.py --full`; its `--short` mode, with shortened runs, is the ctest "
           "`make_results_short`). Element-level checks (patch tests, tangents against finite differences, "
           "rigid-body invariance) are unit tests; see [Testing](testing.md) and docs/theory.md §7.", "",
           f"Machine: {env['machine']}; shelldyn {env['version']}.", "",
           "## Conservation after the loads end", "",
           "Energy error = max over the output times after the loads end of |H − H_ref| / (K + V)_ref, "
           "H = K + V − W_ext, ref = the first output at or after the loads' end (docs/manual.md §4). "
           "‖ΔL‖, ‖ΔJ‖: largest change of linear and angular momentum after the loads, relative to their norm "
           "(absolute where the norm is ≈ 0: the hemisphere's loads are self-equilibrated).", ""]
    for b, (_, title, _) in zip(dyn, BENCHMARKS):
        out += [f"### {title}", "", f"    {b['command']}", "", headline_table(b), ""]
    if statics:
        out += ["## Nonlinear statics (Sze, Liu & Lo 2004)", "",
                "Values at the last load level (P_max) against the references of docs/benchmarks.md §4.", "",
                "| benchmark | quantity | shelldyn | reference | error |", "|---|---|---|---|---|"]
        for s in statics:
            for label, value, ref, source, err in s["cells"]:
                out.append(f"| {s['title']} | {label} | {value:.5g} | {ref} ({source}) | {100 * err:+.2f} % |")
        out += ["", "Commands:", ""] + [f"    {s['command']}" for s in statics] + [""]
    if modes:
        out += ["## Natural frequencies", "",
                "Simply supported square plate, t/L = 0.005, 8 × 8 elements, against Kirchhoff's "
                "f_mn = (π/2)(m²/a² + n²/b²)√(D/(ρh)):", "", f"    {modes['command']}", "",
                "| mode | shelldyn [Hz] | Kirchhoff [Hz] | error |", "|---|---|---|---|"]
        for k, (c, r, e) in enumerate(zip(modes["computed"], modes["reference"], modes["errors"]), 1):
            out.append(f"| {k} | {c:.5g} | {r:.5g} | {100 * e:+.3f} % |")
        out.append("")
    return "\n".join(out)


def performance_page(mode, dyn, env):
    out = [GENERATED.format(mode=mode), "", "# Performance", "",
           "Cost of the runs of the [validation page](validation.md): CPU seconds of each run (`cpu_s` of its "
           "run.json; one OpenMP thread per run, two runs at a time). CPU seconds vary with the "
           "machine and its load; ratios between runs of one table, and iteration counts, are the robust part.", "",
           f"Machine: {env['machine']}; shelldyn {env['version']}.", ""]
    for b, (_, title, _) in zip(dyn, BENCHMARKS):
        out += [f"## {title}", "", f"    {b['command']}", "",
                f"Load average {b['load'][0]:.1f} before, {b['load'][1]:.1f} after the runs.", "",
                performance_table(b), ""]
    return "\n".join(out)


def replace_block(text, key, body):
    begin, end = f"<!-- make_results:{key} -->", f"<!-- /make_results:{key} -->"
    pat = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    if not pat.search(text):
        raise CheckFailed(f"README.md has no block {begin} ... {end}")
    return pat.sub(lambda _: f"{begin}\n{body}\n{end}", text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--short", action="store_true", help="shortened runs; write into --out only (the ctest)")
    g.add_argument("--full", action="store_true", help="full runs; rewrite README.md, docs/validation.md")
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"), help="folder of the built shelldyn (default build/bin)")
    ap.add_argument("--report-only", action="store_true",
                    help="run no comparison; make the pages from the run folders an earlier run of this mode left in --out")
    ap.add_argument("--out", help="folder for runs and pages (default build/make-results-short or build/make-results-full)")
    args = ap.parse_args()
    args.bin = os.path.abspath(args.bin)
    mode = "--short" if args.short else "--full"
    out_dir = os.path.abspath(args.out or os.path.join(ROOT, "build", "make-results-" + mode[2:]))
    os.makedirs(out_dir, exist_ok=True)
    log = os.path.join(out_dir, "commands.log")
    open(log, "a" if args.report_only else "w").close()
    try:
        version = run([os.path.join(args.bin, "shelldyn"), "--version"], log)[0].splitlines()[0]
        env = {"machine": machine(), "version": version.replace("shelldyn ", "", 1)}
        t0 = time.time()
        dyn = [compare_benchmark(args, name, short, out_dir, log) for name, _, short in BENCHMARKS]
        statics = static_validation(args, out_dir, log)
        modes = modal_validation(args, out_dir, log)
    except CheckFailed as e:
        print(f"make_results: FAILED: {e}\n(all output: {log})", file=sys.stderr)
        return 1
    pages = {"validation.md": validation_page(mode, dyn, statics, modes, env),
             "integrator-costs.md": performance_page(mode, dyn, env)}
    if args.full:
        # docs/performance.md is scripts/make_performance.py's page; the cost tables of these runs stay in --out.
        with open(os.path.join(ROOT, "docs", "validation.md"), "w", encoding="utf-8") as f:
            f.write(pages["validation.md"])
        with open(os.path.join(out_dir, "integrator-costs.md"), "w", encoding="utf-8") as f:
            f.write(pages["integrator-costs.md"])
        readme = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
        for b in dyn:
            body = f"{headline_table(b)}\n\n<sub>`{b['command']}`</sub>"
            readme = replace_block(readme, b["name"], body)
            if b["figure"]:
                shutil.copy(b["figure"], os.path.join(ROOT, "docs", "img", f"headline-{b['name']}-energy.png"))
        with open(os.path.join(ROOT, "README.md"), "w", encoding="utf-8") as f:
            f.write(readme)
        written = f"README.md, docs/validation.md, docs/img/headline-*.png, {out_dir}/integrator-costs.md"
    else:
        for name, text in pages.items():
            with open(os.path.join(out_dir, name), "w", encoding="utf-8") as f:
                f.write(text)
        with open(os.path.join(out_dir, "README-headline.md"), "w", encoding="utf-8") as f:
            f.write("\n\n".join(headline_table(b) for b in dyn) + "\n")
        written = out_dir
    runs = sum(len(b["rows"]) for b in dyn) + len(statics) + 1
    print(f"make_results {mode}: {runs} runs checked in {time.time() - t0:.0f} s wall; wrote {written}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
