"""Cost of the Python call boundary for internal(): time per call from Python (returning F as a NumPy array
and K as a scipy.sparse.csr_matrix) vs the same evaluation timed inside C++ (preallocated storage).

    PYTHONPATH=build/python OMP_NUM_THREADS=1 /usr/bin/python3 python/examples/bench_internal.py
"""
import argparse
import time

import numpy as np

import shelldyn

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--case", default="pinched-hemisphere")
ap.add_argument("--repeats", type=int, default=50)
ap.add_argument("--rounds", type=int, default=5, help="alternating rounds; the median of each side is reported")
args = ap.parse_args()

system = shelldyn.load_case(args.case).system()
s = system.initial_state()
rng = np.random.default_rng(0)
s.u = s.u + 1e-3 * rng.standard_normal(system.num_dofs)
print("%s: %d unknowns, %d nonzeros" % (args.case, system.num_dofs, system.nnz))
for tangent in (False, True):
    py_t, cpp_t = [], []
    for _ in range(args.rounds):  # alternate, so that load changes hit both sides alike
        cpp_t.append(shelldyn._shelldyn._time_internal_cpp(system, s.u, s.charts, args.repeats, tangent))
        t0 = time.perf_counter()
        for _ in range(args.repeats):
            system.internal(s.u, s.charts, tangent=tangent)
        py_t.append((time.perf_counter() - t0) / args.repeats)
    p, c = np.median(py_t), np.median(cpp_t)
    print("internal(%s): Python %.3f ms/call, C++ %.3f ms/call, ratio %.3f" % (
        "F, K" if tangent else "F", 1e3 * p, 1e3 * c, p / c))
