"""Obstacles: fixed meshes the sheet touches but never passes.

Scene: three panels 4 | 12 | 4 mm in a row (10 mm deep), H = 1 mm, both
creases valleys driven to 180°, on a pedestal 8 × 8 mm 0.05 mm below the
middle panel, with a block 9 × 6 × 3 mm standing 0.05 mm above it. The outer
panels fold up onto the block and must stop on it: folded flat they would
cut through it (checked without the block: they reach 180° and overlap its
hull). The pedestal stays clear of the hinges: a valley's hinge strip swings
its outer face below the sheet as it folds, and on a table under the whole
sheet the strips press on it and lift the sheet against the block, which
then holds it with 0.1 mm of play: the creases jam short of the block
(checked too: the table, the block and the strips all pressed).
Bounds: the stop is symmetric (the scene is mirror-symmetric) to what the
barrier leaves open: each contact holds somewhere within d̂ = 0.01 H of the
block, so the two creases within degrees(d̂ / 4 mm) = 0.14°; no panel's convex hull
overlaps the cube's or the ground's by more than 1e-4 of a panel (the
acceptance bound of contact, manifold3d's exact boolean).
"""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("ipctk")

from foldcore.contact import Obstacle, ObstacleError, read_obstacle  # noqa: E402
from foldcore.errors import SimulationError  # noqa: E402
from foldcore.io import write_fold  # noqa: E402
from foldcore import patterns  # noqa: E402
from foldcore.simulation import Simulation  # noqa: E402
from foldcore.thickening import thicken  # noqa: E402

from solids import hull  # noqa: E402

H = 1.0  # mm
GAP = 0.05  # mm between the sheet and each obstacle at the start


def letter():
    return patterns.panel_row([4.0, 12.0, 4.0])


def cube(centre=(10.0, 5.0, 0.5 * H + GAP + 1.5), half=(4.5, 3.0, 1.5)) -> Obstacle:
    c = np.asarray(centre)
    v = np.array([c + np.asarray(half) * np.array([sx, sy, sz])
                  for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    f = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
         [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    return Obstacle(v, np.array(f), "cube")


def ground(size: float = 8.0) -> Obstacle:
    """A plane 0.05 mm below the sheet, ``size`` mm square about the middle panel's
    centre: 8, a pedestal clear of the hinges; 200, a table under the whole sheet."""
    return Obstacle.plane((10.0, 5.0, -0.5 * H - GAP), (0.0, 0.0, 1.0), size=size,
                          name="ground")


def fold(obstacles):
    pattern = letter()
    mesh = thicken(pattern, H)
    sim = Simulation(mesh, pattern, solver="rigid", obstacles=obstacles)
    sim.set_fold_angles({0: 180.0, 1: 180.0})
    return mesh, sim.run(tolerance=1e-8, max_iterations=2_000)


def overlaps(mesh, positions, obstacle) -> float:
    """Largest overlap of a panel's hull with the obstacle's hull, over a panel's volume."""
    g = mesh.groups[mesh.panel_group]
    other = hull(obstacle.vertices)
    worst = 0.0
    for p in range(len(g)):
        panel = hull(positions[g.indices[g.slots(p)]])
        worst = max(worst, (panel ^ other).volume() / panel.volume())
    return worst


@pytest.fixture(scope="module")
def grasped():
    return fold([cube(), ground()])


def test_without_the_cube_the_panels_fold_through_its_place():
    mesh, result = fold([ground()])
    assert np.abs(result.fold_angles_deg[:2] - 180.0).max() < 0.01
    assert overlaps(mesh, result.positions, cube()) > 0.1


def test_the_panels_stop_on_the_cube_without_passing_it(grasped):
    mesh, result = grasped
    a, b = result.fold_angles_deg[:2]
    assert result.converged and a < 150.0 and abs(a - b) < np.degrees(0.01 * H / 4.0)
    assert overlaps(mesh, result.positions, cube()) <= 1e-4
    assert overlaps(mesh, result.positions, ground()) <= 1e-4
    entries = {o["name"]: o for o in result.contact["obstacles"]}
    assert {0, 2} <= set(entries["cube"]["touching_faces"])


def test_on_a_table_the_hinges_press_on_it_and_jam_against_the_block(grasped):
    """The strips' outer faces swing below the sheet: on a table under the whole sheet
    they press on it, the block presses the panels back, and the creases stop short
    of where the pedestal let them reach (without hinge strips among the parts
    contact keeps apart, they passed through the table)."""
    mesh, result = fold([cube(), ground(200.0)])
    a, b = result.fold_angles_deg[:2]
    assert a < grasped[1].fold_angles_deg[0] - 1.0 and abs(a - b) < np.degrees(0.01 * H / 4.0)
    entries = {o["name"]: o for o in result.contact["obstacles"]}
    assert entries["ground"]["touching_creases"] == [0, 1]
    assert entries["ground"]["magnitude"] > 0 and entries["cube"]["magnitude"] > 0
    assert overlaps(mesh, result.positions, cube()) <= 1e-4
    assert result.positions[:, 2].min() > -0.5 * H - GAP  # every vertex above the table


def test_an_obstacle_through_the_sheet_at_the_start_is_refused():
    through = Obstacle.plane((10.0, 5.0, 0.0), (0.0, 0.0, 1.0), size=200.0, name="table")
    with pytest.raises(SimulationError, match="'table' touches or cuts the panel of face"):
        fold([through])
    with pytest.raises(SimulationError, match="obstacles need contact"):
        Simulation(thicken(letter(), H), letter(), solver="rigid", contact=False,
                   obstacles=[ground()])


@pytest.mark.parametrize("vertices, faces, message", [
    (np.zeros((3, 2)), [[0, 1, 2]], "vertices must be"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, np.nan]], [[0, 1, 2]], "vertex 2 is not finite"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]], "face 0 names vertex"),
    ([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]], "face 0 has no area"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0.0, 1.0, 2.0]], "integers")])
def test_bad_obstacle_meshes_are_refused_by_name(vertices, faces, message):
    with pytest.raises(ObstacleError, match=message):
        Obstacle(np.asarray(vertices, dtype=float), np.asarray(faces), "thing")


def test_obstacle_files(tmp_path):
    meshio = pytest.importorskip("meshio")
    c = cube()
    path = tmp_path / "cube.stl"
    meshio.write_points_cells(path, c.vertices, [("triangle", c.faces)])
    read = read_obstacle(path)
    assert read.name == "cube.stl" and len(read.faces) == 12
    assert np.allclose(np.sort(read.vertices, axis=0), np.sort(c.vertices, axis=0), atol=1e-6)
    bad = tmp_path / "bad.stl"
    bad.write_bytes(b"solid nothing\n facet oops\n")
    with pytest.raises(ObstacleError, match="bad.stl"):
        read_obstacle(bad)


def test_command_line_obstacles(tmp_path):
    meshio = pytest.importorskip("meshio")
    c = cube()
    mesh_path = tmp_path / "cube.obj"
    meshio.write_points_cells(mesh_path, c.vertices, [("triangle", c.faces)])
    src = tmp_path / "letter.fold"
    write_fold(src, letter().replace(fold_angles=[180.0, 180.0] + [None] * 8), thickness=H)
    cli = [sys.executable, "-m", "foldcore", "simulate", str(src), "--solver", "rigid",
           "--obstacle", str(mesh_path), "--ground", str(-0.5 * H - GAP)]
    done = subprocess.run(cli + ["--report", str(tmp_path / "r.json")],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["settings"]["contact"] == "on" and report["settings"]["ground_mm"] == -0.55
    assert [o["name"] for o in report["contact"]["obstacles"]] == ["cube.obj", "ground"]
    assert max(report["fold_angles_deg"][:2]) < 150.0
    (tmp_path / "junk.obj").write_text("v 0 0\nf 1 2 9\n")
    for extra in (["--obstacle", str(tmp_path / "junk.obj")], ["--ground", "0"],
                  ["--ground", "10"]):  # through the sheet, above it: refused before the run
        refused = subprocess.run(cli[:7] + extra, capture_output=True, text=True)
        assert refused.returncode == 2 and "Traceback" not in refused.stderr
        assert refused.stderr.count("\n") == 1, refused.stderr
    ground = subprocess.run(cli[:7] + ["--ground", "10"], capture_output=True, text=True)
    assert f"--ground = 10 mm is not below the flat sheet, whose bottom face is at z = " \
           f"{-0.5 * H:g} mm" in ground.stderr
    assert "junk.obj" in subprocess.run(cli[:7] + ["--obstacle", str(tmp_path / "junk.obj")],
                                        capture_output=True, text=True).stderr
