"""thicken(): the steps from a crease pattern to its ThickMesh."""
from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np

from ..errors import MeshError, PatternWarning
from ..limits import check_mesh_size
from ..mesh import ThickMesh
from ..pattern import CreasePattern
from .cells import elastic_cells
from .geometry import PointTable
from .groups import crease_panels, hinge_group, panel_group, stretch_group
from .inputs import (check_stiffness, check_thickness, mesh_vertices, plate_counts,
                     resolve_stretch, split_elastic, strip_segments)
from .panels import panel_corners, panel_loops
from .strips import build_strips
from .widths import (automatic_widths, fit_widths, resolve_hinges, resolve_subdivisions,
                     resolve_widths)

__all__ = ["thicken"]


def thicken(pattern: CreasePattern, thickness: float, hinge_width=None,
            subdivisions="auto", bend_radius: float = 0.0, hinge=None,
            stiffness=None, stretch=None, elastic=None,
            cell_size: float | None = None) -> ThickMesh:
    """Build the thick prism mesh of a crease pattern (paper §2.2;
    docs/architecture.md#thickening-a-crease-pattern).

    Parameters
    ----------
    pattern : CreasePattern
    thickness : float
        Sheet thickness H, mm (> 0).
    hinge_width : float or (E,) array, optional
        Hinge width W per edge, mm; overrides the pattern's widths. NaN entries
        (and patterns without widths) use Eq. 7, W = (r + H/2)·θmax.
    subdivisions : int, (E,) ints or "auto"
        Sub-strips per hinge, each in 1..64 (:data:`foldcore.limits.SUBDIVISIONS`);
        "auto" uses :func:`auto_subdivisions`.
    bend_radius : float
        Inner bend radius r for Eq. 7 widths, mm.
    hinge : {"axis", "arc", "eq8", "slack"} or (E,) of them (None entries: default), optional
        Hinge kinematics per crease (default
        :data:`foldcore.hinges.DEFAULT_HINGE`; :mod:`foldcore.hinges`); FOLD
        files carry it as ``foldcore:edges_hinge``.
    stiffness : dict, optional
        ``{"panel": (F,) or float, "hinge": (E,) or float}`` factors (> 0,
        default 1) multiplying the elements' volume weights
        (docs/architecture.md#stiffness-factors).
    stretch : dict {edge id: Poisson ratio ν}, optional
        Creases made stretch hinges (§6.3, group ``stretch_hinge``, one strip
        each, passive until :meth:`foldcore.Simulation.set_stretch_ratios`);
        ν in [−1, 0.5].
    elastic : dict {face id: n, "auto", (n1, n2) or ("rings", n)}, "plates" or "facets", optional
        Elastic panels (§5.5), faces cut into cells: n cells for a bar (a
        quadrilateral with one crease side), an n1 × n2 grid for a plate, n
        rings for a facet; "plates" / "facets" for every face that can be one
        (docs/architecture.md#elastic-panels-bars-plates-and-facets).
    cell_size : float, optional
        Target cell length (mm) for ``"auto"`` counts.

    Returns
    -------
    ThickMesh

    Raises
    ------
    MeshError
        Among others, when the mesh would have more vertices than
        :data:`foldcore.limits.MAX_MESH_VERTICES`, or its elastic cells more than
        :data:`foldcore.limits.MAX_ELASTIC_VERTICES` (estimated before it is built).
    """
    sheet = _resolve(pattern, thickness, hinge_width, subdivisions, bend_radius, hinge,
                     stiffness, stretch)
    try:
        return _build(sheet, elastic, cell_size)
    except MeshError:  # a face or crease too small for automatic widths: narrow them
        narrowed = _narrowed(sheet, hinge_width, subdivisions)
        if narrowed is None:
            raise
    return _build(narrowed, elastic, cell_size)


def _build(sheet, elastic, cell_size) -> ThickMesh:
    """:func:`thicken`'s mesh of its resolved ``sheet``."""
    pattern = sheet.pattern
    table = PointTable()
    corners, corner_ids, steps = panel_corners(pattern, sheet.widths, table)
    bars, plates, facets = split_elastic(pattern, elastic)
    plates = plate_counts(pattern, plates, corners, cell_size)
    segments = strip_segments(pattern, plates, sheet.stretch, bars)
    check_mesh_size(*mesh_vertices(pattern, sheet.ks, segments, corners,
                                   (bars, plates, facets), cell_size), pattern.source)
    strip_points, inserts = build_strips(pattern, sheet.widths, sheet.ks, segments, corners,
                                         corner_ids, table)
    loops = panel_loops(corner_ids, inserts, steps)
    cells, built = elastic_cells(pattern, loops, corner_ids, strip_points, (bars, plates, facets),
                                 table, cell_size)
    return _assemble(sheet, np.array(table.coords), strip_points, loops, cells, segments, built)


class _Sheet(NamedTuple):
    """``thicken``'s arguments checked and resolved per edge."""

    pattern: CreasePattern
    thickness: float
    widths: np.ndarray  # (E,) hinge width, mm (NaN on boundary edges)
    hinges: np.ndarray  # (E,) hinge model name ("" on boundary edges)
    ks: np.ndarray  # (E,) sub-strips per hinge (1 on stretch hinges, 0 on boundary edges)
    share: np.ndarray | None  # (E,) share of Eq. 7's width kept (None: none narrowed)
    stretch: dict  # {crease: ν}
    stiffness: dict  # {"panel": factors, "hinge": factors}, as given


def _resolve(pattern, thickness, hinge_width, subdivisions, bend_radius, hinge, stiffness,
             stretch) -> _Sheet:
    """Check ``thicken``'s arguments and resolve widths, hinge models and sub-strips."""
    pattern.check_one_piece()
    pattern.check_no_dangling()
    check_thickness(pattern, thickness)
    check_stiffness(pattern, stiffness)
    widths = resolve_widths(pattern, thickness, hinge_width, bend_radius)
    hinges = resolve_hinges(pattern, hinge)
    ks = resolve_subdivisions(pattern, widths, thickness, subdivisions, hinges)
    stretch = resolve_stretch(pattern, stretch)
    ks[list(stretch)] = 1
    return _Sheet(pattern, thickness, widths, hinges, ks, None, stretch, stiffness or {})


def _narrowed(sheet: _Sheet, hinge_width, subdivisions) -> _Sheet | None:
    """The sheet with the automatic widths around faces and creases too small for them
    narrowed (said once; :func:`.widths.fit_widths`) and its sub-strips chosen again;
    None when no automatic width is in the way."""
    pattern = sheet.pattern
    share = fit_widths(pattern, sheet.widths, automatic_widths(pattern, hinge_width))
    if (share == 1.0).all():
        return None
    widths = sheet.widths * share
    ks = resolve_subdivisions(pattern, widths, sheet.thickness, subdivisions, sheet.hinges)
    ks[list(sheet.stretch)] = 1
    narrowed = np.flatnonzero(share < 1.0)
    warnings.warn(f"{pattern.source}: {len(narrowed)} hinge{'s' if len(narrowed) != 1 else ''} "
                  f"narrowed to fit small faces (edge {int(narrowed[0])}, …; down to "
                  f"{share.min():g} of Eq. 7's width): they bind before their full fold; "
                  "give thickening.hinge_width (mm) for others", PatternWarning, stacklevel=3)
    return sheet._replace(widths=widths, ks=ks, share=share)


def _assemble(sheet: _Sheet, points, strip_points, loops, cells, segments, built) -> ThickMesh:
    """The ThickMesh: element groups on the sheet's points (N, 2) mm, and what
    measures each crease."""
    pattern, thickness, stretch = sheet.pattern, sheet.thickness, sheet.stretch
    panels, panel_of_face = panel_group(pattern, points, loops, cells, thickness,
                                        sheet.stiffness.get("panel", 1.0))
    bending = {e: lines for e, lines in strip_points.items() if e not in stretch}
    strips, strips_of = hinge_group(pattern, points, bending, sheet.widths, sheet.ks, thickness,
                                    sheet.hinges, sheet.stiffness.get("hinge", 1.0))
    groups = {"rigid_panel": panels, "bending_hinge": strips}
    if stretch:
        groups["stretch_hinge"] = stretch_group(pattern, points, strip_points, stretch,
                                                sheet.widths, thickness,
                                                sheet.stiffness.get("hinge", 1.0))
    return ThickMesh(points=points, thickness=float(thickness), groups=groups,
                     panel_of_face=panel_of_face,
                     strips_of_crease=strips_of, hinge_width=sheet.widths, subdivisions=sheet.ks,
                     segments=segments, elastic=built, hinge_model=sheet.hinges,
                     crease_panels=crease_panels(pattern, points, cells, panel_of_face),
                     width_share=sheet.share)
