"""A pattern with no thickness folds as a thin sheet (:mod:`foldcore.sheet_job`):
the note, the outputs and what they hold, the thick-only options refused."""
from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import foldcore
from foldcore import cli, patterns
from foldcore.errors import RunWarning
from foldcore.io import write_fold
from foldcore.sheet import SheetFold

REAL = "tests/data/real/"


def _dihedral_deg(x, a, b, c, d):
    """Fold angle (degrees, valley > 0) of the crease a → b with c left, d right,
    measured from the points alone (numpy, independent of the kernels)."""
    e = x[b] - x[a]
    n1 = np.cross(x[b] - x[a], x[c] - x[a])   # upward normal of the left triangle
    n2 = np.cross(x[d] - x[a], x[b] - x[a])   # and of the right one
    sine = np.dot(np.cross(n1, n2), e) / np.linalg.norm(e)
    return np.degrees(np.arctan2(-sine, np.dot(n1, n2)))


@pytest.fixture
def miura_file(tmp_path):
    """A 3 × 3 Miura at half its rigid-fold angles (not rigidly compatible: facets bend)."""
    angles = 0.5 * patterns.miura_fold_angles(3, 3, 60.0, 50.0)
    path = tmp_path / "miura.fold"
    write_fold(path, patterns.miura(3, 3, gamma=60.0).replace(fold_angles=angles))
    return path


def test_no_thickness_folds_a_thin_sheet_and_writes_what_it_measured(miura_file, tmp_path,
                                                                      capsys):
    out, report, png = tmp_path / "r.fold", tmp_path / "r.json", tmp_path / "r.png"
    assert cli.main(["simulate", str(miura_file), "--fold-percent", "80", "-o", str(out),
                     "--report", str(report), "--render", str(png)]) == 0
    err = capsys.readouterr().err
    assert "no thickness given: folded as a thin sheet" in err and "--thickness" in err
    data, rep = json.loads(out.read_text()), json.loads(report.read_text())
    assert data["foldcore:model"] == "sheet" and "foldcore:thickness" not in data
    assert rep["model"] == "sheet" and rep["converged"] and rep["reason"] == "converged"
    assert png.stat().st_size > 0
    frame = data["file_frames"][0]
    x = np.array(frame["vertices_coords"])
    pattern = foldcore.io.read(miura_file)
    assert x.shape == (pattern.n_vertices, 3)
    # every triangle names its pattern face; the faces are covered
    assert sorted(set(frame["foldcore:faces_face"])) == list(range(len(pattern.faces)))
    # the angles written are those of the folded form, measured independently
    tris = np.array(frame["faces_vertices"])
    left = {(t[i], t[(i + 1) % 3]): t[(i + 2) % 3] for t in tris for i in range(3)}
    for e, (a, b) in enumerate(np.asarray(pattern.edges)):
        if pattern.assignments[e] == "B":
            assert rep["fold_angles_deg"][e] is None
            continue
        if (a, b) not in left:
            a, b = b, a
        measured = _dihedral_deg(x, a, b, left[(a, b)], left[(b, a)])
        assert rep["fold_angles_deg"][e] == pytest.approx(measured, abs=1e-9)
        assert data["edges_foldAngle"][e] == pytest.approx(measured, abs=1e-9)
    # the targets are 80 % of the file's
    targets = np.array([np.nan if t is None else t for t in rep["target_angles_deg"]])
    assert np.allclose(targets, 0.8 * np.asarray(pattern.fold_angles), equal_nan=True)


def test_library_call_gives_the_sheet_fold_and_a_thickness_still_gives_a_thick_one(miura_file):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        thin = foldcore.simulate(miura_file, solving={"fold_percent": 50})
    assert isinstance(thin, SheetFold) and thin.converged
    assert any(issubclass(w.category, RunWarning) and "thin sheet" in str(w.message)
               for w in caught)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RunWarning)
        thick = foldcore.simulate(miura_file, thickening={"thickness": 0.2},
                                  solving={"fold_percent": 50, "max_iterations": 50})
    assert not isinstance(thick, SheetFold)


@pytest.mark.parametrize("flag", [["--hinge", "arc"], ["--hinge-width", "1"],
                                  ["--elastic-cells", "5"], ["--solver", "newton"],
                                  ["--ground", "0"]])
def test_options_of_a_thick_sheet_are_refused_before_any_work(miura_file, tmp_path, capsys,
                                                              flag):
    out = tmp_path / "r.fold"
    assert cli.main(["simulate", str(miura_file), "-o", str(out), *flag]) == 2
    err = capsys.readouterr().err
    assert f"{flag[0]} is an option of a thick sheet" in err and "Traceback" not in err
    assert not out.exists()


def test_origami_simulator_svg_folds_without_a_thickness(tmp_path):
    """An Origami Simulator file as it comes (no thickness in an SVG)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RunWarning)
        fold = foldcore.simulate(REAL + "waterbombBase.svg", solving={"fold_percent": 90},
                                 outputs={"report": tmp_path / "w.json"})
    assert fold.converged
    report = json.loads((tmp_path / "w.json").read_text())
    assert report["sheet"]["triangles"] == len(foldcore.io.read(REAL + "waterbombBase.svg").faces)


def test_a_fold_that_squashes_facets_settles():
    """Origami Simulator's traditional crane at 60 %: on its way Newton's steps
    squash facets next to its creases towards zero height, where the crease forces
    grow as 1 / height; without the sliver barrier it ran its 500 steps out with
    the largest force stuck near 2e-6. The barrier holds the facets open (no
    corner closes below half the barrier's threshold) and it settles."""
    from foldcore.sheet import SheetSolver, build_sheet
    from foldcore.sheet.build import TRIANGLE, corner_angles
    from foldcore.sheet.kernels import SLIVER

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = foldcore.io.read_file(REAL + "traditionalCrane.svg")
    sheet = build_sheet(loaded.pattern, merge_straight=True, drawn=loaded.drawing)
    solver = SheetSolver(sheet, 60.0, pattern_edges=loaded.pattern.n_edges)
    fold = solver.run(max_iterations=200)
    assert fold.converged and fold.residual < 1e-8
    assert fold.sliver_corners >= 1  # the barrier holds, and the result counts it
    triangles = sheet.kinds == TRIANGLE
    angles = corner_angles(solver.x[sheet.nodes[triangles][:, :3]])
    assert np.all(angles >= 0.5 * SLIVER * sheet.rest[triangles])


def test_corners_held_by_the_sliver_barrier_are_said_and_reported(tmp_path, miura_file):
    report = tmp_path / "r.json"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        foldcore.simulate(REAL + "traditionalCrane.svg", solving={"fold_percent": 60},
                          outputs={"report": report})
        foldcore.simulate(miura_file, outputs={"report": tmp_path / "m.json"})
    said = [str(w.message) for w in caught if "sliver barrier" in str(w.message)]
    held = json.loads(report.read_text())["sheet"]["sliver_corners"]
    assert held >= 1 and len(said) == 1 and said[0].startswith(REAL + "traditionalCrane.svg")
    assert json.loads((tmp_path / "m.json").read_text())["sheet"]["sliver_corners"] == 0


def test_a_sheet_whose_bars_dwarf_its_springs_settles():
    """Origami Simulator's shell14 at 60 %, from its SVG: bars by facets 1e-3 high
    are ~10⁴ stiffer than the bending springs, so a Hessian whose bar blocks carry
    a forward difference's 1e-8 relative error hides the soft directions, and
    Newton's line search stalled there for its whole budget (500 steps). With
    the bars' Hessian analytic it settles in 58 steps."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RunWarning)
        fold = foldcore.simulate(REAL + "shell14.svg",
                                 solving={"fold_percent": 60, "max_iterations": 200})
    assert fold.converged


def test_the_newton_budget_is_the_sheets_own_unless_given(miura_file, tmp_path):
    report = tmp_path / "r.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RunWarning)
        foldcore.simulate(miura_file, outputs={"report": report})
        assert json.loads(report.read_text())["settings"]["max_iterations"] == 500
        short = foldcore.simulate(miura_file, solving={"max_iterations": 2})
        foldcore.simulate(miura_file, solving={"max_iterations": 10_000},
                          outputs={"report": report})
    assert short.iterations == 2 and short.reason == "budget" and not short.converged
    # a budget given is kept, even one equal to a thick sheet's default
    assert json.loads(report.read_text())["settings"]["max_iterations"] == 10_000


def test_a_drawings_straight_degree2_vertices_are_left_out_and_said(tmp_path, capsys):
    """An SVG whose valley line is drawn as two segments (a degree-2 vertex on a
    straight crease): the thin sheet leaves the vertex out as Origami Simulator does
    with a drawing, says so in one line, and the result still places it — on its
    merged crease, which folds as one (both halves at the target)."""
    svg = tmp_path / "split.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">'
        '<rect x="0" y="0" width="100" height="100" fill="none" stroke="#000"/>'
        '<line x1="50" y1="0" x2="50" y2="40" stroke="#00f" opacity="0.5"/>'
        '<line x1="50" y1="40" x2="50" y2="100" stroke="#00f" opacity="0.5"/></svg>')
    report = tmp_path / "r.json"
    assert cli.main(["simulate", str(svg), "--report", str(report), "-o",
                     str(tmp_path / "r.fold")]) == 0
    err = capsys.readouterr().err
    assert "1 vertex of degree 2 on straight lines left out" in err
    data = json.loads(report.read_text())
    assert data["sheet"]["merged_vertices"] == 1 and data["converged"]
    creases = [a for a in data["fold_angles_deg"] if a is not None and abs(a) > 1.0]
    assert len(creases) == 2 and np.allclose(creases, 90.0, atol=1e-6)
    frame = json.loads((tmp_path / "r.fold").read_text())["file_frames"][0]
    x = np.array(frame["vertices_coords"])
    pattern = foldcore.io.read(svg)
    middle = int(np.argmin(np.linalg.norm(np.asarray(pattern.vertices) - [50, 60], axis=1)))
    ends = [int(np.argmin(np.linalg.norm(np.asarray(pattern.vertices) - p, axis=1)))
            for p in ([50, 0], [50, 100])]
    assert np.allclose(x[middle], 0.6 * x[ends[0]] + 0.4 * x[ends[1]], atol=1e-9)


def test_a_series_and_an_animation_fold_the_sheet_frame_by_frame(miura_file, tmp_path):
    """From flat to 90 % in 4 frames, each from the last: one FOLD frame per percent
    with its targets (that percent of the file's), its verdict and iterations
    counted from the start; the last frame is the run's result (-o); a GIF of one
    picture per frame; the series reads back and opens as a thin result."""
    from foldcore.result_file import read_result

    series, movie, out = tmp_path / "s.fold", tmp_path / "s.gif", tmp_path / "r.fold"
    assert cli.main(["simulate", str(miura_file), "--fold-percent", "90", "--frames", "4",
                     "--series", str(series), "--animate", str(movie), "-o", str(out),
                     "-q"]) == 0
    d = json.loads(series.read_text())
    frames = d["file_frames"]
    assert d["foldcore:model"] == "sheet"
    assert [f["foldcore:fold_percent"] for f in frames] == [0.0, 30.0, 60.0, 90.0]
    assert all(f["foldcore:converged"] for f in frames)
    steps = [f["foldcore:iterations"] for f in frames]
    assert steps == sorted(steps) and steps[-1] > steps[1] > 0
    file_angles = np.asarray(foldcore.io.read(miura_file).fold_angles)
    largest = []
    for f in frames:
        targets = np.array([np.nan if t is None else t for t in f["foldcore:pattern_targetAngle"]])
        assert np.allclose(targets, f["foldcore:fold_percent"] / 100 * file_angles,
                           equal_nan=True)
        largest.append(max(abs(a) for a in f["foldcore:pattern_foldAngle"] if a is not None))
    assert largest[0] < 1e-9 and np.all(np.diff(largest) > 1.0)  # folding further each frame
    result = json.loads(out.read_text())["file_frames"][0]["vertices_coords"]
    assert np.array_equal(frames[-1]["vertices_coords"], result)
    assert len(read_result(series, thin=True).frames) == 4
    import imageio.v3 as iio

    pictures = iio.imread(movie, index=None)
    assert pictures.shape[:3] == (4, 480, 640)
    assert np.abs(pictures[0].astype(int) - pictures[-1]).sum() > 0  # it moved
