"""Exceptions a user can cause. The CLI turns each into one line and exit code 2."""


class FoldcoreError(Exception):
    """Base class of every error foldcore raises for bad user input."""


class PatternError(FoldcoreError, ValueError):
    """A crease pattern (or the file it came from) is malformed.

    The message names the source (file name or ``<pattern>``) and the offending
    item (vertex, edge, face or line index) so the user can find it.
    """


class PatternWarning(UserWarning):
    """A pattern was accepted after a change the user should know about
    (for example a clockwise face reversed to counter-clockwise)."""


class RunWarning(UserWarning):
    """A run ended in a state the user should look at: nothing driven, or converged
    with its targets missed (the model binds)."""


class KernelCacheWarning(UserWarning):
    """numba could not cache kernels where it normally does (a read-only install
    without a writable home); says which folder is used instead, or that kernels
    compile in every process, and how to choose with ``NUMBA_CACHE_DIR``."""


class MeshError(FoldcoreError, ValueError):
    """The thick mesh cannot be built (e.g. hinge widths too large for a face)."""


class SimulationError(FoldcoreError, ValueError):
    """A simulation was set up with inconsistent or out-of-range inputs."""
