"""Planar-graph helpers for crease patterns: faces from edges, edge crossings.

All coordinates are 2D (mm). Faces are returned counter-clockwise (seen from +z).
"""
from __future__ import annotations

import numpy as np

from .errors import PatternError


def signed_area(polygon: np.ndarray) -> float:
    """Signed area (mm²) of a closed polygon, positive when counter-clockwise.

    Parameters
    ----------
    polygon : (n, 2) float array
        Vertex coordinates in order; the closing edge is implied.
    """
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _sorted_neighbours(vertices: np.ndarray, edges: np.ndarray) -> list[np.ndarray]:
    """Neighbours of each vertex sorted by counter-clockwise angle."""
    nbrs: list[list[int]] = [[] for _ in range(len(vertices))]
    for u, v in edges:
        nbrs[u].append(v)
        nbrs[v].append(u)
    out = []
    for u, nb in enumerate(nbrs):
        nb = np.asarray(nb, dtype=np.int64)
        d = vertices[nb] - vertices[u]
        out.append(nb[np.argsort(np.arctan2(d[:, 1], d[:, 0]), kind="stable")])
    return out


def trace_faces(vertices: np.ndarray, edges: np.ndarray) -> list[np.ndarray]:
    """All face cycles of a connected plane graph, each as a vertex loop.

    Every directed edge lies on exactly one cycle, the face to its left.
    Interior faces come out counter-clockwise (positive area); the outer face
    comes out clockwise.

    Parameters
    ----------
    vertices : (V, 2) float array, mm
    edges : (E, 2) int array

    Returns
    -------
    list of (n,) int arrays
    """
    nbrs = _sorted_neighbours(vertices, edges)
    position = [{int(w): i for i, w in enumerate(nb)} for nb in nbrs]
    seen: set[tuple[int, int]] = set()
    cycles = []
    for a, b in np.concatenate([edges, edges[:, ::-1]]):
        start = (int(a), int(b))
        if start in seen:
            continue
        cycle, (u, v) = [], start
        while (u, v) not in seen:
            seen.add((u, v))
            cycle.append(u)
            around = nbrs[v]
            w = int(around[(position[v][u] - 1) % len(around)])  # next clockwise
            u, v = v, w
        cycles.append(np.asarray(cycle, dtype=np.int64))
    return cycles


def derive_faces(vertices: np.ndarray, edges: np.ndarray, boundary: np.ndarray,
                 source: str) -> list[np.ndarray]:
    """Panels of a connected crease pattern, derived from its planar graph.

    The outer face (clockwise) is dropped, and so are holes: counter-clockwise
    cycles made only of boundary edges that have a panel on their other side.

    Parameters
    ----------
    vertices : (V, 2) float array, mm
    edges : (E, 2) int array
    boundary : (E,) bool array
        True for edges assigned ``B``.
    source : str
        Name used in error messages.
    """
    cycles = trace_faces(vertices, edges)
    areas = np.array([signed_area(vertices[c]) for c in cycles])
    if np.count_nonzero(areas < 0) > 1:
        raise PatternError(f"{source}: the pattern is not connected "
                           f"({np.count_nonzero(areas < 0)} separate pieces); "
                           "simulate each piece on its own")
    key = {(int(u), int(v)): i for i, (u, v) in enumerate(edges)}
    key.update({(int(v), int(u)): i for i, (u, v) in enumerate(edges)})
    outer_edges = set()
    for c, area in zip(cycles, areas):
        if area < 0:
            outer_edges.update(key[(int(u), int(v))] for u, v in zip(c, np.roll(c, -1)))
    faces = []
    for c, area in zip(cycles, areas):
        if area <= 0:
            continue
        ids = [key[(int(u), int(v))] for u, v in zip(c, np.roll(c, -1))]
        is_hole = all(boundary[i] for i in ids) and not any(i in outer_edges for i in ids)
        if not is_hole:
            faces.append(c)
    return faces


def crossing_pairs(vertices: np.ndarray, edges: np.ndarray) -> list[tuple[int, int]]:
    """Pairs of edges that cross, overlap, or touch other than at a shared end.

    Uses a shapely STRtree, so the cost is near-linear in the number of edges.

    Returns
    -------
    list of (i, j) with i < j
    """
    import shapely

    lines = shapely.linestrings(vertices[edges])
    tree = shapely.STRtree(lines)
    left, right = tree.query(lines, predicate="intersects")
    keep = left < right
    left, right = left[keep], right[keep]
    shared = ((edges[left, 0] == edges[right, 0]) | (edges[left, 0] == edges[right, 1])
              | (edges[left, 1] == edges[right, 0]) | (edges[left, 1] == edges[right, 1]))
    bad = list(zip(left[~shared].tolist(), right[~shared].tolist()))
    if shared.any():  # sharing an end: only that end point may be common
        inter = shapely.intersection(lines[left[shared]], lines[right[shared]])
        not_point = shapely.get_type_id(inter) != 0
        bad += list(zip(left[shared][not_point].tolist(), right[shared][not_point].tolist()))
    return sorted(bad)
