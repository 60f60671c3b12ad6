"""Accuracy against the closed forms of :mod:`foldcore.kinematics`, from the CLI defaults.

Every case is folded by ``foldcore simulate PATTERN.fold --thickness H -o OUT.fold``
with no other option — default hinge model (axis), actuation (equal weights),
branch stage, strategy (hybrid), subdivisions (auto), tolerance (1e-8) — and
the achieved angles read back from the written file, so what a user of the
command line gets is what is held to the closed form.

Bound: 0.01° per crease. Why the thick model can meet it: the
axis hinge turns a crease's two panels about the crease's mid-line, so the
hinges around a vertex meet at it and a rigid-foldable pattern folds without
strain at any thickness (:mod:`foldcore.hinges`); what is left is the
iteration's stopping tolerance (measured errors 1e-10…5e-7°, bench/accuracy).
Sizes: H/R = 1e-3 and W = 3H for the vertices; thin
Miura H = 1e-3·a (5 × 5: W = 3H, 10 × 10: W = H); thick Miura H = 0.1·a,
W = H, folded to facet tilt 30° (zig-zag 60°, straight 32.2°: its panels
clear each other).
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from foldcore import kinematics, patterns
from foldcore.cli import main
from foldcore.io import write_fold

BOUND = 0.01  # degrees
R = 10.0      # mm, vertex disc radius
H = R * 1e-3  # thin limit: H/R = 1e-3
W = 3 * H
SECTORS = [(135.0, 90.0, 45.0, 90.0),    # Pehrson
           (150.0, 60.0, 30.0, 120.0),
           (120.0, 75.0, 60.0, 105.0)]


def cli_fold(tmp_path, pattern, thickness: float) -> np.ndarray:
    """(E,) achieved fold angles (degrees) of ``foldcore simulate`` at its defaults."""
    src, out = tmp_path / "in.fold", tmp_path / "out.fold"
    write_fold(src, pattern)
    assert main(["simulate", str(src), "--thickness", repr(thickness), "-o", str(out)]) == 0
    angles = json.loads(out.read_text())["edges_foldAngle"]
    return np.array([np.nan if a is None else a for a in angles])


def closed_vertex(sectors, known: dict, angles_deg) -> np.ndarray:
    """Closure-oracle angles (degrees) of one vertex with ``known`` prescribed, on the
    branch of the measured ``angles_deg`` (used as the starting guess)."""
    starts = np.radians(np.concatenate([[0.0], np.cumsum(sectors)[:-1]]))
    directions = np.column_stack([np.cos(starts), np.sin(starts), np.zeros(len(starts))])
    rho = kinematics.solve_vertex(directions, {i: np.radians(v) for i, v in known.items()},
                                  np.radians(angles_deg))
    assert kinematics.closure_residual(directions, rho) < 1e-12
    return np.degrees(rho)


@pytest.mark.parametrize("mode", ["A", "B"])
@pytest.mark.parametrize("sectors", SECTORS)
def test_flat_foldable_vertex_folds_its_assigned_mode(tmp_path, sectors, mode):
    """Crease 1 driven to 70°, the others passive: the M/V assignment of the mode
    selects the branch from flat, and all four angles follow its closed form."""
    pattern = patterns.degree4_vertex(sectors=sectors, radius=R, widths=[W] * 4,
                                      mode=mode, rho1=70.0)
    achieved = cli_fold(tmp_path, pattern, H)[:4]
    closed = kinematics.degree4_deg(sectors[0], sectors[1], 70.0, mode)
    assert np.abs(achieved - closed).max() < BOUND


def test_non_flat_foldable_vertex_closes(tmp_path):
    """A general degree-4 vertex (sectors 100/70/110/80, α1 + α3 ≠ 180°): crease 1 at
    70° fixes the other three by closure; assignment from that branch."""
    sectors = (100.0, 70.0, 110.0, 80.0)
    branch = closed_vertex(sectors, {0: 70.0}, [70.0, 40.0, 60.0, -40.0])
    kinds = ["V" if a > 0 else "M" for a in branch]
    pattern = patterns.degree4_vertex(sectors=sectors, radius=R, widths=[W] * 4,
                                      assignments=kinds, flat_foldable=False, rho1=70.0)
    achieved = cli_fold(tmp_path, pattern, H)[:4]
    assert np.abs(achieved - branch).max() < BOUND


def test_degree5_box_corner_closes(tmp_path):
    """The box scene's corner (sectors 120 bottom, 90 wall, 30 + 30 gusset, 90 wall):
    both bottom–wall creases driven to 60° leave no freedom; the gusset's valleys
    and its mountain diagonal follow by closure."""
    sectors = (120.0, 90.0, 30.0, 30.0, 90.0)
    kinds = ["V", "V", "V", "M", "V"]
    pattern = patterns.single_vertex(sectors, kinds, [60.0, 60.0, None, None, None],
                                     radius=R, widths=[W] * 5)
    achieved = cli_fold(tmp_path, pattern, H)[:5]
    closed = closed_vertex(sectors, {0: 60.0, 1: 60.0}, achieved)
    assert np.sign(closed[2:]).tolist() == [1.0, -1.0, 1.0]  # the assigned branch
    assert np.abs(achieved - closed).max() < BOUND


@pytest.mark.parametrize("n, width_over_h, thickness_over_a", [(5, 3.0, 1e-3),
                                                                (10, 1.0, 1e-3),
                                                                (10, 1.0, 0.1)])
def test_miura_driven_by_one_crease_follows_rigid_folding(tmp_path, n, width_over_h,
                                                          thickness_over_a):
    thickness = thickness_over_a * 20.0
    pattern = patterns.miura_one_crease(n, n, width=width_over_h * thickness)
    expected = patterns.miura_fold_angles(n, n, 60.0, 30.0)
    achieved = cli_fold(tmp_path, pattern, thickness)
    creases = patterns.miura_edge_kinds(n, n) != "boundary"
    assert np.abs(achieved[creases] - expected[creases]).max() < BOUND


def test_driving_one_crease_of_a_file_that_targets_all_four(tmp_path):
    """``--drive 0`` on a vertex whose file gives every crease a target (the others
    deliberately wrong: 10° each way) folds as if only crease 0 had one: the
    other three follow the closed form of mode A, not their targets."""
    sectors = SECTORS[0]
    pattern = patterns.degree4_vertex(sectors=sectors, radius=R, widths=[W] * 4,
                                      mode="A", rho1=70.0)
    angles = pattern.fold_angles.copy()
    angles[1:4] = [10.0, 10.0, -10.0]
    src, out = tmp_path / "all.fold", tmp_path / "out.fold"
    write_fold(src, pattern.replace(fold_angles=angles))
    assert main(["simulate", str(src), "--thickness", repr(H), "--drive", "0",
                 "-o", str(out)]) == 0
    achieved = np.array(json.loads(out.read_text())["edges_foldAngle"][:4], dtype=float)
    closed = kinematics.degree4_deg(sectors[0], sectors[1], 70.0, "A")
    assert np.abs(achieved - closed).max() < BOUND
