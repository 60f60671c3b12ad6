"""Offscreen picture of a folded thin sheet (pyvista, imported only inside functions).

The sheet's triangles in light grey, its creases drawn over them as lines in
the assignment colours of :mod:`foldcore.render` (valley blue, mountain red,
unassigned amber, flat grey) and the boundary in black; the same camera
presets and orthographic fit as the thick solid's pictures.
"""
from __future__ import annotations

import numpy as np

from . import files
from .errors import PatternError
from .files import ExportError
from .render import (BACKGROUND, EDGE_COLOUR, HINGE_COLOURS, PANEL_COLOUR, behind_lines,
                     check_size, fit_camera, require_pyvista, view_vectors)


def render_sheet_png(pattern, triangles, positions, path, size=(1024, 768), view="iso",
                     padding: float = 0.04) -> None:
    """Render the thin sheet at ``positions`` to a PNG file, offscreen, atomically.

    Parameters
    ----------
    pattern : CreasePattern, whose vertices the positions move
    triangles : (T, 3) int, the sheet's triangles (:class:`foldcore.sheet.Sheet`)
    positions : (N, 3) float, mm, one per pattern vertex
    path : str or os.PathLike, the PNG (appears only when complete)
    size : (int, int), width and height in pixels
    view : {"iso", "top", "front", "side"} or (3,) array, see :mod:`foldcore.render`
    padding : float, margin around the sheet, fraction of its extent
    """
    size = check_size(size)
    direction, up = view_vectors(view)
    pv = require_pyvista()
    x = np.asarray(positions, dtype=float)
    faces = np.hstack([np.full((len(triangles), 1), 3), triangles]).ravel()
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    try:
        plotter.set_background(BACKGROUND)
        behind_lines(plotter.add_mesh(pv.PolyData(x, faces), color=PANEL_COLOUR))
        kinds = np.asarray(pattern.assignments)
        for kind, colour in {"B": EDGE_COLOUR, **HINGE_COLOURS}.items():
            edges = np.asarray(pattern.edges)[kinds == kind]
            if len(edges):
                lines = np.hstack([np.full((len(edges), 1), 2), edges]).ravel()
                plotter.add_mesh(pv.PolyData(x, lines=lines), color=colour,
                                 line_width=2 if kind != "B" else 1)
        fit_camera(plotter.camera, x, direction, up, size[0] / size[1], (0.0, 1.0, 0.0, 1.0),
                   padding)
        files.check_folder(path, ExportError)
        plotter.render()
        with files.atomic_path(path, suffix=".png") as tmp:
            plotter.screenshot(tmp)
    finally:
        plotter.close()


def render_sheet_result(result, path, size=(1024, 768), view="iso",
                        color_by: str = "none") -> None:
    """``foldcore render`` of a thin sheet's result file (a
    :class:`~foldcore.result_file.SheetResultFile`): its last folded frame's
    triangles, creases in their assignment colours (:func:`render_sheet_png`).

    Raises
    ------
    PatternError
        ``color_by`` other than "none": the colourings are of a thick sheet's
        hinge strips, which a thin sheet has not.
    """
    if color_by != "none":
        raise PatternError(f"{result.source}: --color-by {color_by} colours a thick sheet's "
                           "hinge strips; a thin sheet's result is drawn with its creases "
                           "in their assignment colours (--color-by none)")
    render_sheet_png(result.pattern, result.triangles, result.frames[-1].positions, path,
                     size=size, view=view)
