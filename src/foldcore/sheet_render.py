"""Offscreen pictures of a folded thin sheet (pyvista, imported only inside functions).

The sheet's triangles in light grey, its creases drawn over them as lines in
the assignment colours of :mod:`foldcore.render` (valley blue, mountain red,
unassigned amber, flat grey) and the boundary in black; the same camera
presets, orthographic fit, titles and frames as the thick solid's pictures
(:class:`SheetRenderer` is a :class:`foldcore.render.Renderer` whose scene is
the sheet), so an animation of a thin sheet is made as a thick one's is.
"""
from __future__ import annotations

import numpy as np

from .errors import PatternError
from .render import (EDGE_COLOUR, HINGE_COLOURS, PANEL_COLOUR, Renderer, RenderError,
                     behind_lines, require_pyvista)


class SheetRenderer(Renderer):
    """An offscreen picture of a thin sheet; move it and take frames
    (:class:`foldcore.render.Renderer`'s ``update``, ``fit``, ``image``, ``save``).

    Parameters
    ----------
    pattern : CreasePattern, whose vertices the positions move
    triangles : (T, 3) int, the sheet's triangles (:class:`foldcore.sheet.Sheet`)
    size, view, padding, title : as :class:`~foldcore.render.Renderer`
    """

    def __init__(self, pattern, triangles, size=(1024, 768), view="iso", *,
                 padding: float = 0.04, title=None):
        self.triangles = np.asarray(triangles, dtype=np.int64)
        super().__init__(pattern, None, size, view, padding=padding, title=title)

    def _add_scene(self, scalars, scalar_name, cmap, clim, legend):
        """The triangles and, over them, the edges in their assignment colours."""
        pv = require_pyvista()
        x = np.column_stack([self.pattern.vertices, np.zeros(self.pattern.n_vertices)])
        faces = np.hstack([np.full((len(self.triangles), 1), 3), self.triangles]).ravel()
        surface = pv.PolyData(x.copy(), faces)
        behind_lines(self.plotter.add_mesh(surface, color=PANEL_COLOUR))
        moving = [surface]
        kinds = np.asarray(self.pattern.assignments)
        for kind, colour in {"B": EDGE_COLOUR, **HINGE_COLOURS}.items():
            edges = np.asarray(self.pattern.edges)[kinds == kind]
            if len(edges):
                lines = pv.PolyData(x.copy(),
                                    lines=np.hstack([np.full((len(edges), 1), 2), edges]).ravel())
                self.plotter.add_mesh(lines, color=colour, line_width=2 if kind != "B" else 1)
                moving.append(lines)
        self.moving, self.n_points = tuple(moving), self.pattern.n_vertices


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
    with SheetRenderer(pattern, triangles, size, view, padding=padding) as r:
        r.update(positions)
        r.fit()
        r.save(path)


def render_sheet_frames(pattern, triangles, positions, *, size=(640, 480), view="iso",
                        titles=None) -> list:
    """Each of ``positions`` ((N, 3) mm, one list entry per frame) rendered with one
    camera fitted to all of them (as :func:`foldcore.animate.render_frames`);
    ``titles``: text in the upper-left corner of each. A list of (height, width, 3)
    uint8."""
    positions = [np.asarray(p, dtype=float) for p in positions]
    if not positions:
        raise RenderError("no frames to render")
    titles = None if titles is None else list(titles)
    if titles is not None and len(titles) != len(positions):
        raise RenderError(f"{len(titles)} titles for {len(positions)} frames")
    frames = []
    with SheetRenderer(pattern, triangles, size, view,
                       title=titles[0] if titles else None) as r:
        r.update(positions[0])
        r.fit(np.vstack(positions))
        for i, x in enumerate(positions):
            r.update(x, title=None if titles is None else titles[i])
            frames.append(r.image())
    return frames


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
