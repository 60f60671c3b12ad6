"""Contact: panels that never pass through each other.

:class:`ContactModel` gives the barrier energy of every pair of rigid panels
that no crease joins, its gradient and Hessian, and the largest
collision-free fraction of a step (:mod:`.barrier`); :class:`PanelSolids`
holds the panels' closed prisms and the broad phase (:mod:`.solids`);
:class:`Obstacle` a fixed mesh the panels touch but never pass
(:mod:`.obstacles`).
Strategies that take contact read ``model.contact``.
"""
from .barrier import ContactModel, ContactSettings, ContactState
from .obstacles import Obstacle, ObstacleError, read_obstacle
from .solids import PanelSolids

__all__ = ["ContactModel", "ContactSettings", "ContactState", "Obstacle", "ObstacleError",
           "PanelSolids", "read_obstacle"]
