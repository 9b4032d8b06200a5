"""No leaks across 1000 internal() calls: the resident set stays flat (each tangent is ~0.6 MB, so a
leaked matrix per call would add ~600 MB)."""
import gc

import pytest


def rss_mb():
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    import resource
    return pages * resource.getpagesize() / 2**20


@pytest.mark.skipif(not __import__("os").path.exists("/proc/self/statm"), reason="needs /proc")
def test_rss_stable_over_1000_internal_calls(shelldyn):
    system = shelldyn.load_case("flying-plate").system()
    s = system.initial_state()
    s.u[2::5] = 1e-3
    nnz_mb = system.nnz * 8 / 2**20
    for _ in range(100):  # warm up allocator pools
        system.internal(s.u, s.charts)
    gc.collect()
    before = rss_mb()
    for _ in range(1000):
        V, F, K = system.internal(s.u, s.charts)
        M = system.mass(s.u, s.charts)
    del V, F, K, M
    gc.collect()
    growth = rss_mb() - before
    assert nnz_mb > 0.3
    assert growth < 5.0, "RSS grew by %.1f MB over 1000 calls (one tangent: %.2f MB)" % (growth, nnz_mb)
