"""Per-element stiffness factors: API, FOLD keys, validation, and what they change.

Physics checked: factors change nothing where every target can be met (a
single actuated hinge reaches its angle whatever its factor, to the stopping
tolerance), and decide the compromise where targets conflict — the stiffer
of two conflicting hinges ends closer to its own target (examples/stiffness.py).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from foldcore import patterns
from foldcore.cli import main
from foldcore.errors import MeshError, PatternError
from foldcore.io import read_fold_file, write_fold
from foldcore.io.fold import EDGE_STIFFNESS_KEY, FACE_STIFFNESS_KEY
from foldcore.simulation import Simulation
from foldcore.thickening import thicken

sys.path.insert(0, str(Path(__file__).parent.parent / "examples"))
import stiffness as example  # noqa: E402


def test_compatible_target_is_reached_whatever_the_factor():
    pattern = patterns.single_hinge(panel_length=5.0, depth=10.0, angle=60.0, width=2.0)
    for factor in (0.1, 1.0, 10.0):
        mesh = thicken(pattern, 1.0, subdivisions=4, stiffness={"hinge": factor})
        result = Simulation(mesh, pattern, solver="rigid").run(tolerance=1e-10,
                                                              max_iterations=50)
        assert abs(result.fold_angles_deg[0] - 60.0) < 0.01


def test_the_stiffer_of_two_conflicting_hinges_wins(tmp_path):
    rho = example.main(str(tmp_path))
    equal, one, two = rho["equal"], rho["crease1_stiff"], rho["crease2_stiff"]
    assert abs(one[0] - 90.0) < abs(equal[0] - 90.0) < abs(two[0] - 90.0)
    assert abs(two[1] - 20.0) < abs(equal[1] - 20.0) < abs(one[1] - 20.0)


def test_fold_keys_round_trip_into_the_mesh_weights(tmp_path):
    pattern = patterns.single_hinge(panel_length=5.0, depth=10.0, angle=60.0, width=2.0)
    edges = [4.0] + [None] * (pattern.n_edges - 1)
    path = tmp_path / "stiff.fold"
    write_fold(path, pattern, thickness=1.0,
               extra={EDGE_STIFFNESS_KEY: edges, FACE_STIFFNESS_KEY: [2.0, None]})
    fold = read_fold_file(path)
    np.testing.assert_array_equal(fold.stiffness["hinge"], [4.0] + [1.0] * (pattern.n_edges - 1))
    np.testing.assert_array_equal(fold.stiffness["panel"], [2.0, 1.0])
    mesh = thicken(fold.pattern, 1.0, subdivisions=2, stiffness=fold.stiffness)
    hinges, panels = mesh.groups["bending_hinge"], mesh.groups["rigid_panel"]
    np.testing.assert_allclose(hinges.weights, 4.0 * hinges.volumes)
    np.testing.assert_allclose(panels.weights, [2.0, 1.0] * panels.volumes)
    report = tmp_path / "r.json"
    assert main(["simulate", str(path), "--solver", "rigid", "--tolerance", "1e-10",
                 "--report", str(report)]) == 0
    assert abs(json.loads(report.read_text())["fold_angles_deg"][0] - 60.0) < 0.01


@pytest.mark.parametrize("key, value, message", [
    (EDGE_STIFFNESS_KEY, [0.0] + [None] * 6, r"edges_stiffness\[0\] \(edge 0\) must be a positive"),
    (EDGE_STIFFNESS_KEY, ["x"] + [None] * 6, r"edges_stiffness\[0\] \(edge 0\) must be a finite"),
    (FACE_STIFFNESS_KEY, [1.0], r"faces_stiffness has 1 entries for 2 faces"),
])
def test_bad_fold_stiffness_is_refused_naming_the_item(tmp_path, key, value, message):
    pattern = patterns.single_hinge(angle=60.0, width=2.0)
    path = tmp_path / "bad.fold"
    write_fold(path, pattern, thickness=1.0, extra={key: value})
    with pytest.raises(PatternError, match=message):
        read_fold_file(path)


@pytest.mark.parametrize("stiffness, message", [
    ({"hinge": -1.0}, r"stiffness\['hinge'\] must be a positive"),
    ({"hinge": [1.0, 2.0]}, r"one factor per edge \(7\)"),
    ({"panel": [1.0, np.nan]}, r"stiffness\['panel'\] \(face 1\) must be a positive"),
    ({"glue": 1.0}, r"stiffness key 'glue'"),
])
def test_bad_api_stiffness_is_refused(stiffness, message):
    pattern = patterns.single_hinge(angle=60.0, width=2.0)
    with pytest.raises(MeshError, match=message):
        thicken(pattern, 1.0, stiffness=stiffness)
