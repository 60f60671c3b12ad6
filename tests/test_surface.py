"""The outer surface as triangles (foldcore.surface) and the one STL writer.

A non-convex panel (a U, its notch 10 mm wide and 20 mm deep) is triangulated
by earcut: the triangles cover exactly the polygon's area (mm²) and none lies
outside it, where a fan from the first vertex spans the notch. The STL of a mesh with that panel is closed, outward and encloses
the prisms' volume; ``ThickMesh.export`` writes the same bytes.
"""
from __future__ import annotations

import numpy as np
import pytest
import shapely

from foldcore.mesh import surface_polygons
from foldcore.pattern import CreasePattern
from foldcore.surface import (TriangulationError, enclosed_volume, stl_bytes, write_stl,
                              surface_triangles, triangulate_polygon)
from foldcore.thickening import thicken

#: A U-shaped polygon (mm), counter-clockwise, its notch open to +y.
U_SHAPE = np.array([[0, 0], [30, 0], [30, 30], [20, 30], [20, 10], [10, 10], [10, 30],
                    [0, 30]], dtype=float)


def _area(xy) -> float:
    xy = np.asarray(xy, dtype=float)
    return 0.5 * float(np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1]))


def _outside(polygon, xy, tris) -> list:
    """The triangles (index rows) not inside ``polygon`` (a shapely Polygon, 1e-9 mm slack)."""
    grown = polygon.buffer(1e-9)
    return [t for t in tris if not grown.contains(shapely.Polygon(xy[t]))]


def _fan(n: int) -> np.ndarray:
    return np.array([[0, j, j + 1] for j in range(1, n - 1)])


@pytest.mark.parametrize("reverse", [False, True])
def test_a_non_convex_face_is_covered_exactly_where_a_fan_is_not(reverse):
    xy = U_SHAPE[::-1].copy() if reverse else U_SHAPE
    polygon = shapely.Polygon(xy)
    area = abs(_area(xy))
    assert area == pytest.approx(polygon.area) == 700.0
    fan = _fan(len(xy))
    assert _outside(polygon, xy, fan)                     # the fan spans the notch...
    assert sum(abs(_area(xy[t])) for t in fan) > area     # ...and so covers too much
    tris = triangulate_polygon(xy)
    assert tris.shape == (len(xy) - 2, 3)
    assert sorted(set(tris.ravel())) == list(range(len(xy)))    # every vertex used
    areas = np.array([_area(xy[t]) for t in tris])
    assert (np.sign(_area(xy)) * areas > 0).all()         # the polygon's own winding
    assert np.abs(areas).sum() == pytest.approx(area, rel=1e-12)
    assert _outside(polygon, xy, tris) == []


def _u_panel_mesh():
    """A U-shaped panel left of a crease at x = 30 mm, a square right of it; 1 mm thick."""
    vertices = np.vstack([U_SHAPE, [[60, 0], [60, 30]]])
    edges = [[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 6], [6, 7], [7, 0], [1, 8], [8, 9],
             [9, 2]]
    kinds = ["B", "M"] + ["B"] * 9
    angles = [np.nan, -90.0] + [np.nan] * 9
    pattern = CreasePattern(vertices, edges, kinds, fold_angles=angles,
                            faces=[[0, 1, 2, 3, 4, 5, 6, 7], [1, 8, 9, 2]])
    return thicken(pattern, 1.0, 2.0, 2)


def test_the_stl_of_a_non_convex_panel_is_closed_with_the_prism_volume(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    mesh = _u_panel_mesh()
    surface = surface_polygons(mesh)
    caps = [loop for loop, cap in zip(surface.loops, surface.is_cap) if cap and len(loop) == 8]
    xy = mesh.points[caps[0] % len(mesh.points)]
    assert _outside(shapely.Polygon(xy), xy, _fan(len(xy)))   # a fan would get it wrong
    data = stl_bytes(mesh)
    path = tmp_path / "u.stl"
    write_stl(path, mesh)
    assert path.read_bytes() == data                    # one STL writer
    solid = trimesh.load(str(path), file_type="stl", process=True)
    assert solid.is_watertight and solid.is_winding_consistent
    assert solid.volume == pytest.approx(mesh.volume(), rel=1e-6)
    triangles = surface_triangles(mesh)
    assert enclosed_volume(mesh.rest_positions, triangles) == \
        pytest.approx(mesh.volume(), rel=1e-12)


def test_a_polygon_earcut_cannot_cover_is_refused_naming_the_face_and_the_file():
    bowtie = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], dtype=float)
    with pytest.raises(TriangulationError, match="face 7"):
        triangulate_polygon(bowtie, face=7)
    mesh = _u_panel_mesh()
    surface = surface_polygons(mesh)
    first_cap = int(np.flatnonzero(surface.is_cap & (np.array(list(map(len, surface.loops)))
                                                     == 8))[0])
    loop = surface.loops[first_cap] % len(mesh.points)
    mesh.points[[loop[1], loop[2]]] = mesh.points[[loop[2], loop[1]]]   # tangle the U
    with pytest.raises(TriangulationError) as info:
        surface_triangles(mesh, source="tangled.fold")
    message = str(info.value)
    assert message.startswith("tangled.fold: ") and f"face {first_cap}" in message
