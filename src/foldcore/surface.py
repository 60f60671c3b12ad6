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
Design notes: ``docs/design.md#triangulating-the-outer-surface``.
"""
from __future__ import annotations

import mapbox_earcut
import numpy as np

from . import files
from .files import ExportError
from .io.obj import STL_RECORD
from .mesh import SurfaceFaces, surface_polygons

#: Relative tolerance of a triangulation's area to its polygon's (mm² per mm²).
AREA_TOLERANCE = 1e-9


class TriangulationError(ExportError):
    """A face's polygon cannot be triangulated into its own area (not simple)."""


def triangulate_polygon(xy, face: int | None = None) -> np.ndarray:
    """Triangles of a simple polygon, (n−2, 3) int64 local indices (mapbox-earcut).

    Parameters
    ----------
    xy : (n, 2) float
        Vertices in order, mm (either orientation; collinear points allowed).
    face : int, optional
        The face's index, named in the error.

    Returns
    -------
    (n−2, 3) int64
        Each triangle in the polygon's own orientation; every vertex is used.

    Raises
    ------
    TriangulationError
        The triangles do not cover exactly the polygon's area, or leave a vertex
        out (a polygon that is not simple, or degenerate).
    """
    xy = np.asarray(xy, dtype=np.float64)
    n = len(xy)
    local = xy - xy.min(axis=0) if n else xy        # small coordinates: exact areas
    tris = mapbox_earcut.triangulate_float64(np.ascontiguousarray(local),
                                             np.array([n], dtype=np.uint32))
    tris = tris.reshape(-1, 3).astype(np.int64)
    area = _shoelace(local)
    twice = _twice_areas(local, tris)
    if twice.sum() * area < 0:                      # into the polygon's orientation
        tris, twice = tris[:, ::-1], -twice
    _check_cover(local, tris, twice * (1.0 if area >= 0 else -1.0), abs(area), face)
    return tris


def _shoelace(xy: np.ndarray) -> float:
    """Signed area of a polygon (n, 2), counter-clockwise > 0."""
    return 0.5 * float(np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1]))


def _twice_areas(xy: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """(T,) twice the signed area of each triangle."""
    a, b, c = xy[tris[:, 0]], xy[tris[:, 1]], xy[tris[:, 2]]
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def _check_cover(xy, tris, twice, area: float, face) -> None:
    """Refuse triangles that are not n−2 of the polygon's orientation (``twice``: twice
    their areas, > 0 for that orientation) covering its ``area`` (mm²)."""
    n = len(xy)
    extent = float(np.ptp(xy, axis=0).max()) if n else 0.0
    tolerance = AREA_TOLERANCE * (area + n * extent ** 2 * 1e-6)
    covered = 0.5 * float(np.abs(twice).sum())
    where = "a face" if face is None else f"face {face}"
    if n < 3 or len(tris) != n - 2 or abs(covered - area) > tolerance or (twice < 0).any():
        left = np.setdiff1d(np.arange(n), tris.ravel())
        detail = f"; vertex {int(left[0])} left out" if len(left) else ""
        raise TriangulationError(
            f"cannot triangulate {where}: its {n}-vertex polygon of {area:.6g} mm² is not "
            f"simple ({len(tris)} triangle(s) covering {covered:.6g} mm²{detail})")


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
    tris, owner = [], []
    for f, (loop, cap) in enumerate(zip(surface.loops, surface.is_cap)):
        if cap:
            try:
                local = triangulate_polygon(mesh.points[loop % n_top], face=f)
            except TriangulationError as exc:
                raise TriangulationError(f"{source}: {exc}" if source else str(exc)) from None
            # a bottom loop is reversed, so its footprint is clockwise: the
            # triangles keep that orientation, outward (−z) at rest
            tris.append(loop[local])
        else:
            tris.append(loop[[[0, 1, 2], [0, 2, 3]]])
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
    tris = surface_triangles(mesh, source=source)
    v = x[tris]
    normal = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    length = np.linalg.norm(normal, axis=1)
    normal = np.divide(normal, length[:, None], out=np.zeros_like(normal),
                       where=length[:, None] > 0)
    records = np.zeros(len(tris), dtype=STL_RECORD)
    records["normal"], records["v"] = normal, v
    head = header.encode("ascii", "replace")[:80].ljust(80, b" ")
    if head.lower().startswith(b"solid"):   # binary STL must not look like ASCII STL
        head = b"foldcore " + head[:71]
    return head + np.uint32(len(tris)).tobytes() + records.tobytes()


def write_stl(path, mesh, positions=None, source: str | None = None) -> None:
    """Write :func:`stl_bytes` (binary, mm) to ``path`` atomically.

    Raises
    ------
    ExportError
        No such folder, or as :func:`stl_bytes`.
    """
    files.check_folder(path, ExportError)
    files.write_bytes(path, stl_bytes(mesh, positions, source=source))
