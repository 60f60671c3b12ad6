"""The solids that touch: every rigid panel's closed prism, which panels are joined,
and a panel-level broad phase that proves most pairs apart without a narrow phase.

A panel is a prism: its top loop, the same loop H lower, and side quads, all
vertices its own (the rigid-body layout checks that panels share none). Two
panels are *joined* when a crease's hinge strip connects them; the hinge
model keeps those apart, and at a flat fold they touch face to face by design,
so contact leaves them to it. Every other pair is a contact candidate.

The broad phase has two stages, both in numba (:mod:`.kernels`): axis-aligned
boxes (within a margin, sweep and prune), then a separating-axis bound: the gap
between the two panels' vertex intervals along their normals, the bisectors
of those and the line between their centroids. That bound is a lower bound
of the true distance, so a pair it proves farther than the
margin cannot touch. Units: mm.
"""
from __future__ import annotations

import numpy as np

from ..mesh import prism_face_loops
from ..triangulation import triangulate_polygons
from . import kernels


class PanelSolids:
    """Every rigid panel of a thick mesh as a closed triangulated prism.

    Parameters
    ----------
    mesh : foldcore.mesh.ThickMesh
    pattern : foldcore.pattern.CreasePattern

    Attributes
    ----------
    n_panels : int
    vertices : (n,) int64
        Model vertex ids of every panel's corners (top loop, then bottom), panel
        by panel.
    ptr : (n_panels + 1,) int64
        Panel p's vertices are ``vertices[ptr[p]:ptr[p + 1]]``.
    triangles : list of (T_p, 3) int32
        Each panel's outward surface triangles, indices local to its vertices.
    joined : (J,) int64
        Sorted codes a · n_panels + b (a < b) of the panel pairs a crease joins.
    joined_pairs : (J, 2) int64
        The joined pairs themselves (a < b).
    """

    def __init__(self, mesh, pattern):
        group = mesh.groups.get(mesh.panel_group)
        self.n_panels = len(group) if group is not None else 0
        ids = [_corners(group.indices[group.slots(p)], mesh.rest_positions)
               for p in range(self.n_panels)]
        sizes = np.array([len(i) for i in ids], dtype=np.int64)
        self.vertices = np.concatenate(ids).astype(np.int64) if ids else np.zeros(0, np.int64)
        self.ptr = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        self.panel_of_vertex = np.repeat(np.arange(self.n_panels), sizes)
        self.triangles = self._triangles(mesh, ids)
        self.joined = self._joined(mesh, pattern)

    def _triangles(self, mesh, ids) -> list:
        """Outward triangles of each prism, local vertex indices."""
        n_top = len(mesh.points)
        caps = []
        for panel_ids in ids:
            for loop, is_cap in prism_face_loops(np.arange(len(panel_ids))):
                if is_cap:
                    caps.append(mesh.points[panel_ids[loop] % n_top])
        cap_tris = triangulate_polygons(caps)
        out = []
        for p, panel_ids in enumerate(ids):
            tris = []
            for loop, is_cap in prism_face_loops(np.arange(len(panel_ids))):
                tris.append(loop[cap_tris.pop(0)] if is_cap else loop[[[0, 1, 2], [0, 2, 3]]])
            out.append(np.ascontiguousarray(np.vstack(tris), dtype=np.int32))
        return out

    def _joined(self, mesh, pattern) -> np.ndarray:
        creases = np.array(sorted(mesh.strips_of_crease), dtype=np.int64)
        if not len(creases):
            self.joined_pairs = np.zeros((0, 2), dtype=np.int64)
            self.joined_edge = np.zeros((0, 2), dtype=np.int64)
            return np.zeros(0, dtype=np.int64)
        left, right = mesh.measuring_panels(pattern, creases)
        a, b = np.minimum(left, right), np.maximum(left, right)
        codes, first = np.unique(a * self.n_panels + b, return_index=True)
        self.joined_pairs = np.column_stack([codes // self.n_panels, codes % self.n_panels])
        self.joined_edge = self._crease_edges(mesh, pattern, creases[first], a[first])
        return codes

    def _crease_edges(self, mesh, pattern, creases, panels) -> np.ndarray:
        """(J, 2) model vertex ids of the top-loop edge of each joined pair's first
        panel most nearly parallel to the crease joining them: it turns with the
        panel, and the in-plane normal to it separates the pair while it is
        (nearly) flat."""
        rest = mesh.rest_positions[:, :2]
        ends = pattern.vertices[pattern.edges[creases]]
        d = ends[:, 1] - ends[:, 0]
        d /= np.linalg.norm(d, axis=1)[:, None]
        out = np.zeros((len(creases), 2), dtype=np.int64)
        for k, p in enumerate(panels):
            loop = self.vertices[self.ptr[p]:self.ptr[p] + (self.ptr[p + 1] - self.ptr[p]) // 2]
            edge = rest[np.roll(loop, -1)] - rest[loop]
            cosine = np.abs(edge @ d[k]) / np.maximum(np.linalg.norm(edge, axis=1), 1e-300)
            j = int(np.argmax(cosine))
            out[k] = loop[j], loop[(j + 1) % len(loop)]
        return out

    # ---------------------------------------------------------- geometry
    def boxes(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi), each (n_panels, 3): every panel's axis-aligned box at positions x."""
        lo, hi = np.empty((self.n_panels, 3)), np.empty((self.n_panels, 3))
        kernels.boxes(_positions(x), self.vertices, self.ptr, lo, hi)
        return lo, hi

    def normals(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(normal, mid-plane point), each (n_panels, 3): each panel's unit normal
        (Newell's, of its top loop) and the centroid of its vertices."""
        normal, centre = np.empty((self.n_panels, 3)), np.empty((self.n_panels, 3))
        kernels.normals(_positions(x), self.vertices, self.ptr, normal, centre)
        return normal, centre

    def _centres(self, points: np.ndarray) -> np.ndarray:
        """(n_panels, 3) centroid of each panel's vertices, from ``points`` = x[vertices]."""
        return np.add.reduceat(points, self.ptr[:-1]) / np.diff(self.ptr)[:, None]

    def pairs_near(self, lo, hi, margin: float) -> np.ndarray:
        """(K, 2) panel pairs (a < b, sorted), not joined, whose boxes (lo, hi), each
        (n_panels, 3), come within ``margin`` mm of each other.

        Sweep and prune in numba (:func:`.kernels.boxes_near`), anew per call: on a
        Miura 40 × 40 it costs about what the exact box test alone cost on a
        Verlet list kept between calls, whose rebuilds (most steps of a fold move
        the panels by more than its skin) cost ten times as much."""
        if self.n_panels < 2:
            return np.zeros((0, 2), dtype=np.int64)
        return kernels.boxes_near(np.ascontiguousarray(lo, np.float64),
                                  np.ascontiguousarray(hi, np.float64), float(margin),
                                  self.joined)

    def gap_bounds(self, x: np.ndarray, pairs: np.ndarray, edges=None,
                   later: np.ndarray | None = None) -> np.ndarray:
        """(K,) a lower bound (mm) of each pair's distance at positions x (≤ 0: not
        proved apart): the widest gap between the two panels' vertex intervals
        along any of five axes: the panels' normals, their sum and difference
        (the bisector planes of two panels hinged together) and the line between
        their centroids (two panels side by side in one plane); given ``edges``
        (K, 2) vertex ids of an edge per pair, also the in-plane normals to it
        (two panels a crease joins, flat). A gap along any axis separates the
        panels' convex hulls, which contain the panels.

        With ``later`` positions, the bound holds for the whole straight-line
        motion x → later (axes taken at x): along a fixed axis, b's lowest point
        less a's highest is concave in the motion's parameter, so the smaller of
        its two end values bounds it, and so for a over b; the larger of those
        two bounds the gap. (The smaller of the two ends' gaps is not a bound: a
        panel that passes through the other in one step is apart at both ends.)
        In numba: :func:`.kernels.gap_bounds`."""
        out = np.empty(len(pairs))
        if len(pairs):
            x = _positions(x)
            kernels.gap_bounds(x, x if later is None else _positions(later), later is not None,
                               self.vertices, self.ptr, np.ascontiguousarray(pairs, np.int64),
                               _NO_EDGES if edges is None else
                               np.ascontiguousarray(edges, np.int64), out)
        return out

    def shrunk(self, x: np.ndarray, share: float) -> np.ndarray:
        """(N, 3) x with every panel scaled by 1 − ``share`` about its vertices'
        centroid (other vertices as they are): the geometry joined panels touch
        with, so faces that meet by design (a flat fold's inner faces, a pivoting
        hinge's inner edges) stay ``share`` × their distance from the centroids
        apart."""
        out = x.copy()
        points = x[self.vertices]
        centre = self._centres(points)
        out[self.vertices] = (1.0 - share) * points + share * centre[self.panel_of_vertex]
        return out

    def pair_vertices(self, a: int, b: int) -> np.ndarray:
        """Model vertex ids of panels a then b."""
        return np.concatenate([self.vertices[self.ptr[a]:self.ptr[a + 1]],
                               self.vertices[self.ptr[b]:self.ptr[b + 1]]])


def _corners(ids: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """A prism's vertex ids (top loop, then bottom) without the points on straight
    runs of its loop: a panel shares such points with its hinge strips, and the
    zero-area triangles they leave in a triangulation read as intersections to
    a collision check. The solid is the same."""
    n = len(ids) // 2
    top = rest[ids[:n]]
    before, after = top - np.roll(top, 1, axis=0), np.roll(top, -1, axis=0) - top
    turn = np.linalg.norm(np.cross(before, after), axis=1)
    keep = turn > 1e-9 * np.linalg.norm(before, axis=1) * np.linalg.norm(after, axis=1)
    return np.concatenate([ids[:n][keep], ids[n:][keep]])


def _positions(x: np.ndarray) -> np.ndarray:
    """x as the kernels take it: (N, 3) float64, C-contiguous (a view where it is)."""
    return np.ascontiguousarray(x, dtype=np.float64)


_NO_EDGES = np.zeros((0, 2), dtype=np.int64)

