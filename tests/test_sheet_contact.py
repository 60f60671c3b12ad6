"""A thin sheet with contact: its triangles never pass through each other.

Origami Simulator's ``miura-ori.svg`` at 90 % asks some creases for more than
180° (its opacities), so Origami Simulator's model folds facets through each
other. The crossings are counted here by a segment–triangle test of the
test's own (Möller–Trumbore), not by the library the contact uses.
"""
from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from foldcore import cli
from foldcore.errors import PatternWarning
from foldcore.io import read_file
from foldcore.sheet import SheetSolver, build_sheet

from solids import crossings

pytest.importorskip("ipctk")

MIURA = Path(__file__).parent / "data" / "real" / "miura-ori.svg"
#: From Origami Simulator's ``needsCollisions`` folder: its panels stack at 90 %.
SOLAR = Path(__file__).parent / "data" / "real" / "byu-solar-driven.svg"


def sheet_of(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PatternWarning)
        loaded = read_file(path)
    sheet = build_sheet(loaded.pattern, merge_straight=True, drawn=loaded.drawing)
    return sheet, loaded.pattern


@pytest.fixture(scope="module")
def miura():
    return sheet_of(MIURA)


def fold(miura, percent, contact):
    sheet, pattern = miura
    return SheetSolver(sheet, percent, pattern_edges=pattern.n_edges, contact=contact).run()


def test_without_contact_the_facets_pass_through_each_other(miura):
    result = fold(miura, 90, contact=False)
    assert result.converged and result.contact is None
    assert np.nanmax(np.abs(result.fold_angles_deg)) > 180.0
    assert crossings(result.positions, miura[0].triangles) > 0  # the check can fail


def test_with_contact_no_facet_passes_through_another(miura):
    result = fold(miura, 90, contact=True)
    assert result.converged
    assert crossings(result.positions, miura[0].triangles) == 0
    # the barrier holds the facets a crease would fold past flat: 180° at most
    assert np.nanmax(np.abs(result.fold_angles_deg)) <= 180.0
    c = result.contact
    assert c["active_pairs"] > 0
    assert 0.0 < c["smallest_gap_mm"] < c["activation_mm"]


def test_a_file_that_needs_collisions_folds_without_passing_through_itself():
    """Origami Simulator's own ``needsCollisions`` file: at 90 % its solar panels fold
    through each other (a crease past 180°) in Origami Simulator's model; with
    contact they stack, no crease past flat and no triangle through another."""
    solar = sheet_of(SOLAR)
    free, held = fold(solar, 90, contact=False), fold(solar, 90, contact=True)
    assert crossings(free.positions, solar[0].triangles) > 0
    assert held.converged and crossings(held.positions, solar[0].triangles) == 0
    assert np.nanmax(np.abs(held.fold_angles_deg)) <= 180.0


def test_a_contact_that_never_engages_changes_nothing(miura):
    """At 60 % no two facets come within d̂: the fold is Origami Simulator's model's,
    bit for bit."""
    free, held = fold(miura, 60, contact=False), fold(miura, 60, contact=True)
    assert held.contact["active_pairs"] == 0
    assert np.array_equal(free.positions, held.positions)
    assert held.iterations == free.iterations


def test_command_line_thin_contact(tmp_path, capsys):
    report = tmp_path / "r.json"
    code = cli.main(["simulate", str(MIURA), "--fold-percent", "90", "--contact", "on",
                     "-q", "--report", str(report)])
    assert code == 0, capsys.readouterr().err
    data = json.loads(report.read_text())
    assert data["settings"]["contact"] == "on" and data["contact"]["active_pairs"] > 0
    assert cli.main(["simulate", str(MIURA), "--fold-percent", "90", "-q",
                     "--report", str(report)]) == 0
    data = json.loads(report.read_text())
    assert data["settings"]["contact"] == "off" and data["contact"] is None



def test_a_long_step_through_a_facet_is_cut_short_of_it():
    """A triangle 0.5 above another, moved 1.0 down through it (ten pieces of the
    sweep): the share taken stops short of the touch at 0.5; moved sideways far
    from it, the whole step is free."""
    from foldcore.contact.sheet import MAX_SWEEP, SheetContact

    flat = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0],
                     [0.2, 0.2, 0.5], [0.5, 0.2, 0.5], [0.2, 0.5, 0.5]], dtype=float)
    contact = SheetContact(flat, np.array([[0, 1, 2], [3, 4, 5]]), force=1.0)
    down = flat.copy()
    down[3:, 2] -= 1.0
    assert 1.0 / MAX_SWEEP >= 10
    share = contact.free_share(flat, down)
    assert 0.4 < share < 0.5
    aside = flat.copy()
    aside[3:, 0] += 3.0
    assert contact.free_share(flat, aside) == 1.0


def test_contact_on_a_cut_sheet_is_refused_naming_the_file(tmp_path, capsys):
    """A cut's two sides lie on each other in the flat sheet: no d̂ keeps it outside
    the barrier, so contact is refused in one line, before any output."""
    from foldcore.io import write_fold
    from foldcore.pattern import CreasePattern

    xy = [(0, 0), (50, 0), (100, 0), (100, 50), (100, 100), (0, 100), (0, 50), (50, 50)]
    border = [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 6), (6, 0)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pattern = CreasePattern(xy, border + [(6, 7), (7, 3), (1, 7)],
                                ["B"] * 7 + ["V", "M", "C"],
                                fold_angles=[None] * 7 + [90, -90, None])
    source, out = tmp_path / "cut.fold", tmp_path / "r.fold"
    write_fold(source, pattern)
    assert cli.main(["simulate", str(source), "--contact", "on", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{source}: contact needs the flat sheet's triangles apart" in err
    assert "Traceback" not in err and err.count("foldcore: error") == 1
    assert not out.exists()
    assert cli.main(["simulate", str(source), "-q", "-o", str(out)]) == 0  # without: folds


def test_without_ipctk_contact_is_refused_in_one_line(tmp_path, capsys, monkeypatch):
    from foldcore.contact import sheet as sheet_contact

    def missing():
        raise ImportError("No module named 'ipctk'")

    monkeypatch.setattr(sheet_contact, "load_ipctk", missing)
    out = tmp_path / "r.fold"
    assert cli.main(["simulate", str(MIURA), "--contact", "on", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{MIURA}: contact needs the ipctk package" in err and "Traceback" not in err
    assert not out.exists()


def test_with_contact_no_step_turns_a_hinge_through_flat():
    """Two triangles that share a crease: the barrier never checks them against each
    other, so the solver refuses a trial that turns their hinge through ±180°."""
    from foldcore.pattern import CreasePattern

    square = CreasePattern([(0, 0), (100, 0), (100, 100), (0, 100)],
                           [(0, 1), (1, 2), (2, 3), (3, 0), (0, 2)], list("BBBBV"),
                           fold_angles=[None] * 4 + [90.0])
    sheet = build_sheet(square)
    solver = SheetSolver(sheet, 100.0, pattern_edges=square.n_edges, contact=True)
    (a, b, c, d), = sheet.hinges[sheet.hinge_edge == 4]

    def folded(degrees):
        """The flat sheet with tip d turned about the crease a–b by ``degrees``."""
        x = sheet.flat.copy()
        axis = (x[b] - x[a]) / np.linalg.norm(x[b] - x[a])
        r, t = x[d] - x[a], np.radians(degrees)
        x[d] = x[a] + r * np.cos(t) + np.cross(axis, r) * np.sin(t) + \
            axis * (axis @ r) * (1 - np.cos(t))
        return x

    near = folded(175.0)
    solver.x = near
    solver.energy.settle_references(near)
    angle = abs(np.degrees(solver.result("x").hinge_angles[sheet.hinge_edge == 4][0]))
    assert abs(angle - 175.0) < 1e-6
    assert not solver._through_flat(folded(179.0))
    assert solver._through_flat(folded(185.0))
    assert solver._trial_energy(folded(185.0)) == np.inf
