"""``foldcore simulate``: its contract (report, FOLD output, exit codes, one-line refusals).

Runs in-process through ``foldcore.cli.main`` for speed; one test runs the
installed console script to check the real exit code and the absence of a
traceback. Scene: a short-panel single hinge at 90° (converges in ~10⁴
plain iterations).
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from foldcore import patterns
from foldcore.cli import main
from foldcore.io import write_fold

TARGET = 90.0


@pytest.fixture
def fold_file(tmp_path):
    pattern = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=TARGET, width=2.0)
    path = tmp_path / "hinge.fold"
    write_fold(path, pattern, thickness=1.0)
    return path


def _simulate(path, tmp_path, *extra):
    out, report = tmp_path / "out.fold", tmp_path / "report.json"
    code = main(["simulate", str(path), "-o", str(out), "--report", str(report),
                 "--subdivisions", "4", "--tolerance", "1e-9", "--max-iterations", "60000",
                 *extra])
    return code, out, report


def test_simulate_writes_report_and_fold_of_the_contract(fold_file, tmp_path):
    code, out, report = _simulate(fold_file, tmp_path)
    assert code == 0
    rep = json.loads(report.read_text())
    for key in ("iterations", "converged", "energy", "fold_angles_deg", "vertices",
                "elements", "timings_s"):
        assert key in rep
    assert set(rep["timings_s"]) >= {"total", "setup", "projection", "solve"}
    assert rep["converged"] is True
    assert abs(rep["fold_angles_deg"][0] - TARGET) < 0.05
    assert all(a is None for a in rep["fold_angles_deg"][1:])   # boundary edges
    fold = json.loads(out.read_text())
    assert abs(fold["edges_foldAngle"][0] - TARGET) < 0.05
    assert fold["foldcore:thickness"] == 1.0
    (frame,) = fold["file_frames"]
    assert frame["frame_classes"] == ["foldedForm"]
    coords = np.array(frame["vertices_coords"])
    assert coords.shape == (rep["vertices"], 3)
    faces = frame["faces_vertices"]
    assert max(max(f) for f in faces) < len(coords)


def test_not_converging_is_a_result_with_a_warning(fold_file, tmp_path, capsys):
    out, report = tmp_path / "out.fold", tmp_path / "r.json"
    code = main(["simulate", str(fold_file), "--solver", "paper", "--max-iterations", "5",
                 "-o", str(out), "--report", str(report)])
    assert code == 0
    rep = json.loads(report.read_text())
    assert rep["converged"] is False and rep["reason"] == "budget"
    assert "its budget of 5 iterations ran out" in capsys.readouterr().err
    assert out.exists()


def test_a_stalled_run_says_so_in_the_report_and_on_stderr(tmp_path, capsys):
    """A small step is not a verdict, through the CLI: a hinge at thickness / size =
    1e-4 under lbfgs takes steps far below the tolerance 90° short of its target
    (a step-length rule called it converged after 2 iterations;
    docs/architecture.md#a-small-step-is-not-a-verdict)."""
    pattern = patterns.single_hinge(panel_length=10.0, depth=10.0, angle=TARGET)
    path, report = tmp_path / "thin.fold", tmp_path / "r.json"
    write_fold(path, pattern, thickness=0.002)
    code = main(["simulate", str(path), "--solver", "lbfgs", "--max-iterations", "300",
                 "--report", str(report)])
    assert code == 0
    rep = json.loads(report.read_text())
    assert rep["fold_angles_deg"][0] < 80.0
    assert rep["converged"] is False and rep["reason"] == "stalled"
    assert rep["residual"] is None or rep["residual"] > 1e-8
    warning, summary = capsys.readouterr().err.splitlines()
    assert str(path) in warning and "stalled" in warning
    assert summary.startswith(f"foldcore: {path}: not converged (stalled) after ")


def _edit(fold_file, tmp_path, change) -> str:
    d = json.loads(fold_file.read_text())
    change(d)
    bad = tmp_path / "bad.fold"
    bad.write_text(json.dumps(d))
    return str(bad)


def _set(key, index, value):
    def change(d):
        d[key][index] = value
    return change


def _text(tmp_path, text: str) -> str:
    bad = tmp_path / "bad.fold"
    bad.write_text(text)
    return str(bad)


MALFORMED = {
    "not_json": lambda f, t: _text(t, "{not json"),
    "nan": lambda f, t: _text(t, f.read_text().replace("[0.0, 0.0]", "[NaN, 0.0]", 1)),
    "overflow": lambda f, t: _text(t, f.read_text().replace("[0.0, 0.0]", "[1e999, 0.0]", 1)),
    "bad_index": lambda f, t: _edit(f, t, _set("edges_vertices", 2, [2, 99])),
    "unknown_assignment": lambda f, t: _edit(f, t, _set("edges_assignment", 0, "X")),
    "crossing": lambda f, t: _edit(f, t, lambda d: (
        d["vertices_coords"].append([-2.0, 1.0]), d["vertices_coords"].append([2.0, 1.0]),
        d["edges_vertices"].append([6, 7]), d["edges_assignment"].append("V"),
        d["edges_foldAngle"].append(None), d.pop("faces_vertices", None))),
    "zero_length": lambda f, t: _edit(f, t, lambda d: (
        d["vertices_coords"].__setitem__(2, d["vertices_coords"][0]))),
    "sign_vs_assignment": lambda f, t: _edit(f, t, _set("edges_foldAngle", 0, -90.0)),
}
WHAT = {"not_json": "JSON", "nan": "NaN", "overflow": "1e999", "bad_index": "edge 2", "unknown_assignment": "edge 0",
        "crossing": "edge", "zero_length": "edge", "sign_vs_assignment": "edge 0"}


@pytest.mark.parametrize("kind", sorted(MALFORMED))
def test_malformed_file_exits_2_with_one_line_and_no_output(kind, fold_file, tmp_path,
                                                              capsys):
    bad = MALFORMED[kind](fold_file, tmp_path)
    out, report = tmp_path / "out.fold", tmp_path / "r.json"
    code = main(["simulate", bad, "-o", str(out), "--report", str(report)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("foldcore: error: ")
    assert os.path.basename(bad) in err
    assert WHAT[kind] in err
    assert "Traceback" not in err
    assert not out.exists() and not report.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp files


def test_missing_file_exits_2_and_missing_thickness_folds_a_thin_sheet(tmp_path, capsys):
    assert main(["simulate", str(tmp_path / "nope.fold")]) == 2
    assert "nope.fold" in capsys.readouterr().err
    pattern = patterns.single_hinge(angle=30.0, width=2.0)
    path, report = tmp_path / "thin.fold", tmp_path / "thin.json"
    write_fold(path, pattern)                       # no foldcore:thickness
    assert main(["simulate", str(path), "--report", str(report)]) == 0
    err = capsys.readouterr().err
    assert "folded as a thin sheet" in err and "--thickness" in err
    hinge = json.loads(report.read_text())["fold_angles_deg"][0]
    assert hinge == pytest.approx(30.0, abs=1e-6)   # one spring, nothing resists it


def test_bad_option_values_exit_2(fold_file, capsys):
    for args in (["--thickness", "-1"], ["--subdivisions", "0"], ["--solver", "magic"],
                 ["--fold-percent", "400"]):
        assert main(["simulate", str(fold_file), *args]) == 2, args
        err = capsys.readouterr().err
        assert err.count("\n") == 1, err


def test_console_script_exit_code_without_traceback(tmp_path):
    bad = tmp_path / "bad.fold"
    bad.write_text("[1, 2")
    proc = subprocess.run([sys.executable, "-m", "foldcore.cli", "simulate", str(bad)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "bad.fold" in proc.stderr


def test_render_option_writes_a_png(fold_file, tmp_path):
    pytest.importorskip("pyvista")
    png = tmp_path / "hinge.png"
    assert main(["simulate", str(fold_file), "--max-iterations", "200",
                 "--render", str(png)]) == 0
    import imageio.v3 as iio

    image = iio.imread(png)
    assert image.ndim == 3 and image.shape[0] > 100
    assert (image[..., :3] < 200).any()      # something other than white background


def test_report_gives_each_actuated_crease_and_where_the_hinge_model_breaks(tmp_path):
    """Pehrson's vertex at the paper's size, crease 1 driven to 180° at 50 %: the
    report's targets are the effective ones (90°), each actuated crease has its
    target, achieved angle and miss; the hinges section names the model of every
    crease. Folded fully (100 %) creases pass the axis hinge's pivot angle
    2·atan(W/H) (157/103/136/103°), are listed as pivoting, the vertex binds and
    the strips' misfit and the panels' overlap are reported; angle-controlled
    actuation meets the actuated target where equal weights do not."""
    pattern = patterns.degree4_vertex(rho1=180.0, widths=(16.0, 4.0, 8.0, 4.0))
    src = tmp_path / "d4.fold"
    write_fold(src, pattern, thickness=3.175)
    misses = {}
    for percent, actuation in (("50", "equal"), ("100", "equal"), ("100", "angle")):
        report = tmp_path / f"{percent}{actuation}.json"
        assert main(["simulate", str(src), "--fold-percent", percent, "--actuation", actuation,
                     "--report", str(report), "--subdivisions", "4"]) == 0
        data = json.loads(report.read_text())
        (crease,) = data["actuation"]["creases"]
        assert crease["edge"] == 0 and data["target_angles_deg"][0] == crease["target_deg"]
        assert crease["target_deg"] == pytest.approx(1.8 * float(percent))
        assert crease["miss_deg"] == pytest.approx(crease["achieved_deg"] - crease["target_deg"])
        assert data["hinges"]["model"][:4] == ["axis"] * 4
        assert data["settings"]["actuation"] == actuation
        misses[percent, actuation] = abs(crease["miss_deg"])
        if percent == "50":
            assert data["hinges"]["pivoting_edges"] == [] and misses["50", "equal"] < 1e-3
            assert data["hinges"]["largest_misfit_mm"] < 1e-6
        else:
            assert set(data["hinges"]["pivoting_edges"]) >= {1, 2, 3}
            assert data["hinges"]["largest_misfit_mm"] > 1e-3
            assert data["hinges"]["largest_overlap_mm"] >= 0.0
    assert misses["100", "angle"] < 0.1 < misses["100", "equal"]
    assert main(["simulate", str(src), "--branch-floor", "-1"]) == 2


# ------------------------------------------------ the output contract on failure paths
def _reversed_faces(fold_file, tmp_path) -> str:
    """The hinge file with both faces clockwise: each read warns once."""
    d = json.loads(fold_file.read_text())
    d["faces_vertices"] = [f[::-1] for f in d["faces_vertices"]]
    path = tmp_path / "clockwise.fold"
    path.write_text(json.dumps(d))
    return str(path)


def test_a_bad_output_path_is_refused_before_the_run_and_nothing_is_written(
        fold_file, tmp_path, capsys):
    out = tmp_path / "o.fold"
    code = main(["simulate", str(fold_file), "-o", str(out),
                 "--report", str(tmp_path / "missing" / "r.json")])
    assert code == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert "--report" in line and str(tmp_path / "missing" / "r.json") in line
    assert ".tmp" not in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hinge.fold"]


def test_an_output_that_is_the_input_is_refused(fold_file, capsys):
    before = fold_file.read_bytes()
    assert main(["simulate", str(fold_file), "-o", str(fold_file)]) == 2
    assert "is the input file" in capsys.readouterr().err
    assert fold_file.read_bytes() == before


def test_warnings_are_one_line_per_kind_and_a_refusal_is_one_line(fold_file, tmp_path,
                                                                    capsys):
    path = _reversed_faces(fold_file, tmp_path)
    assert main(["simulate", path, "--max-iterations", "3"]) == 0
    lines = capsys.readouterr().err.splitlines()
    clockwise = [x for x in lines if "was clockwise" in x]
    assert len(clockwise) == 1 and "(and 1 more like it)" in clockwise[0]
    assert main(["simulate", path, "--report", str(tmp_path / "no" / "r.json")]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("foldcore: error:")


@pytest.mark.parametrize("how, code", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_during_the_writes_leaves_no_file(fold_file, tmp_path, capsys,
                                                  monkeypatch, how, code):
    """The report is written after the FOLD file: a signal there must take the
    finished FOLD's temporary file with it (all or nothing) and end in one line."""
    import os
    import signal

    from foldcore import outputs

    def interrupted(*args):
        if how == "SIGINT":
            raise KeyboardInterrupt
        os.kill(os.getpid(), signal.SIGTERM)

    monkeypatch.setattr(outputs, "report_dict", interrupted)
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    assert main(["simulate", str(fold_file),
                 "-o", str(out_dir / "o.fold"), "--report", str(out_dir / "r.json")]) == code
    (line,) = capsys.readouterr().err.splitlines()
    assert how in line
    assert list(out_dir.iterdir()) == []
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # the handler is put back


def test_a_render_that_fails_keeps_the_result(fold_file, tmp_path, capsys, monkeypatch):
    """A picture the renderer cannot make (here: VTK failing) is one line naming it,
    exit 2, and takes neither the result FOLD nor the report with it."""
    from foldcore import render

    def broken(*args, **kw):
        raise RuntimeError("vtkOpenGLRenderWindow: no display\n(details)")

    monkeypatch.setattr(render, "render_png", broken)
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    fold, report, png = out_dir / "o.fold", out_dir / "r.json", out_dir / "p.png"
    assert main(["simulate", str(fold_file), "-o", str(fold), "--report", str(report),
                 "--render", str(png)]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert f"{png}: the picture was not written (vtkOpenGLRenderWindow: no display " \
           "(details)); the other outputs were:" in line
    assert str(fold) in line and str(report) in line
    assert sorted(p.name for p in out_dir.iterdir()) == ["o.fold", "r.json"]  # no temp
    assert json.loads(report.read_text())["converged"]


def test_version_and_a_render_that_is_not_png(fold_file, tmp_path, capsys):
    """`--version` exists; `--render out.jpg` (a PNG render under a .jpg name) is
    refused before the run."""
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip().startswith("foldcore 0.")
    assert main(["simulate", str(fold_file), "--render", str(tmp_path / "out.jpg")]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert "--render" in line and ".png" in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hinge.fold"]


def test_running_out_of_memory_is_one_line(fold_file, capsys, monkeypatch):
    """A MemoryError anywhere in a command is one line naming the input, exit 2, not
    a traceback."""
    import foldcore.io

    def exhausted(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(foldcore.io, "read_file", exhausted)
    assert main(["simulate", str(fold_file)]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith(f"foldcore: error: {fold_file}: out of memory")


def test_reading_warnings_are_printed_before_the_run(fold_file, tmp_path, capsys,
                                                     monkeypatch):
    """A file without ``edges_foldAngle`` is read with a warning; it is printed when
    the run starts, not after it (a long run kept it back until the end)."""
    import json

    from foldcore.simulation import Simulation

    d = json.loads(fold_file.read_text())
    del d["edges_foldAngle"]
    path = tmp_path / "no_angles.fold"
    path.write_text(json.dumps(d))
    run = Simulation.run

    def marked(self, *args, **kwargs):
        print("RUN STARTS", file=sys.stderr)
        return run(self, *args, **kwargs)

    monkeypatch.setattr(Simulation, "run", marked)
    assert main(["simulate", str(path), "--max-iterations", "5"]) == 0
    lines = capsys.readouterr().err.splitlines()
    said = [i for i, line in enumerate(lines) if "no edges_foldAngle" in line]
    assert said and said[0] < lines.index("RUN STARTS"), lines


def test_a_negative_number_in_exponent_form_is_a_value():
    """argparse takes "-1e2" for an option unless told: a value below the sheet given
    as users write it needs no "=" (``--ground -1e2``), and "-x" is still an option."""
    from foldcore.cli import build_parser

    args = build_parser().parse_args(["simulate", "p.fold", "--ground", "-1e2",
                                      "--fold-percent", "-.5E+1"])
    assert args.ground == -100.0 and args.fold_percent == -5.0
    with pytest.raises(SystemExit):
        build_parser().parse_args(["simulate", "p.fold", "--ground", "-e2"])


@pytest.mark.parametrize("drive, words", [("1", "cannot drive edge 1: it is a boundary"),
                                          ("3-1", "argument --drive: expected edge ids"),
                                          ("0,x", "argument --drive: expected edge ids")])
def test_drive_refuses_what_it_cannot_drive_in_one_line(fold_file, tmp_path, capsys, drive,
                                                        words):
    out = tmp_path / "o.fold"
    assert main(["simulate", str(fold_file), "--drive", drive, "-o", str(out)]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert words in line
    assert not out.exists()
