"""An integrator written in Python runs through the same machinery as the C++ ones: it matches the
in-tree C++ copy of the same scheme (verlet_cpp.cpp) to round-off, and compare/study treat it as a
built-in (rows, history columns, run.json)."""
import json
import os

import numpy as np
import pytest

import verlet  # python/examples/verlet.py

DT = 5e-5


@pytest.fixture(scope="module")
def registered(shelldyn):
    verlet.register("verlet")
    if "verlet-cpp" not in shelldyn.integrator_names():
        shelldyn._register_verlet_cpp("verlet-cpp")
    return shelldyn


def test_registered_like_a_builtin(registered):
    sd = registered
    assert "verlet" in sd.integrator_names() and "verlet-cpp" in sd.integrator_names()
    assert sd.integrator_origin("verlet") == "python:verlet.Verlet"
    cat = dict(sd.integrator_catalogue())
    assert cat["verlet"].startswith("explicit central difference / velocity Verlet in NumPy/SciPy")
    assert "hysteresis=1" in cat["verlet"]


def test_python_matches_cpp_copy_to_round_off(registered, tmp_path):
    sd = registered
    runs = {}
    for name in ("verlet", "verlet-cpp"):
        runs[name] = sd.run("flying-plate", name, dt=DT, t_end=0.05, output_interval=0.005, out_dir=tmp_path / name)
    py, cpp = runs["verlet"], runs["verlet-cpp"]
    assert py.status == cpp.status == "complete"
    assert py.summary["steps"] == cpp.summary["steps"] == 1000
    np.testing.assert_array_equal(py.history["step"], cpp.history["step"])
    np.testing.assert_array_equal(py.history["t"], cpp.history["t"])
    scale = np.max(py.history["kinetic"] + py.history["strain"])
    assert scale > 1e-5  # the loads have set the plate moving
    for col in ("kinetic", "strain", "external_work", "total"):
        diff = np.max(np.abs(py.history[col] - cpp.history[col]))
        assert diff <= 1e-11 * scale, (col, diff, scale)
    for col in ("uxA", "uzA", "uxB"):
        assert np.max(np.abs(py.history[col] - cpp.history[col])) <= 1e-11 * np.max(np.abs(cpp.history[col]))
    # the scheme is not trivially exact: its energy balance error is visible but small
    drift = np.max(np.abs(py.history["total"]))
    assert 0 < drift < 1e-3 * scale
    # run.json as the CLI writes it, with the Python integrator's own settings
    rj = json.load(open(tmp_path / "verlet" / "run.json"))
    assert rj == py.run_json and rj["status"] == "complete"
    assert os.path.exists(tmp_path / "verlet" / "fields.pvd")


def test_compare_runs_python_beside_builtins(registered, tmp_path):
    sd = registered
    r = sd.compare("flying-plate", ["em-galpha", "verlet:dt=5e-5", "verlet-cpp:dt=5e-5"], tmp_path / "cmp",
                   t_end=0.02, output_interval=0.005)
    assert [row["status"] for row in r.rows] == ["complete"] * 3
    labels = [row["label"] for row in r.rows]
    assert labels == ["em-galpha", "verlet_dt=5e-05", "verlet-cpp_dt=5e-05"]
    h_ref, h_py = r.history("em-galpha"), r.history("verlet_dt=5e-05")
    assert list(h_py.keys()) == list(h_ref.keys())  # same history columns as a built-in
    np.testing.assert_array_equal(h_py["t"], h_ref["t"])
    assert r.row("verlet_dt=5e-05")["summary"]["steps"] == 400
    summary = open(r.summary_csv).read()
    assert "verlet_dt=5e-05" in summary
    # the case's hysteresis (1.1) is inherited by the Python scheme, as by any integrator that reads it
    rj = json.load(open(os.path.join(r.row("verlet_dt=5e-05")["out_dir"], "run.json")))
    assert "1.1" in json.dumps(rj)


STUDY = """
name: py-verlet
case: flying-plate.yaml     # not next to base_dir: the shipped case of that name
window:
  t_end: 0.01
  output_interval: 0.005
  dt: [5e-5, 2.5e-5]
  reference: em-galpha:dt=1.25e-5
methods:
  - em-galpha
"""


def test_study_with_a_python_method(registered, tmp_path):
    sd = registered
    shipped = sd.study_files()
    assert {"flying-plate", "cylindrical-panel", "pinched-hemisphere"} <= set(shipped)
    fp = sd.load_study("flying-plate")
    assert fp.source == shipped["flying-plate"] and "em-galpha" in [m["integrator"] for m in fp.methods]
    # a Python-registered name is a method like a built-in: in a study's methods: list ...
    s = sd.load_study_from_string(STUDY.replace("  - em-galpha\n", "  - em-galpha\n  - verlet\n"), base_dir=tmp_path)
    assert [(m["integrator"], m["adaptive"]) for m in s.methods] == [("em-galpha", False), ("verlet", False)]
    # ... and added by name (add_methods, as `shelldyn study --add-method`); the given Study is left unchanged
    base = sd.load_study_from_string(STUDY, base_dir=tmp_path)
    d = sd.study(base, tmp_path / "study", add_methods=["verlet"], groups=["window"])
    assert [m["integrator"] for m in base.methods] == ["em-galpha"]
    rows = {(r["label"]): r for r in d["rows"]}
    assert d["failed"] == 0 and d["ran"] == 5, sorted(rows)
    for label in ("verlet_dt=5e-05", "verlet_dt=2.5e-05"):
        assert label in rows, sorted(rows)
        r = rows[label]
        assert r["status"] == "complete" and r["kind"] == "fixed" and r["steps"] == round(0.01 / r["dt"])
        assert r["displacement_error"] > 0
    # halving dt reduces the displacement error of a second-order scheme about 4x
    ratio = rows["verlet_dt=5e-05"]["displacement_error"] / rows["verlet_dt=2.5e-05"]["displacement_error"]
    assert 2.5 < ratio < 6, ratio
    assert os.path.exists(d["study_csv"]) and "verlet" in open(d["study_md"]).read()
    # the same study from the text, with the method added by name: every run is kept from the first call
    d2 = sd.study_from_string(STUDY, tmp_path / "study", base_dir=tmp_path, add_methods="verlet", groups=["window"])
    assert d2["ran"] == 0 and d2["skipped"] == 5 and d2["failed"] == 0


def test_study_errors(registered, tmp_path):
    sd = registered
    with pytest.raises(sd.InputError, match="unknown benchmark or study file 'flying-plat'.*flying-plate"):
        sd.load_study("flying-plat")
    with pytest.raises(sd.InputError, match=r"s\.yaml:\d+: methods\[1\]: unknown integrator 'verlett'"):
        sd.load_study_from_string(STUDY + "  - verlett\n", base_dir=tmp_path, source="s.yaml")
    with pytest.raises(sd.InputError, match="add_method\('nosuch'\).*unknown integrator 'nosuch'"):
        sd.study(sd.load_study_from_string(STUDY, base_dir=tmp_path), tmp_path / "x", add_methods=["nosuch"])
    with pytest.raises(sd.InputError, match="has no full: section"):
        sd.study_from_string(STUDY, tmp_path / "y", base_dir=tmp_path, groups=["full"])
    assert not os.path.exists(tmp_path / "x") and not os.path.exists(tmp_path / "y")
