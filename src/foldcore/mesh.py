"""ThickMesh: the volumetric mesh of prisms (second box of the data flow).

Vertices are numbered top layer first (``z = +H/2``, ids ``0..M-1``) then the
bottom layer (``z = -H/2``, ids ``M..2M-1``), where ``M`` is the number of
2D points of the thickened sheet. Units: mm.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(eq=False)
class ElementGroup:
    """All elements of one registered type, as flat arrays (CSR over vertices).

    Attributes
    ----------
    kind : str
        Registered element type name (see :mod:`elements`).
    indptr : (n+1,) int64
        Element ``i`` owns slots ``indptr[i]:indptr[i+1]``.
    indices : (nnz,) int64
        Mesh vertex id of each slot.
    rest : (nnz, 3) float64
        Rest shape of each element in its local frame, centred, mm.
    params : (n, p) float64
        Per-element parameters (columns named by the element type).
    volumes : (n,) float64
        Rest volume of each prism, mm³.
    weights : (n,) float64
        Volume (mm³) times stiffness factor (dimensionless, default 1).
    source : (n,) int64
        Pattern item the element came from (face id for panels, edge id for hinges).
    """

    kind: str
    indptr: np.ndarray
    indices: np.ndarray
    rest: np.ndarray
    params: np.ndarray
    volumes: np.ndarray
    weights: np.ndarray
    source: np.ndarray

    def __len__(self) -> int:
        return len(self.weights)

    def slots(self, i: int) -> slice:
        """Slot range of element ``i``."""
        return slice(int(self.indptr[i]), int(self.indptr[i + 1]))


@dataclass(eq=False)
class ThickMesh:
    """Prism mesh of a thickened crease pattern.

    Attributes
    ----------
    points : (M, 2) float64
        Mid-plane footprint points of the thickened sheet, mm.
    thickness : float
        Sheet thickness H, mm.
    groups : dict[str, ElementGroup]
        Element groups by type name (``rigid_panel``, ``bending_hinge``, …).
    panel_of_face : (F,) int64
        Element index (in the panel group) of each pattern face.
    strips_of_crease : dict[int, (k,) int64]
        Hinge element indices of each crease (edge id), left to right.
    hinge_width : (E,) float64
        Hinge width used per edge, mm (NaN for boundary edges).
    subdivisions : (E,) int64
        Sub-strips per edge across its width (0 for boundary edges).
    segments : (E,) int64
        Prisms along each crease (1; more where an elastic plate's cells line
        the crease, so the strip conforms with them; 0 for boundary edges).
        ``strips_of_crease[e]`` lists segment after segment, each left to
        right: k·m strips, k in series across the crease, m side by side.
    panel_group : str
        Name of the group holding the panels.
    elastic : dict {face: n or (n1, n2)}
        The elastic faces as built (counts resolved: ``"auto"`` replaced),
        so the same mesh can be rebuilt (stored in result FOLD files as
        ``foldcore:faces_cells``); empty for rigid panels only.
    hinge_model : (E,) str, optional
        Hinge kinematics of each crease's bending strips (``"axis"``,
        ``"arc"``, ``"eq8"``; ``""`` for boundary edges), see
        :func:`foldcore.thicken`.
    crease_panels : (E, 2) int64, optional
        The panel elements that measure each crease's fold angle, on its faces
        ``pattern.edge_faces[e]`` (−1 where there is none): the panel, or on an
        elastic face the cell nearest the crease's middle, so a bent face does
        not count as fold. Default: ``panel_of_face`` of both faces.
    width_share : (E,) float64, optional
        The share of Eq. 7's width each crease kept where a face was too small for
        it (:func:`foldcore.thickening.widths.fit_widths`); None when none was
        narrowed.
    """

    points: np.ndarray
    thickness: float
    groups: dict
    panel_of_face: np.ndarray
    strips_of_crease: dict
    hinge_width: np.ndarray
    subdivisions: np.ndarray
    segments: np.ndarray | None = None
    panel_group: str = "rigid_panel"
    elastic: dict = field(default_factory=dict)
    hinge_model: np.ndarray | None = None
    crease_panels: np.ndarray | None = None
    width_share: np.ndarray | None = None

    def __post_init__(self):
        if self.segments is None:
            self.segments = (np.asarray(self.subdivisions) > 0).astype(np.int64)

    def measuring_panels(self, pattern, edges) -> tuple[np.ndarray, np.ndarray]:
        """Panel elements (n,), (n,) left and right of the creases ``edges`` (n,) that
        measure their fold angles (:attr:`crease_panels`)."""
        if self.crease_panels is not None:
            return self.crease_panels[edges, 0], self.crease_panels[edges, 1]
        faces = pattern.edge_faces[edges]
        return self.panel_of_face[faces[:, 0]], self.panel_of_face[faces[:, 1]]

    def crease_bends(self, strip_angles: np.ndarray) -> np.ndarray:
        """(E,) bend of each crease's hinge from per-strip bend angles (S,): the sum over
        its k sub-strips in series, averaged over its segments along the crease
        (units of ``strip_angles``; NaN for boundary edges)."""
        out = np.full(len(self.subdivisions), np.nan)
        for e, strips in self.strips_of_crease.items():
            out[e] = np.asarray(strip_angles)[strips].sum() / self.segments[e]
        return out

    @property
    def n_vertices(self) -> int:
        return 2 * len(self.points)

    @property
    def rest_positions(self) -> np.ndarray:
        """(N, 3) float64: rest vertex positions, mm."""
        h = 0.5 * self.thickness
        top = np.column_stack([self.points, np.full(len(self.points), h)])
        bottom = np.column_stack([self.points, np.full(len(self.points), -h)])
        return np.vstack([top, bottom])

    @property
    def n_elements(self) -> int:
        return sum(len(g) for g in self.groups.values())

    def volume(self) -> float:
        """Total rest volume of all prisms, mm³."""
        return float(sum(g.volumes.sum() for g in self.groups.values()))

    def prism_faces(self, positions: np.ndarray | None = None):
        """Boundary polygons of every prism, for export and rendering.

        Returns
        -------
        faces : list of (n,) int arrays
            Vertex loops (top, bottom and side quads of every prism; groups
            whose elements are not prisms, e.g. 2-vertex bars, have none).
        element_kind : list of str
            Group name of the prism each face belongs to.
        """
        faces, kinds = [], []
        for name, g in self.groups.items():
            if not is_prism_group(g):
                continue
            for i in range(len(g)):
                for loop, _ in prism_face_loops(g.indices[g.slots(i)]):
                    faces.append(loop)
                    kinds.append(name)
        return faces, kinds


def surface_faces(mesh: ThickMesh) -> list:
    """Outer surface of the prism mesh: prism faces not shared by two prisms."""
    return surface_polygons(mesh).loops


@dataclass(frozen=True)
class SurfaceFaces:
    """Outer-surface polygons of a ThickMesh (faces not shared by two prisms).

    Attributes
    ----------
    loops : list of (n,) int64
        Vertex ids of each face, counter-clockwise seen from outside.
    group : (F,) str
        Element group of the prism each face belongs to.
    element : (F,) int64
        Index of that prism in its group.
    source : (F,) int64
        The pattern item that prism came from (its group's ``source``: a face
        for panels, an edge for hinges).
    is_hinge : (F,) bool
        The prism is not a panel (a bending or stretch hinge strip, …).
    is_cap : (F,) bool
        Top or bottom face (planar in the footprint), else a side quad.
    """

    loops: list
    group: np.ndarray
    element: np.ndarray
    source: np.ndarray
    is_hinge: np.ndarray
    is_cap: np.ndarray


def prism_face_loops(ids: np.ndarray):
    """(loop, is_cap) of a prism's faces: top, bottom (reversed), side quads, outward.

    ``ids`` (2n,): the top loop (counter-clockwise seen from +z) then the bottom.
    """
    n = len(ids) // 2
    top, bot = ids[:n], ids[n:]
    yield top, True
    yield bot[::-1], True
    for j in range(n):
        k = (j + 1) % n
        yield np.array([top[k], top[j], bot[j], bot[k]]), False


def is_prism_group(group) -> bool:
    """Every element has an even number (≥ 6) of vertex ids: top loop then bottom loop."""
    sizes = np.diff(group.indptr)
    return bool(len(sizes) and (sizes >= 6).all() and (sizes % 2 == 0).all())


def surface_polygons(mesh) -> SurfaceFaces:
    """The outer surface of ``mesh``: every prism face not shared with another prism.

    Conforming neighbours share whole faces, so a face listed twice is inside
    (:func:`surface_faces` is its ``loops``).
    """
    faces = []
    for name, g in mesh.groups.items():
        if not is_prism_group(g):
            continue  # e.g. a 2-vertex bar (examples/plugin_bar): no faces of its own
        for i in range(len(g)):
            for loop, cap in prism_face_loops(g.indices[g.slots(i)]):
                faces.append((loop, name, i, cap))
    count: dict = {}
    keys = [tuple(sorted(loop.tolist())) for loop, *_ in faces]
    for key in keys:
        count[key] = count.get(key, 0) + 1
    kept = [f for f, key in zip(faces, keys) if count[key] == 1]
    return SurfaceFaces(loops=[f[0].astype(np.int64) for f in kept],
                        group=np.array([f[1] for f in kept], dtype=object),
                        element=np.array([f[2] for f in kept], dtype=np.int64),
                        source=np.array([mesh.groups[f[1]].source[f[2]] for f in kept],
                                        dtype=np.int64),
                        is_hinge=np.array([f[1] != mesh.panel_group for f in kept], dtype=bool),
                        is_cap=np.array([f[3] for f in kept], dtype=bool))
