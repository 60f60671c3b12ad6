"""Panels: each face inset by half the hinge width of each of its sides (mitered, Eq. 1)."""
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
        different amounts (no corner; ``corners`` holds the side's point there).
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
    return p + off_in[..., None] * n_in + t[..., None] * u_in, mismatched


def _face_offsets(pattern, widths) -> list[np.ndarray]:
    """Inward offset (mm) of each side of each face: half its hinge width, 0 on B."""
    key = {}
    for e, (a, b) in enumerate(pattern.edges):
        key[(int(a), int(b))] = key[(int(b), int(a))] = e
    half = np.nan_to_num(0.5 * widths)
    return [np.array([half[key[(int(a), int(b))]] for a, b in zip(f, np.roll(f, -1))])
            for f in pattern.faces]


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
    """(corners, failing, mismatched): each face's inset corners ((m, 2) mm) by half of
    ``widths`` (E,) mm, the faces of one vertex count computed together
    (docs/architecture.md#building-the-thick-mesh-fast); (F,) bool, the faces whose
    panel that makes vanish or turn inside out; (F,) int, per face a vertex where two
    collinear sides have different widths (−1: none)."""
    offsets = _face_offsets(pattern, widths)
    corners = [None] * len(pattern.faces)
    failing = np.zeros(len(pattern.faces), dtype=bool)
    mismatched = np.full(len(pattern.faces), -1, dtype=np.int64)
    for group in _faces_by_size(pattern):
        p = pattern.vertices[np.array([pattern.faces[f] for f in group])]
        inset, uneven = _inset_corners(p, np.array([offsets[f] for f in group]))
        failing[group] = _inset_fails(p, inset)
        for row, f in enumerate(group):
            corners[f] = inset[row]
            if uneven[row].any():
                mismatched[f] = pattern.faces[f][int(np.flatnonzero(uneven[row])[0])]
    return corners, failing, mismatched


def panel_corners(pattern, widths, table):
    """Each face's inset corners ((m, 2) mm, :func:`inset_faces`) and their point ids
    (added to ``table`` face by face). Raises on the first face (by id) whose inset
    fails."""
    corners, failing, mismatched = inset_faces(pattern, widths)
    bad = np.flatnonzero(failing | (mismatched >= 0))
    if len(bad):
        f = int(bad[0])
        if mismatched[f] >= 0:
            raise MeshError(f"{pattern.source}: face {f}: two collinear sides at vertex "
                            f"{mismatched[f]} have different hinge widths")
        raise MeshError(f"{pattern.source}: face {f}: hinge widths are too large for this "
                        "face (its panel would vanish or turn inside out); use narrower "
                        "hinges or a larger pattern")
    return corners, [table.extend(c) for c in corners]


def corner_lookup(pattern) -> dict:
    """{(face, vertex): the vertex's place in the face's loop} (its first)."""
    lookup = {}
    for f, face in enumerate(pattern.faces):
        for i, v in enumerate(face):
            lookup.setdefault((f, int(v)), i)
    return lookup


def panel_loops(corner_ids, inserts) -> list:
    """Footprint point ids of each panel: its corners with the strip ends inserted
    (``inserts[f]``: {corner place: ids inserted after it})."""
    loops = []
    for f, ids in enumerate(corner_ids):
        loop = []
        for i, cid in enumerate(ids):
            loop.append(cid)
            loop += inserts[f].get(i, [])
        loops.append(loop)
    return loops
