"""thicken(): crease pattern → ThickMesh (paper §2.2).

Each crease becomes a strip of its hinge width, split into sub-strips; the
panels are the faces inset by half the width of each side; everything is
extruded to thickness H, mid-plane at z = 0, and panels and strips share their
points (docs/architecture.md#thickening-a-crease-pattern). Units: mm, angles in
degrees at this API.
"""
from __future__ import annotations

from .build import thicken
from .widths import MAX_SUBDIVISIONS, auto_subdivisions, minimum_hinge_width

__all__ = ["MAX_SUBDIVISIONS", "auto_subdivisions", "minimum_hinge_width", "thicken"]
