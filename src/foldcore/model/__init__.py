"""The model strategies drive (:class:`Model`): positions, element groups, targets,
pins, stops, and the local and global step of the paper's method."""
from .groups import GroupState
from .model import Model
from .pins import PositionTarget

__all__ = ["GroupState", "Model", "PositionTarget"]
