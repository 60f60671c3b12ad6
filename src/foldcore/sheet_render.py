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
from .render import (EDGE_COLOUR, HINGE_COLOURS, PANEL_COLOUR, Renderer, behind_lines,
                     colour_limits, require_pyvista)


class SheetRenderer(Renderer):
    """An offscreen picture of a thin sheet; move it and take frames
    (:class:`foldcore.render.Renderer`'s ``update``, ``fit``, ``image``, ``save``).

    Parameters
    ----------
    pattern : CreasePattern, whose vertices the positions move
    triangles : (T, 3) int, the sheet's triangles (:class:`foldcore.sheet.Sheet`)
    size, view, padding, title : as :class:`~foldcore.render.Renderer`
    facets, creases : (T,) or (E,) float, optional
        Colour the triangles by ``facets`` (e.g. their strain), or the creases by
        ``creases`` (one per pattern edge, e.g. fold angles in degrees; the
        boundary stays black), with a colour bar titled ``scalar_name``; default
        the assignment colours. ``cmap`` and ``clim`` as the Renderer's.
    """

    def __init__(self, pattern, triangles, size=(1024, 768), view="iso", *, facets=None,
                 creases=None, scalar_name="value", cmap=None, clim=None,
                 padding: float = 0.04, title=None):
        self.triangles = np.asarray(triangles, dtype=np.int64)
        self.values = {"facets": facets, "creases": creases}
        super().__init__(pattern, None, size, view, scalar_name=scalar_name, cmap=cmap,
                         clim=clim, padding=padding, title=title)

    def _add_scene(self, scalars, scalar_name, cmap, clim, legend):
        """The triangles and, over them, the edges in their assignment colours (or
        either coloured by values, with a colour bar)."""
        pv = require_pyvista()
        x = np.column_stack([self.pattern.vertices, np.zeros(self.pattern.n_vertices)])
        faces = np.hstack([np.full((len(self.triangles), 1), 3), self.triangles]).ravel()
        surface = pv.PolyData(x.copy(), faces)
        facets, creases = self.values["facets"], self.values["creases"]
        shown = facets if facets is not None else creases
        if shown is not None:
            self.clim = tuple(float(c) for c in (clim or colour_limits(shown)))
        if facets is not None:
            surface.cell_data["value"] = np.asarray(facets, dtype=float)
            behind_lines(self.add_scalars(surface, scalar_name, cmap))
        else:
            behind_lines(self.plotter.add_mesh(surface, color=PANEL_COLOUR))
        lines = self._add_edges_of(pv, x, creases, scalar_name, cmap)
        self.moving, self.n_points = (surface, *lines), self.pattern.n_vertices

    def _add_edges_of(self, pv, x, creases, name, cmap) -> list:
        """The pattern's edges as lines, by assignment colour, or its creases by
        ``creases`` (the boundary black); the PolyData added."""
        kinds = np.asarray(self.pattern.assignments)
        edges = np.asarray(self.pattern.edges)
        groups = [(kinds == "B", EDGE_COLOUR, 1)]  # (which edges, colour or None: by value, width)
        if creases is None:
            groups += [(kinds == kind, colour, 2) for kind, colour in HINGE_COLOURS.items()]
        else:
            groups.append((kinds != "B", None, 3))
        added = []
        for chosen, colour, width in groups:
            if not chosen.any():
                continue
            lines = pv.PolyData(x.copy(), lines=np.hstack(
                [np.full((int(chosen.sum()), 1), 2), edges[chosen]]).ravel())
            if colour is None:
                lines.cell_data["value"] = np.asarray(creases, dtype=float)[chosen]
                self.add_scalars(lines, name, cmap, line_width=width)
            else:
                self.plotter.add_mesh(lines, color=colour, line_width=width)
            added.append(lines)
        return added


def render_sheet_png(pattern, triangles, positions, path, size=(1024, 768), view="iso",
                     padding: float = 0.04, **colouring) -> None:
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
    colouring : ``facets`` or ``creases`` values and their ``scalar_name``,
        ``cmap``, ``clim`` (:class:`SheetRenderer`); default assignment colours
    """
    with SheetRenderer(pattern, triangles, size, view, padding=padding, **colouring) as r:
        r.update(positions)
        r.fit()
        r.save(path)


def render_sheet_frames(pattern, triangles, positions, *, size=(640, 480), view="iso",
                        titles=None) -> list:
    """Each of ``positions`` ((N, 3) mm, one list entry per frame) rendered with one
    camera fitted to all of them (as :func:`foldcore.animate.render_frames`);
    ``titles``: text in the upper-left corner of each. A list of (height, width, 3)
    uint8."""
    from .animate import checked_frames, take_frames

    positions, titles = checked_frames(positions, titles)
    renderer = SheetRenderer(pattern, triangles, size, view,
                             title=titles[0] if titles else None)
    return take_frames(renderer, positions, titles, progress=False)


def render_sheet_result(result, path, size=(1024, 768), view="iso",
                        color_by: str = "none") -> None:
    """``foldcore render`` of a thin sheet's result file (a
    :class:`~foldcore.result_file.SheetResultFile`): its last folded frame's
    triangles (:func:`render_sheet_png`), creases in their assignment colours
    (``none``), or coloured by their fold angle (``angle``: degrees, valley > 0
    blue), or the facets by their strain (``strain``: each triangle's largest side
    strain against the flat sheet, :func:`foldcore.measure.facet_strains`).

    Raises
    ------
    PatternError
        ``strip-angle``: a thick sheet's sub-strips, which a thin sheet has not.
    """
    frame = result.frames[-1]
    if color_by == "strain":
        from .measure import facet_strains

        values = facet_strains(result.pattern, result.triangles, frame.positions)
        colouring = dict(facets=values, clim=colour_limits(values, signed=False),
                         cmap="viridis", scalar_name="facet strain (largest side)")
    elif color_by == "angle":
        colouring = dict(creases=frame.angles, cmap="RdBu", scalar_name="fold angle (deg)",
                         clim=colour_limits(frame.angles[np.isfinite(frame.angles)],
                                            signed=True))
    elif color_by != "none":
        raise PatternError(f"{result.source}: --color-by {color_by} colours a thick sheet's "
                           "hinge sub-strips; a thin sheet's result takes none, angle or "
                           "strain")
    else:
        colouring = {}
    render_sheet_png(result.pattern, result.triangles, frame.positions, path, size=size,
                     view=view, **colouring)
