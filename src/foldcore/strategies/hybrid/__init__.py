"""The ``hybrid`` strategy: rigid-body steps, then ``newton`` (or ``lbfgs``), and the
rigid start of meshes in rings."""
from .strategy import Hybrid, HybridOptions

__all__ = ["Hybrid", "HybridOptions"]
