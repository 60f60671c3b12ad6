"""Panels: each face inset by half the hinge width of each of its sides (mitered, Eq. 1).

Where two sides of a face meet in line at a vertex but are inset by different
amounts (a crease that goes on as a cut or a boundary, as in pop-ups; collinear
creases of different widths) there is no mitre: the panel steps across at the
vertex, square to the sides. Its corner there is on the side leaving the
vertex, and the point on the side arriving is a *step* point of the outline
(a strip's end where that side is a crease, which the strip puts there;
:func:`panel_corners` adds it where the side is a boundary).
"""
from __future__ import annotations

import numpy as np

from ..errors import MeshError
from .geometry import cross2d

__all__ = ["corner_lookup", "inset_faces", "panel_corners", "panel_loops"]


def _inset_corners(p, offsets):
    """Mitered inward offsets of faces of one vertex count: one corner per face vertex.

    Parameters
    ----------
    p : (n, m, 2) float
        The faces' vertices, mm, counter-clockwise.
    offsets : (n, m) float
        Inward offset (mm) of the side leaving each vertex.

    Returns
    -------
    corners : (n, m, 2) float
        mm.
    mismatched : (n, m) bool
        Where the two sides meeting at a vertex are collinear but offset by
        different amounts (a step: ``corners`` holds the leaving side's point
        there, module docstring).
    """
    d = np.roll(p, -1, axis=1) - p
    u = d / np.linalg.norm(d, axis=2)[..., None]
    n = np.stack([-u[..., 1], u[..., 0]], axis=-1)
    u_in, n_in, off_in = np.roll(u, 1, axis=1), np.roll(n, 1, axis=1), np.roll(offsets, 1, axis=1)
    denom = cross2d(u_in, u)
    rhs = offsets[..., None] * n - off_in[..., None] * n_in
    straight = np.abs(denom) < 1e-9
    mismatched = straight & (np.abs(offsets - off_in) > 1e-9 * (1 + offsets))
    t = np.where(straight, 0.0, cross2d(rhs, u) / np.where(straight, 1.0, denom))
    mitred = p + off_in[..., None] * n_in + t[..., None] * u_in
    return np.where(mismatched[..., None], p + offsets[..., None] * n, mitred), mismatched


def _side_edges(pattern) -> list[np.ndarray]:
    """Per face, (m,) int: the edge along each side (side i from its vertex i to i + 1)."""
    lengths = pattern.face_loops.lengths
    return np.split(pattern.side_slots % pattern.n_edges, np.cumsum(lengths)[:-1])


def _inset_fails(p, corners) -> np.ndarray:
    """(n,) bool: faces (vertices ``p``, (n, m, 2) mm) whose inset ``corners`` turned a
    side around or make an invalid polygon (the panel vanished or turned inside out)."""
    import shapely

    side_old = np.roll(p, -1, axis=1) - p
    side_new = np.roll(corners, -1, axis=1) - corners
    flipped = (np.einsum("fij,fij->fi", side_old, side_new) <= 0).any(axis=1)
    return flipped | ~shapely.is_valid(shapely.polygons(corners))


def _faces_by_size(pattern) -> list:
    """The face ids grouped by vertex count (each group's insets computed at once)."""
    by_size: dict[int, list[int]] = {}
    for f, face in enumerate(pattern.faces):
        by_size.setdefault(len(face), []).append(f)
    return list(by_size.values())


def inset_faces(pattern, widths):
    """(corners, failing, steps): each face's inset corners ((m, 2) mm) by half of
    ``widths`` (E,) mm, the faces of one vertex count computed together
    (docs/architecture.md#building-the-thick-mesh-fast); (F,) bool, the faces whose
    panel that makes vanish or turn inside out; per face, {place in its loop: the
    step point (2,) mm before that corner} where its outline steps and the side
    arriving there is a boundary (module docstring)."""
    sides = _side_edges(pattern)
    half = np.nan_to_num(0.5 * np.asarray(widths, dtype=float))
    corners = [None] * len(pattern.faces)
    failing = np.zeros(len(pattern.faces), dtype=bool)
    steps = [dict() for _ in pattern.faces]
    boundary = pattern.assignments == "B"
    for group in _faces_by_size(pattern):
        p = pattern.vertices[np.array([pattern.faces[f] for f in group])]
        inset, uneven = _inset_corners(p, np.array([half[sides[f]] for f in group]))
        failing[group] = _inset_fails(p, inset)
        for row, f in enumerate(group):
            corners[f] = inset[row]
            for i in np.flatnonzero(uneven[row]):
                if boundary[sides[f][i - 1]]:  # the side arriving at vertex i
                    steps[f][int(i)] = p[row, i]
    return corners, failing, steps


def panel_corners(pattern, widths, table):
    """Each face's inset corners ((m, 2) mm, :func:`inset_faces`), their point ids
    (added to ``table`` face by face) and, per face, {place: [id of its step point]}
    (:func:`inset_faces`; for :func:`panel_loops`). Raises on the first face (by id)
    whose inset fails."""
    corners, failing, steps = inset_faces(pattern, widths)
    bad = np.flatnonzero(failing)
    if len(bad):
        raise MeshError(f"{pattern.source}: face {int(bad[0])}: hinge widths are too large "
                        "for this face (its panel would vanish or turn inside out); use "
                        "narrower hinges or a larger pattern")
    ids = [table.extend(c) for c in corners]
    step_ids = [{(i - 1) % len(corners[f]): [table.add(point)] for i, point in step.items()}
                for f, step in enumerate(steps)]
    return corners, ids, step_ids


def corner_lookup(pattern) -> dict:
    """{(face, vertex): the vertex's place in the face's loop} (its first)."""
    lookup = {}
    for f, face in enumerate(pattern.faces):
        for i, v in enumerate(face):
            lookup.setdefault((f, int(v)), i)
    return lookup


def panel_loops(corner_ids, inserts, steps) -> list:
    """Footprint point ids of each panel: its corners with the strip ends and the step
    points inserted (``inserts[f]``, ``steps[f]``: {corner place: ids inserted after
    it}; a step point comes last, nearest the next corner)."""
    loops = []
    for f, ids in enumerate(corner_ids):
        loop = []
        for i, cid in enumerate(ids):
            loop.append(cid)
            loop += inserts[f].get(i, []) + steps[f].get(i, [])
        loops.append(loop)
    return loops
