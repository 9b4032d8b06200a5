"""Round trips of the bindings: the system's evaluations seen from NumPy/SciPy agree with each other
(forces = gradients of energies, tangents = derivatives of forces, kinetic energy = 1/2 v.M v) and
with the command line's figures; arrays are views where the layout allows."""
import numpy as np
import pytest
import scipy.sparse as sp


@pytest.fixture(scope="module")
def plate(shelldyn):
    case = shelldyn.load_case("flying-plate")
    return case, case.system()


def perturbed(system, seed=1, scale=1e-2):
    rng = np.random.default_rng(seed)
    s = system.initial_state()
    s.u = s.u + scale * rng.standard_normal(system.num_dofs)
    return s, rng


def test_dimensions_and_dof_map(plate, shelldyn):
    case, system = plate
    summary = case.check()
    assert system.num_dofs == summary["dofs"] == 5 * system.num_nodes
    assert system.num_nodes == summary["nodes"] == 147
    assert system.num_elements == summary["elements"] == 30
    dm = system.dof_map
    assert dm.shape == (system.num_dofs, 2)
    assert all(system.dof(int(n), int(c)) == i for i, (n, c) in list(enumerate(dm))[::37])
    assert system.nodes.shape == (system.num_nodes, 3)
    assert summary["total_mass"] == pytest.approx(3.0)
    assert len(system.constrained_dofs) == 0 and len(system.free_dofs) == system.num_dofs  # free flight


def test_internal_force_is_gradient_and_tangent_is_derivative(plate):
    _, system = plate
    s, rng = perturbed(system)
    V, F, K = system.internal(s.u, s.charts)
    assert isinstance(K, sp.csr_matrix) and K.shape == (system.num_dofs,) * 2
    assert V > 0 and np.linalg.norm(F) > 0
    d = rng.standard_normal(system.num_dofs)
    eps = 1e-6
    Vp, Fp, _ = system.internal(s.u + eps * d, s.charts, tangent=False)
    Vm, Fm, _ = system.internal(s.u - eps * d, s.charts, tangent=False)
    assert (Vp - Vm) / (2 * eps) == pytest.approx(F @ d, rel=1e-6)
    np.testing.assert_allclose((Fp - Fm) / (2 * eps), K @ d, rtol=0, atol=1e-6 * np.abs(K @ d).max())
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()  # symmetric: CSC of K read as CSR is K itself
    _, none_f, none_k = system.internal(s.u, s.charts, force=False, tangent=False)
    assert none_f is None and none_k is None


def test_mass_and_invariants(plate):
    _, system = plate
    s, rng = perturbed(system, seed=2)
    s.v = rng.standard_normal(system.num_dofs)
    M = system.mass(s.u, s.charts)
    inv = system.invariants(s)
    assert inv["kinetic"] == pytest.approx(0.5 * s.v @ (M @ s.v), rel=1e-12)
    assert inv["strain"] == pytest.approx(system.internal(s.u, s.charts, tangent=False)[0], rel=1e-14)
    # total mass from the translational block: 1ᵀ M_xx 1 = rho h A = 3 kg
    x = np.zeros(system.num_dofs)
    x[0::5] = 1.0
    assert x @ (M @ x) == pytest.approx(3.0, rel=1e-12)
    # linear momentum of a uniform translation = m v
    s0 = system.initial_state()
    s0.v = 2.0 * x
    np.testing.assert_allclose(system.invariants(s0)["L"], [6.0, 0.0, 0.0], atol=1e-12)
    fm = system.inertial(s.u, s.v, s.charts)
    a = rng.standard_normal(system.num_dofs)
    np.testing.assert_allclose(system.inertia_force(s.u, s.v, a, s.charts), M @ a + fm, rtol=1e-10, atol=1e-10)


def test_external_load_matches_case(plate):
    _, system = plate
    s = system.initial_state()
    F = system.external(2.5, s.u, s.charts)  # hat peak: 5 N along z at A, along x at B
    assert F[2::5].sum() == pytest.approx(5.0) and F[0::5].sum() == pytest.approx(5.0)
    assert np.abs(system.external(6.0, s.u, s.charts)).max() == 0.0
    assert system.loads_end == pytest.approx(5.0)


def test_state_arrays_are_views(plate):
    _, system = plate
    s = system.initial_state()
    u = s.u
    u[3] = 0.25
    assert s.u[3] == 0.25  # written through
    assert np.shares_memory(s.u, u)
    _, _, K1 = system.internal(s.u, s.charts)
    _, _, K2 = system.internal(s.u, s.charts)
    assert np.shares_memory(K1.indices, K2.indices)  # one pattern for every matrix
    assert not np.shares_memory(K1.data, K2.data)
    assert not K1.data.flags.owndata  # the assembled C++ storage itself, not a copy


def test_rechart_keeps_directors(plate):
    _, system = plate
    s = system.initial_state()
    assert s.charts[0].l == 2
    s.u[system.dof(0, 3)] = 0.8  # p = (0.8, 0, 0.6): x is now the largest component
    p_before = system.directors(s)
    n = system.rechart(s)
    assert n == 1 and s.charts[0].l == 0
    np.testing.assert_allclose(system.directors(s), p_before, atol=1e-15)
    assert s.charts.array().shape == (system.num_nodes, 4)


def test_constraints_of_a_supported_plate(shelldyn):
    case = shelldyn.load_case("plate-modes-ss-thin")
    system = case.system()
    c = system.constrained_dofs
    assert len(c) == case.check()["constrained_dofs"] > 0
    s = system.initial_state()
    M = system.apply_dirichlet(system.mass(s.u, s.charts))
    dense_rows = M[c].toarray()
    expected = np.zeros_like(dense_rows)
    expected[np.arange(len(c)), c] = 1.0
    np.testing.assert_array_equal(dense_rows, expected)


def test_case_overrides(shelldyn):
    case = shelldyn.load_case("flying-plate")
    assert case.integrator == "em-galpha" and case.integrator_settings["rho_inf"] == "1.0"
    case.material = {"rho": 2.0}
    assert case.check()["total_mass"] == pytest.approx(6.0)
    case.integrator = "newmark"  # keeps only the settings newmark understands
    assert "xi" not in case.integrator_settings
    case.dt, case.t_end = 2e-3, 0.1
    assert case.num_steps == 50
    with pytest.raises(shelldyn.InputError, match="dt"):
        case.dt = -1.0
