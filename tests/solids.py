"""The folded solid of a result FOLD, part by part: an independent check of what a
run wrote (no foldcore code but the file's own keys). Each panel is the convex hull
of its faces' vertices (``foldcore:faces_face``), two panels' overlap the volume of
their hulls' intersection (manifold3d's exact boolean)."""
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
