"""A folded form's crease pattern, unfolded from its faces.

A FOLD file may give only a folded form: 3D coordinates off any plane, or 2D
coordinates of a flat-folded model (its layers on each other), with no
``vertices_flatUnfoldCoords``. Its faces still know their own shapes, so the
flat sheet is found as a paper folder would find it: the first face is laid
flat where it is (rotated into z = 0 when it lies in 3D), and each face next to
a placed one is laid beside it, turned about their shared edge until it lies in
the plane on the other side of that edge (mirrored if it had been folded over
onto the same side), face by face across the sheet (breadth first).

This is possible only where the faces allow it: each face must be flat (its
vertices within :data:`PLANE_TOLERANCE` of its plane, relative to the sheet's
extent), and a vertex reached through two chains of faces must land at one
point (within :data:`AGREEMENT` of the extent); otherwise the file is refused,
naming the face or the vertex. Overlaps of the unfolded faces are left to the
pattern's checks (:class:`foldcore.pattern.CreasePattern`). Lengths: the
file's, scaled to mm.
"""
from __future__ import annotations

from collections import deque

import numpy as np

from ..errors import PatternError

#: Largest distance of a face's vertex from the face's plane, share of the extent
#: (coordinates written to 6 or 7 significant digits and rounding along a chain of
#: faces stay far below it; a visibly bent face does not).
PLANE_TOLERANCE = 1e-4
#: Largest distance between two placements of one vertex, share of the extent.
AGREEMENT = 1e-4


def unfold_faces(xyz: np.ndarray, faces, source: str) -> np.ndarray:
    """(V, 2) flat coordinates of the folded form ``xyz`` (V, 2 or 3), mm, from its
    ``faces`` (lists of vertex ids, one connected sheet); module docstring.

    Raises
    ------
    PatternError
        No faces, a face that is not flat, a vertex two faces place apart, or a
        vertex on no face.
    """
    if not faces:
        raise PatternError(f"{source}: a folded form without faces_vertices cannot be "
                           "unfolded; give vertices_flatUnfoldCoords or a 2D crease pattern")
    if xyz.shape[1] == 3 and not (xyz[:, 2] != 0).any():
        xyz = xyz[:, :2]
    flat_given = xyz.shape[1] == 2      # each face keeps its own x, y (mirrored or not)
    xyz = np.column_stack([xyz, np.zeros(len(xyz))]) if flat_given else xyz
    extent = max(float(np.ptp(xyz, axis=0).max()), 1e-300)
    loops = [np.asarray(f, dtype=np.int64) for f in faces]
    local = [xyz[loop, :2] if flat_given else _face_in_plane(xyz, loop, f, extent, source)
             for f, loop in enumerate(loops)]
    flat = np.full((len(xyz), 2), np.nan)
    placed = np.zeros(len(loops), dtype=bool)
    neighbours = _face_neighbours(loops)
    for root in range(len(loops)):
        if placed[root]:
            continue
        _place(flat, loops[root], local[root], root, extent, source)
        placed[root] = True
        queue = deque([root])
        while queue:
            f = queue.popleft()
            for g, (a, b) in neighbours[f]:
                if not placed[g]:
                    _place(flat, loops[g], _beside(local[g], loops[g], flat, loops[f], a, b),
                           g, extent, source)
                    placed[g] = True
                    queue.append(g)
    lost = np.flatnonzero(np.isnan(flat).any(axis=1))
    if len(lost):
        raise PatternError(f"{source}: vertex {int(lost[0])} is on no face, so the folded "
                           "form cannot be unfolded there")
    return flat


def _face_in_plane(xyz, loop, f: int, extent: float, source: str) -> np.ndarray:
    """(n, 2) the face's vertices (in 3D) in its own plane, counter-clockwise about its
    normal (Newell's)."""
    p = xyz[loop]
    normal = np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)
    length = float(np.linalg.norm(normal))
    if length == 0.0:
        raise PatternError(f"{source}: face {f} has no area, so the folded form cannot "
                           "be unfolded")
    normal /= length
    off = float(np.abs((p - p.mean(axis=0)) @ normal).max())
    if off > PLANE_TOLERANCE * extent:
        raise PatternError(f"{source}: face {f} is not flat (a vertex off its plane by "
                           f"{off:g}), so the folded form cannot be unfolded")
    if abs(normal[2]) > 1.0 - 1e-12:     # in a plane z = const: x, y, turned to face up
        return p[:, :2] if normal[2] > 0 else p[:, :2] * [1.0, -1.0]
    u = np.cross([0.0, 0.0, 1.0], normal)
    u /= np.linalg.norm(u)
    return np.column_stack([p @ u, p @ np.cross(normal, u)])


def _face_neighbours(loops) -> list:
    """Per face, [(face, (a, b))]: the faces across each of its sides."""
    side_faces: dict = {}
    for f, loop in enumerate(loops):
        for a, b in zip(loop, np.roll(loop, -1)):
            side_faces.setdefault((min(a, b), max(a, b)), []).append(f)
    out = [[] for _ in loops]
    for (a, b), fs in side_faces.items():
        for f in fs:
            out[f] += [(g, (a, b)) for g in fs if g != f]
    return out


def _beside(local, loop, flat, placed_loop, a: int, b: int) -> np.ndarray:
    """(n, 2) face ``loop``'s ``local`` shape moved so its side a–b lies on the placed
    a–b, on the other side of it from the placed face (mirrored where needed)."""
    ia, ib = int(np.flatnonzero(loop == a)[0]), int(np.flatnonzero(loop == b)[0])
    target = flat[b] - flat[a]
    other = flat[placed_loop].mean(axis=0) - flat[a]
    for mirror in (1.0, -1.0):
        shape = local * [1.0, mirror]
        source = shape[ib] - shape[ia]
        angle = np.arctan2(target[1], target[0]) - np.arctan2(source[1], source[0])
        c, s = np.cos(angle), np.sin(angle)
        moved = (shape - shape[ia]) @ np.array([[c, s], [-s, c]]) + flat[a]
        side = _cross(target, moved.mean(axis=0) - flat[a]) * _cross(target, other)
        if side < 0:
            return moved
    return moved


def _cross(u: np.ndarray, v: np.ndarray) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


def _place(flat, loop, points, f: int, extent: float, source: str) -> None:
    """Put face ``f``'s ``points`` at its vertices; a vertex already placed elsewhere
    is refused, naming it."""
    known = ~np.isnan(flat[loop]).any(axis=1)
    gap = np.linalg.norm(flat[loop[known]] - points[known], axis=1)
    far = np.flatnonzero(gap > AGREEMENT * extent)
    if len(far):
        v = int(loop[known][far[0]])
        raise PatternError(f"{source}: vertex {v} unfolds to two places ({gap[far[0]]:g} "
                           f"apart, face {f} and a face before it): the folded form's faces "
                           "do not make one flat sheet; give vertices_flatUnfoldCoords")
    flat[loop[~known]] = points[~known]
