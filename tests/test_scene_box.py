"""The box scene (paper §6.2, reconstructed hexagonal tray) checked against physics.

Tolerances and why:

* Thin reconstruction: the zero-thickness folded state is built in closed
  form, so it must be an isometry of the pattern and reach the target angles
  to rounding (1e-9 mm and 1e-9° on a 150 mm sheet, float64 gives ~1e-13);
  its convex hull at 90° is the hexagonal prism (3√3/2)s²h to 1e-12 relative.
* M/V: no crease may fold against its assignment, and the 180° mountain may
  not fold through itself; 0.1° slack as in tests/test_scenes.py (a strip
  held at its bound, measured from the panels).
* "A box": walls rise by more than 60° (the rim stands at ≥ sin 60° = 87 % of
  the wall height), the gusset fins sit inside the
  corners (> 0 mm inward; a fin folded outward would be < 0).
* Thickness: the corner mismatch grows with W against the panels, so the
  4 mm box flares more and keeps a smaller fraction of the thin tray's
  capacity at the same tilt; the residual holes grow and the panels shrink
  (insets W/2 grow with H).
* Capacity: below the thin tray with the same bottom and wall tilt (the
  material and the fins take room) and above it minus the material (the
  shell's mid-surface is the thin tray to O(W) and lies inside the hull).
* Sheet: outline = panels + hinges + holes to the rounding of the report
  (3 decimals, 0.01 mm²); a hinge strip is at most W × its crease length
  (strips are cut at the vertices, never extended).
* Material: panels are rigid (rigid strategy), so the folded volume differs
  from the rest volume by less than the hinges' own volume.
"""
from __future__ import annotations

import numpy as np
import pytest

from foldcore.scenes import box

SIGN_SLACK_DEG = 0.1


@pytest.fixture(scope="module")
def boxes(runs):
    run = runs["box"]
    return run, {r["thickness_mm"]: r for r in run.quantities["runs"]}


def test_thin_tray_is_an_isometry_with_the_target_angles():
    pattern = box.hexagonal_tray(box.SIDE, box.HEIGHT)
    for bottom in (90.0, 75.0, 45.0):
        assert box.isometry_error(pattern, box.thin_tray(box.SIDE, box.HEIGHT, bottom)) < 1e-9
    folded = box.thin_fold_angles(pattern, box.thin_tray(box.SIDE, box.HEIGHT, 90.0))
    crease = pattern.creases
    reached = box.toward(folded[crease], pattern.fold_angles[crease])
    assert np.abs(reached - pattern.fold_angles[crease]).max() < 1e-9
    assert sorted(np.unique(np.bincount(pattern.edges[crease].ravel()))) == [1, 5]
    assert np.count_nonzero(np.bincount(pattern.edges[crease].ravel()) == 5) == 6


def test_thin_capacity_at_90_is_the_hexagonal_prism():
    hand = 1.5 * np.sqrt(3.0) * box.SIDE ** 2 * box.HEIGHT
    assert box.thin_capacity(box.SIDE, box.HEIGHT, 90.0) == pytest.approx(hand, rel=1e-12)


def test_both_thicknesses_fold_into_boxes_keeping_mv(boxes):
    _, rows = boxes
    assert set(rows) == set(box.THICKNESSES)
    for q in rows.values():
        angles = q["fold_angles_deg"]
        assert q["converged"]
        assert q["hinge_width_mm"] == pytest.approx(np.pi * q["thickness_mm"] / 2, abs=1e-4)
        assert angles["bottom"]["achieved_min_deg"] > 60.0
        assert angles["side"]["achieved_min_deg"] >= -SIGN_SLACK_DEG
        assert angles["diagonal"]["achieved_max_deg"] <= SIGN_SLACK_DEG
        assert angles["diagonal"]["achieved_min_deg"] >= -180.0 - SIGN_SLACK_DEG
        assert q["fin_inward_mm"] > 0.0


def test_thicker_box_flares_more_and_keeps_less_of_the_thin_capacity(boxes):
    _, rows = boxes
    thin, thick = rows[min(rows)], rows[max(rows)]
    assert 0.0 < thin["wall_tilt_deg"] < thick["wall_tilt_deg"]
    assert (thick["volume_mm3"]["capacity_vs_thin_same_tilt"]
            < thin["volume_mm3"]["capacity_vs_thin_same_tilt"])
    # the paper's "the volume of the box is also reduced", in absolute terms too
    assert thick["volume_mm3"]["capacity"] < thin["volume_mm3"]["capacity"]


def test_capacity_lies_between_the_thin_tray_and_it_minus_the_material(boxes):
    _, rows = boxes
    for q in rows.values():
        v = q["volume_mm3"]
        assert v["thin_same_tilt"] - v["material"] < v["capacity"] < v["thin_same_tilt"]
        assert abs(v["material"] - v["material_rest"]) < v["hinge_rest"]


def test_the_2d_sheets_differ_with_thickness(boxes):
    run, rows = boxes
    for q in rows.values():
        s = q["sheet_mm2"]
        assert s["panels"] + s["hinges"] + s["holes"] == pytest.approx(s["outline"], abs=0.01)
    thin, thick = rows[min(rows)]["sheet_mm2"], rows[max(rows)]["sheet_mm2"]
    assert thick["holes"] > thin["holes"] and thick["panels"] < thin["panels"]
    lengths = run.pattern.edge_lengths()[run.pattern.creases].sum()
    assert thick["hinges"] <= rows[max(rows)]["hinge_width_mm"] * lengths


def test_scene_run_shows_the_thicker_box(boxes):
    run, rows = boxes
    assert run.name == "box" and run.thickness == max(box.THICKNESSES)
    assert run.result.positions.shape == (run.mesh.n_vertices, 3)
    line = box.headline(run.quantities)
    assert all(f"flared {q['wall_tilt_deg']:.1f}°" in line for q in rows.values())
