"""ThickMesh: the volumetric mesh of prisms (second box of the data flow).

Vertices are numbered top layer first (``z = +H/2``, ids ``0..M-1``) then the
bottom layer (``z = -H/2``, ids ``M..2M-1``), where ``M`` is the number of
2D points of the thickened sheet. Units: mm.
"""
from __future__ import annotations

from dataclasses import dataclass

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
        Sub-strips per edge (0 for boundary edges).
    panel_group : str
        Name of the group holding the panels.
    """

    points: np.ndarray
    thickness: float
    groups: dict
    panel_of_face: np.ndarray
    strips_of_crease: dict
    hinge_width: np.ndarray
    subdivisions: np.ndarray
    panel_group: str = "rigid_panel"

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
            Vertex loops (top, bottom and side quads of every prism).
        element_kind : list of str
            Group name of the prism each face belongs to.
        """
        faces, kinds = [], []
        for name, g in self.groups.items():
            for i in range(len(g)):
                ids = g.indices[g.slots(i)]
                n = len(ids) // 2
                top, bot = ids[:n], ids[n:]
                faces.append(top)
                faces.append(bot[::-1])
                kinds += [name, name]
                for j in range(n):
                    k = (j + 1) % n
                    faces.append(np.array([top[k], top[j], bot[j], bot[k]]))
                    kinds.append(name)
        return faces, kinds

    def to_pyvista(self, positions: np.ndarray | None = None):
        """A ``pyvista.PolyData`` of the prism surfaces (pyvista imported lazily)."""
        import pyvista as pv

        faces, kinds = self.prism_faces()
        pts = self.rest_positions if positions is None else np.asarray(positions)
        flat = np.concatenate([np.r_[len(f), f] for f in faces])
        mesh = pv.PolyData(pts, flat)
        mesh.cell_data["is_hinge"] = np.array([k != self.panel_group for k in kinds])
        return mesh

    def export(self, path, positions: np.ndarray | None = None) -> None:
        """Write the prism surfaces to VTU/VTK/STL/OBJ/PLY (format from suffix).

        Uses meshio (imported lazily). STL output is triangulated.
        """
        import meshio

        faces, _ = self.prism_faces()
        pts = self.rest_positions if positions is None else np.asarray(positions)
        tris = np.array([[f[0], f[j], f[j + 1]] for f in faces for j in range(1, len(f) - 1)])
        meshio.write(str(path), meshio.Mesh(pts, [("triangle", tris)]))


def surface_faces(mesh: ThickMesh) -> list:
    """Outer surface of the prism mesh: prism faces not shared by two prisms.

    Conforming neighbours share whole faces, so a face listed twice is inside.
    """
    faces, _ = mesh.prism_faces()
    count: dict = {}
    for f in faces:
        key = tuple(sorted(int(i) for i in f))
        count[key] = count.get(key, 0) + 1
    return [f for f in faces if count[tuple(sorted(int(i) for i in f))] == 1]
