"""Hinge strips: each crease widened to its hinge width, cut square where its panels'
corners lie, split into sub-strips across and segments along it."""
from __future__ import annotations

import numpy as np

from ..errors import MeshError
from .geometry import left_normal, vector_length
from .panels import corner_lookup

__all__ = ["build_strips"]


def build_strips(pattern, widths, ks, segments, corners, corner_ids, table) -> tuple[dict, list]:
    """Every crease's strip points, added to ``table`` crease by crease.

    Parameters
    ----------
    pattern : CreasePattern
    widths : (E,) float
        Hinge width per edge, mm.
    ks, segments : (E,) int
        Sub-strips across and segments along each crease's strip.
    corners, corner_ids : list
        Each face's inset corners ((m, 2) mm) and their point ids
        (:func:`.panels.panel_corners`).
    table : PointTable

    Returns
    -------
    strip_points : dict
        {crease: (k + 1) lists of m + 1 point ids}: line 0 the left side, line
        k the right one, each from end a to end b.
    inserts : list of dict
        Per face, {corner place: ids of strip points inserted after it}.
    """
    place = corner_lookup(pattern)
    inserts: list[dict] = [dict() for _ in pattern.faces]
    scale = float(np.ptp(pattern.vertices, axis=0).max())
    strip_points = {}
    for e in pattern.creases:
        lines = _strip_lines(pattern, e, widths[e], ks[e], _strip_cuts(pattern, e, corners, place),
                             int(segments[e]))
        sides = _attach_strip_sides(pattern, e, lines, corners, corner_ids, place, table, inserts,
                                    scale)
        inner = [[table.add(p) for p in lines[j]] for j in range(1, ks[e])]
        strip_points[int(e)] = [sides[0]] + inner + [sides[ks[e]]]
    return strip_points, inserts


def short_creases(pattern, corners) -> np.ndarray:
    """(E,) bool: the creases whose strip the panels' ``corners`` cut back past its
    length (at acute corners, a panel's inset corner lies along the crease)."""
    place = corner_lookup(pattern)
    lengths = pattern.edge_lengths()
    out = np.zeros(pattern.n_edges, dtype=bool)
    for e in pattern.creases:
        out[e] = _cut_away(_strip_cuts(pattern, e, corners, place), lengths[e])
    return out


def _cut_away(cuts: tuple[float, float], length: float) -> bool:
    """Whether a crease ``length`` mm long keeps no strip between its end ``cuts`` (mm)."""
    return cuts[0] + cuts[1] >= length * (1 - 1e-9)


def _strip_cuts(pattern, e, corners, place) -> tuple[float, float]:
    """Distances (mm) from each crease end to where its strip starts (≥ 0); ``place``:
    :func:`.panels.corner_lookup`."""
    a, b = pattern.edges[e]
    pa, pb = pattern.vertices[a], pattern.vertices[b]
    u = (pb - pa) / vector_length(pb - pa)
    cuts = []
    for end, point, direction in ((a, pa, u), (b, pb, -u)):
        along = [float((corners[f][place[(int(f), int(end))]] - point) @ direction)
                 for f in pattern.edge_faces[e]]
        cuts.append(max(along + [0.0]))
    return cuts[0], cuts[1]


def _strip_lines(pattern, e, width, k, cuts, segments: int = 1):
    """(k+1, m+1, 2) array: for each line across the strip, its m+1 points from end a
    to end b (m = ``segments``, equal lengths; 1: just the two ends).

    Line 0 is the left side (left face), line k the right side.
    """
    a, b = pattern.edges[e]
    pa, pb = pattern.vertices[a], pattern.vertices[b]
    length = vector_length(pb - pa)
    if _cut_away(cuts, length):
        raise MeshError(f"{pattern.source}: edge {e} ({length:.6g} mm) is too short for the "
                        "hinge widths around it; use narrower hinges")
    u = (pb - pa) / length
    n = left_normal(u)
    start, stop = pa + cuts[0] * u, pb - cuts[1] * u
    t_along = np.arange(segments + 1)[:, None] / segments
    ends = start + t_along * (stop - start)
    ends[-1] = stop  # exactly the end (the path is compared across units to 1e-9)
    t = 0.5 * width * (1 - 2 * np.arange(k + 1) / k)
    return ends[None, :, :] + t[:, None, None] * n[None, None, :]


def _close(p, q, scale) -> bool:
    return vector_length(p - q) <= 1e-9 * scale


def _attach_strip_sides(pattern, e, lines, corners, corner_ids, place, table, inserts, scale):
    """Ids of the strip's side points (a → b), shared with (or inserted into) its panels
    (``place``: :func:`.panels.corner_lookup`).

    A side's end points are the panel's corners where they coincide, else new
    points inserted into the panel's loop; its intermediate points (a strip
    split into segments along the crease) are always inserted, in loop order.
    """
    a, b = pattern.edges[e]
    f_left, f_right = pattern.edge_faces[e]
    side_ids = {}
    for side, face, first in ((0, f_left, a), (len(lines) - 1, f_right, b)):
        i = place[(int(face), int(first))]
        j = (i + 1) % len(pattern.faces[face])
        pts = lines[side] if side == 0 else lines[side][::-1]  # in the face's loop order
        got = []
        for n, point in enumerate(pts):
            corner = i if n == 0 else (j if n == len(pts) - 1 else None)
            if corner is not None and _close(point, corners[face][corner], scale):
                got.append(corner_ids[face][corner])
            else:
                got.append(table.add(point))
                inserts[face].setdefault(i, []).append(got[-1])
        side_ids[side] = got if side == 0 else got[::-1]
    return side_ids
