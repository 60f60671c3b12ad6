"""Elastic plates: a quadrilateral face cut into a grid of quads that conforms with the
strips along its sides (docs/architecture.md#elastic-panels-bars-plates-and-facets)."""
from __future__ import annotations

import numpy as np

from ..errors import MeshError
from .geometry import chord_params, cross2d, edge_of, polygon_area

__all__ = ["plate_cells"]


def plate_cells(pattern, loops, corner_ids, plates, table, strip_pieces) -> dict:
    """{face: [cell loops]}: each plate a grid of quads conforming with its outline.

    The outline's four geometric corners split it into sides whose points
    become grid points, opposite sides evened out (:func:`_equal_counts`);
    interior points: Coons patch of the four sides. The cell at the middle of
    the first crease side comes first (it measures the face).

    Parameters
    ----------
    pattern : CreasePattern
    loops, corner_ids : list
        Each panel's footprint point ids and its inset corners' point ids.
    plates : dict
        {face: (n1, n2)} resolved cell counts.
    table : PointTable
    strip_pieces : set of frozenset
        Pairs of consecutive point ids along the strips' sides.
    """
    cells = {}
    for f, counts in plates.items():
        sides = _plate_sides(pattern, f, loops[f], corner_ids[f], table, strip_pieces, counts)
        grid = _coons_grid(sides, table)
        n1, n2 = grid.shape[0] - 1, grid.shape[1] - 1
        quads = {(i, j): _distinct([grid[i, j], grid[i + 1, j], grid[i + 1, j + 1],
                                    grid[i, j + 1]])
                 for i in range(n1) for j in range(n2)}
        for key, quad in quads.items():
            if polygon_area(np.array([table.coords[k] for k in quad])) <= 0:
                raise MeshError(f"{pattern.source}: elastic plate on face {f}: cell {key} of "
                                "its grid is folded over (outline too far from a "
                                "quadrilateral); use fewer cells")
        first = _measuring_cell(pattern, f, n1, n2)
        cells[f] = [quads[first]] + [q for key, q in quads.items() if key != first]
    return cells


def _distinct(loop: list) -> list:
    """A cell loop without repeated points (a corner where two grid lines meet makes
    a quad a triangle)."""
    return [p for k, p in enumerate(loop) if p != loop[k - 1]]


def _plate_sides(pattern, f, loop, corners, table, strip_pieces, counts) -> list:
    """Point ids along the four sides of a plate's outline, geometric corner to
    corner, opposite sides with equal counts (see :func:`plate_cells`); two
    opposite sides without strip points are cut into their count (n1 or n2)
    of equal pieces."""
    xy = np.array([table.coords[i] for i in loop])
    turn = cross2d(xy - np.roll(xy, 1, axis=0), np.roll(xy, -1, axis=0) - xy)
    scale = float(np.ptp(xy, axis=0).max())
    bends = np.flatnonzero(np.abs(turn) > 1e-9 * scale ** 2)
    if len(bends) != 4:
        raise MeshError(f"{pattern.source}: elastic plate on face {f}: its inset outline has "
                        f"{len(bends)} corners, a grid needs 4")
    inset = np.array([table.coords[c] for c in corners])
    order = [int(bends[np.argmin(np.linalg.norm(xy[bends] - c, axis=1))]) for c in inset]
    if len(set(order)) != 4:
        raise MeshError(f"{pattern.source}: elastic plate on face {f}: cannot match its "
                        "outline's corners to the face's")
    sides = []
    for s in range(4):
        a, b = order[s], order[(s + 1) % 4]
        sides.append([loop[(a + k) % len(loop)] for k in range((b - a) % len(loop) + 1)])
    bare = [len(side) == 2 for side in sides]
    for s in range(4):  # two opposite sides without strip points: equal pieces
        n = counts[s % 2]
        if bare[s] and bare[(s + 2) % 4] and n > 1:
            sides[s] = table.between(sides[s][0], sides[s][1], np.arange(1, n) / n)
    for s in (0, 1):
        sides[s], sides[s + 2] = _equal_counts(pattern, f, s, sides[s], sides[s + 2], table,
                                               strip_pieces)
    return sides


def _equal_counts(pattern, f, s, near, far, table, strip_pieces) -> tuple[list, list]:
    """Opposite sides (``far`` runs the other way) with as many points each: a side
    without a strip copies the other's positions; otherwise the gaps between a
    corner and a strip end are split (the longest first); a side without gaps
    repeats the corner facing the other's gap (its cells there are triangles)."""
    face = pattern.faces[f]
    strip = [pattern.assignments[edge_of(pattern, face[k], face[(k + 1) % 4])] != "B"
             for k in (s, s + 2)]
    far_fwd = far[::-1]
    for _ in range(4 * (len(near) + len(far))):
        if len(near) == len(far_fwd):
            return near, far_fwd[::-1]
        short_is_near = len(near) < len(far_fwd)
        short, long_, short_strip = ((near, far_fwd, strip[0]) if short_is_near
                                     else (far_fwd, near, strip[1]))
        refined = _refined(short, long_, short_strip, table, strip_pieces)
        if refined is None:  # no gap to split: the long side's extra piece meets a corner
            gap_first = frozenset((long_[0], long_[1])) not in strip_pieces
            refined = [short[0]] + short if gap_first else short + [short[-1]]
        short = refined
        near, far_fwd = (short, far_fwd) if short_is_near else (near, short)
    raise MeshError(f"{pattern.source}: elastic plate on face {f}: cannot even sides {s} "
                    f"and {s + 2}")


def _refined(side, other, has_strip, table, strip_pieces):
    """``side`` with one more point: at the other side's next relative position if it
    has no strip, else splitting its longest end gap; None if it cannot."""
    if not has_strip:
        return table.between(side[0], side[-1],
                             chord_params(np.array([table.coords[i] for i in other]))[1:-1])
    pts = np.array([table.coords[i] for i in side])
    ends = [(float(np.linalg.norm(pts[1] - pts[0])), 0),
            (float(np.linalg.norm(pts[-1] - pts[-2])), len(side) - 2)]
    ends = [(length, k) for length, k in ends if len(side) > 2 and length > 0]
    gaps = [(length, k) for length, k in ends
            if frozenset((side[k], side[k + 1])) not in strip_pieces]
    if not gaps:
        return None
    _, k = max(gaps)
    middle = table.add(0.5 * (pts[k] + pts[k + 1]))
    return side[:k + 1] + [middle] + side[k + 1:]


def _coons_grid(sides, table) -> np.ndarray:
    """(n1 + 1, n2 + 1) point ids: the four sides on the border, interior points by a
    Coons patch of the sides over their chord-length parameters."""
    b0 = np.array([table.coords[i] for i in sides[0]])
    b1 = np.array([table.coords[i] for i in sides[1]])
    b2 = np.array([table.coords[i] for i in sides[2][::-1]])
    b3 = np.array([table.coords[i] for i in sides[3][::-1]])
    n1, n2 = len(b0) - 1, len(b1) - 1
    u = 0.5 * (chord_params(b0) + chord_params(b2))
    v = 0.5 * (chord_params(b3) + chord_params(b1))
    c0, c1, c2, c3 = b0[0], b0[-1], b2[-1], b2[0]
    grid = np.empty((n1 + 1, n2 + 1), dtype=np.int64)
    grid[:, 0], grid[n1, :] = sides[0], sides[1]
    grid[:, n2], grid[0, :] = sides[2][::-1], sides[3][::-1]
    for i in range(1, n1):
        for j in range(1, n2):
            p = ((1 - v[j]) * b0[i] + v[j] * b2[i] + (1 - u[i]) * b3[j] + u[i] * b1[j]
                 - ((1 - u[i]) * (1 - v[j]) * c0 + u[i] * (1 - v[j]) * c1
                    + u[i] * v[j] * c2 + (1 - u[i]) * v[j] * c3))
            grid[i, j] = table.add(p)
    return grid


def _measuring_cell(pattern, f: int, n1: int, n2: int) -> tuple[int, int]:
    """Grid index (i, j) of the cell at the middle of the face's first crease side."""
    face = pattern.faces[f]
    middle = {0: (n1 // 2, 0), 1: (n1 - 1, n2 // 2), 2: (n1 // 2, n2 - 1), 3: (0, n2 // 2)}
    for side in range(4):
        if pattern.assignments[edge_of(pattern, face[side], face[(side + 1) % 4])] != "B":
            return middle[side]
    return (0, 0)
