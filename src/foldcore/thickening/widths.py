"""Hinge widths (mm), hinge models and sub-strip counts per edge."""
from __future__ import annotations

import numpy as np

from ..errors import MeshError
from ..hinges import DEFAULT_HINGE, HINGE_MODELS
from ..limits import SUBDIVISIONS

__all__ = ["MAX_SUBDIVISIONS", "auto_subdivisions", "minimum_hinge_width", "resolve_hinges",
           "resolve_subdivisions", "resolve_widths"]

MAX_SUBDIVISIONS = 16


def minimum_hinge_width(thickness: float, max_angle_deg, bend_radius: float = 0.0):
    """Eq. 7: hinge width W = (r + H/2)·θmax in mm (θmax given in degrees)."""
    return (bend_radius + 0.5 * thickness) * np.radians(max_angle_deg)


def auto_subdivisions(width, thickness: float, max_angle_deg, hinge=DEFAULT_HINGE) -> np.ndarray:
    """Sub-strips per hinge chosen from its largest fold angle.

    k = max(2, ceil(θmax / 45°)); for Eq. 8 hinges (``hinge="eq8"``, per
    hinge or for all) k is then raised, up to :data:`MAX_SUBDIVISIONS`, while
    θmax/k > 2·atan(W/(k·H)), the most one sub-strip can bend
    (docs/architecture.md#sub-strips-per-hinge).

    Parameters
    ----------
    width : float or (n,) float
        Hinge width W, mm.
    thickness : float
        Sheet thickness H, mm.
    max_angle_deg : float or (n,) float
        Largest fold angle θmax, degrees.
    hinge : str or (n,) str
        Hinge model of each hinge.

    Returns
    -------
    (n,) int64
    """
    width = np.atleast_1d(np.asarray(width, dtype=float))
    theta = np.radians(np.broadcast_to(max_angle_deg, width.shape))
    eq8 = np.broadcast_to(np.asarray(hinge) == "eq8", width.shape)
    k = np.maximum(2, np.ceil(np.degrees(theta) / 45.0 - 1e-9)).astype(np.int64)
    for _ in range(MAX_SUBDIVISIONS):
        short = (theta / k > 2 * np.arctan(width / (k * thickness))) & (k < MAX_SUBDIVISIONS) & eq8
        if not short.any():
            break
        k[short] += 1
    return k


def resolve_widths(pattern, thickness, hinge_width, bend_radius) -> np.ndarray:
    """(E,) hinge width per edge, mm (NaN on boundary edges), validated: ``hinge_width``
    or the pattern's, Eq. 7 where NaN."""
    widths = np.array(pattern.widths, dtype=float)
    if hinge_width is not None:
        widths = np.broadcast_to(np.asarray(hinge_width, dtype=float), widths.shape).copy()
    auto = np.isnan(widths)
    widths[auto] = minimum_hinge_width(thickness, pattern.max_angles[auto], bend_radius)
    widths[pattern.assignments == "B"] = np.nan
    bad = np.flatnonzero(~(widths > 0) & (pattern.assignments != "B"))
    if len(bad):
        raise MeshError(f"{pattern.source}: edge {bad[0]}: hinge width must be > 0 mm")
    return widths


def resolve_hinges(pattern, hinge) -> np.ndarray:
    """(E,) hinge model name per edge ("" for boundary edges), validated."""
    names = np.broadcast_to(np.asarray(DEFAULT_HINGE if hinge is None else hinge, dtype=object),
                            (pattern.n_edges,)).copy()
    names[[n is None for n in names]] = DEFAULT_HINGE
    bad = [e for e, n in enumerate(names) if n not in HINGE_MODELS]
    if bad:
        raise MeshError(f"{pattern.source}: edge {bad[0]}: unknown hinge model "
                        f"{names[bad[0]]!r} (available: {', '.join(HINGE_MODELS)})")
    names[pattern.assignments == "B"] = ""
    return names.astype(str)


def resolve_subdivisions(pattern, widths, thickness, subdivisions, hinges) -> np.ndarray:
    """(E,) int64 sub-strips per edge (0 on boundary edges): ``subdivisions`` validated,
    or :func:`auto_subdivisions` for ``"auto"`` / None."""
    crease = pattern.assignments != "B"
    if subdivisions is None or (isinstance(subdivisions, str) and subdivisions == "auto"):
        k = np.zeros(pattern.n_edges, dtype=np.int64)
        k[crease] = auto_subdivisions(widths[crease], thickness, pattern.max_angles[crease],
                                      hinges[crease])
        return k
    k = np.broadcast_to(np.asarray(subdivisions), (pattern.n_edges,))
    lo, hi = SUBDIVISIONS
    if not np.issubdtype(k.dtype, np.integer) or ((k[crease] < lo) | (k[crease] > hi)).any():
        raise MeshError(f"{pattern.source}: subdivisions must be integers in {lo}..{hi} or "
                        f"'auto', got {subdivisions!r}")
    return np.where(crease, k, 0).astype(np.int64)
