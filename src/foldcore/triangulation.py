"""Simple polygons cut into triangles by mapbox-earcut, checked to cover their area.

Used for the thick solid's caps (:mod:`foldcore.surface`), the contact
solids and the thin sheet's facets (:mod:`foldcore.sheet`). Units: mm.
"""
from __future__ import annotations

import mapbox_earcut
import numpy as np

from .files import ExportError

#: Relative tolerance of a triangulation's area to its polygon's (mm² per mm²).
AREA_TOLERANCE = 1e-9


class TriangulationError(ExportError):
    """A face's polygon cannot be triangulated into its own area (not simple)."""


def triangulate_polygon(xy, face: int | None = None) -> np.ndarray:
    """Triangles of a simple polygon, (n−2, 3) int64 local indices (mapbox-earcut).

    Parameters
    ----------
    xy : (n, 2) float
        Vertices in order, mm (either orientation; collinear points allowed).
    face : int, optional
        The face's index, named in the error.

    Returns
    -------
    (n−2, 3) int64
        Each triangle in the polygon's own orientation; every vertex is used.

    Raises
    ------
    TriangulationError
        The triangles do not cover exactly the polygon's area, or leave a vertex
        out (a polygon that is not simple, or degenerate).
    """
    return triangulate_polygons([xy], None if face is None else [face])[0]


def triangulate_polygons(polygons, faces=None) -> list:
    """:func:`triangulate_polygon` of many polygons, checked all at once.

    Parameters
    ----------
    polygons : sequence of (n_i, 2) float
        mm.
    faces : sequence of int, optional
        The index named in the error of each polygon (default: its position).

    Returns
    -------
    list of (n_i − 2, 3) int64, local indices in each polygon's orientation.
    """
    local = [np.asarray(xy, dtype=np.float64) for xy in polygons]
    if not local:
        return []
    sizes = np.array([len(xy) for xy in local], dtype=np.int64)
    faces = np.arange(len(local)) if faces is None else np.asarray(faces)
    small = np.flatnonzero(sizes < 3)
    if len(small):
        raise TriangulationError(_not_simple(faces[small[0]], local[small[0]], (), 0.0))
    # each polygon relative to its first vertex: small coordinates, exact areas
    local = [np.ascontiguousarray(xy - xy[0]) for xy in local]
    tris = [mapbox_earcut.triangulate_float64(xy, np.array([len(xy)], dtype=np.uint32))
            .reshape(-1, 3).astype(np.int64) for xy in local]
    flip, bad, covered = _covers(local, sizes, tris)
    if bad.any():
        i = int(np.argmax(bad))
        raise TriangulationError(_not_simple(faces[i], local[i], tris[i], covered[i]))
    return [t[:, ::-1] if f else t for t, f in zip(tris, flip)]


def _covers(local: list, sizes: np.ndarray, tris: list):
    """Per polygon: whether earcut's triangles need reversing into its orientation, whether
    they fail to be n−2 of one winding covering its area (relative
    :data:`AREA_TOLERANCE`), and the area they cover (mm²); (P,) bool, bool, float."""
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    xy = np.vstack(local)
    count = np.array([len(t) for t in tris], dtype=np.int64)
    owner = np.repeat(np.arange(len(local)), count)
    v = xy[np.vstack(tris) + np.repeat(starts, count)[:, None]]
    ab, ac = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
    twice = ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0]
    following = np.arange(len(xy)) + 1
    following[starts + sizes - 1] = starts               # each polygon closes on itself
    polygon = np.repeat(np.arange(len(local)), sizes)
    area2 = np.bincount(polygon, xy[:, 0] * xy[following, 1] - xy[following, 0] * xy[:, 1],
                        minlength=len(local))
    flip = np.bincount(owner, twice, minlength=len(local)) * area2 < 0
    wound = twice * np.where(flip == (area2 >= 0), -1.0, 1.0)[owner]   # > 0 once flipped
    wrong = np.bincount(owner, wound < 0, minlength=len(local)) > 0
    covered = 0.5 * np.bincount(owner, np.abs(twice), minlength=len(local))
    extent = (np.maximum.reduceat(xy, starts) - np.minimum.reduceat(xy, starts)).max(axis=1)
    area = 0.5 * np.abs(area2)
    tolerance = AREA_TOLERANCE * (area + sizes * extent ** 2 * 1e-6)
    bad = (count != sizes - 2) | wrong | ~(np.abs(covered - area) <= tolerance)  # NaN: bad
    return flip, bad, covered


def _not_simple(face, xy: np.ndarray, tris, covered: float) -> str:
    """The message of a polygon (n, 2) mm whose triangles ``tris`` fail the checks."""
    n = len(xy)
    area = abs(_shoelace(xy)) if n >= 3 else 0.0
    left = np.setdiff1d(np.arange(n), np.asarray(tris, dtype=np.int64).ravel())
    detail = f"; vertex {int(left[0])} left out" if len(left) else ""
    return (f"cannot triangulate face {face}: its {n}-vertex polygon of {area:.6g} mm² is "
            f"not simple ({len(tris)} triangle(s) covering {covered:.6g} mm²{detail})")


def slit_free_loops(xy: np.ndarray, loop: np.ndarray) -> list:
    """A face's loop cut into loops without slits, each a simple polygon for earcut.

    Where a crease ends inside a face, the face's loop runs out along it to its
    tip and back (``…, b, t, b, …``), which ear clipping does not take. Each
    tip is joined by a straight segment to the nearest vertex of the loop it
    sees (met once in the loop; the segment crosses no side and runs inside
    the face): the loop is cut in two along it, each running along the slit
    once. The segments are new diagonals of the face.

    Parameters
    ----------
    xy : (V, 2) float, mm (any frame), indexed by the loop's ids
    loop : (n,) int, counter-clockwise

    Returns
    -------
    list of (n_i,) int loops, counter-clockwise; ``[loop]`` when it has no slit.
    """
    pending, done = [np.asarray(loop)], []
    while pending:
        here = pending.pop()
        tips = np.flatnonzero(np.roll(here, 1) == np.roll(here, -1))
        if not len(tips) or len(here) < 4:
            done.append(here)
            continue
        i = int(tips[0])
        j = _seen_from(xy, here, i)
        if j is None:
            done.append(here)  # earcut's check then names the face
            continue
        lo, hi = min(i, j), max(i, j)
        pending += [here[lo:hi + 1], np.concatenate([here[hi:], here[:lo + 1]])]
    return done


def _seen_from(xy: np.ndarray, loop: np.ndarray, i: int):
    """Position in ``loop`` of the nearest vertex met once in it that the tip at
    position ``i`` sees inside the face, or None."""
    ids, counts = np.unique(loop, return_counts=True)
    once = np.isin(loop, ids[counts == 1])
    once[[(i - 1) % len(loop), i, (i + 1) % len(loop)]] = False
    tip = xy[loop[i]]
    a, b = xy[loop], xy[np.roll(loop, -1)]
    for k in np.flatnonzero(once)[np.argsort(np.linalg.norm(xy[loop[once]] - tip, axis=1))]:
        w = xy[loop[k]]
        apart = (loop != loop[i]) & (loop != loop[k]) & (np.roll(loop, -1) != loop[i]) \
            & (np.roll(loop, -1) != loop[k])
        if not segments_meet(tip, w, a[apart], b[apart]).any() \
                and _inside(0.5 * (tip + w), xy[loop]):
            return int(k)
    return None


def segments_meet(p, q, a, b) -> np.ndarray:
    """(m,) bool: segment p–q (2,) meets segment a[k]–b[k] ((m, 2) each; touching
    counts)."""
    def orient(u, v, w):
        return np.sign((v[..., 0] - u[..., 0]) * (w[..., 1] - u[..., 1])
                       - (v[..., 1] - u[..., 1]) * (w[..., 0] - u[..., 0]))

    o1, o2 = orient(p, q, a), orient(p, q, b)
    o3, o4 = orient(a, b, p), orient(a, b, q)
    d = np.asarray(q, dtype=float) - p
    along_a, along_b = (a - p) @ d, (b - p) @ d     # on one line: do their spans overlap?
    overlap = (np.maximum(along_a, along_b) >= 0) & (np.minimum(along_a, along_b) <= d @ d)
    return np.where((o1 == 0) & (o2 == 0), overlap, (o1 * o2 <= 0) & (o3 * o4 <= 0))


def _inside(point, ring: np.ndarray) -> bool:
    """Whether ``point`` lies inside the closed ``ring`` (n, 2) (even–odd rule)."""
    x, y = point
    a, b = ring, np.roll(ring, -1, axis=0)
    spans = (a[:, 1] > y) != (b[:, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        cross_x = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    return bool(np.count_nonzero(spans & (cross_x > x)) % 2)


def _shoelace(xy: np.ndarray) -> float:
    """Signed area of a polygon (n, 2), counter-clockwise > 0."""
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(x @ np.roll(y, -1) - np.roll(x, -1) @ y)
