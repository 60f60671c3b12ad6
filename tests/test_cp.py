"""The ``.cp`` reader (ORIPA / Oriedita / flat-folder lines): what it reads, what it
refuses in one line naming the line, and a fold of what it read."""
from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest

from foldcore import patterns
from foldcore.errors import PatternError
from foldcore.io import read_file

SQUARE = ["1 -200 -200 200 -200", "1 200 -200 200 200", "1 200 200 -200 200",
          "1 -200 200 -200 -200"]


def cp_file(tmp_path, lines, name="p.cp"):
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def cp_lines(pattern) -> list[str]:
    """A pattern written as .cp lines (B 1, M 2, V 3), coordinates to 17 digits."""
    code = {"B": 1, "M": 2, "V": 3}
    return [f"{code[a]} " + " ".join(f"{c:.17g}" for c in pattern.vertices[list(e)].ravel())
            for e, a in zip(pattern.edges, pattern.assignments)]


def test_a_square_with_a_valley_diagonal_reads_as_drawn(tmp_path):
    loaded = read_file(cp_file(tmp_path, SQUARE + ["3 -200 -200 200 200"]))
    p = loaded.pattern
    assert p.n_vertices == 4 and p.n_edges == 5
    assert sorted(p.assignments) == ["B", "B", "B", "B", "V"]
    diagonal = int(np.flatnonzero(np.asarray(p.assignments) == "V")[0])
    assert p.fold_angles[diagonal] == 180.0
    assert np.ptp(p.vertices[:, 0]) == pytest.approx(400.0)  # one unit = 1 mm
    assert loaded.frame_unit == "mm"


def test_a_miura_written_as_lines_reads_back_the_same(tmp_path):
    miura = patterns.miura(3, 2, a=20.0, b=15.0, gamma=60.0)
    p = read_file(cp_file(tmp_path, cp_lines(miura))).pattern
    assert p.n_vertices == miura.n_vertices and p.n_edges == miura.n_edges
    order = np.lexsort(p.vertices.T[::-1])
    want = np.lexsort(miura.vertices.T[::-1])
    from foldcore.io.cp import MERGE

    # noding rounds every coordinate to the merge distance's grid (1e-6 of the extent)
    tol = MERGE * np.ptp(miura.vertices, axis=0).max()
    np.testing.assert_allclose(p.vertices[order], miura.vertices[want], rtol=0, atol=tol)
    assert sorted(p.assignments) == sorted(miura.assignments)


def test_crossing_lines_are_noded_and_auxiliary_lines_left_out(tmp_path):
    lines = SQUARE + ["3 -200 -200 200 200", "2 -200 200 200 -200", "4 0 -200 0 200"]
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        p = read_file(cp_file(tmp_path, lines)).pattern
    assert p.n_vertices == 5 and p.n_edges == 8  # the diagonals meet at the centre
    assert sum(a == "M" for a in p.assignments) == 2
    assert any("1 auxiliary lines" in str(w.message) for w in said)


def test_a_sheet_size_rescales_it(tmp_path):
    from foldcore.io import Reading

    p = read_file(cp_file(tmp_path, SQUARE + ["3 -200 -200 200 200"]),
                  reading=Reading(size=100.0)).pattern
    assert np.ptp(p.vertices[:, 0]) == pytest.approx(100.0)


@pytest.mark.parametrize("line, message", [
    ("2 0 0 1", "line 5: expected TYPE X1 Y1 X2 Y2, got 4 fields"),
    ("x 0 0 1 1", "line 5: expected an integer type and four numbers"),
    ("7 0 0 1 1", r"line 5: type 7 is not 1 \(border\)"),
    ("2 0 nan 1 1", "line 5: coordinates must be finite"),
    ("2 0 1e300 1 1", "line 5: coordinates must be finite numbers within"),
    ("3 5 5 5 5", "line 5: a segment of zero length"),
])
def test_a_malformed_line_is_refused_naming_it(tmp_path, line, message):
    with pytest.raises(PatternError, match=message):
        read_file(cp_file(tmp_path, SQUARE + [line]))


def test_two_types_on_one_segment_are_refused_naming_both_lines(tmp_path):
    lines = SQUARE + ["3 -200 -200 200 200", "2 -100 -100 100 100"]
    with pytest.raises(PatternError, match="line 6 and line 5 overlap|line 5 and line 6 "
                                           "overlap"):
        read_file(cp_file(tmp_path, lines))


def test_a_file_without_creases_or_text_is_refused(tmp_path):
    with pytest.raises(PatternError, match="no border, mountain or valley line"):
        read_file(cp_file(tmp_path, ["4 0 0 1 1"]))
    binary = tmp_path / "b.cp"
    binary.write_bytes(b"\xff\xfe\x00\x81" * 10)
    with pytest.raises(PatternError, match="not a text file"):
        read_file(binary)


def test_the_command_line_folds_a_cp_file_and_refuses_a_bad_one(tmp_path):
    good = cp_file(tmp_path, SQUARE + ["3 -200 -200 200 200"])
    run = subprocess.run([sys.executable, "-m", "foldcore", "simulate", str(good),
                          "--thickness", "2", "--fold-percent", "50", "--report",
                          str(tmp_path / "r.json"), "-q"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    import json

    report = json.loads((tmp_path / "r.json").read_text())
    assert report["converged"]
    assert max(a for a in report["fold_angles_deg"] if a is not None) == \
        pytest.approx(90.0, abs=1e-6)  # the valley at 50 % of 180°
    bad = cp_file(tmp_path, SQUARE + ["9 0 0 1 1"], name="bad.cp")
    run = subprocess.run([sys.executable, "-m", "foldcore", "simulate", str(bad),
                          "--thickness", "2"], capture_output=True, text=True)
    assert run.returncode == 2
    assert run.stderr.count("\n") == 1 and "bad.cp: line 5: type 9" in run.stderr
