"""The ranges of the numbers foldcore accepts: the arithmetic survives inside them.

Each window sits at least 10× inside the values at which a hinge scene was seen to
fold wrongly, stop, raise from SVD or CHOLMOD, or go non-finite
(docs/architecture.md#accepted-ranges-of-inputs); ``tests/test_limits.py`` folds the
corners of the window. Coordinates relative to the sheet need no limit of
their own.
"""
from __future__ import annotations

import math

import numpy as np

from .errors import PatternError

#: Thickness H accepted, × the sheet's extent.
THICKNESS_RATIO = (1e-6, 1e4)
#: Hinge widths W accepted, × the sheet's extent.
WIDTH_RATIO = (1e-8, 1e4)
#: Every length accepted (extent, thickness, widths), mm.
LENGTH_MM = (1e-6, 1e7)
#: Stiffness factors accepted (dimensionless).
STIFFNESS = (1e-6, 1e6)


def sheet_extent(vertices) -> float:
    """Largest side of the bounding box of the flat sheet's ``vertices`` (V, 2), mm."""
    v = np.asarray(vertices, dtype=float).reshape(-1, 2)
    return float(np.ptp(v, axis=0).max()) if len(v) else 0.0


def check_extent(extent: float, where: str) -> None:
    """PatternError unless the sheet's extent (mm) is within :data:`LENGTH_MM`."""
    lo, hi = LENGTH_MM
    if not lo <= extent <= hi:
        raise PatternError(f"{where}: the sheet is {extent:g} mm across, outside the accepted "
                           f"{lo:g} … {hi:g} mm (wrong units?)")


def length_window(ratio: tuple[float, float], extent: float) -> tuple[float, float]:
    """The accepted (low, high) mm of a length given as ``ratio`` × ``extent``,
    clipped to :data:`LENGTH_MM`."""
    return max(ratio[0] * extent, LENGTH_MM[0]), min(ratio[1] * extent, LENGTH_MM[1])


def check_length(value: float, ratio: tuple[float, float], extent: float, what: str,
                 where: str) -> None:
    """PatternError naming ``where`` and ``what`` unless ``value`` (mm) is in the window.

    Parameters
    ----------
    value : float
        mm.
    ratio : (float, float)
        :data:`THICKNESS_RATIO` or :data:`WIDTH_RATIO`.
    extent : float
        The sheet's extent, mm (:func:`sheet_extent`).
    what, where : str
        The item (``"foldcore:thickness"``, ``"hinge width"``) and the file or option.
    """
    lo, hi = length_window(ratio, extent)
    if not (math.isfinite(value) and lo <= value <= hi):
        raise PatternError(f"{where}: {what} = {value:g} mm is outside the accepted "
                           f"{lo:.3g} … {hi:.3g} mm ({ratio[0]:g} … {ratio[1]:g} × the "
                           f"sheet's extent {extent:g} mm, within {LENGTH_MM[0]:g} … "
                           f"{LENGTH_MM[1]:g} mm)")


def check_thickness(thickness: float, vertices, what: str, where: str) -> None:
    """The sheet's extent and the thickness (mm) against :data:`LENGTH_MM` and
    :data:`THICKNESS_RATIO`; PatternError naming ``where`` and ``what``."""
    extent = sheet_extent(vertices)
    check_extent(extent, where)
    check_length(thickness, THICKNESS_RATIO, extent, what, where)


def check_width(width: float, vertices, what: str, where: str) -> None:
    """A hinge width (mm) against :data:`WIDTH_RATIO` of the sheet ``vertices``.

    Skipped when the sheet's extent is itself out of :data:`LENGTH_MM` (the
    pattern or :func:`check_extent` refuses that, naming the right item).
    """
    extent = sheet_extent(vertices)
    if LENGTH_MM[0] <= extent <= LENGTH_MM[1]:
        check_length(float(width), WIDTH_RATIO, extent, what, where)


def check_stiffness(stiffness: dict | None, where: str) -> None:
    """FOLD stiffness factors (``{"hinge": (E,), "panel": (F,)}``) within :data:`STIFFNESS`."""
    keys = {"hinge": ("foldcore:edges_stiffness", "edge"),
            "panel": ("foldcore:faces_stiffness", "face")}
    lo, hi = STIFFNESS
    for kind, values in (stiffness or {}).items():
        values = np.atleast_1d(np.asarray(values, dtype=float))
        bad = np.flatnonzero(~((values >= lo) & (values <= hi)))
        if len(bad):
            key, item = keys.get(kind, (kind, "item"))
            i = int(bad[0])
            raise PatternError(f"{where}: {key}[{i}] ({item} {i}) = {values[i]:g} is outside "
                               f"the accepted stiffness factors {lo:g} … {hi:g}")


def check_inputs(pattern, thickness=None, hinge_width=None, stiffness=None) -> None:
    """What ``foldcore simulate`` was given beyond the pattern file's own checks:
    the sheet's extent, the ``thickening.thickness`` and ``thickening.hinge_width`` options (mm)
    and the file's stiffness factors; PatternError naming the file and option."""
    source = pattern.source
    if thickness is not None or hinge_width is not None:
        check_extent(sheet_extent(pattern.vertices), source)
    if thickness is not None:
        check_thickness(thickness, pattern.vertices, "thickening.thickness", source)
    if hinge_width is not None:
        check_width(hinge_width, pattern.vertices, "thickening.hinge_width", source)
    check_stiffness(stiffness, source)
