"""Thick Miura folded flat: the layers a degree-4 vertex stacks.

Flat, a degree-4 vertex stacks its four panels in four layers, and the crease
opposite its odd crease (M/V unlike the other three) wraps around the other
three: its arc radius must be the sum of theirs. Arc hinges (radius W / π at
180°) of equal width leave the loop two layers short, so the sheet cannot
reach flat; widths that satisfy the sum at every vertex
(:func:`foldcore.patterns.miura_flat_widths` for a Miura) fold it exactly.

Pehrson's thick vertex (H = 3.175 mm, widths 16/4/8/4 mm from its wrapping
crease on) folds flat with slack hinges, whose strips may lengthen up to their
width: the wrapping crease then spans the three layers (3H = 9.5 mm, an arc of
16 mm spans up to 10.2 mm). Its flat state is compatible, so it is reached to
the run's tolerance (1e-8 × 152 mm over hinges ≥ 4 mm: ≤ 1e-4°; 0.01° asserted)
with its panels in four layers whose mid-planes are at least H apart, to the
positions' rounding at that tolerance (1e-4 mm); two panels' solids may share
a face there but overlap by no more than 1e-4 of a panel. Axis hinges hold
every flat crease's panels H apart, so the same vertex binds short of flat.

Bounds: a compatible flat state is reached to the run's tolerance, 1e-8 ×
size; over a hinge of width W ≥ 0.785 mm that is a fold angle within
2 × 1e-8 × 100 mm / W ≈ 1.5e-4°, so 1e-3° per crease. The incompatible ones
must miss by more than 1° on their straight creases (measured 2.5–6°; the
singular flat state amplifies the miss on them:
docs/architecture.md#a-thick-miura-has-no-flat-state-with-equal-hinges).
"""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from foldcore import patterns
from foldcore.io import write_fold
from foldcore.simulation import Simulation
from foldcore.thickening import thicken

GAMMA = 84.0  # degrees, Origami Simulator's Miura
SECTORS = [GAMMA, 180.0 - GAMMA, 180.0 - GAMMA, GAMMA]  # creases 1, 3 collinear (straight)
H = 0.5  # mm
EXACT = 1e-3  # degrees
SHORT = 1.0  # degrees


def fold_flat(pattern, thickness):
    """(E,) achieved fold angles (degrees) of ``pattern`` thickened with arc hinges."""
    mesh = thicken(pattern, thickness, hinge="arc")
    result = Simulation(mesh, pattern, solver="newton").run(tolerance=1e-8, max_iterations=200)
    return result.fold_angles_deg


def flat_vertex(widths):
    mv = patterns.degree4_assignments(SECTORS, "B")
    targets = [180.0 if a == "V" else -180.0 for a in mv]
    return patterns.single_vertex(SECTORS, mv, targets, radius=50.0, widths=widths), targets


def test_wrapping_crease_as_wide_as_the_other_three_folds_a_vertex_flat():
    width = np.pi / 2 * H  # Eq. 7: the arc's inner radius is 0 at 180°
    wrap = patterns.wrapping_crease(patterns.degree4_assignments(SECTORS, "B"))
    widths = [3 * width if k == wrap else width for k in range(4)]
    pattern, targets = flat_vertex(widths)
    miss = np.abs(fold_flat(pattern, H)[:4] - targets)
    assert miss.max() < EXACT
    pattern, targets = flat_vertex([width] * 4)
    miss = np.abs(fold_flat(pattern, H)[:4] - targets)
    assert miss[[0, 2]].min() > SHORT  # the straight pair, creases 1 and 3


def test_miura_flat_widths_close_every_vertex():
    """At each interior vertex the crease opposite the odd one is as wide as the
    other three together (checked from the M/V, not from the formula)."""
    n, m, width = 5, 4, 1.5
    pattern = patterns.miura(n, m, a=20.0, b=20.0, gamma=GAMMA)
    widths = patterns.miura_flat_widths(n, m, width)
    kinds = patterns.miura_edge_kinds(n, m)
    assert np.isnan(widths[kinds == "boundary"]).all()
    assert np.allclose(widths[kinds == "zigzag"], width)
    at_vertex = {}
    for e, (u, v) in enumerate(pattern.edges):
        if kinds[e] != "boundary":
            at_vertex.setdefault(u, []).append(e)
            at_vertex.setdefault(v, []).append(e)
    checked = 0
    for vertex, edges in at_vertex.items():
        if len(edges) != 4:
            continue
        mv = [pattern.assignments[e] for e in edges]
        odd = [e for e, a in zip(edges, mv) if mv.count(a) == 1][0]
        wrap = [e for e in edges if kinds[e] == kinds[odd] and e != odd][0]
        others = sum(widths[e] for e in edges if e != wrap)
        assert widths[wrap] == pytest.approx(others)
        checked += 1
    assert checked == (n - 1) * (m - 1)


def test_graded_miura_folds_flat_and_equal_one_does_not():
    n, m = 4, 2
    thickness = 0.2
    angles = patterns.miura_fold_angles(n, m, GAMMA, 90.0)
    straight = patterns.miura_edge_kinds(n, m) == "straight"
    base = patterns.miura(n, m, a=20.0, b=20.0, gamma=GAMMA,
                          width=np.pi / 2 * thickness).replace(fold_angles=angles)
    graded = base.replace(widths=patterns.miura_flat_widths(n, m, np.pi / 2 * thickness))
    miss = np.abs(fold_flat(graded, thickness) - angles)
    assert np.nanmax(miss) < EXACT
    miss = np.abs(fold_flat(base, thickness) - angles)
    assert miss[straight].min() > SHORT


def test_rigid_model_folds_a_graded_miura_flat():
    # The rigid-body model's M/V side rows read a valley folded a hair past flat as
    # a crease 180° on its wrong side (the dihedral wraps at ±π): its run stopped
    # "converged" 13.4° short of flat here. Its own equilibrium is flat too.
    n, m = 4, 4
    thickness = 0.2
    angles = patterns.miura_fold_angles(n, m, GAMMA, 90.0)
    pattern = patterns.miura(n, m, a=20.0, b=20.0, gamma=GAMMA).replace(
        widths=patterns.miura_flat_widths(n, m, np.pi / 2 * thickness), fold_angles=angles)
    mesh = thicken(pattern, thickness, hinge="arc")
    result = Simulation(mesh, pattern, solver="rigid").run(tolerance=1e-8, max_iterations=500)
    assert result.converged
    assert np.nanmax(np.abs(result.fold_angles_deg - angles)) < EXACT


def test_miura_flat_widths_refuses_a_bad_width():
    with pytest.raises(Exception, match="width"):
        patterns.miura_flat_widths(3, 3, 0.0)


PEHRSON_H = 3.175  # mm


def pehrson_flat_file(tmp_path, hinge: str):
    """FOLD of Pehrson's vertex (mode A), every crease's target ±180°, ``hinge`` joints."""
    pattern = patterns.degree4_vertex(mode="A")
    targets = [180.0 if a == "V" else -180.0 for a in pattern.assignments[:4]]
    pattern = pattern.replace(fold_angles=targets + [None] * (pattern.n_edges - 4))
    path = tmp_path / f"pehrson-{hinge}.fold"
    write_fold(path, pattern, thickness=PEHRSON_H, extra={
        "foldcore:edges_hinge": [hinge] * 4 + [None] * (pattern.n_edges - 4)})
    return path, np.array(targets)


def simulate(path, *options):
    out = path.with_suffix(".out.fold")
    done = subprocess.run([sys.executable, "-m", "foldcore", "simulate", str(path), "-o",
                           str(out), *options], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads(out.read_text())


def layers(frame):
    """Mid-plane heights (mm) of the panels of a folded vertex, sorted, along the
    normal of panel 0 (its top and bottom faces' mean offset)."""
    from solids import panel_points

    points = panel_points(frame)
    first = points[0] - points[0].mean(axis=0)
    normal = np.linalg.svd(first)[2][2]
    return np.sort([p.mean(axis=0) @ normal for p in points.values()])


@pytest.mark.parametrize("contact", ["off", "on"])
def test_pehrsons_vertex_folds_flat_in_four_layers_with_slack_hinges(tmp_path, contact):
    from solids import folded_frame, hull, panel_overlaps, panel_points

    if contact == "on":
        pytest.importorskip("ipctk")
    path, targets = pehrson_flat_file(tmp_path, "slack")
    fold = simulate(path, "--contact", contact)
    angles = np.array(fold["edges_foldAngle"][:4])  # the achieved angles
    assert np.abs(angles - targets).max() < 0.01
    frame = folded_frame(fold)
    gaps = np.diff(layers(frame))
    assert len(gaps) == 3 and gaps.min() >= PEHRSON_H - 1e-4  # four layers, none shared
    smallest = min(hull(p).volume() for p in panel_points(frame).values())
    assert all(v <= 1e-4 * smallest for _, _, v in panel_overlaps(frame))


def test_pehrsons_vertex_binds_short_of_flat_with_axis_hinges(tmp_path):
    path, targets = pehrson_flat_file(tmp_path, "axis")
    fold = simulate(path)
    angles = np.array(fold["edges_foldAngle"][:4])
    assert np.abs(angles - targets).max() > SHORT


def test_the_rigid_strategy_refuses_slack_hinges(tmp_path):
    path, _ = pehrson_flat_file(tmp_path, "slack")
    done = subprocess.run([sys.executable, "-m", "foldcore", "simulate", str(path),
                           "--solver", "rigid"], capture_output=True, text=True)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "slack" in done.stderr and "0, 1, 2, 3" in done.stderr
