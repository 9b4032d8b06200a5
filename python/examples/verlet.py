"""An explicit central-difference / velocity-Verlet integrator in NumPy/SciPy, registered with shelldyn.

One step of size h from (u_n, v_n, a_n) at t_n (the charts are re-selected before each step by the
caller, with the `hysteresis` setting):

    v_h     = v_n + h/2 a_n
    u_{n+1} = u_n + h v_h
    a_{n+1} = M(u_{n+1})^-1 [F_ext(t_{n+1}, u_{n+1}) - F_int(u_{n+1}) - F_m(u_{n+1}, v_h)]   (a = 0 on Dirichlet DOFs)
    v_{n+1} = v_h + h/2 a_{n+1}
    W_ext  += 1/2 (F_ext(t_n, u_n) + F_ext(t_{n+1}, u_{n+1})) . (u_{n+1} - u_n)        (trapezoidal work)

M(q) depends on the director unknowns, so it is assembled and factorized (SuperLU) every step. F_m is
taken at the half-step velocity v_h. Explicit: stable only for h below about 2/omega_max (the flying
plate needs h <= 1e-4). python/tests/verlet_cpp.cpp is the same scheme in C++.

    import shelldyn, verlet
    verlet.register()                       # as "verlet"
    shelldyn.run("flying-plate", "verlet", dt=5e-5, t_end=0.1)
"""

import numpy as np
import scipy.sparse.linalg as spla

import shelldyn


class Verlet(shelldyn.Integrator):
    """explicit central difference / velocity Verlet in NumPy/SciPy (python/examples/verlet.py)"""

    def __init__(self, settings, dt):
        super().__init__(settings, dt)
        self.hysteresis = settings.get("hysteresis", 1.0)  # chart switches (docs/theory.md §2.3)
        self.external_work = 0.0

    def settings(self):
        return [("dt", self.dt), ("hysteresis", self.hysteresis)]

    def _acceleration(self, system, t, u, v, charts):
        """a = M(u)^-1 [F_ext(t, u) - F_int(u) - F_m(u, v)], Dirichlet rows a = 0; also returns F_ext(t, u)."""
        _, fint, _ = system.internal(u, charts, tangent=False)
        fm = system.inertial(u, v, charts)
        fext = system.external(t, u, charts)
        r = fext - fint - fm
        r[system.constrained_dofs] = 0.0
        M = system.apply_dirichlet(system.mass(u, charts))
        a = spla.splu(M.tocsc()).solve(r)
        return a, fext

    def initialize(self, system, state):
        system.rechart(state, self.hysteresis)
        state.a, _ = self._acceleration(system, state.t, state.u, state.v, state.charts)
        self.external_work = 0.0

    def step(self, system, state, h):
        u, v, a, charts = state.u, state.v, state.a, state.charts
        f0 = system.external(state.t, u, charts)
        vh = v + 0.5 * h * a
        u1 = u + h * vh
        a1, f1 = self._acceleration(system, state.t + h, u1, vh, charts)
        self.external_work += 0.5 * np.dot(f0 + f1, u1 - u)
        state.v = vh + 0.5 * h * a1
        state.u = u1
        state.a = a1
        return {"rhs_evaluations": 1, "factorizations": 1}


def register(name="verlet"):
    """Registers Verlet under `name` (replacing an earlier Python registration of it)."""
    return shelldyn.register_integrator(name, Verlet, replace=True)
