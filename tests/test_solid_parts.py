"""The folded solid names its parts: every face of a result frame says which
crease-pattern face (``foldcore:faces_face``) or crease (``foldcore:faces_edge``) it
belongs to, so anyone can check the solid part by part (tests/solids.py)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from foldcore import patterns, thicken
from foldcore.outputs import write_result
from foldcore.simulation import Simulation

from solids import folded_frame, hull, panel_overlaps, panel_points

pytest.importorskip("manifold3d")

A, H = 20.0, 1.0  # mm


def written(tmp_path, pattern, mesh, percent: float) -> dict:
    # rigid: panels exactly rigid (the mesh's own equilibrium, which the default
    # strategy certifies, strains them by ~1e-5 where the thick hinges bind a little)
    sim = Simulation(mesh, pattern, solver="rigid")
    sim.set_fold_percent(percent)
    result = sim.run(tolerance=1e-9)
    assert result.converged
    path = tmp_path / "r.fold"
    write_result(result, pattern, mesh, H, {}, fold=path)
    return json.loads(path.read_text())


@pytest.fixture(scope="module")
def miura():
    """A thick Miura 3 × 3 (a = 20 mm, H = 1 mm, W = H, axis hinges), every crease
    driven to its rigid-fold angle at facet tilt 60°: rigidly foldable."""
    n = 3
    angles = patterns.miura_fold_angles(n, n, 60.0, 60.0)
    pattern = patterns.miura(n, n, a=A, b=A, gamma=60.0, width=H).replace(fold_angles=angles)
    return pattern, thicken(pattern, H, subdivisions=2)


def test_every_face_is_one_panel_or_one_crease(tmp_path, miura):
    pattern, mesh = miura
    frame = folded_frame(written(tmp_path, pattern, mesh, 50.0))
    faces, panels, creases = (frame[k] for k in ("faces_vertices", "foldcore:faces_face",
                                                 "foldcore:faces_edge"))
    assert len(faces) == len(panels) == len(creases)
    assert all((p is None) != (c is None) for p, c in zip(panels, creases))
    assert {p for p in panels if p is not None} == set(range(len(pattern.faces)))
    assert {c for c in creases if c is not None} == set(pattern.creases.tolist())


def test_each_panel_part_is_its_prism(tmp_path, miura):
    """The hull of the faces labelled with a pattern face has exactly the volume of that
    face's panel prism (convex panels): a face given to the wrong part would change
    two hulls."""
    pattern, mesh = miura
    frame = folded_frame(written(tmp_path, pattern, mesh, 50.0))
    panels = mesh.groups["rigid_panel"]
    volume = np.bincount(panels.source, weights=panels.volumes, minlength=len(pattern.faces))
    for part, points in panel_points(frame).items():
        assert hull(points).volume() == pytest.approx(volume[part], rel=1e-9)


def test_panels_of_a_rigid_fold_do_not_overlap_and_a_crossing_is_found(tmp_path, miura):
    """At 50 % the thick Miura's panels are apart (axis hinges, W = H); moving one
    panel's vertices into its neighbour makes an overlap the check measures."""
    pattern, mesh = miura
    frame = folded_frame(written(tmp_path, pattern, mesh, 50.0))
    assert panel_overlaps(frame) == []
    points = panel_points(frame)
    a, b = 0, int(np.argmin([np.linalg.norm(p.mean(axis=0) - points[0].mean(axis=0))
                             if k else np.inf for k, p in sorted(points.items())]))
    shift = 0.5 * (points[b].mean(axis=0) - points[a].mean(axis=0))
    x = np.asarray(frame["vertices_coords"])
    moved = {v for f, part in zip(frame["faces_vertices"], frame["foldcore:faces_face"])
             if part == a for v in f}
    x[sorted(moved)] += shift
    frame["vertices_coords"] = x.tolist()
    ((first, second, volume),) = [o for o in panel_overlaps(frame) if {o[0], o[1]} == {a, b}]
    assert volume > 1e-3 * hull(points[a]).volume()
