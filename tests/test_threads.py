"""BLAS stays on one thread while a multi-threaded simulation steps (foldcore.threads)."""
import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from foldcore import Simulation, patterns, thicken


def _blas_threads():
    return {lib["filepath"]: lib["num_threads"] for lib in threadpool_info()
            if lib["user_api"] == "blas"}


@pytest.fixture()
def miura_sim():
    def make(threads):
        pattern = patterns.miura(3, 3, a=10, b=10, gamma=60)
        pattern = pattern.replace(fold_angles=patterns.miura_fold_angles(3, 3, 60, 20))
        return Simulation(thicken(pattern, 1.0, hinge_width=2.0), pattern, solver="lbfgs",
                          threads=threads)
    return make


def test_blas_limited_inside_a_two_thread_run_and_restored_after(miura_sim):
    import numba
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs two numba threads")
    sim = miura_sim(2)
    np.ones(20_000) @ np.ones(20_000)  # load numpy's BLAS
    with threadpool_limits(limits=2, user_api="blas"):
        before = _blas_threads()
        if not before or max(before.values()) < 2:
            pytest.skip("no multi-threaded BLAS to limit")
        seen = []
        sim.run(max_iterations=3, callback=lambda s, moved: seen.append(_blas_threads()))
        assert seen and all(set(t.values()) == {1} for t in seen)
        assert _blas_threads() == before
        sim.step()
        assert _blas_threads() == before


def test_serial_simulation_leaves_blas_alone(miura_sim):
    sim = miura_sim(1)
    np.ones(20_000) @ np.ones(20_000)
    with threadpool_limits(limits=2, user_api="blas"):
        before = _blas_threads()
        seen = []
        sim.run(max_iterations=2, callback=lambda s, moved: seen.append(_blas_threads()))
        assert seen and all(t == before for t in seen)
