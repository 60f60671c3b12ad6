"""ORIPA's ``.opx`` reader: a pattern as Java's XMLEncoder writes it reads as its ``.cp``
lines do; what it refuses, in one line naming the file and the line."""
from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest

from foldcore import patterns
from foldcore.errors import PatternError
from foldcore.io import read_file

from test_cp import cp_file, cp_lines

HEAD = ('<?xml version="1.0" encoding="UTF-8"?>\n<java version="1.8.0" '
        'class="java.beans.XMLDecoder">\n <object class="oripa.DataSet">\n'
        '  <void property="paperSize"><double>400.0</double></void>\n'
        '  <void property="lines">\n   <array class="oripa.OriLineProxy" length="{n}">\n')
TAIL = '   </array>\n  </void>\n </object>\n</java>\n'


def opx_text(lines) -> str:
    """``.cp`` lines written as ORIPA writes them: XMLEncoder leaves out each property
    at its default (0), so a zero coordinate or an auxiliary type is not written."""
    body = []
    for i, line in enumerate(lines):
        kind, *xy = line.split()
        props = [("type", "int", kind)] + [(k, "double", v) for k, v in
                                           zip(("x0", "y0", "x1", "y1"), xy)]
        written = "".join(f'<void property="{k}"><{t}>{v}</{t}></void>' for k, t, v in props
                          if float(v) != 0)
        body.append(f'<void index="{i}"><object class="oripa.OriLineProxy">{written}'
                    '</object></void>\n')
    return HEAD.format(n=len(lines)) + "".join(body) + TAIL


def opx_file(tmp_path, text, name="p.opx"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_miura_reads_as_its_cp_lines_do(tmp_path):
    """Zero coordinates left out (the Miura's corner at the origin): read as 0."""
    miura = patterns.miura(3, 2, a=20.0, b=15.0, gamma=60.0)
    lines = cp_lines(miura) + ["4 0 0 10 10"]  # an auxiliary line, type written
    assert any(" 0 " in f" {x} " for x in lines)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from_opx = read_file(opx_file(tmp_path, opx_text(lines))).pattern
        from_cp = read_file(cp_file(tmp_path, lines)).pattern
    np.testing.assert_array_equal(from_opx.vertices, from_cp.vertices)
    np.testing.assert_array_equal(from_opx.edges, from_cp.edges)
    assert list(from_opx.assignments) == list(from_cp.assignments)
    assert from_opx.n_vertices == miura.n_vertices


@pytest.mark.parametrize("text, needle", [
    ("not xml <", "not well-formed XML"),
    ("<svg/>", "the root element is <svg>, not <java>"),
    ("<java><object class='x'/></java>", "no oripa.DataSet"),
    ('<?xml version="1.0"?><!DOCTYPE java [<!ENTITY a "b">]><java/>', "refused XML"),
    (opx_text(["1 0 0 1 0"]).replace("<int>1</int>", "<int>x</int>"),
     "line 0: type: expected <int>NUMBER</int>"),
    (opx_text(["1 0 0 1 0", "7 0 0 0 1"]), "line 1: type 7 is not 1 (border)"),
    (opx_text(["1 0 0 1 0", "1 0 0 1e400 1"]), "line 1: coordinates must be finite"),
])
def test_malformed_files_are_refused_in_one_line(tmp_path, text, needle):
    path = opx_file(tmp_path, text)
    with pytest.raises(PatternError) as info:
        read_file(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and needle in message and "\n" not in message


def test_the_command_line_folds_an_opx_file(tmp_path):
    square = ["1 -200 -200 200 -200", "1 200 -200 200 200", "1 200 200 -200 200",
              "1 -200 200 -200 -200", "3 -200 -200 200 200"]
    path = opx_file(tmp_path, opx_text(square))
    out = tmp_path / "o.fold"
    proc = subprocess.run([sys.executable, "-m", "foldcore", "simulate", str(path),
                           "--thickness", "2", "--fold-percent", "50", "-o", str(out)],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "converged" in proc.stderr and out.exists()
