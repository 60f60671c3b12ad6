"""Obstacles: rigid triangle meshes fixed in space that the sheet touches but never passes.

A table the sheet rests on (:meth:`Obstacle.plane`), an object a gripper
closes on (:func:`read_obstacle`: STL, OBJ, PLY, … through meshio). Each
obstacle meets each part (rigid panel, hinge strip) as IPC meets two parts
(:mod:`.barrier`): the same barrier (d̂, κ), the same CCD-bounded steps, on a
two-body collision mesh of the part's surface and the obstacle's triangles
near it, whose vertices do not move (their rows of the barrier's derivatives
are dropped). Broad phase: the obstacle's triangle boxes (a k-d tree of their
centres) against each part's box. Units: mm.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from ..errors import FoldcoreError


class ObstacleError(FoldcoreError, ValueError):
    """An obstacle that cannot be used (its file or its mesh)."""


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A fixed rigid triangle mesh.

    Attributes
    ----------
    vertices : (M, 3) float
        Positions, mm, in the crease pattern's frame (the flat sheet's
        mid-surface is z = 0, its faces at ±H/2).
    faces : (F, 3) int
        Triangles, indices into ``vertices``.
    name : str
        What the report and the errors call it.
    """

    vertices: np.ndarray
    faces: np.ndarray
    name: str = "obstacle"

    def __post_init__(self):
        v = np.array(self.vertices, dtype=float)
        f = np.array(self.faces)
        if v.ndim != 2 or v.shape[1] != 3 or not len(v):
            raise ObstacleError(f"{self.name}: vertices must be (M, 3), got shape {v.shape}")
        if not np.isfinite(v).all():
            bad_vertex = int(np.flatnonzero(~np.isfinite(v).all(axis=1))[0])
            raise ObstacleError(f"{self.name}: vertex {bad_vertex} is not finite")
        if f.ndim != 2 or f.shape[1] != 3 or not len(f) or not np.issubdtype(f.dtype, np.integer):
            raise ObstacleError(f"{self.name}: faces must be (F, 3) integers, got {f.dtype} "
                                f"{f.shape}")
        bad = np.flatnonzero(((f < 0) | (f >= len(v))).any(axis=1))
        if len(bad):
            raise ObstacleError(f"{self.name}: face {int(bad[0])} names vertex "
                                f"{f[bad[0]].tolist()} of {len(v)}")
        area = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
        flat = np.flatnonzero(area <= 1e-12 * max(float(np.ptp(v, axis=0).max()), 1e-300) ** 2)
        if len(flat):
            raise ObstacleError(f"{self.name}: face {int(flat[0])} has no area")
        object.__setattr__(self, "vertices", np.ascontiguousarray(v))
        object.__setattr__(self, "faces", np.ascontiguousarray(f, dtype=np.int32))

    @classmethod
    def plane(cls, point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), size: float = 1e4,
              name: str = "plane") -> "Obstacle":
        """A square of side ``size`` (mm) centred at ``point`` (mm), facing ``normal``:
        a ground or a wall, as large as the sheet can reach."""
        p, n = np.asarray(point, dtype=float), np.asarray(normal, dtype=float)
        if p.shape != (3,) or n.shape != (3,) or not (np.isfinite(p).all() and
                                                       np.isfinite(n).all()):
            raise ObstacleError(f"{name}: point and normal must be 3 finite numbers")
        if not (np.isfinite(size) and size > 0) or np.linalg.norm(n) == 0:
            raise ObstacleError(f"{name}: needs a size > 0 and a non-zero normal")
        n = n / np.linalg.norm(n)
        u = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
        u /= np.linalg.norm(u)
        w = np.cross(n, u)
        half = 0.5 * size
        corners = [p + half * (a * u + b * w) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        return cls(np.array(corners), np.array([[0, 1, 2], [0, 2, 3]]), name)

    @classmethod
    def ball(cls, centre, radius: float, subdivisions: int = 2,
             name: str = "ball") -> "Obstacle":
        """A ball of ``radius`` (mm) about ``centre`` (mm): an icosahedron whose
        triangles are split in four ``subdivisions`` times, its vertices on the
        sphere (20·4^k faces; the flat faces lie inside the sphere by at most
        about 5 % of the radius at k = 2)."""
        c = np.asarray(centre, dtype=float)
        if c.shape != (3,) or not np.isfinite(c).all():
            raise ObstacleError(f"{name}: centre must be 3 finite numbers")
        if not (np.isfinite(radius) and radius > 0) or int(subdivisions) != subdivisions \
                or not 0 <= subdivisions <= 5:
            raise ObstacleError(f"{name}: needs a radius > 0 and 0 ≤ subdivisions ≤ 5")
        vertices, faces = _icosahedron()
        for _ in range(int(subdivisions)):
            vertices, faces = _split_in_four(vertices, faces)
        unit = vertices / np.linalg.norm(vertices, axis=1)[:, None]
        return cls(c + radius * unit, faces, name)


def read_obstacle(path, name: str | None = None) -> Obstacle:
    """An obstacle from a mesh file meshio reads (STL, OBJ, PLY, VTK, …), in mm;
    polygons are split into triangles (fans). ObstacleError naming the file."""
    path = Path(path)
    name = name or path.name
    try:
        import meshio
    except ImportError:
        raise ObstacleError(f"{path}: reading obstacles needs meshio: "
                            f"pip install 'foldcore[contact]'") from None
    try:
        with warnings.catch_warnings():  # a garbled binary STL overflows its count check
            warnings.simplefilter("ignore", RuntimeWarning)
            mesh = meshio.read(path)
    except Exception as error:  # meshio raises many kinds for a bad file
        raise ObstacleError(f"{path}: not a mesh meshio reads ({type(error).__name__}: "
                            f"{error})") from None
    faces = []
    for block in mesh.cells:
        data = np.asarray(block.data)
        if block.type in ("triangle", "quad", "polygon") and data.ndim == 2 and data.shape[1] >= 3:
            faces += [data[:, [0, k, k + 1]] for k in range(1, data.shape[1] - 1)]
    if not faces:
        raise ObstacleError(f"{path}: no triangles or polygons in it")
    return Obstacle(mesh.points[:, :3] if mesh.points.shape[1] >= 3 else mesh.points,
                    np.vstack(faces), name)


class ObstacleContacts:
    """Barrier terms and collision-free step fractions between parts and fixed
    obstacles.

    Parameters
    ----------
    solids : PartSolids
    obstacles : sequence of Obstacle
    potential
        ipctk barrier potential (d̂, κ) of unjoined pairs (the contact model resets it
        when κ changes).
    ccd
        ipctk narrow-phase CCD.
    """

    def __init__(self, solids, obstacles, potential, ccd):
        self.solids, self.obstacles = solids, list(obstacles)
        self.potential, self._ccd = potential, ccd
        self._boxes, self._trees, self._reach = [], [], []
        for o in self.obstacles:
            tri = o.vertices[o.faces]
            lo, hi = tri.min(axis=1), tri.max(axis=1)
            self._boxes.append((lo, hi))
            self._trees.append(cKDTree(0.5 * (lo + hi)))
            self._reach.append(float(np.linalg.norm(0.5 * (hi - lo), axis=1).max()))

    def near(self, lo: np.ndarray, hi: np.ndarray, margin: float) -> list:
        """[(part, obstacle, triangle ids)] whose boxes come within ``margin`` mm,
        for part boxes (lo, hi), each (n_parts, 3)."""
        centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        radius = np.linalg.norm(half, axis=1) + margin
        out = []
        for o, ((t_lo, t_hi), tree, reach) in enumerate(zip(self._boxes, self._trees,
                                                             self._reach)):
            hits = tree.query_ball_point(centre, radius + reach)
            for p, tris in enumerate(hits):
                if not tris:
                    continue
                tris = np.asarray(tris, dtype=np.int64)
                close = ((t_lo[tris] <= hi[p] + margin) & (t_hi[tris] >= lo[p] - margin)).all(1)
                if close.any():
                    out.append((p, o, np.sort(tris[close])))
        return out

    def pair_mesh(self, p: int, o: int, tris: np.ndarray):
        """(collision mesh, part's model vertex ids, obstacle points, selection): part
        p's surface and obstacle o's triangles ``tris``; the selection (3n, 3n_p) maps
        the part's dofs into the pair's (the obstacle's do not move)."""
        import ipctk

        s, obstacle = self.solids, self.obstacles[o]
        ids = s.vertices[s.ptr[p]:s.ptr[p + 1]]
        used, local = np.unique(obstacle.faces[tris], return_inverse=True)
        points = obstacle.vertices[used]
        n_p, n = len(ids), len(ids) + len(used)
        faces = np.vstack([s.triangles[p], local.reshape(-1, 3) + n_p]).astype(np.int32)
        rest = np.vstack([np.zeros((n_p, 3)), points])
        mesh = ipctk.CollisionMesh(np.asfortranarray(rest), ipctk.edges(faces), faces)
        mesh.can_collide = ipctk.make_vertex_patches_filter(
            np.repeat([0, 1], [n_p, len(used)]).astype(np.int32))
        return mesh, ids, points, np.eye(3 * n)[:, :3 * n_p]

    def terms(self, x: np.ndarray, dhat: float) -> tuple[list, list, list]:
        """([(obstacle, term)], part–obstacle pairs, their gaps) at positions x; a term
        is (ids, collisions, mesh, local positions, potential, selection) as
        :class:`~.barrier.ContactModel` keeps them."""
        import ipctk

        found, pairs, gaps = [], [], []
        for p, o, tris in self.near(*self.solids.boxes(x), dhat):
            mesh, ids, points, select = self.pair_mesh(p, o, tris)
            local = np.asfortranarray(np.vstack([x[ids], points]))
            collisions = ipctk.NormalCollisions()
            collisions.build(mesh, local, dhat)
            if not len(collisions):
                continue
            found.append((o, (ids, collisions, mesh, local, self.potential, select)))
            pairs.append((p, o))
            gaps.append(float(np.sqrt(collisions.compute_minimum_distance(mesh, local))))
        return found, pairs, gaps

    def free_fraction(self, x0: np.ndarray, x1: np.ndarray) -> float:
        """The largest share t ∈ [0, 1] of the straight-line step x0 → x1 that keeps
        every part off every obstacle (additive CCD, rescaled)."""
        import ipctk

        s = self.solids
        lo0, hi0 = s.boxes(x0)
        lo1, hi1 = s.boxes(x1)
        fraction = 1.0
        for p, o, tris in self.near(np.minimum(lo0, lo1), np.maximum(hi0, hi1), 0.0):
            mesh, ids, points, _ = self.pair_mesh(p, o, tris)
            t = ipctk.compute_collision_free_stepsize(
                mesh, np.asfortranarray(np.vstack([x0[ids], points])),
                np.asfortranarray(np.vstack([x1[ids], points])), narrow_phase_ccd=self._ccd)
            fraction = min(fraction, float(t))
        return fraction

    def touching(self, x: np.ndarray) -> list:
        """[(part, obstacle)] whose surfaces intersect or touch at x: a start no
        barrier can leave."""
        import ipctk

        out = []
        for p, o, tris in self.near(*self.solids.boxes(x), 0.0):
            mesh, ids, points, _ = self.pair_mesh(p, o, tris)
            local = np.asfortranarray(np.vstack([x[ids], points]))
            collisions = ipctk.NormalCollisions()
            collisions.build(mesh, local, 1e-12 * max(self._reach[o], 1.0))
            if ipctk.has_intersections(mesh, local) or len(collisions):
                out.append((p, o))
        return out


def _icosahedron() -> tuple[np.ndarray, np.ndarray]:
    """(12, 3) vertices and (20, 3) outward triangles of a regular icosahedron."""
    g = (1.0 + 5.0 ** 0.5) / 2.0
    v = np.array([(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g),
                  (0, -1, -g), (0, 1, -g), (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)],
                 dtype=float)
    f = np.array([(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9),
                  (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2),
                  (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
                  (8, 6, 7), (9, 8, 1)])
    return v, f


def _split_in_four(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each triangle split into four at its edges' midpoints (shared midpoints once)."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, index = np.unique(edges, axis=0, return_inverse=True)
    mid = len(vertices) + index.reshape(3, -1).T  # (F, 3): midpoints of edges 01, 12, 20
    out = np.vstack([vertices, 0.5 * (vertices[unique[:, 0]] + vertices[unique[:, 1]])])
    a, b, c = faces.T
    ab, bc, ca = mid.T
    return out, np.concatenate([np.column_stack(t) for t in
                                ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))])
