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
"""
from __future__ import annotations

from contextlib import nullcontext

_controller = None  # threadpoolctl.ThreadpoolController, built on first use


def blas_on_one_thread(active: bool = True, refresh: bool = False):
    """Context manager: BLAS libraries on one thread inside, restored after.

    Parameters
    ----------
    active : bool
        False returns a no-op context (a serial simulation does not compete).
    refresh : bool
        Re-scan the loaded BLAS libraries (~1 ms) instead of reusing the list
        found on first use; a library loaded since would otherwise be missed.
    """
    global _controller
    if not active:
        return nullcontext()
    if _controller is None or refresh:
        from threadpoolctl import ThreadpoolController

        _controller = ThreadpoolController()
    return _controller.limit(limits=1, user_api="blas")
