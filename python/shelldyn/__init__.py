"""shelldyn: nonlinear dynamics of thin shells and comparisons of time integrators, from Python.

    import shelldyn
    case = shelldyn.load_case("flying-plate")       # a built-in case, or a path to a case file
    sys = case.system()                              # the semi-discrete system (NumPy / SciPy objects)
    s = sys.initial_state()
    V, F, K = sys.internal(s.u, s.charts)            # K: scipy.sparse.csr_matrix
    run = shelldyn.run(case, "em-galpha", t_end=0.5)  # history as a dict of NumPy arrays, run.json as a dict

The tutorial is docs/tutorials/10-python.md. Errors raise shelldyn.InputError (bad input; also a
ValueError) or shelldyn.Error with the one-line message the command line prints.
"""

import json
import os
import shutil
import tempfile

# Bounded spinning of idle OpenMP threads, as the shelldyn executables set it (lib/linalg/openmp_wait_policy.hpp):
# libgomp reads the variables when it is loaded with the extension below; values set by the user are kept.
if "OMP_WAIT_POLICY" not in os.environ:
    os.environ.setdefault("GOMP_SPINCOUNT", "10000")

from ._shelldyn import (  # noqa: F401  (re-exported)
    DOFS_PER_NODE,
    Case,
    Chart,
    Charts,
    Error,
    InputError,
    IntegratorSettings,
    RunStopped,
    State,
    StepFailure,
    System,
    __version__,
    case_from_string,
    find_case_file,
    find_script,
    integrator_catalogue,
    integrator_names,
    integrator_origin,
    mechanical_energy_drift,
    read_history,
    run_script,
    Study,
)
from . import _shelldyn

__all__ = [
    "Case", "Chart", "Charts", "Error", "InputError", "Integrator", "IntegratorSettings", "RunResult", "RunStopped",
    "State", "StepFailure", "System", "compare", "integrator_catalogue", "integrator_names", "load_case",
    "read_history", "register_integrator", "run", "study", "Study", "study_files", "load_study", "load_study_from_string",
    "study_from_string", "unregister_integrator",
]


class Integrator:
    """Optional base class of integrators written in Python (see register_integrator).

    Subclasses implement ``step(self, system, state, h)`` (one step of size h from state.t: update
    state.u, state.v, state.a in place; the caller advances state.t and re-selects director charts
    before each step with ``self.hysteresis``) or ``advance(self, system, state, t_out)``, optionally
    ``initialize(self, system, state)``, and keep ``self.external_work`` (W_ext since initialize,
    evaluated consistently with the scheme) up to date. The constructor receives the run's
    IntegratorSettings (read them with settings.get(key, default)) and the time step dt.
    """

    hysteresis = 1.0
    external_work = 0.0

    def __init__(self, settings, dt):
        self.dt = dt


def register_integrator(name, factory, summary=None, replace=False):
    """Registers a Python integrator by name, so that run/compare/study (and anything else that makes
    integrators by name in this process) can use it beside the built-ins.

    factory: a class (or callable) called as factory(settings, dt) for every run; see Integrator.
    summary: one line for integrator_catalogue() (default: the first line of the class docstring).
    replace: replace an earlier Python registration of the same name (built-ins cannot be replaced).
    """
    if summary is None:
        doc = (getattr(factory, "__doc__", None) or "").strip()
        summary = doc.splitlines()[0] if doc else "integrator written in Python"
    origin = "python:%s.%s" % (getattr(factory, "__module__", "?"), getattr(factory, "__qualname__", repr(factory)))
    _shelldyn._register_integrator(name, factory, summary, origin, replace)
    return name


def unregister_integrator(name):
    """Removes an integrator registered from Python; returns False if there was none of that name."""
    return _shelldyn.unregister_integrator(name)


def _installed_case(name):
    """<prefix>/share/shelldyn/cases/NAME.yaml of an installed package (<prefix>/lib/pythonX.Y/dist-packages/shelldyn)."""
    share = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "..", "share", "shelldyn", "cases")
    path = os.path.normpath(os.path.join(share, name if name.endswith(".yaml") else name + ".yaml"))
    return path if os.path.isfile(path) else None


def _resolve_case(name_or_path):
    name_or_path = os.fspath(name_or_path)
    if os.path.exists(name_or_path) or "/" in name_or_path:
        return name_or_path
    try:
        return find_case_file(name_or_path if name_or_path.endswith(".yaml") else name_or_path + ".yaml")
    except Error:
        installed = _installed_case(name_or_path)
        if installed is None:
            raise
        return installed


def load_case(name_or_path):
    """Loads a case file, or a built-in case by name (e.g. "flying-plate": apps/cases/flying-plate.yaml, or
    <prefix>/share/shelldyn/cases/ when installed). Errors raise InputError/Error with the CLI's message."""
    return _shelldyn.load_case(_resolve_case(name_or_path))


def _as_case(case):
    if isinstance(case, Case):
        return case
    return load_case(os.fspath(case))


def _progress_sink(progress):
    if progress is None or progress is False:
        return None
    if progress is True:
        return lambda line: print(line, flush=True)
    return progress


class RunResult:
    """One run: ``summary`` (dict of the run's figures), ``run_json`` (run.json as a dict), ``history``
    (history.csv as a dict of NumPy arrays, one per column) and ``out_dir`` (None when the run was
    written to a temporary folder that has been removed)."""

    def __init__(self, summary, out_dir, keep):
        self.summary = summary
        folder = summary["out_dir"]
        self.history = read_history(os.path.join(folder, "history.csv"))
        with open(os.path.join(folder, "run.json")) as f:
            self.run_json = json.load(f)
        self.out_dir = folder if keep else None

    @property
    def status(self):
        return self.summary["status"]

    def __repr__(self):
        return "RunResult(%s, %s, %d steps, max_rel_drift=%.3g)" % (
            self.summary["integrator"], self.summary["status"], self.summary["steps"], self.summary["max_rel_drift"])


def run(case, integrator=None, settings=None, dt=None, t_end=None, output_interval=None, out_dir=None, vtu_every=None,
        overwrite=False, threads=0, progress=None):
    """Integrates a case in time as ``shelldyn run`` does and returns a RunResult.

    case: a Case, a case file path or a built-in case name. integrator: a registered name (default:
    the case's). settings: dict of integrator-setting overrides (``--set KEY=VALUE``). dt, t_end,
    output_interval: overrides of the case's time block. out_dir: result folder written exactly as
    the CLI writes it (history.csv, run.json, fields/ unless vtu_every=0); None: a temporary folder,
    read back and removed (VTU off unless vtu_every is given). progress: True prints the CLI's progress
    lines, a callable receives each line, None is silent.
    """
    c = _as_case(case)
    for key, value, ok in (("dt", dt, lambda x: x > 0), ("t_end", t_end, lambda x: x >= 0),
                           ("output_interval", output_interval, lambda x: x > 0)):
        if value is not None and not (isinstance(value, (int, float)) and ok(value) and value < 1e15):
            raise InputError("%s = %r: must be a number %s (e.g. %s=%s)" % (
                key, value, "> 0" if key != "t_end" else ">= 0", key, {"dt": "1e-3", "t_end": "2.0"}.get(key, "0.01")))
    keep = out_dir is not None
    folder = os.fspath(out_dir) if keep else tempfile.mkdtemp(prefix="shelldyn-run-")
    if vtu_every is None:
        vtu_every = -1 if keep else 0
    command = "python: shelldyn.run(%r, integrator=%r)" % (c.name, integrator)
    try:
        summary = _shelldyn._run(c, integrator or "", settings, dt or 0.0, -1.0 if t_end is None else t_end,
                                 output_interval or 0.0, vtu_every, folder, overwrite or not keep, threads,
                                 _progress_sink(progress), command)
        return RunResult(summary, folder, keep)
    finally:
        if not keep:
            shutil.rmtree(folder, ignore_errors=True)


class CompareResult:
    """A comparison: ``rows`` (one dict per run: label, integrator, dt, status, energy_error,
    displacement_error, summary, out_dir), ``reference``, ``summary_csv``/``summary_md`` paths and
    ``history(label)`` / ``run_json(label)`` (that run's history.csv as arrays, its run.json as a dict)."""

    def __init__(self, d):
        self.__dict__.update(d)
        for row in self.rows:  # the CPU and wall time of a run are those its run.json records
            path = os.path.join(row["out_dir"], "run.json")
            if row["summary"] is not None and os.path.exists(path):
                with open(path) as f:
                    rs = json.load(f).get("summary", {})
                for key in ("cpu_s", "wall_s"):
                    if key in rs:
                        row["summary"][key] = rs[key]

    def row(self, label):
        for r in self.rows:
            if r["label"] == label:
                return r
        raise KeyError(label)

    def history(self, label):
        return read_history(os.path.join(self.row(label)["out_dir"], "history.csv"))

    def run_json(self, label):
        with open(os.path.join(self.row(label)["out_dir"], "run.json")) as f:
            return json.load(f)

    def __repr__(self):
        return "CompareResult(%d runs, reference %r)" % (len(self.rows), self.reference)


def compare(case, integrators, out_dir, dts=(), rtols=(), t_end=None, output_interval=None, jobs=2, threads=0,
            reference="", vtu_every=0, resume=False, plots=False, progress=None):
    """``shelldyn compare``: one case, several integrator specs (NAME[:KEY=VALUE...], Python-registered
    names included), each an independent run into out_dir/<label>/, and summary.csv/summary.md.
    plots=True also runs scripts/plot_compare.py as the CLI does. Returns a CompareResult."""
    path = case.path if isinstance(case, Case) else _resolve_case(case)
    if isinstance(integrators, str):
        integrators = integrators.split(",")
    d = _shelldyn._compare(path, list(integrators), [float(x) for x in dts], [float(x) for x in rtols],
                           -1.0 if t_end is None else t_end, output_interval or 0.0, vtu_every, jobs, threads,
                           os.fspath(out_dir), reference, resume, _progress_sink(progress),
                           "python: shelldyn.compare(%r, %r)" % (path, list(integrators)))
    if plots:
        run_script("plot_compare.py", [os.fspath(out_dir)])
    return CompareResult(d)


def _installed_studies():
    """<prefix>/share/shelldyn/studies/*.yaml of an installed package (see _installed_case)."""
    share = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "..", "share",
                                          "shelldyn", "studies"))
    if not os.path.isdir(share):
        return {}
    return {f[:-5]: os.path.join(share, f) for f in sorted(os.listdir(share)) if f.endswith(".yaml")}


def study_files():
    """The shipped study files (docs/reference/study-files.md) as a dict name -> path, e.g.
    {"flying-plate": ".../apps/studies/flying-plate.yaml", ...}: the studies of ``shelldyn study NAME``."""
    return _shelldyn._study_files() or _installed_studies()


def load_study(name_or_path):
    """Reads and validates a study file: a shipped study by name (study_files()) or the path of a study file
    of your own. Returns a Study (name, case_file, methods, window_t_end, dts, rtols, reference, ...;
    add_method(spec) adds a method). Errors raise InputError with the file, the line and the key."""
    name_or_path = os.fspath(name_or_path)
    shipped = study_files()
    if name_or_path in shipped:
        return _shelldyn._load_study_file(shipped[name_or_path])
    if os.path.exists(name_or_path):
        return _shelldyn._load_study_file(name_or_path)
    raise InputError("study: unknown benchmark or study file '%s' (shipped: %s; or the path of a study file)"
                     % (name_or_path, ", ".join(shipped) or "none found"))


def load_study_from_string(text, base_dir=".", source="<string>"):
    """A study from YAML text (the study-file format); a relative ``case:`` is taken relative to base_dir,
    and error messages name ``source``. Returns a Study."""
    return _shelldyn._load_study_from_string(text, source, os.fspath(base_dir))


def _study_case(s, case):
    """The study's case, as ``shelldyn study`` picks it: case=..., else the study file's case: next to the
    file, else the shipped case of that file name."""
    if case is not None:
        return case.path if isinstance(case, Case) else _resolve_case(case)
    if s.case_path:
        return s.case_path
    try:
        return _resolve_case(os.path.basename(s.case_file))
    except Error as e:
        raise InputError("%s: %s" % (s.source or s.name, e))


def study(study, out_dir=None, add_methods=(), case=None, groups=None, rerun=False, jobs=2, max_wall_per_run=0.0,
          max_steps_per_run=0, dry_run=False, plots=False, progress=None):
    """``shelldyn study``: the work-precision sweep (group "window") and full-duration runs (group "full")
    of a study: a shipped study by name (study_files()), the path of a study file, or a Study
    (load_study / load_study_from_string). add_methods: specs NAME[:KEY=VALUE...] added as
    ``--add-method`` does (any registered integrator, Python ones included); case: another case file for
    the same methods and sweeps; out_dir: default results/<name>/study; groups: e.g. ["window"] (default:
    every group the study has); dry_run=True lists the runs and runs nothing. Returns a dict with
    ``rows`` (one per run: group, label, kind, dt, rtol,
    status, cpu_s, energy_error, displacement_error, ...), the counts ran/skipped/failed/stopped and the
    study.csv/study.md paths; plots=True runs scripts/plot_study.py."""
    s = study if isinstance(study, Study) else load_study(study)
    if isinstance(add_methods, str):
        add_methods = add_methods.split(",")
    if add_methods:
        if isinstance(study, Study):  # do not change the caller's Study
            s = s.copy()
        for spec in add_methods:
            s.add_method(spec)
    if out_dir is None:
        out_dir = os.path.join("results", s.name, "study")
    if isinstance(groups, str):
        groups = [groups]
    d = _shelldyn._study(s, _study_case(s, case), os.fspath(out_dir), list(groups or ()), rerun, dry_run, jobs,
                         max_wall_per_run, max_steps_per_run, _progress_sink(progress),
                         "python: shelldyn.study(%r)" % (s.source or s.name))
    if plots and not dry_run:
        run_script("plot_study.py", [os.fspath(out_dir)])
    return d


def study_from_string(text, out_dir=None, base_dir=".", source="<string>", **kwargs):
    """study() of a study given as YAML text (load_study_from_string(text, base_dir, source))."""
    return study(load_study_from_string(text, base_dir, source), out_dir, **kwargs)


def _register_verlet_cpp(name="verlet-cpp"):
    """Test-only: the C++ copy of python/examples/verlet.py (python/tests/verlet_cpp.cpp)."""
    _shelldyn._register_verlet_cpp(name)


import atexit as _atexit  # noqa: E402

# Python integrators hold Python objects: drop them from the (C++) registry before the interpreter goes.
_atexit.register(_shelldyn._unregister_python_integrators)
