"""The outer surface of a ThickMesh as triangles, and the one STL writer.

Caps (top and bottom faces) are triangulated on the flat footprint
``mesh.points``, where every panel is a simple polygon, by mapbox-earcut
(:func:`triangulate_polygon`), so non-convex panels are triangulated
correctly; side faces are quads split in two. Each triangle is wound
counter-clockwise seen from outside: the surface is closed, every edge is
shared by exactly two triangles, and its signed volume is the solid's. The
renders (:func:`foldcore.render.surface_polydata`), the viewer page, the STL
file and the scenes' volumes all use :func:`surface_triangles`.

STL: binary, mm, written with NumPy (a 50-byte record per triangle,
:data:`foldcore.io.obj.STL_RECORD`) and atomically (:mod:`foldcore.files`).
Design notes: ``docs/architecture.md#triangulating-the-outer-surface``.
"""
from __future__ import annotations

import numpy as np

from . import files
from .files import ExportError
from .io.obj import STL_RECORD
from .mesh import SurfaceFaces, surface_polygons
from .triangulation import (AREA_TOLERANCE, TriangulationError, triangulate_polygon,  # noqa: F401
                            triangulate_polygons)

def surface_triangles(mesh, surface: SurfaceFaces | None = None, return_faces: bool = False,
                      source: str | None = None):
    """(T, 3) int64 vertex ids of the outer surface, outward (counter-clockwise) winding.

    Parameters
    ----------
    mesh : ThickMesh
    surface : SurfaceFaces, optional
        ``surface_polygons(mesh)``, if already made.
    return_faces : bool
        Also return the (T,) int64 index of each triangle's face in ``surface``.
    source : str, optional
        The file the mesh came from, named in a :class:`TriangulationError`.
    """
    surface = surface or surface_polygons(mesh)
    n_top = len(mesh.points)
    caps = np.flatnonzero(surface.is_cap)
    try:
        local = triangulate_polygons([mesh.points[surface.loops[f] % n_top] for f in caps], caps)
    except TriangulationError as exc:
        raise TriangulationError(f"{source}: {exc}" if source else str(exc)) from None
    cap_tris = dict(zip(caps.tolist(), local))
    tris, owner = [], []
    for f, loop in enumerate(surface.loops):
        # a bottom loop is reversed, so its footprint is clockwise: the triangles keep
        # that orientation, outward (−z) at rest; a side quad is split in two
        tris.append(loop[cap_tris[f]] if f in cap_tris else loop[[[0, 1, 2], [0, 2, 3]]])
        owner.append(np.full(len(tris[-1]), f, dtype=np.int64))
    out = np.vstack(tris) if tris else np.zeros((0, 3), dtype=np.int64)
    if return_faces:
        return out, (np.concatenate(owner) if owner else np.zeros(0, dtype=np.int64))
    return out


def surface_edges(surface: SurfaceFaces) -> np.ndarray:
    """(K, 2) int64 distinct polygon edges of the outer surface (vertex ids, sorted pairs)."""
    pairs = [np.column_stack([loop, np.roll(loop, -1)]) for loop in surface.loops]
    if not pairs:
        return np.zeros((0, 2), dtype=np.int64)
    return np.unique(np.sort(np.vstack(pairs), axis=1), axis=0)


def enclosed_volume(positions, triangles) -> float:
    """Signed volume (mm³) enclosed by a closed triangle surface (divergence theorem).

    Parameters
    ----------
    positions : (N, 3) float, mm
    triangles : (T, 3) int, outward winding
    """
    v = np.asarray(positions, dtype=float)[np.asarray(triangles)]
    return float(np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6.0)


def stl_bytes(mesh, positions=None, header: str = "foldcore thick solid, mm",
              source: str | None = None) -> bytes:
    """Binary STL of the mesh's outer surface.

    Parameters
    ----------
    mesh : ThickMesh
    positions : (N, 3) float, optional
        Vertex positions, mm (default: the rest positions).
    header : str
        The 80-byte header's text (ASCII; never starting with ``solid``).
    source : str, optional
        The file the mesh came from, named in errors.

    Raises
    ------
    ExportError
        ``positions`` not a finite (N, 3) array; a cap that cannot be triangulated.
    """
    x = mesh.rest_positions if positions is None else np.asarray(positions, dtype=float)
    if x.shape != (mesh.n_vertices, 3) or not np.isfinite(x).all():
        raise ExportError(f"positions must be a finite ({mesh.n_vertices}, 3) array of mm, "
                          f"got shape {x.shape}")
    return triangles_stl_bytes(x[surface_triangles(mesh, source=source)], header)


def triangles_stl_bytes(v: np.ndarray, header: str) -> bytes:
    """Binary STL of triangles ``v`` (T, 3, 3) mm, each facet's normal from its winding."""
    normal = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    length = np.linalg.norm(normal, axis=1)
    normal = np.divide(normal, length[:, None], out=np.zeros_like(normal),
                       where=length[:, None] > 0)
    records = np.zeros(len(v), dtype=STL_RECORD)
    records["normal"], records["v"] = normal, v
    head = header.encode("ascii", "replace")[:80].ljust(80, b" ")
    if head.lower().startswith(b"solid"):   # binary STL must not look like ASCII STL
        head = b"foldcore " + head[:71]
    return head + np.uint32(len(v)).tobytes() + records.tobytes()


def write_stl(path, mesh, positions=None, source: str | None = None) -> None:
    """Write :func:`stl_bytes` (binary, mm) to ``path`` atomically.

    Raises
    ------
    ExportError
        No such folder, or as :func:`stl_bytes`.
    """
    files.check_folder(path, ExportError)
    files.write_bytes(path, stl_bytes(mesh, positions, source=source))
