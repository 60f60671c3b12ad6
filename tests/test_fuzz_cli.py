"""Property-based fuzzing of the command line, command by command.

Each case runs ``foldcore.cli.main`` in this process on a generated command:
inputs from the readers' generators (corrupted FOLD files, hostile SVG
drawings), corrupted result files, and option values from the extremes
(NaN, infinities, 1e±300, negative, empty, text, far too many cells or
strips), with output names that cannot be written.

Property: exit code 0 or 2; a refusal (2) is exactly one line on stderr,
``foldcore: error: …``; no traceback; no temporary file left in the output
folder; nothing written when the command is refused.

Example counts as in ``tests/test_fuzz_readers.py``: 300 per command in CI
(derandomized), ``FOLDCORE_FUZZ=long`` 10 000, ``FOLDCORE_FUZZ=N`` N.
"""
from __future__ import annotations

import contextlib
import io
import os
import warnings

import pytest
from hypothesis import event, given
from hypothesis import strategies as st

from foldcore import patterns
from foldcore.cli import main
from foldcore.io import write_fold
from test_fuzz_readers import FUZZ, _json_bytes, corrupted_folds, svg_documents
from test_fuzz_results import corrupted_results, time_limit

pytestmark = pytest.mark.filterwarnings("ignore")

#: Longest a case may take, s (a tiny fold; a refusal is immediate).
CASE_SECONDS = 60

NUMBERS = ["1", "0.5", "0", "-1", "nan", "inf", "-inf", "1e300", "1e-300", "5e-324", "",
           "abc", "1e309", "0x10", "100"]
COUNTS = ["1", "2", "0", "-3", "1000000", "1e3", "auto", "", "nan", "999999999999"]
OPTIONS = {  # option: values drawn for it
    "--thickness": NUMBERS, "--hinge-width": NUMBERS, "--scale": NUMBERS,
    "--sheet-size": NUMBERS, "--fold-percent": NUMBERS, "--tolerance": NUMBERS,
    "--elastic-cells": NUMBERS, "--branch-floor": NUMBERS, "--ground": NUMBERS,
    "--subdivisions": COUNTS, "--max-iterations": COUNTS, "--frames": COUNTS,
    "--solver": ["rigid", "hybrid", "newton", "paper", "lbfgs", "anderson", "x"],
    "--hinge": ["axis", "arc", "slack", "eq8", "x"], "--contact": ["on", "off", "x"],
    "--drive": ["0", "1", "0,1", "1-3", "3-1", "-1", "x", "", "0-999999999999",
                "999999999999", "1,,2", "0-1000000"],
}
OUTPUTS = ["out.fold", "", "sub/none/out.fold", "x" * 300 + ".fold", ".", "out.txt"]


def run(argv: list[str]) -> tuple[int, str]:
    """(exit code, stderr) of ``foldcore ARGV`` in this process, bounded in time."""
    err = io.StringIO()
    with time_limit(CASE_SECONDS), contextlib.redirect_stderr(err), \
            contextlib.redirect_stdout(io.StringIO()), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(argv)
    return code, err.getvalue()


def check(argv: list[str], folder, outputs: list[str]) -> None:
    """Run ``argv`` and assert the property (module docstring); ``outputs``: the
    files the command may write, relative to ``folder``."""
    before = set(os.listdir(folder))
    code, err = run(argv)
    after = set(os.listdir(folder))
    assert "Traceback" not in err, err
    assert code in (0, 2), (code, err)
    assert not [n for n in after if n.endswith(".tmp")], after
    if code == 2:
        lines = [line for line in err.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith("foldcore: error:"), err
        assert after == before, after - before
        event("refused")
    else:
        assert all(line.startswith("foldcore:") for line in err.splitlines()), err
        event("ran")
    for name in after - before:
        assert name in outputs, (name, argv)


def crease_bytes(folder, thickness: float | None) -> bytes:
    """One crease that folds in a few steps, as a FOLD file (thickness in the file,
    mm, or none: a thin sheet)."""
    path = folder / "crease.fold"
    write_fold(path, patterns.single_hinge(panel_length=10.0, depth=5.0, angle=60.0,
                                           width=2.0), thickness=thickness)
    return path.read_bytes()


@pytest.fixture(scope="module")
def crease(tmp_path_factory):
    """The crease with H = 1 mm in the file, and without a thickness (a thin sheet)."""
    return (crease_bytes(tmp_path_factory.mktemp("cli"), 1.0),
            crease_bytes(tmp_path_factory.mktemp("cli"), None))


@st.composite
def simulate_commands(draw, crease: tuple[bytes, bytes]) -> tuple[str, bytes, list[str], str]:
    """(input name, its bytes, options, output name)."""
    kind = draw(st.sampled_from(["crease", "thin", "fold", "svg"]))
    if kind in ("crease", "thin"):
        name, blob = "in.fold", crease[kind == "thin"]
    elif kind == "fold":
        name, blob = "in.fold", _json_bytes(draw(corrupted_folds())) or b"{}"
    else:
        name, blob = "in.svg", draw(svg_documents())
    options = []
    for option in draw(st.lists(st.sampled_from(sorted(OPTIONS)), max_size=3, unique=True)):
        options += [option, draw(st.sampled_from(OPTIONS[option]))]
    return name, blob, options, draw(st.sampled_from(OUTPUTS))


@FUZZ
@given(data=st.data())
def test_fuzz_simulate(crease, tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("sim")
    name, blob, options, output = data.draw(simulate_commands(crease))
    (folder / name).write_bytes(blob)
    argv = ["simulate", str(folder / name), *options]
    if output:
        argv += ["-o", str(folder / output)]
    check(argv, folder, [name, output.split("/")[0]])


@pytest.fixture(scope="module")
def results(crease, tmp_path_factory):
    """Result files of the crease, thick and thin, as written by ``simulate -o``."""
    import json

    folder = tmp_path_factory.mktemp("res")
    files = []
    for name, blob in zip(("thick", "thin"), crease):
        (folder / f"{name}.fold").write_bytes(blob)
        out = folder / f"{name}.result.fold"
        assert main(["simulate", str(folder / f"{name}.fold"), "-o", str(out)]) == 0
        files.append(json.loads(out.read_text()))
    return files


@pytest.mark.parametrize("command", ["view", "export", "render"])
@FUZZ
@given(data=st.data())
def test_fuzz_result_commands(results, tmp_path_factory, data, command):
    """``view``, ``export`` and ``render`` on corrupted result files (renders small)."""
    folder = tmp_path_factory.mktemp(command)
    d = data.draw(corrupted_results(results))
    path = folder / "r.fold"
    path.write_bytes(_json_bytes(d) or b"{}")
    good = {"view": "out.html", "export": "out.stl", "render": "out.png"}[command]
    output = data.draw(st.sampled_from([good, "", "none/out.x", "x" * 300 + ".html"]))
    flag = "--stl" if command == "export" else "-o"
    if command == "export":
        flag = data.draw(st.sampled_from(["--stl", "--svg"]))
    argv = [command, str(path)] + ([flag, str(folder / output)] if output else [])
    if command == "render":
        argv += ["--size", data.draw(st.sampled_from(["64x48", "0x0", "64", "nan", "1e9x1"]))]
    check(argv, folder, ["r.fold", output.split("/")[0]])


@FUZZ
@given(name=st.sampled_from(["d4v", "box", "chain", "nope", "", "../d4v", "D4V"]),
       options=st.lists(st.sampled_from([["--solver", "x"], ["--contact", "maybe"],
                                         ["--out", ""], ["--bogus"], ["--solver"],
                                         ["--out", "x" * 300]]), min_size=1, max_size=3))
def test_fuzz_scene_arguments(tmp_path_factory, name, options):
    """``scene`` with a name or an option it cannot take (a scene that runs is a long
    fold; tests/test_scenes.py runs them): always refused in one line, nothing
    written."""
    folder = tmp_path_factory.mktemp("scene")
    argv = ["scene", name, "--quick", *[part for option in options for part in option]]
    if name in ("d4v", "box", "chain") and all(o[0] == "--out" and o[1] for o in options):
        argv += ["--solver", "x"]  # keep it a refusal
    code, err = run(argv + (["--out", str(folder)] if "--out" not in argv else []))
    assert code == 2 and "Traceback" not in err, err
    assert len([line for line in err.splitlines() if line.strip()]) == 1, err
    assert os.listdir(folder) == []
    event("refused")
