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


def test_overlapping_guards_from_two_threads_restore_the_original_setting(monkeypatch):
    """A opens, B opens, A closes, B closes: BLAS must end where it started (a
    per-guard save/restore would leave it on one thread for good). A stand-in
    controller records the setting: OpenBLAS itself ignores a raise of its
    thread count requested from a non-main thread (measured), which would hide
    the logic under test."""
    import threading

    import foldcore.threads as threads

    setting = {"threads": 2}

    class Limiter:
        def __init__(self):
            self.original = setting["threads"]
            setting["threads"] = 1

        def restore_original_limits(self):
            setting["threads"] = self.original

    class Controller:
        def limit(self, limits, user_api):
            assert (limits, user_api) == (1, "blas")
            return Limiter()

    monkeypatch.setattr(threads, "_controller", Controller())
    a_open, b_open, a_closed = threading.Event(), threading.Event(), threading.Event()
    seen = {}

    def guard_b():
        a_open.wait()
        with threads.blas_on_one_thread():
            b_open.set()
            a_closed.wait()
            seen["b_after_a_closed"] = setting["threads"]

    worker = threading.Thread(target=guard_b)
    worker.start()
    with threads.blas_on_one_thread():
        a_open.set()
        b_open.wait()
    a_closed.set()
    worker.join()
    assert seen["b_after_a_closed"] == 1
    assert setting["threads"] == 2 and threads._depth == 0


def test_the_thread_chooser_follows_the_faster_count_and_backs_off_its_probes():
    """ThreadChooser, fed step times: parallel while it is faster, serial once the
    cores are shared (a parallel step waits for a descheduled thread), probing the
    slower count at doubling intervals, and back to parallel when the load ends."""
    from foldcore.threads import ThreadChooser

    chooser = ThreadChooser(2)
    cost = {1: 1.0, 2: 0.6}  # quiet: parallel faster
    counts = []
    for _ in range(200):
        t = chooser.next()
        counts.append(t)
        chooser.record(t, cost[t])
    assert counts[0] == 2 and chooser.best() == 2
    assert 1 <= counts.count(1) <= 200 / ThreadChooser.EXPLORE_EVERY  # only probes
    probes = [i for i, t in enumerate(counts) if t == 1]
    assert np.all(np.diff(probes) >= ThreadChooser.EXPLORE_EVERY)
    assert np.diff(probes)[-1] > np.diff(probes)[0]  # backed off
    cost = {1: 2.0, 2: 20.0}  # loaded: parallel steps wait a time slice
    loaded = []
    for _ in range(400):
        t = chooser.next()
        loaded.append(t)
        chooser.record(t, cost[t])
    assert chooser.best() == 1 and loaded[-100:].count(2) <= 2
    assert loaded.count(2) <= 20  # the switch took a few probes, then few more
    cost = {1: 1.0, 2: 0.6}  # quiet again
    for _ in range(2 * ThreadChooser.EXPLORE_MOST):
        t = chooser.next()
        chooser.record(t, cost[t])
    assert chooser.best() == 2


def test_a_simulation_keeps_the_users_thread_count():
    from foldcore import Simulation, patterns, thicken

    pattern = patterns.miura_one_crease(5, 5, width=0.6)
    mesh = thicken(pattern, 0.2)
    assert Simulation(mesh, pattern, threads=1).thread_chooser is None
    sim = Simulation(mesh, pattern)
    assert sim.thread_chooser is not None and sim.thread_chooser.most == sim.threads
