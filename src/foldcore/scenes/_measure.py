"""Measurements the scenes share (positions in mm, angles in degrees)."""
from __future__ import annotations

import numpy as np


def panel_normal(mesh, positions: np.ndarray, face: int) -> np.ndarray:
    """(3,) unit normal of a panel's best-fit plane (its top face's side)."""
    panels = mesh.groups[mesh.panel_group]
    ids = panels.indices[panels.slots(int(mesh.panel_of_face[face]))]
    top = positions[ids[: len(ids) // 2]]
    bottom = positions[ids[len(ids) // 2:]]
    centred = np.vstack([top, bottom]) - np.vstack([top, bottom]).mean(axis=0)
    normal = np.linalg.svd(centred)[2][2]
    return normal if (top.mean(axis=0) - bottom.mean(axis=0)) @ normal > 0 else -normal


def extent_along(positions: np.ndarray, direction: np.ndarray) -> float:
    """Extent (mm) of the points along a unit direction: max − min of x·d."""
    along = positions @ direction
    return float(along.max() - along.min())


def rounded(values, digits: int = 4) -> list:
    """JSON-ready list of floats (NaN → None) rounded to ``digits`` decimals."""
    return [None if not np.isfinite(v) else round(float(v), digits)
            for v in np.atleast_1d(np.asarray(values, dtype=float))]
