"""Errors arrive as Python exceptions carrying the command line's one-line message."""
import os
import subprocess

import numpy as np
import pytest

GOOD = open(os.path.join(os.path.dirname(__file__), "..", "..", "apps", "cases", "flying-plate.yaml")).read()


def cli_error(cli, *args):
    p = subprocess.run([cli, *args], capture_output=True, text=True)
    assert p.returncode == 1, p.stdout + p.stderr
    first = p.stderr.splitlines()[0]
    assert first.startswith("shelldyn: error: ")
    return first[len("shelldyn: error: "):]


@pytest.mark.parametrize("edit, where", [
    (("material: {E: 1.0e6,", "material: {E: -1.0e6,"), "material.E"),            # bad value
    (("rho_inf: 1.0", "rho_inf: 1.0\n  rho_infinity: 0.5"), "rho_infinity"),        # unknown integrator key
    (("generator: cell_union", "generator: cell_unoin"), "mesh.generator"),         # typo in a name
])
def test_bad_case_same_message_as_cli(shelldyn, cli, tmp_path, edit, where):
    path = tmp_path / "bad.yaml"
    assert edit[0] in GOOD
    path.write_text(GOOD.replace(*edit))
    expected = cli_error(cli, "check", str(path), "-o", str(tmp_path / "out"))
    with pytest.raises(shelldyn.InputError) as e:
        shelldyn.load_case(str(path)).check()
    assert str(e.value).splitlines()[0] == expected
    assert where in expected and str(path) in expected
    assert isinstance(e.value, ValueError) and isinstance(e.value, shelldyn.Error)


def test_missing_case(shelldyn):
    with pytest.raises(shelldyn.InputError, match="no-such-case.yaml"):
        shelldyn.load_case("no-such-case")


def test_unknown_integrator_and_setting(shelldyn, tmp_path):
    with pytest.raises(shelldyn.InputError, match="'no-such-scheme': unknown integrator"):
        shelldyn.run("flying-plate", "no-such-scheme", t_end=0.01)
    with pytest.raises(shelldyn.InputError, match="rho_inf"):
        shelldyn.run("flying-plate", "em-galpha", settings={"rho_inf": "abc"}, t_end=0.01)
    with pytest.raises(shelldyn.InputError, match="dt = -0.001: must be a number > 0"):
        shelldyn.run("flying-plate", "em-galpha", dt=-1e-3, t_end=0.01, out_dir=tmp_path / "x")
    assert not (tmp_path / "x").exists()  # rejected before any folder is made


def test_bad_arrays(shelldyn):
    system = shelldyn.load_case("flying-plate").system()
    s = system.initial_state()
    with pytest.raises(shelldyn.InputError, match="expected 735 entries, got 3"):
        system.internal(np.zeros(3), s.charts)
    with pytest.raises(TypeError):
        system.internal(s.u, "not charts")


class Exploding(object):
    """fails in its third step"""

    def __init__(self, settings, dt):
        self.kind = settings.get("kind", "value")
        self.n = 0
        self.external_work = 0.0

    def step(self, system, state, h):
        self.n += 1
        if self.n == 3:
            if self.kind == "step":
                raise __import__("shelldyn").StepFailure("step 3 did not converge")
            raise ZeroDivisionError("boom in step %d" % self.n)


def test_python_integrator_errors(shelldyn, tmp_path):
    shelldyn.register_integrator("exploding", Exploding, replace=True)
    try:
        with pytest.raises(shelldyn.Error, match=r"exploding: step: ZeroDivisionError: boom in step 3") as e:
            shelldyn.run("flying-plate", "exploding", t_end=0.01, out_dir=tmp_path / "run")
        assert not isinstance(e.value, shelldyn.StepFailure)
        status = __import__("json").load(open(tmp_path / "run" / "run.json"))["status"]
        assert status.startswith("incomplete: ") and "boom in step 3" in status
        with pytest.raises(shelldyn.StepFailure, match="step 3 did not converge"):
            shelldyn.run("flying-plate", "exploding", settings={"kind": "step"}, t_end=0.01)
        with pytest.raises(shelldyn.InputError, match="kind") as e:  # unknown keys listed as for built-ins
            shelldyn.run("flying-plate", "exploding", settings={"knid": "x"}, t_end=0.01)
        # the registry's message (integrators/runs/registry.cpp) names the earlier registration
        with pytest.raises(shelldyn.InputError, match=r"^integrator 'exploding' is already registered "
                                                      r"\(by python:test_errors\.Exploding\); choose another name$"):
            shelldyn.register_integrator("exploding", Exploding)
        with pytest.raises(shelldyn.InputError, match=r"^integrator 'em-galpha' is already registered \(by built-in\); "
                                                      r"choose another name$"):
            shelldyn.register_integrator("em-galpha", Exploding, replace=True)
    finally:
        assert shelldyn.unregister_integrator("exploding")
    assert "exploding" not in shelldyn.integrator_names()
