"""Keep BLAS threads from competing with numba's while a simulation iterates.

numpy's and scipy's OpenBLAS run large dot products (n > ~10⁴: the weighted
energy sum, L-BFGS's inner products, the rigid step's residual norms) on their
own threads, which keep spinning for a while after each call and take a core
from numba's parallel projection, which waits for its slowest thread. While a
:class:`~foldcore.simulation.Simulation` with more than one numba thread steps
(or a serial one with vectors of ``BLAS_GUARD_FROM`` entries or more), BLAS
runs on one thread (its calls there are vector operations that do not gain
from threads); the previous setting is restored on exit, so the user's own
BLAS work outside is unaffected. Caveat (numpy's and scipy's OpenBLAS): after
the main thread lowered the count, a raise requested from another Python
thread was ignored; so when the last guard to close runs in another thread
than the first one opened, BLAS may stay on one thread.

The thread count of each step (:func:`choose_threads`, :class:`ThreadChooser`)
and OpenMP's wait policy, which ``import foldcore`` sets to ``PASSIVE`` unless
the user set it (idle threads sleep instead of spinning; libgomp reads it once,
when it loads, so only if no OpenMP code was loaded before, and child processes
inherit it): why each, with the measurements, `docs/architecture.md#threads`.
"""
from __future__ import annotations

import logging
import threading
from contextlib import contextmanager, nullcontext
from statistics import median_low

import numpy as np

log = logging.getLogger(__name__)

# threadpoolctl.ThreadpoolController, built on first use: by then a Simulation
# exists, and building one loads numpy's and scipy's BLAS (checked)
_controller = None
_limiter = None  # the active limit while any guard is open
_depth = 0  # guards open in this process (nested, or from several Python threads)
_lock = threading.Lock()


def blas_on_one_thread(active: bool = True, refresh: bool = False):
    """Context manager: BLAS libraries on one thread inside, restored after.

    Guards nest and may overlap across Python threads: the first to open sets
    the limit, the last to close restores the setting found by the first.

    Parameters
    ----------
    active : bool
        False makes it a no-op (a serial simulation does not compete).
    refresh : bool
        Re-scan the loaded BLAS libraries (~1 ms) instead of reusing the list
        found on first use; a library loaded since would otherwise be missed.
        Only the outermost guard scans.
    """
    # inactive: a plain nullcontext, not a generator — serial simulations of
    # small meshes open one per step, at ~25 µs per iteration
    return _one_blas_thread(refresh) if active else nullcontext()


@contextmanager
def _one_blas_thread(refresh: bool):
    global _controller, _limiter, _depth
    with _lock:
        if _depth == 0:
            if _controller is None or refresh:
                from threadpoolctl import ThreadpoolController

                _controller = ThreadpoolController()
            _limiter = _controller.limit(limits=1, user_api="blas")
        _depth += 1
    try:
        yield
    finally:
        with _lock:
            _depth -= 1
            if _depth == 0:
                _limiter.restore_original_limits()
                _limiter = None


class ThreadChooser:
    """Numba threads per step for a simulation whose count the user did not fix:
    the faster of one thread and ``most``, by the steps' own times.

    On a quiet machine the parallel projection is faster from a few hundred
    element-vertex slots on; on a shared one, a parallel loop waits at its end
    for a thread the scheduler took away, so a step can cost a time slice
    (``bench/load.py``; `docs/architecture.md#threads`). Now and then one
    step runs with the other count: after ``EXPLORE_EVERY`` steps, an interval
    that doubles (up to ``EXPLORE_MOST``) each time the other count was still
    the slower, so a loaded machine pays for few parallel probes; each count's
    cost is the median of its last ``WINDOW`` step times (a probe's time alone
    for the probed count: its older ones ran under another load), and the
    cheaper one runs the others (the parallel count until the serial one has
    been timed). The choice follows the load as it changes.
    """

    EXPLORE_EVERY = 16
    EXPLORE_MOST = 512
    WINDOW = 7

    def __init__(self, most: int):
        self.most = int(most)
        self._times = {1: [], self.most: []}
        self._interval = self.EXPLORE_EVERY
        self._until = self.EXPLORE_EVERY  # steps to the next probe of the other count
        self._probing = None  # the count a probe step is running with

    def next(self) -> int:
        """The thread count for the next step (call :meth:`record` after it)."""
        if self.most == 1:
            return 1
        best = self.best()
        self._until -= 1
        if self._until <= 0:
            self._probing = 1 if best == self.most else self.most
            return self._probing
        return best

    def best(self) -> int:
        """The count whose recent steps were cheaper (``most`` until both are timed)."""
        serial, parallel = self._times[1], self._times[self.most]
        if not serial or not parallel:
            return self.most
        return 1 if median_low(serial) < median_low(parallel) else self.most

    def record(self, threads: int, seconds: float) -> None:
        """The wall time of a step run with ``threads`` (a probe's replaces that count's
        history: its earlier steps ran under another load)."""
        times = self._times[threads]
        if self._probing is not None:
            times.clear()
        times.append(float(seconds))
        del times[:-self.WINDOW]
        if self._probing is not None:  # back off while the probed count stays slower
            lost = self.best() != self._probing
            log.debug("threads: a step on %d thread(s) was %s; %d run the next steps",
                      self._probing, "slower" if lost else "faster", self.best())
            self._interval = min(2 * self._interval, self.EXPLORE_MOST) if lost \
                else self.EXPLORE_EVERY
            self._until, self._probing = self._interval, None


#: Element-vertex slots below which a simulation's kernels run on one thread (a
#: parallel launch costs more than it saves there): `docs/architecture.md#threads`.
SERIAL_BELOW_SLOTS = 500
#: Vector length (3 × vertices) from which a serial simulation's steps hold BLAS to
#: one thread too (OpenBLAS threads dot products of such vectors).
BLAS_GUARD_FROM = 10_000


def choose_threads(threads, slots: int) -> int:
    """numba threads of a simulation: the user's count (checked, 1..numba's), or by
    default one thread below ``SERIAL_BELOW_SLOTS`` element-vertex slots, else all."""
    import numba

    from .errors import SimulationError

    if threads is None:
        return 1 if slots < SERIAL_BELOW_SLOTS else numba.config.NUMBA_NUM_THREADS
    if not (isinstance(threads, (int, np.integer)) and
            1 <= threads <= numba.config.NUMBA_NUM_THREADS):
        raise SimulationError(f"threads must be an integer in "
                              f"1..{numba.config.NUMBA_NUM_THREADS}, got {threads!r}")
    return int(threads)
