"""Inputs the command line must refuse before any work: one line on stderr naming the
file and the item, exit code 2, no traceback, nothing written.

Each case runs ``python -m foldcore`` in a fresh process, as a user would: the
exit code and stderr are the real ones.
"""
from __future__ import annotations

import json
import subprocess
import sys

import pytest


def foldcore(*args, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "foldcore", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout)


def refused(proc: subprocess.CompletedProcess, *needles: str) -> str:
    """The one line of a refusal (exit 2), holding every needle."""
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr, proc.stderr
    (line,) = proc.stderr.splitlines()
    assert line.startswith("foldcore: error: "), line
    for needle in needles:
        assert needle in line, line
    return line


def nothing_written(folder) -> None:
    assert not list(folder.iterdir()), list(folder.iterdir())


@pytest.fixture
def out(tmp_path):
    """An empty folder for outputs."""
    folder = tmp_path / "out"
    folder.mkdir()
    return folder


# ------------------------------------------------------------------ a pinched sheet
def test_a_bow_tie_is_refused_when_read_under_every_solver(tmp_path, out):
    """Two triangles sharing only vertex 0: the thick mesh had no stiffness to hold one
    to the other and CHOLMOD found K not positive definite (a traceback)."""
    path = tmp_path / "bowtie.fold"
    path.write_text(json.dumps({
        "file_spec": 1.1, "vertices_coords": [[0, 0], [10, 0], [10, 10], [-10, 0], [-10, -10]],
        "faces_vertices": [[0, 1, 2], [0, 3, 4]],
        "edges_vertices": [[0, 1], [1, 2], [2, 0], [0, 3], [3, 4], [4, 0]],
        "edges_assignment": ["B"] * 6}))
    for solver in ("hybrid", "paper"):
        proc = foldcore("simulate", path, "--thickness", "5", "--solver", solver,
                        "-o", out / "o.fold", "--report", out / "r.json")
        refused(proc, f"{path}: vertex 0: faces meet only at this vertex (a bow-tie)")
    nothing_written(out)
