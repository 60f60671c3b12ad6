"""Keep BLAS threads from competing with numba's while a simulation iterates.

numpy's and scipy's OpenBLAS run large dot products (n > ~10⁴: the weighted
energy sum, L-BFGS's inner products, the rigid step's residual norms) on their
own threads, which keep spinning for a while after each call. On a 2-core
machine they then take a core from numba's parallel projection, which waits
for its slowest thread: measured on Miura 50 × 50 (2-core Xeon), the hinge
kernel took 16 ms on two numba threads against 10.6 ms on one; with BLAS held
to one thread, 5.2 ms. While a :class:`~foldcore.simulation.Simulation` with
more than one numba thread steps, BLAS runs on one thread (its calls there are
vector operations that do not gain from threads); the previous setting is
restored on exit, so the user's own BLAS work outside is unaffected.
Caveat (measured with numpy's and scipy's OpenBLAS here): after the main
thread lowered the count, a raise requested from another Python thread was
ignored; so when the last guard to close runs in another thread than the
first one opened, BLAS may stay on one thread.
"""
from __future__ import annotations

import threading
from contextlib import contextmanager, nullcontext

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
