"""Contact: panels and hinge strips that never pass through each other.

:class:`ContactModel` gives the barrier energy of every pair of parts (rigid
panels, hinge strips) that contact keeps apart, its gradient and Hessian, and
the largest collision-free fraction of a step (:mod:`.barrier`);
:class:`PartSolids` holds the panels' closed prisms, the strips' surfaces and
the broad phase (:mod:`.solids`); :class:`Obstacle` a fixed mesh the parts
touch but never pass (:mod:`.obstacles`).
Strategies that take contact read ``model.contact``.
"""
from .barrier import ContactModel, ContactSettings, ContactState
from .obstacles import Obstacle, ObstacleError, read_obstacle
from .solids import PartSolids

__all__ = ["ContactModel", "ContactSettings", "ContactState", "Obstacle", "ObstacleError",
           "PartSolids", "read_obstacle"]
