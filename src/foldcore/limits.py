"""The ranges of the numbers foldcore accepts.

Lengths and stiffness factors: each window sits at least 10× inside the values at
which a hinge scene was seen to fold wrongly, stop, raise from SVD or CHOLMOD, or
go non-finite; ``tests/test_limits.py`` folds the corners of the window.
Coordinates relative to the sheet need no limit of their own. Counts and run
options (sub-strips, the thick mesh's size, the tolerance, the iteration
budget) are bounded so that a run's memory and its verdict stay meaningful;
every bound is far beyond what a real fold uses
(docs/architecture.md#accepted-ranges-of-inputs). NumPy is imported only by
the checks that need it: the command line reads these numbers at start-up.
"""
from __future__ import annotations

import math

from .errors import MeshError, PatternError

#: Thickness H accepted, × the sheet's extent.
THICKNESS_RATIO = (1e-6, 1e4)
#: Hinge widths W accepted, × the sheet's extent.
WIDTH_RATIO = (1e-8, 1e4)
#: Every length accepted (extent, thickness, widths), mm.
LENGTH_MM = (1e-6, 1e7)
#: Stiffness factors accepted (dimensionless).
STIFFNESS = (1e-6, 1e6)
#: Elastic cell lengths accepted, × the sheet's extent (and within :data:`LENGTH_MM`).
CELL_RATIO = (1e-4, 1e4)
#: Ground heights accepted: |z| at most this × the sheet's extent (and :data:`LENGTH_MM`).
GROUND_RATIO = 1e4
#: SVG stroke widths accepted (``foldcore export --stroke-width``), × the sheet's extent.
STROKE_RATIO = (1e-6, 1.0)
#: SVG margins accepted (``foldcore export --margin``), × the sheet's extent.
MARGIN_RATIO = (0.0, 10.0)
#: Sub-strips per hinge accepted when given (``"auto"`` chooses 2 … 16).
SUBDIVISIONS = (1, 64)
#: Vertices a thick mesh may have, estimated from the pattern and the options before
#: it is built: about 14 GB of memory for a fold at 1.4 kB a vertex; the largest
#: benchmark (a Miura 400 × 400) has 5.75 million.
MAX_MESH_VERTICES = 10_000_000
#: Of these, vertices inside elastic faces' cells: about 10 GB at the 20 kB a vertex
#: an elastic fold takes (a Miura 4 × 4 in 0.01 mm cells: 304 000 vertices, 6 GB).
MAX_ELASTIC_VERTICES = 500_000
#: Relative tolerances accepted (× the pattern's size): the tolerance bounds the
#: distance left to the equilibrium, and above 1e-2 a run reads "converged" degrees
#: short of it; below 1e-15 no float64 step or distance can be resolved.
TOLERANCE = (1e-15, 1e-2)
#: Iteration budget accepted per run: the report lists every iteration's energy
#: (10⁶ of them are about 20 MB of JSON).
MAX_ITERATIONS = 1_000_000
#: Default iteration budgets: a thick sheet's strategies take many cheap steps,
#: a thin sheet's Newton method tens (``solving.max_iterations`` = None).
THICK_BUDGET = 10_000
SHEET_BUDGET = 500
#: Larger extent, mm, of a FOLD sheet whose file declares no unit of length
#: (``frame_unit`` absent or ``"unit"``: most files are unit squares), unless a
#: size or a scale is given: a sheet of paper's order, on which millimetre
#: thicknesses and hinge widths are what they say.
UNITLESS_SHEET_MM = 100.0
#: Creases a run may be told to drive by id (``--drive``): more than a pattern of
#: any file the readers take has creases worth listing, and a list of them about
#: 40 MB.
MAX_DRIVEN = 1_000_000


def sheet_extent(vertices) -> float:
    """Largest side of the bounding box of the flat sheet's ``vertices`` (V, 2), mm."""
    import numpy as np

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
    import numpy as np

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


def check_mesh_size(vertices: float, elastic: float, where: str) -> None:
    """MeshError naming ``where`` when a thick mesh's estimated vertex count is above
    :data:`MAX_MESH_VERTICES`, or that of its elastic cells above
    :data:`MAX_ELASTIC_VERTICES` (or either is not a number)."""
    if not elastic <= MAX_ELASTIC_VERTICES:
        raise MeshError(f"{where}: the elastic cells would have about {elastic:.3g} "
                        f"vertices, more than the {MAX_ELASTIC_VERTICES:.3g} accepted; use "
                        "larger elastic cells")
    if not vertices <= MAX_MESH_VERTICES:
        raise MeshError(f"{where}: the thick mesh would have about {vertices:.3g} vertices, "
                        f"more than the {MAX_MESH_VERTICES:.3g} accepted; use fewer "
                        "sub-strips per hinge or larger elastic cells")


def check_inputs(pattern, thickness=None, hinge_width=None, stiffness=None,
                 elastic_cells=None, ground=None) -> None:
    """What ``foldcore simulate`` was given beyond the pattern file's own checks:
    the sheet's extent, the ``thickening.thickness``, ``thickening.hinge_width`` and
    ``thickening.elastic_cells`` options and ``solving.ground`` (mm) against the
    sheet's extent, and the file's stiffness factors; PatternError naming the file
    and option."""
    source = pattern.source
    extent = sheet_extent(pattern.vertices)
    if any(v is not None for v in (thickness, hinge_width, elastic_cells, ground)):
        check_extent(extent, source)
    if thickness is not None:
        check_thickness(thickness, pattern.vertices, "thickening.thickness", source)
    if hinge_width is not None:
        check_width(hinge_width, pattern.vertices, "thickening.hinge_width", source)
    if elastic_cells is not None:
        check_length(elastic_cells, CELL_RATIO, extent, "thickening.elastic_cells", source)
    if ground is not None:
        reach = min(GROUND_RATIO * extent, LENGTH_MM[1])
        if not abs(ground) <= reach:
            raise PatternError(f"{source}: solving.ground = {ground:g} mm is outside the "
                               f"accepted ±{reach:.3g} mm (±{GROUND_RATIO:g} × the sheet's "
                               f"extent {extent:g} mm, within ±{LENGTH_MM[1]:g} mm)")
    check_stiffness(stiffness, source)


def check_svg_sizes(stroke, margin, vertices, where: str) -> None:
    """An SVG's stroke width and margin (mm, None: the default) against
    :data:`STROKE_RATIO` and :data:`MARGIN_RATIO` of the sheet ``vertices``;
    PatternError naming ``where``."""
    extent = sheet_extent(vertices)
    if stroke is not None:
        check_length(stroke, STROKE_RATIO, extent, "SVG stroke width", where)
    if margin is not None and not 0 <= margin <= MARGIN_RATIO[1] * extent:
        raise PatternError(f"{where}: SVG margin = {margin:g} mm is outside the accepted "
                           f"0 … {MARGIN_RATIO[1] * extent:.3g} mm (0 … {MARGIN_RATIO[1]:g} × "
                           f"the sheet's extent {extent:g} mm)")
