"""The folded solid of a result FOLD, part by part: an independent check of what a
run wrote (no foldcore code but the file's own keys). Each panel is the convex hull
of its faces' vertices (``foldcore:faces_face``), two panels' overlap the volume of
their hulls' intersection (manifold3d's exact boolean); two parts (a panel, or a
crease's hinge strip: ``foldcore:faces_edge``) cross where an edge of one passes
through a triangle of the other (Möller–Trumbore, written here)."""
from __future__ import annotations

from itertools import combinations

import numpy as np


def folded_frame(fold: dict) -> dict:
    (frame,) = [f for f in fold["file_frames"] if "foldedForm" in f.get("frame_classes", [])]
    return frame


def panel_points(frame: dict) -> dict:
    """{pattern face id: (k, 3) positions (mm) of the vertices of its faces}."""
    x = np.asarray(frame["vertices_coords"], dtype=float)
    ids: dict = {}
    for face, part in zip(frame["faces_vertices"], frame["foldcore:faces_face"]):
        if part is not None:
            ids.setdefault(part, set()).update(face)
    return {part: x[sorted(v)] for part, v in ids.items()}


def hull(points: np.ndarray):
    import manifold3d

    return manifold3d.Manifold.hull_points(np.ascontiguousarray(points, dtype=np.float64))


def panel_overlaps(frame: dict) -> list:
    """[(face a, face b, overlap volume mm³)] of every pair of panels whose hulls
    intersect in a positive volume."""
    hulls = {part: hull(points) for part, points in panel_points(frame).items()}
    out = []
    for a, b in combinations(sorted(hulls), 2):
        volume = (hulls[a] ^ hulls[b]).volume()
        if volume > 0.0:
            out.append((a, b, float(volume)))
    return out


def crossing_edges(x: np.ndarray, triangles: np.ndarray) -> list:
    """[(edge (i, j), triangle index)] of the triangles' edges that pass through a
    triangle sharing no vertex with them (Möller–Trumbore; a touch within 1e-12 of
    the extent does not count). x (N, 3), triangles (T, 3) int."""
    edges = np.unique(np.sort(np.vstack([triangles[:, [0, 1]], triangles[:, [1, 2]],
                                         triangles[:, [2, 0]]]), axis=1), axis=0)
    a, b, c = (x[triangles[:, k]] for k in range(3))
    e1, e2 = b - a, c - a
    eps = 1e-12 * np.ptp(x, axis=0).max()
    found = []
    for i, j in edges:
        far = np.flatnonzero(~np.any(triangles == i, axis=1) & ~np.any(triangles == j, axis=1))
        d = x[j] - x[i]
        p = np.cross(d, e2[far])
        det = np.einsum("ij,ij->i", e1[far], p)
        ok = np.abs(det) > 1e-300
        s = x[i] - a[far]
        u = np.einsum("ij,ij->i", s, p) / np.where(ok, det, 1.0)
        q = np.cross(s, e1[far])
        v = (q @ d) / np.where(ok, det, 1.0)
        t = np.einsum("ij,ij->i", e2[far], q) / np.where(ok, det, 1.0)
        margin = eps / np.linalg.norm(d)
        inside = ok & (u > margin) & (v > margin) & (u + v < 1 - margin) & \
            (t > margin) & (t < 1 - margin)
        found += [((int(i), int(j)), int(k)) for k in far[inside]]
    return found


def crossings(x: np.ndarray, triangles: np.ndarray) -> int:
    """How many edges of the triangles pass through a triangle sharing no vertex."""
    return len(crossing_edges(x, triangles))


def crossing_parts(frame: dict, fold: dict) -> set:
    """{(part, part)} of the folded solid's parts that cross, among those that meet at
    no vertex of the crease pattern (``fold``: the file's top level, its
    ``faces_vertices`` and ``edges_vertices``): a part is ("face", f) or ("edge", e)."""
    x = np.asarray(frame["vertices_coords"], dtype=float)
    triangles, part = [], []
    for loop, f, e in zip(frame["faces_vertices"], frame["foldcore:faces_face"],
                          frame["foldcore:faces_edge"]):
        if f is None and e is None:
            continue
        for k in range(1, len(loop) - 1):
            triangles.append([loop[0], loop[k], loop[k + 1]])
            part.append(("face", f) if f is not None else ("edge", e))
    triangles = np.array(triangles, dtype=np.int64)
    corners = {("face", f): set(v) for f, v in enumerate(fold["faces_vertices"])}
    corners.update({("edge", e): set(v) for e, v in enumerate(fold["edges_vertices"])})
    of_edge: dict = {}
    for tri, p in zip(triangles.tolist(), part):
        for i, j in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            of_edge.setdefault((min(i, j), max(i, j)), set()).add(p)
    out = set()
    for edge, k in crossing_edges(x, triangles):
        for p in of_edge[edge]:
            q = part[k]
            if p != q and not corners[p] & corners[q]:
                out.add(tuple(sorted((p, q))))
    return out
