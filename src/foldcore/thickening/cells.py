"""Elastic faces cut into cells: bars (strips beside one crease), plates (grids, in
:mod:`.plates`) and facets (rings) (docs/architecture.md#elastic-panels-bars-plates-and-facets)."""
from __future__ import annotations

import numpy as np

from ..errors import MeshError
from .geometry import area_centroid, cross2d, edge_of
from .inputs import cell_count
from .plates import plate_cells

__all__ = ["elastic_cells", "nearest"]


def elastic_cells(pattern, loops, corner_ids, strip_points, kinds, table,
                  cell_size) -> tuple[dict, dict]:
    """Cells of every elastic face, their points added to ``table``.

    Parameters
    ----------
    pattern : CreasePattern
    loops : list
        Footprint point ids of each panel (:func:`.panels.panel_loops`).
    corner_ids : list
        Point ids of each face's inset corners.
    strip_points : dict
        {crease: lines of point ids} (:func:`.strips.build_strips`).
    kinds : tuple of dict
        (bars, plates, facets) (:func:`.inputs.split_elastic`), plates' counts
        resolved (:func:`.inputs.plate_counts`).
    table : PointTable
    cell_size : float or None
        Target cell length for ``"auto"`` counts, mm.

    Returns
    -------
    cells : dict
        {face: [cell loops of point ids]}, the measuring cell of a plate or
        facet first.
    built : dict
        {face: cell count} of bars, {face: (n1, n2)} of plates, {face:
        ("rings", n)} of facets (``ThickMesh.elastic``).
    """
    bars, plates, facets = kinds
    cells = _bar_cells(pattern, loops, bars, table, cell_size)
    pieces = {frozenset(pair) for lines in strip_points.values() for side in (lines[0], lines[-1])
              for pair in zip(side, side[1:])}
    cells.update(plate_cells(pattern, loops, corner_ids, plates, table, pieces))
    ring_cells, rings = _facet_cells(pattern, loops, facets, table, cell_size)
    cells.update(ring_cells)
    built = {**{f: len(c) for f, c in cells.items() if f in bars}, **plates, **rings}
    return cells, built


def _bar_cells(pattern, loops, elastic, table, cell_size) -> dict:
    """{face: [cell loops]}: each elastic face cut into n quads parallel to its crease side."""
    cells = {}
    for f, n in elastic.items():
        loop = loops[f]
        side = _single_crease_side(pattern, f, len(loop))
        a, b, c, d = (loop[(side + k) % 4] for k in range(4))
        pa, pb, pc, pd = (table.coords[i] for i in (a, b, c, d))
        length = 0.5 * (np.linalg.norm(pd - pa) + np.linalg.norm(pc - pb))
        n = cell_count(n, length, cell_size, f"{pattern.source}: elastic panel on face {f}",
                       f"the number of cells must be a positive integer or 'auto', got {n!r}")
        side_a = table.between(a, d, np.arange(1, n) / n)
        side_b = table.between(b, c, np.arange(1, n) / n)
        cells[f] = [[side_a[j], side_b[j], side_b[j + 1], side_a[j + 1]] for j in range(int(n))]
    return cells


def _single_crease_side(pattern, f: int, n_points: int) -> int:
    """Index of the one crease side of quadrilateral face ``f`` (MeshError otherwise)."""
    face = pattern.faces[f]
    creases = [i for i, (u, v) in enumerate(zip(face, np.roll(face, -1)))
               if pattern.assignments[edge_of(pattern, u, v)] != "B"]
    if len(face) != 4 or n_points != 4 or len(creases) != 1:
        raise MeshError(f"{pattern.source}: elastic panel on face {f}: only quadrilateral "
                        "faces with exactly one crease side (a bar) can be subdivided, got "
                        f"{len(face)} sides with {len(creases)} creases")
    return creases[0]


def _facet_cells(pattern, loops, facets, table, cell_size) -> tuple[dict, dict]:
    """({face: [cell loops]}, {face: ("rings", n)}): each facet cut into n rings, scaled
    copies of its outline (the panel's own) toward its centroid: quads between
    rings, a fan of triangles at the centre. The face must be star-shaped from
    its centroid. The cell nearest the middle of its first crease side comes
    first (it measures the face)."""
    cells, counts = {}, {}
    for f, n in facets.items():
        loop = loops[f]
        xy = np.array([table.coords[i] for i in loop])
        centre = area_centroid(xy)
        where = f"{pattern.source}: elastic facet on face {f}"
        if np.any(cross2d(xy - centre, np.roll(xy, -1, axis=0) - centre) <= 0):
            raise MeshError(f"{where}: its outline is not star-shaped from its centroid, "
                            "so it cannot be cut into rings; keep it rigid")
        reach = float(np.linalg.norm(xy - centre, axis=1).max())
        n = cell_count(n, reach, cell_size, where,
                       f"the number of rings must be a positive integer or 'auto', got {n!r}")
        rings = [list(loop)] + [[table.add(centre + (1.0 - r / n) * (p - centre)) for p in xy]
                                for r in range(1, n)]
        middle = table.add(centre)
        m = len(loop)
        quads = [[rings[r][i], rings[r][(i + 1) % m], rings[r + 1][(i + 1) % m], rings[r + 1][i]]
                 for r in range(n - 1) for i in range(m)]
        fan = [[rings[-1][i], rings[-1][(i + 1) % m], middle] for i in range(m)]
        found = quads + fan
        first = _nearest_cell(pattern, f, found, table)
        cells[f] = [found[first]] + found[:first] + found[first + 1:]
        counts[f] = ("rings", n)
    return cells, counts


def _nearest_cell(pattern, f: int, cells: list, table) -> int:
    """Index of the cell whose centroid is nearest the middle of face ``f``'s first
    crease side (its first side if it has none)."""
    face = pattern.faces[f]
    sides = [(face[i], face[(i + 1) % len(face)]) for i in range(len(face))]
    creased = [s for s in sides if pattern.assignments[edge_of(pattern, *s)] != "B"]
    u, v = (creased or sides)[0]
    return nearest(cells, table.coords, 0.5 * (pattern.vertices[u] + pattern.vertices[v]))


def nearest(cells: list, coords, point) -> int:
    """Index of the cell (a loop of point ids into ``coords``) whose footprint centroid
    is nearest ``point`` (2,), mm."""
    centres = np.array([np.mean([coords[i] for i in c], axis=0) for c in cells])
    return int(np.argmin(np.linalg.norm(centres - point, axis=1)))
