#!/usr/bin/python3
"""Newton iterations per step of em-exact and em-galpha at equal accuracy, on the benchmark cases.

usage: newton_accuracy.py [--build DIR | --bench PATH] [--out DIR] [--reuse] [--cases NAME ...] [--steps N] [--jobs K]
                          [--e-floors LIST] [--exact-set key=value ...]

Issue 9 asks em-exact's Newton iteration for no more iterations per step than em-galpha's. The two schemes stop
at different accuracies: em-exact iterates to the residual's round-off floor (its exact balances hold to the
residual), em-galpha stops on its energy test (e_floor). This script measures the comparison at equal accuracy
(docs/theory/exact-energy-momentum.md §5.9). For every case it runs, with bench_step_breakdown --residual-trace:

  em-exact with the case's settings (modified Newton, `certify = predicted`),
  em-exact stopped by em-galpha's own rule (`certify = energy`, theory §5.10), and
  em-galpha with its defaults and with tighter energy tests (--e-floors, default 1e-21,1e-22,1e-23,1e-24),

and reads the scaled residual of the accepted iterate of every step from the traces (estimated as
rho_{k-1}^2/rho_{k-2} when the last correction was accepted unevaluated, as bench_step_breakdown does). em-galpha's
iterations per step are then interpolated, linearly in log10(residual), at em-exact's median and 90th-percentile
accepted residual, along the runs that no other em-galpha run beats in both iterations and residual (a tighter
e_floor that only adds iterations at the round-off floor drops out): the ratio of em-exact's iterations to that
value is the comparison at equal accuracy. Where em-exact's residual lies outside that range, the table says so.
The ratio at the schemes' defaults is printed beside it, and so is the ratio when both schemes stop by the same
rule (em-exact with `certify = energy` against em-galpha's default), which compares the Newton iterations alone.

Writes into --out (default results/newton-accuracy): newton-accuracy.csv (one row per run), newton-accuracy.md
(the tables), newton-accuracy.png (iterations per step against the accepted residual, one panel per case; needs
matplotlib) and traces/ (the per-step residual traces). Runs --jobs at a time (default 2), one thread each. The
full runs (21) took about 8 minutes of wall time on this project's 2-core machine (2026-11-30); --steps N runs the
first N steps of every case instead of the whole duration.
"""
import argparse
import concurrent.futures
import csv
import math
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CASES = ["flying-plate", "cylindrical-panel", "pinched-hemisphere"]


def fail(msg, code=2):
    print(f"newton_accuracy.py: {msg}", file=sys.stderr)
    sys.exit(code)


def quantile(sorted_values, q):
    """The same order statistic as bench_step_breakdown: element floor(n*q) of the sorted values."""
    return sorted_values[min(len(sorted_values) - 1, int(len(sorted_values) * q))]


def full_steps(bench, case):
    """The case's number of steps, t_end/dt, as bench_step_breakdown extrapolates it."""
    out = subprocess.run([bench, case, "--steps", "1", "--threads", "1"], capture_output=True, text=True)
    m = re.search(r"extrapolated to (\d+) steps", out.stdout)
    if out.returncode != 0 or not m:
        fail(f"could not read the duration of {case}: {out.stderr.strip() or out.stdout[-300:]}")
    return int(m.group(1))


def run(bench, case_name, steps, integrator, sets, trace):
    case = os.path.join(ROOT, "apps", "cases", case_name + ".yaml")
    cmd = [bench, case, "--steps", str(steps), "--threads", "1", "--integrator", integrator, "--residual-trace", trace]
    for kv in sets:
        cmd += ["--set", kv]
    t0 = time.time()
    out = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, OMP_NUM_THREADS="1"))
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited with {out.returncode}: {out.stderr.strip()[-500:]}")
    m = re.search(r"per step: ([0-9.]+) Newton iterations, ([0-9.]+) factorizations, ([0-9.]+) residual evaluations",
                  out.stdout)
    cpu = re.search(r"window: ([0-9.]+) s CPU", out.stdout)
    if not m or not cpu:
        raise RuntimeError(f"unexpected output of {' '.join(cmd)}:\n{out.stdout[-500:]}")
    accepted, counts = [], {}
    with open(trace) as f:
        for row in csv.DictReader(f):
            accepted.append(float(row["rho_accepted"]))
            it = int(row["iterations"])
            counts[it] = counts.get(it, 0) + 1
    if len(accepted) != steps:
        raise RuntimeError(f"{trace}: {len(accepted)} traced steps, expected {steps}")
    traced = sum(k * v for k, v in counts.items()) / steps  # exact; the report rounds to three decimals
    if abs(traced - float(m.group(1))) > 1.5e-3:  # the report prints three decimals
        raise RuntimeError(f"{trace}: {traced:.4f} iterations per step in the trace, {m.group(1)} in the step report")
    accepted.sort()
    return {
        "case": case_name, "integrator": integrator, "setting": " ".join(sets) or "default", "steps": steps,
        "iterations": traced, "factorizations": float(m.group(2)), "residuals": float(m.group(3)),
        "rho_median": quantile(accepted, 0.5), "rho_p90": quantile(accepted, 0.9), "cpu_s": float(cpu.group(1)),
        "steps_by_iterations": " ".join(f"{k}:{counts[k]}" for k in sorted(counts)), "wall_s": time.time() - t0,
    }


def front(points):
    """em-galpha's (residual, iterations) points that no other point beats in both (the Pareto front), by residual.
    A tighter e_floor that only adds iterations at the round-off floor (the cylindrical panel) drops out."""
    return sorted(p for p in points
                  if not any(q[0] <= p[0] and q[1] <= p[1] and q != p for q in points))


def interpolate(points, rho):
    """em-galpha's iterations per step at accepted residual rho, linear in log10(rho) between the two points of
    the front that bracket it; None outside the front's range."""
    pts = front(points)
    if len(pts) == 1 and pts[0][0] == rho:
        return pts[0][1]
    for (r0, i0), (r1, i1) in zip(pts, pts[1:]):
        if r0 <= rho <= r1:
            w = (math.log10(rho) - math.log10(r0)) / (math.log10(r1) - math.log10(r0))
            return i0 + w * (i1 - i0)
    return None


SAME_RULE = "certify=energy"  # em-exact stopped by em-galpha's modified-Newton rule (theory §5.10)


def exact_runs(rows, case):
    """(em-exact's run with the case's settings, its run with em-galpha's stopping rule) of a case. The second is
    the run whose setting names certify=energy; either is None if absent (an older CSV has no same-rule run). If
    --exact-set itself asked for certify=energy, that one run is both."""
    ex = [r for r in rows if r["case"] == case and r["integrator"] == "em-exact"]
    same = next((r for r in ex if SAME_RULE in r["setting"].split()), None)
    own = next((r for r in ex if r is not same), same)
    return own, same


def tables(rows, cases):
    lines = ["| case | integrator | setting | steps | it/step | factorizations/step | accepted residual median / p90 "
             "| steps by iterations | CPU s |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['integrator']} | {r['setting']} | {r['steps']} | {r['iterations']:.3f} | "
                     f"{r['factorizations']:.3f} | {r['rho_median']:.2e} / {r['rho_p90']:.2e} | "
                     f"{r['steps_by_iterations']} | {r['cpu_s']:.1f} |")
    lines += ["", "| case | em-exact it/step | em-galpha default it/step | ratio at the defaults | em-galpha interpolated "
              "at em-exact's median / p90 residual | ratio at equal accuracy (median / p90) "
              "| em-exact with em-galpha's stopping rule (certify = energy): it/step, ratio |",
              "|---|---|---|---|---|---|---|"]
    summary = []
    for case in cases:
        ex, same = exact_runs(rows, case)
        gd = next((r for r in rows if r["case"] == case and r["integrator"] == "em-galpha" and r["setting"] == "default"), None)
        if ex is None or gd is None:
            fail(f"{case}: the runs lack em-exact's or em-galpha's default run; rerun without --reuse", 1)
        pts_med = [(r["rho_median"], r["iterations"]) for r in rows if r["case"] == case and r["integrator"] == "em-galpha"]
        pts_p90 = [(r["rho_p90"], r["iterations"]) for r in rows if r["case"] == case and r["integrator"] == "em-galpha"]
        gm, gp = interpolate(pts_med, ex["rho_median"]), interpolate(pts_p90, ex["rho_p90"])
        fmt = lambda v: "outside em-galpha's range" if v is None else f"{v:.3f}"
        rat = lambda v: "–" if v is None else f"{ex['iterations'] / v:.2f}"
        same_ratio = same and same["iterations"] / gd["iterations"]
        same_text = "– (no such run)" if same is None else f"{same['iterations']:.4f}, {same_ratio:.5f}"
        lines.append(f"| {case} | {ex['iterations']:.3f} | {gd['iterations']:.3f} | {ex['iterations'] / gd['iterations']:.2f} "
                     f"| {fmt(gm)} / {fmt(gp)} | {rat(gm)} / {rat(gp)} | {same_text} |")
        summary.append((case, ex["iterations"] / gd["iterations"], gm and ex["iterations"] / gm, gp and ex["iterations"] / gp,
                        same_ratio))
    return "\n".join(lines) + "\n", summary


def plot(rows, cases, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("newton_accuracy.py: matplotlib not found, no figure written (apt-get install python3-matplotlib)")
        return False
    fig, axes = plt.subplots(1, len(cases), figsize=(4.6 * len(cases), 4.0), squeeze=False)
    for ax, case in zip(axes[0], cases):
        g = [r for r in rows if r["case"] == case and r["integrator"] == "em-galpha"]  # in sweep order
        own, same = exact_runs(rows, case)
        for key, style, lab in (("rho_median", "-o", "median"), ("rho_p90", "--s", "90th percentile")):
            ax.semilogx([r[key] for r in g], [r["iterations"] for r in g], style, color="tab:blue", ms=4,
                        label=f"em-galpha (e_floor sweep), {lab}")
            if own is not None:
                ax.semilogx([own[key]], [own["iterations"]], style[-1], color="tab:red", ms=8, label=f"em-exact, {lab}")
            if same is not None and same is not own:
                ax.semilogx([same[key]], [same["iterations"]], style[-1], color="tab:green", ms=8,
                            label=f"em-exact, em-galpha's rule, {lab}")
        for r in g:
            ax.annotate(r["setting"].replace("e_floor=", ""), (r["rho_median"], r["iterations"]), fontsize=7,
                        xytext=(3, -9), textcoords="offset points")
        ax.set_title(case)
        ax.set_xlabel("accepted iterate's scaled residual")
        ax.set_ylabel("Newton iterations per step")
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8)
    fig.suptitle("Newton iterations per step against the accepted residual (modified Newton; em-galpha labelled by e_floor)")
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    fig.savefig(path, dpi=120)
    return True


def measure(a):
    """Runs every (case, integrator, setting) and returns one row per run."""
    bench = a.bench or os.path.join(a.build, "bin", "bench_step_breakdown")
    if not os.access(bench, os.X_OK):
        fail(f"{bench} not found: build with -DSHELLDYN_BUILD_BENCHMARKS=ON (the default), or pass --build DIR or --bench PATH")
    if a.steps < 0 or a.jobs < 1:
        fail("--steps must be >= 0 and --jobs >= 1")
    try:
        floors = [float(x) for x in a.e_floors.split(",") if x.strip()]
    except ValueError:
        fail(f"--e-floors: '{a.e_floors}' is not a comma-separated list of numbers (e.g. 1e-21,1e-22)")
    if any(not f > 0 for f in floors):
        fail("--e-floors: every value must be > 0 (em-galpha's energy test, theory §6.5)")
    for kv in a.exact_set:
        if "=" not in kv:
            fail(f"--exact-set: '{kv}' is not key=value")
    traces = os.path.join(a.out, "traces")
    os.makedirs(traces, exist_ok=True)

    jobs = []
    for case in a.cases:
        steps = a.steps or full_steps(bench, os.path.join(ROOT, "apps", "cases", case + ".yaml"))
        jobs.append((case, steps, "em-exact", list(a.exact_set)))
        same = [kv for kv in a.exact_set if not kv.startswith("certify=")] + [SAME_RULE]
        if sorted(same) != sorted(a.exact_set):
            jobs.append((case, steps, "em-exact", same))
        jobs.append((case, steps, "em-galpha", []))
        jobs += [(case, steps, "em-galpha", [f"e_floor={f:g}"]) for f in floors]
    print(f"newton_accuracy.py: {len(jobs)} runs, {a.jobs} at a time, traces in {traces}", flush=True)
    rows = [None] * len(jobs)
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        futures = {}
        for j, (case, steps, integ, sets) in enumerate(jobs):
            tag = "-".join([case, integ] + [s.replace("=", "") for s in sets])
            futures[pool.submit(run, bench, case, steps, integ, sets, os.path.join(traces, tag + ".csv"))] = j
        done = 0
        for fut in concurrent.futures.as_completed(futures):
            j = futures[fut]
            try:
                rows[j] = fut.result()
            except Exception as e:  # report, let the others finish, and write no table
                print(f"newton_accuracy.py: run failed: {e}", file=sys.stderr, flush=True)
                continue
            done += 1
            r = rows[j]
            print(f"[{done}/{len(jobs)}] {r['case']} {r['integrator']} {r['setting']}: {r['iterations']:.3f} it/step, "
                  f"accepted residual median {r['rho_median']:.2e}, {r['cpu_s']:.1f} s CPU", flush=True)
    if any(r is None for r in rows):
        fail("some runs failed (above); no tables written", 1)

    return rows


def main():
    class Formatter(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
        pass

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=Formatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"), help="build directory with bin/bench_step_breakdown")
    ap.add_argument("--bench", help="the bench_step_breakdown executable, if not BUILD/bin/bench_step_breakdown")
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "newton-accuracy"), help="output directory")
    ap.add_argument("--cases", nargs="+", default=CASES, choices=CASES, help="benchmark cases (apps/cases/NAME.yaml)")
    ap.add_argument("--steps", type=int, default=0, help="steps per run (0: each case's full duration)")
    ap.add_argument("--jobs", type=int, default=2, help="runs at a time (each one thread)")
    ap.add_argument("--e-floors", default="1e-21,1e-22,1e-23,1e-24", help="em-galpha's tighter e_floor values")
    ap.add_argument("--reuse", action="store_true",
                    help="no runs: redo the tables and the figure from --out's newton-accuracy.csv")
    ap.add_argument("--exact-set", action="append", default=[], metavar="KEY=VALUE",
                    help="extra em-exact setting (repeatable), e.g. certify=floor")
    a = ap.parse_args()
    fields = ["case", "integrator", "setting", "steps", "iterations", "factorizations", "residuals", "rho_median",
              "rho_p90", "steps_by_iterations", "cpu_s"]
    table_csv = os.path.join(a.out, "newton-accuracy.csv")
    if a.reuse:
        if not os.path.exists(table_csv):
            fail(f"--reuse: {table_csv} not found (run without --reuse first)")
        with open(table_csv) as f:
            rows = [dict(r) for r in csv.DictReader(f)]
        for r in rows:
            for k in ("iterations", "factorizations", "residuals", "rho_median", "rho_p90", "cpu_s"):
                r[k] = float(r[k])
        cases = [c for c in a.cases if any(r["case"] == c for r in rows)]
    else:
        rows = measure(a)
        cases = a.cases
        with open(table_csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)
    text, summary = tables(rows, cases)
    with open(os.path.join(a.out, "newton-accuracy.md"), "w") as f:
        f.write("# Newton iterations at equal accuracy (scripts/newton_accuracy.py)\n\n"
                "Modified Newton with each case's settings, one thread per run. The accepted residual is the scaled "
                "residual of the accepted iterate (docs/theory/exact-energy-momentum.md §5.9).\n\n" + text)
    figure = plot(rows, cases, os.path.join(a.out, "newton-accuracy.png"))
    print("\n" + text)
    for case, d, m, p, same in summary:
        f = lambda v: "outside em-galpha's range" if v is None else f"{v:.2f}"
        eq = f"{f(m)} (median) / {f(p)} (p90)"
        rule = "no same-rule run" if same is None else f"{same:.5f}"
        print(f"{case}: em-exact / em-galpha iterations {d:.2f} at the defaults, {eq} at equal accuracy, "
              f"{rule} with em-galpha's stopping rule (certify = energy)")
    print(f"\nwritten: {os.path.join(a.out, 'newton-accuracy.md')}, newton-accuracy.csv"
          + (", newton-accuracy.png" if figure else ""))


if __name__ == "__main__":
    main()
