"""A crease pattern as a bar-and-hinge sheet (:class:`Sheet`), Origami Simulator's way.

Each face is cut into triangles as Origami Simulator cuts it (a quadrilateral
along its shorter diagonal, or on a tie the one through its lowest vertex id,
which is the one Origami Simulator's face order picks; a larger face by earcut);
the new diagonals are facet creases, held flat. Every edge is a bar; every
edge between two triangles is a hinge: a crease spring where the pattern
gives the crease a target (``M``, ``V`` or ``F``), a facet spring on a
diagonal, none on a passive crease (``U`` or no angle). Every triangle keeps
its corner angles. Stiffnesses follow Origami Simulator's conventions in its
normalised frame, where the sheet's bounding radius is 1 (:class:`Stiffness`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..pattern import CreasePattern
from ..triangulation import triangulate_polygon

BAR, HINGE, TRIANGLE = 0, 1, 2
TIE = 1e-9  # diagonals of a quadrilateral this close (relative, squared) are equal


@dataclass(frozen=True)
class Stiffness:
    """Origami Simulator's stiffnesses (its defaults), in its normalised frame.

    Attributes
    ----------
    axial : float, a bar's ``k = axial / L₀``
    crease : float, a crease's ``k = crease · L₀`` (per radian²)
    facet : float, a facet diagonal's ``k = facet · L₀`` (Origami Simulator's
        "panel stiffness")
    face : float, each corner angle's ``k`` (its "face stiffness")
    """

    axial: float = 20.0
    crease: float = 0.7
    facet: float = 0.7
    face: float = 0.2


@dataclass
class Sheet:
    """Bars, hinges and triangles of a thin sheet, in the normalised frame.

    Attributes
    ----------
    flat : (N, 3) float, the flat sheet, normalised (centred, bounding radius 1)
    centre : (2,) float, mm, the pattern point at the origin
    radius : float, mm, the pattern's bounding radius (one normalised unit)
    triangles : (T, 3) int, counter-clockwise seen from +z
    triangle_face : (T,) int, the pattern face each triangle cuts
    hinges : (H, 4) int, (a, b, c, d): the hinge a → b, c left, d right
    hinge_edge : (H,) int, the pattern edge of each hinge, −1 for a diagonal
    nodes, sizes, kinds, stiffness, rest : the element arrays of
        :func:`foldcore.sheet.kernels.evaluate`; hinges are the elements
        ``hinge_elements``
    hinge_elements : (H,) int, element index of each hinge with a spring, −1 without
    constants : Stiffness, the stiffnesses the elements were made with
    """

    flat: np.ndarray
    centre: np.ndarray
    radius: float
    triangles: np.ndarray
    triangle_face: np.ndarray
    hinges: np.ndarray
    hinge_edge: np.ndarray
    nodes: np.ndarray
    sizes: np.ndarray
    kinds: np.ndarray
    stiffness: np.ndarray
    rest: np.ndarray
    hinge_elements: np.ndarray
    constants: Stiffness

    def to_mm(self, x: np.ndarray) -> np.ndarray:
        """(N, 3) positions of the normalised frame in the pattern's mm."""
        out = x * self.radius
        out[:, :2] += self.centre
        return out


def face_triangles(xy: np.ndarray, loop: np.ndarray, face: int) -> np.ndarray:
    """(n − 2, 3) vertex ids of face ``loop`` cut as Origami Simulator cuts it."""
    if len(loop) == 3:
        return loop[None, :].copy()
    if len(loop) == 4:
        p = xy[loop]
        across_02, across_13 = np.sum((p[0] - p[2]) ** 2), np.sum((p[1] - p[3]) ** 2)
        if abs(across_02 - across_13) <= TIE * max(across_02, across_13):
            use_13 = int(np.argmin(loop)) % 2 == 1  # a tie: the diagonal through the lowest id
        else:
            use_13 = across_13 < across_02
        if use_13:
            return loop[np.array([[0, 1, 3], [1, 2, 3]])]
        return loop[np.array([[0, 1, 2], [0, 2, 3]])]
    return loop[triangulate_polygon(xy[loop], face)]


def _hinges(triangles: np.ndarray):
    """(H, 4) hinges and (B, 2) bars (every triangle side once) of a triangle mesh."""
    sides = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    tips = np.concatenate([triangles[:, 2], triangles[:, 0], triangles[:, 1]])
    left = {(int(a), int(b)): int(c) for (a, b), c in zip(sides, tips)}
    hinges, bars = [], []
    for (a, b), c in left.items():
        d = left.get((b, a))
        if d is None or a < b:
            bars.append((a, b))
        if d is not None and a < b:
            hinges.append((a, b, c, d))
    return np.array(hinges, dtype=np.int64).reshape(-1, 4), np.array(bars, dtype=np.int64)


def _corner_angles(p: np.ndarray) -> np.ndarray:
    """(T, 3) corner angles (radians) of triangles with points p (T, 3, 2)."""
    out = np.empty(p.shape[:2])
    for i in range(3):
        u = p[:, (i + 1) % 3] - p[:, i]
        v = p[:, (i + 2) % 3] - p[:, i]
        out[:, i] = np.arctan2(np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]),
                               np.einsum("ij,ij->i", u, v))
    return out


def tip_heights(flat: np.ndarray, hinges: np.ndarray) -> np.ndarray:
    """(H, 2) heights of each hinge's tips c and d over its line a → b in the flat
    sheet ``flat`` (N, 3), normalised units."""
    e = flat[hinges[:, 1], :2] - flat[hinges[:, 0], :2]
    length = np.maximum(np.linalg.norm(e, axis=1), 1e-300)
    r = flat[hinges[:, 2:], :2] - flat[hinges[:, :1], :2]          # (H, 2, 2)
    return np.abs(e[:, None, 0] * r[..., 1] - e[:, None, 1] * r[..., 0]) / length[:, None]


def _collapsed_hinges(flat: np.ndarray, hinges: np.ndarray) -> np.ndarray:
    """(H,) bool: a hinge one of whose triangles is lower over it than
    :data:`~.kernels.COLLAPSED` in the flat sheet (a face cut along collinear points)."""
    from .kernels import COLLAPSED

    return tip_heights(flat, hinges).min(axis=1) < COLLAPSED


def build_sheet(pattern: CreasePattern, stiffness: Stiffness = Stiffness()) -> Sheet:
    """The bar-and-hinge :class:`Sheet` of ``pattern`` (module docstring)."""
    xy = np.asarray(pattern.vertices, dtype=float)
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    centre = 0.5 * (lo + hi)
    radius = float(np.sqrt(np.max(np.sum((xy - centre) ** 2, axis=1))))
    flat = np.zeros((len(xy), 3))
    flat[:, :2] = (xy - centre) / radius
    cut = [face_triangles(xy, np.asarray(loop), f) for f, loop in enumerate(pattern.faces)]
    triangles = np.concatenate(cut)
    triangle_face = np.repeat(np.arange(len(cut)), [len(t) for t in cut])
    hinges, bars = _hinges(triangles)
    edge_of = {(int(min(a, b)), int(max(a, b))): e for e, (a, b) in enumerate(pattern.edges)}
    hinge_edge = np.array([edge_of.get((a, b), -1) for a, b in hinges[:, :2]], dtype=np.int64)
    angles = np.asarray(pattern.fold_angles, dtype=float)
    kinds = np.asarray(pattern.assignments)
    targets = np.zeros(len(hinges))
    spring = np.zeros(len(hinges))  # per-length stiffness, 0: no spring
    collapsed = _collapsed_hinges(flat, hinges)
    for h, e in enumerate(hinge_edge):
        if collapsed[h]:
            continue  # no angle to spring: Origami Simulator disables it too
        if e < 0:
            spring[h] = stiffness.facet
        elif kinds[e] in ("M", "V", "F") and not np.isnan(angles[e]):
            targets[h] = np.radians(angles[e])
            spring[h] = stiffness.crease if angles[e] != 0 else stiffness.facet
    return _assemble(flat, centre, radius, (triangles, triangle_face), hinges, hinge_edge,
                     targets, spring, bars, stiffness)


def _assemble(flat, centre, radius, cut, hinges, hinge_edge, targets, spring, bars,
              stiffness: Stiffness) -> Sheet:
    """The :class:`Sheet` with its element arrays: bars, sprung hinges, triangles
    (``cut``: the triangles and the face of each)."""
    triangles, triangle_face = cut
    length = np.linalg.norm(flat[bars[:, 1]] - flat[bars[:, 0]], axis=1)
    sprung = np.flatnonzero(spring > 0)
    hinge_length = np.linalg.norm(flat[hinges[sprung, 1]] - flat[hinges[sprung, 0]], axis=1)
    nb, nh, nt = len(bars), len(sprung), len(triangles)
    nodes = np.zeros((nb + nh + nt, 4), dtype=np.int64)
    nodes[:nb, :2] = bars
    nodes[nb:nb + nh] = hinges[sprung]
    nodes[nb + nh:, :3] = triangles
    sizes = np.repeat(np.array([2, 4, 3]), [nb, nh, nt])
    kinds = np.repeat(np.array([BAR, HINGE, TRIANGLE]), [nb, nh, nt])
    k = np.concatenate([stiffness.axial / length, spring[sprung] * hinge_length,
                        np.full(nt, stiffness.face)])
    rest = np.zeros((len(k), 3))
    rest[:nb, 0] = length
    rest[nb:nb + nh, 0] = targets[sprung]
    rest[nb + nh:] = _corner_angles(flat[triangles][:, :, :2])
    hinge_elements = np.full(len(hinges), -1, dtype=np.int64)
    hinge_elements[sprung] = nb + np.arange(nh)
    return Sheet(flat, centre, radius, triangles, triangle_face, hinges, hinge_edge, nodes,
                 sizes, kinds, k, rest, hinge_elements, stiffness)
