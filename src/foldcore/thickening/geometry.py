"""Plane geometry of the thick sheet: vectors, polygons and the table of its points (mm)."""
from __future__ import annotations

import math

import numpy as np

__all__ = ["PointTable", "area_centroid", "chord_params", "cross2d", "edge_of", "left_normal",
           "polygon_area", "vector_length"]


def vector_length(v) -> float:
    """Euclidean length of one vector (mm): ``np.linalg.norm``'s own arithmetic for a
    1-D array, without its dispatch (docs/architecture.md#building-the-thick-mesh-fast)."""
    return math.sqrt(v.dot(v))


def cross2d(a, b):
    """z component of the cross product of 2D vectors (..., 2) × (..., 2)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def left_normal(d):
    """(2,) ``d`` turned a quarter turn counter-clockwise."""
    return np.array([-d[1], d[0]])


def polygon_area(xy) -> float:
    """Signed area (mm²) of a polygon (n, 2) mm, positive counter-clockwise."""
    return 0.5 * float(cross2d(xy, np.roll(xy, -1, axis=0)).sum())


def area_centroid(xy) -> np.ndarray:
    """(2,) area centroid of a simple polygon (n, 2), mm."""
    cross = cross2d(xy, np.roll(xy, -1, axis=0))
    return (xy + np.roll(xy, -1, axis=0)).T @ cross / (3.0 * cross.sum())


def chord_params(points: np.ndarray) -> np.ndarray:
    """(n,) chord-length parameters 0 … 1 of a polyline's points (n, 2)."""
    t = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]
    return t / t[-1]


def edge_of(pattern, u: int, v: int) -> int:
    """Id of the pattern's edge joining vertices ``u`` and ``v`` (either way round)."""
    ends = pattern.edges
    return int(np.flatnonzero(((ends[:, 0] == u) & (ends[:, 1] == v))
                              | ((ends[:, 0] == v) & (ends[:, 1] == u)))[0])


class PointTable:
    """2D points of the thick sheet; ids are allocated as points are added."""

    def __init__(self):
        self.coords: list[np.ndarray] = []

    def add(self, xy) -> int:
        """Id of the point ``xy`` (2,) mm, added."""
        self.coords.append(np.asarray(xy, dtype=float))
        return len(self.coords) - 1

    def extend(self, xy) -> list[int]:
        """Ids of the points of ``xy`` (k, 2), added in order."""
        start = len(self.coords)
        self.coords.extend(np.asarray(xy, dtype=float))
        return list(range(start, len(self.coords)))

    def between(self, a: int, b: int, fractions) -> list[int]:
        """Ids [a, new points at the given fractions of the way a → b, b]."""
        p, q = self.coords[a], self.coords[b]
        return [a] + [self.add(p + t * (q - p)) for t in fractions] + [b]
