"""Inputs the command line must refuse before any work: one line on stderr naming the
file and the item, exit code 2, no traceback, nothing written.

Each case runs ``python -m foldcore`` in a fresh process, as a user would: the
exit code and stderr are the real ones.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest


def foldcore(*args, timeout: float = 300, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "foldcore", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, cwd=cwd)


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


# ------------------------------------------------------------ numbers out of range
def _capped():
    """At most 4 GB of address space in the child: a run that is not refused fails
    there, not on the machine."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))


OPTIONS = {  # name: (options, what the line says)
    "cells_denormal": (["--elastic-cells", "5e-324"],
                       ["hinge.fold: --elastic-cells = 4.94066e-324 mm is outside the accepted "
                        "0.001 … 1e+05 mm"]),
    "cells_tiny": (["--elastic-cells", "1e-300"], ["--elastic-cells = 1e-300 mm is outside"]),
    "sub_strips": (["--subdivisions", "1000000"],
                   ["argument --subdivisions: expected an integer in 1..64 or 'auto'"]),
    "tolerance": (["--tolerance", "1e300"], ["--tolerance must be in [1e-15, 0.01], got 1e+300"]),
    "tolerance_loose": (["--tolerance", "0.1"], ["--tolerance must be in [1e-15, 0.01]"]),
    "budget": (["--max-iterations", "2000000"],
               ["--max-iterations must be an integer in 1..1000000, got 2000000"]),
    "ground": (["--ground", "1e300"], ["hinge.fold: --ground = 1e+300 mm is outside the "
                                       "accepted ±1e+05 mm"]),
    "thickness": (["--thickness", "1e300"], ["hinge.fold: --thickness = 1e+300 mm"]),
    "sheet_size": (["--sheet-size", "1e8"], ["hinge.fold: the sheet is 1e+08 mm across"]),
    "fold_percent": (["--fold-percent", "1e300"], ["--fold-percent must be in [-100, 100]"]),
}


@pytest.mark.parametrize("name", sorted(OPTIONS))
def test_an_option_out_of_its_range_is_refused_before_the_run(name, hinge_file, out):
    options, needles = OPTIONS[name]
    proc = subprocess.run([sys.executable, "-m", "foldcore", "simulate", str(hinge_file),
                           *options, "-o", str(out / "o.fold"), "--report", str(out / "r.json")],
                          capture_output=True, text=True, timeout=300, preexec_fn=_capped)
    refused(proc, *needles)
    nothing_written(out)


def test_too_many_elastic_cells_are_refused_before_the_mesh_is_built(tmp_path, out):
    """A Miura 10 × 10 (210 mm) in 0.0315 mm cells, inside the cells' own window: the
    estimate, 767 000 vertices in cells, is refused before any cell is made."""
    from foldcore import patterns
    from foldcore.io import write_fold

    path = tmp_path / "miura.fold"
    write_fold(path, patterns.miura(10, 10), thickness=1.0)
    proc = subprocess.run([sys.executable, "-m", "foldcore", "simulate", str(path),
                           "--elastic-cells", "0.0315", "-o", str(out / "o.fold")],
                          capture_output=True, text=True, timeout=300, preexec_fn=_capped)
    refused(proc, f"{path}: the elastic cells would have about 7.67e+05 vertices, more than "
                  "the 5e+05 accepted")
    nothing_written(out)


def test_svg_stroke_and_margin_are_bounded(hinge_file, tmp_path, out):
    result = tmp_path / "result.fold"
    assert foldcore("simulate", hinge_file, "-o", result, "--max-iterations", "20").returncode == 0
    for option, needle in (("--stroke-width", "SVG stroke width = 1e+300 mm is outside"),
                           ("--margin", "SVG margin = 1e+300 mm is outside the accepted 0 … "
                                        "100 mm")):
        proc = foldcore("export", result, "--svg", out / "sheet.svg", option, "1e300")
        refused(proc, f"{result}: {needle}")
    nothing_written(out)


def test_the_help_gives_each_range():
    text = " ".join(foldcore("simulate", "--help").stdout.split())
    for needle in ("1..64", "1e-15 … 0.01", "1 … 1,000,000", "0.0001 … 10000 × the sheet's "
                   "extent", "1e-06 … 10000 × the sheet's extent", "10,000,000 vertices",
                   "2..10000", "(0, 100]", "0 … 180"):
        assert needle in text, needle


# ------------------------------------------------------------ inputs that are not files
needs_fifo = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes")


def _fifo(path):
    os.mkfifo(path)
    return path


@needs_fifo
@pytest.mark.parametrize("case", ["fold", "svg", "hinges", "obstacle", "render", "export",
                                  "view", "device"])
def test_an_input_that_is_not_a_regular_file_is_refused_before_it_is_opened(
        case, hinge_file, tmp_path, out):
    """A named pipe blocked the read forever (no writer comes); a device never ends."""
    from foldcore import patterns
    from foldcore.io import write_obj

    folder = tmp_path / "in"
    folder.mkdir()
    if case == "hinges":
        write_obj(folder / "mesh.obj", patterns.single_hinge(width=2.0))
    pipe = {"fold": "p.fold", "svg": "p.svg", "hinges": "mesh.hinges", "obstacle": "wall.stl",
            "render": "r.fold", "export": "r.fold", "view": "r.fold"}.get(case)
    bad = _fifo(folder / pipe) if pipe else folder / "zero.fold"
    if case == "device":
        if not os.path.exists("/dev/zero"):
            pytest.skip("no /dev/zero")
        bad.symlink_to("/dev/zero")
    args = {"fold": ["simulate", bad, "-o", out / "o.fold"],
            "svg": ["simulate", bad, "--thickness", "1", "-o", out / "o.fold"],
            "hinges": ["simulate", folder / "mesh.obj", "--hinges", bad, "--thickness", "1",
                       "-o", out / "o.fold"],
            "obstacle": ["simulate", hinge_file, "--obstacle", bad, "-o", out / "o.fold"],
            "render": ["render", bad, "-o", out / "o.png"],
            "export": ["export", bad, "--stl", out / "o.stl"],
            "view": ["view", bad, "-o", out / "o.html"],
            "device": ["simulate", bad, "-o", out / "o.fold"]}[case]
    kind = "a character device" if case == "device" else "a named pipe (FIFO)"
    refused(foldcore(*args, timeout=120), f"{bad}: cannot read the file: it is {kind}, not a "
                                          "regular file")
    nothing_written(out)


@pytest.mark.parametrize("name", ["patterns", "patterns.fold"])
def test_a_folder_given_as_the_pattern_is_refused_as_a_folder(name, tmp_path, out):
    """A folder without a suffix was 'an unknown file type (no suffix)'."""
    folder = tmp_path / name
    folder.mkdir()
    refused(foldcore("simulate", folder, "-o", out / "o.fold"),
            f"{folder}: cannot read the file: it is a folder, not a regular file")
    nothing_written(out)


# ------------------------------------------------------------------ output names
@pytest.mark.parametrize("args", [["simulate", "{hinge}", "-o", ""],
                                  ["simulate", "{hinge}", "--report", ""],
                                  ["view", "{result}", "-o", ""],
                                  ["render", "{result}", "-o", ""],
                                  ["export", "{result}", "--svg", "", "--stl", "x.stl"]],
                         ids=["fold", "report", "view", "render", "export"])
def test_an_empty_output_name_is_refused(args, hinge_file, out):
    """``-o ""`` ran the fold, wrote nothing and exited 0."""
    result = out.parent / "result.fold"
    if "{result}" in args:
        assert foldcore("simulate", hinge_file, "-o", result,
                        "--max-iterations", "20").returncode == 0
    args = [a.format(hinge=hinge_file, result=result) for a in args]
    option = args[args.index("") - 1]
    refused(foldcore(*args, cwd=out), f'{option} "": the file name is empty')
    nothing_written(out)


def test_an_empty_scene_folder_is_refused(out):
    refused(foldcore("scene", "miura", "--quick", "--out", "", cwd=out),
            "--out '': output folder does not exist")
    nothing_written(out)


def test_a_file_name_longer_than_the_folder_takes_is_refused_before_the_run(hinge_file, out):
    """A 305-byte name failed only when the result was written, after the run."""
    name = "a" * 300 + ".fold"
    proc = foldcore("simulate", hinge_file, "-o", out / name, "--report", out / "r.json")
    limit = os.pathconf(out, "PC_NAME_MAX")
    refused(proc, f"-o {out / name}: the file name is 305 bytes, longer than the {limit} "
                  "this system takes")
    nothing_written(out)


# ------------------------------------------------------------------ early signals
SIGNAL_AT_IMPORT = """
import os, signal, sys
class SignalAt:
    def find_spec(self, name, path, target=None):
        if name == {module!r}:
            os.kill(os.getpid(), signal.{signal})
        return None
sys.meta_path.insert(0, SignalAt())
sys.argv = ["foldcore", "simulate", {pattern!r}, "-o", {out!r}]
from foldcore.__main__ import run
sys.exit(run())
"""


def python(script: str) -> subprocess.CompletedProcess:
    """``python -c script`` in a process of its own, its output captured as text."""
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=300)


@pytest.mark.parametrize("module", ["foldcore.cli", "foldcore.scenes"],
                         ids=["starting", "parsing"])
@pytest.mark.parametrize("name, code", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_while_the_command_starts_is_one_line(module, name, code, hinge_file, out):
    """The signal arrives while the command line is imported (before main runs) or
    while it parses the arguments (whose parser imports most of the package): it was
    a KeyboardInterrupt traceback, or for SIGTERM an exit by the signal (−15) saying
    nothing."""
    script = SIGNAL_AT_IMPORT.format(module=module, signal=name, pattern=str(hinge_file),
                                     out=str(out / "o.fold"))
    proc = python(script)
    assert proc.returncode == code, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr
    (line,) = proc.stderr.splitlines()
    what = "interrupted (SIGINT)" if name == "SIGINT" else "terminated (SIGTERM)"
    assert line.startswith(f"foldcore: {what}"), line
    nothing_written(out)


def test_a_signal_after_the_command_leaves_its_exit_code(tmp_path):
    """Once main has returned the work is done: a signal while the interpreter shuts
    down does not change the exit code (it ended the process by the signal)."""
    script = ("import os, signal, sys, time\n"
              "from foldcore import __main__, cli\n"
              "cli.main = lambda argv=None: 0\n"
              "code = __main__.run()\n"
              "os.kill(os.getpid(), signal.SIGTERM)\n"
              "time.sleep(0.5)\n"
              "sys.exit(code)\n")
    proc = python(script)
    assert proc.returncode == 0 and proc.stderr == "", (proc.returncode, proc.stderr)


def test_a_signal_lost_in_a_callback_from_c_is_sent_again():
    """A handler's exception inside a ctypes callback is printed ("Exception ignored")
    and dropped by ctypes; llvmlite calls one while numba compiles: the signal comes
    back 10 ms later in Python code, silently."""
    script = ("import ctypes, os, signal, time\n"
              "from foldcore import interrupts\n"
              "def callback():\n"
              "    os.kill(os.getpid(), signal.SIGTERM)\n"
              "    for _ in range(1000): pass\n"
              "lost = ctypes.CFUNCTYPE(None)(callback)\n"
              "with interrupts.handled():\n"
              "    try:\n"
              "        lost()\n"
              "        time.sleep(5)\n"
              "        print('lost')\n"
              "    except interrupts.Terminated:\n"
              "        print('raised')\n")
    proc = python(script)
    assert proc.stdout.split() == ["raised"] and proc.stderr == "", proc


def test_a_signal_that_code_turned_into_another_error_is_still_the_signal():
    """numpy's import turns an exception raised inside it into an ImportError: the
    command still ends as the signal says."""
    import signal

    from foldcore import interrupts

    with interrupts.handled():
        try:
            try:
                os.kill(os.getpid(), signal.SIGTERM)
                for _ in range(10**6):
                    pass
            except interrupts.Terminated as exc:
                raise ImportError("C-extensions failed") from exc
        except ImportError as exc:
            assert interrupts.caught(exc) == (143, "terminated (SIGTERM)")
    assert interrupts.caught(ImportError("no signal since")) is None


def test_the_console_script_is_the_entry_that_handles_signals_first():
    import tomllib
    from pathlib import Path

    from foldcore import __main__

    project = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())
    assert project["project"]["scripts"]["foldcore"] == "foldcore.__main__:run"
    assert callable(__main__.run)
