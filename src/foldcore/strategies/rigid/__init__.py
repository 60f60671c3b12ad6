"""The ``rigid`` strategy and everything it uses: its engine and the engine's
collaborators, its options, its coarse twin, its numba kernels."""
from .options import RigidOptions
from .strategy import Rigid, at_rest, slack_creases

__all__ = ["Rigid", "RigidOptions", "at_rest", "slack_creases"]
