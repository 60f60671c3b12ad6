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
    return triangulate_polygons([xy], None if face is None else [face])[0]


def triangulate_polygons(polygons, faces=None) -> list:
    """:func:`triangulate_polygon` of many polygons, checked all at once.

    Parameters
    ----------
    polygons : sequence of (n_i, 2) float
        mm.
    faces : sequence of int, optional
        The index named in the error of each polygon (default: its position).

    Returns
    -------
    list of (n_i − 2, 3) int64, local indices in each polygon's orientation.
    """
    local = [np.asarray(xy, dtype=np.float64) for xy in polygons]
    if not local:
        return []
    sizes = np.array([len(xy) for xy in local], dtype=np.int64)
    faces = np.arange(len(local)) if faces is None else np.asarray(faces)
    small = np.flatnonzero(sizes < 3)
    if len(small):
        raise TriangulationError(_not_simple(faces[small[0]], local[small[0]], (), 0.0))
    # each polygon relative to its first vertex: small coordinates, exact areas
    local = [np.ascontiguousarray(xy - xy[0]) for xy in local]
    tris = [mapbox_earcut.triangulate_float64(xy, np.array([len(xy)], dtype=np.uint32))
            .reshape(-1, 3).astype(np.int64) for xy in local]
    flip, bad, covered = _covers(local, sizes, tris)
    if bad.any():
        i = int(np.argmax(bad))
        raise TriangulationError(_not_simple(faces[i], local[i], tris[i], covered[i]))
    return [t[:, ::-1] if f else t for t, f in zip(tris, flip)]


def _covers(local: list, sizes: np.ndarray, tris: list):
    """Per polygon: whether earcut's triangles need reversing into its orientation, whether
    they fail to be n−2 of one winding covering its area (relative
    :data:`AREA_TOLERANCE`), and the area they cover (mm²); (P,) bool, bool, float."""
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    xy = np.vstack(local)
    count = np.array([len(t) for t in tris], dtype=np.int64)
    owner = np.repeat(np.arange(len(local)), count)
    v = xy[np.vstack(tris) + np.repeat(starts, count)[:, None]]
    ab, ac = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]
    twice = ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0]
    following = np.arange(len(xy)) + 1
    following[starts + sizes - 1] = starts               # each polygon closes on itself
    polygon = np.repeat(np.arange(len(local)), sizes)
    area2 = np.bincount(polygon, xy[:, 0] * xy[following, 1] - xy[following, 0] * xy[:, 1],
                        minlength=len(local))
    flip = np.bincount(owner, twice, minlength=len(local)) * area2 < 0
    wound = twice * np.where(flip == (area2 >= 0), -1.0, 1.0)[owner]   # > 0 once flipped
    wrong = np.bincount(owner, wound < 0, minlength=len(local)) > 0
    covered = 0.5 * np.bincount(owner, np.abs(twice), minlength=len(local))
    extent = (np.maximum.reduceat(xy, starts) - np.minimum.reduceat(xy, starts)).max(axis=1)
    area = 0.5 * np.abs(area2)
    tolerance = AREA_TOLERANCE * (area + sizes * extent ** 2 * 1e-6)
    bad = (count != sizes - 2) | wrong | ~(np.abs(covered - area) <= tolerance)  # NaN: bad
    return flip, bad, covered


def _not_simple(face, xy: np.ndarray, tris, covered: float) -> str:
    """The message of a polygon (n, 2) mm whose triangles ``tris`` fail the checks."""
    n = len(xy)
    area = abs(_shoelace(xy)) if n >= 3 else 0.0
    left = np.setdiff1d(np.arange(n), np.asarray(tris, dtype=np.int64).ravel())
    detail = f"; vertex {int(left[0])} left out" if len(left) else ""
    return (f"cannot triangulate face {face}: its {n}-vertex polygon of {area:.6g} mm² is "
            f"not simple ({len(tris)} triangle(s) covering {covered:.6g} mm²{detail})")


def _shoelace(xy: np.ndarray) -> float:
    """Signed area of a polygon (n, 2), counter-clockwise > 0."""
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(x @ np.roll(y, -1) - np.roll(x, -1) @ y)


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
