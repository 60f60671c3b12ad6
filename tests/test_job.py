"""``foldcore.simulate`` and what a run tells its user: its option groups, the
summary line, the binding and nothing-driven warnings, the progress bar, and the
last iterate written as a partial result on Ctrl-C."""
from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import foldcore
from foldcore import cli, interrupts, patterns
from foldcore.errors import RunWarning
from foldcore.job import Interrupted
from foldcore.options import OptionError
from foldcore.simulation import Simulation

REAL = "tests/data/real/"



def test_simulate_is_the_command_line_as_a_call(hinge_file, tmp_path):
    """Same options, same outputs: the FOLD result of the call equals the CLI's."""
    options = ["--subdivisions", "4", "--tolerance", "1e-9", "--max-iterations", "20000"]
    assert cli.main(["simulate", str(hinge_file), "-o", str(tmp_path / "cli.fold"),
                     "-q", *options]) == 0
    result = foldcore.simulate(hinge_file, thickening={"subdivisions": 4},
                               solving={"tolerance": 1e-9, "max_iterations": 20_000},
                               outputs={"fold": tmp_path / "api.fold"})
    assert result.converged and result.fold_angles_deg[0] == pytest.approx(90.0, abs=1e-4)
    a, b = (json.loads((tmp_path / n).read_text()) for n in ("cli.fold", "api.fold"))
    assert a["edges_foldAngle"] == b["edges_foldAngle"]
    assert a["file_frames"][0]["vertices_coords"] == b["file_frames"][0]["vertices_coords"]
    with pytest.raises(TypeError):
        foldcore.job.fold(hinge_file, thickness=1.0)
    with pytest.raises(OptionError, match="thickening: unknown option 'thickness_mm'"):
        foldcore.job.fold(hinge_file, thickening={"thickness_mm": 1.0})


def test_options_are_checked_before_any_work_in_library_words(hinge_file, tmp_path, capsys):
    """A value outside its range fails when its group is made, naming ``group.field``;
    the command line says the same of its flag."""
    from foldcore.options import Solving, Thickening

    with pytest.raises(OptionError, match=r"solving.max_iterations must be an integer in 1..1000000"):
        Solving(max_iterations=0)
    with pytest.raises(OptionError, match=r"solving.fold_percent must be in \[-100, 100\]"):
        foldcore.simulate(hinge_file, solving={"fold_percent": 150})
    with pytest.raises(OptionError, match="thickening.subdivisions"):
        Thickening(subdivisions=0)
    out = tmp_path / "never.fold"
    assert cli.main(["simulate", str(hinge_file), "--fold-percent", "150", "-o", str(out)]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line == "foldcore: error: --fold-percent must be in [-100, 100], got 150.0"
    assert not out.exists()


def test_the_summary_line_gives_verdict_iterations_time_and_miss(hinge_file, capsys):
    assert cli.main(["simulate", str(hinge_file), "--subdivisions", "4"]) == 0
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith(f"foldcore: {hinge_file}: converged after ")
    assert " iterations in " in line and "1 driven creases at fold percent 100" in line
    assert "miss max " in line
    assert cli.main(["simulate", str(hinge_file), "--subdivisions", "4", "-q"]) == 0
    assert capsys.readouterr().err == ""


def test_nothing_driven_is_said(tmp_path, capsys):
    """The crane read with --mv-passive: every crease passive, the sheet stays flat."""
    assert cli.main(["simulate", REAL + "crane.fold", "--mv-passive", "--thickness", "1",
                     "--sheet-size", "200", "-q"]) == 0
    (line,) = capsys.readouterr().err.splitlines()
    assert "crane.fold: no crease is driven" in line


def test_a_run_that_binds_converged_says_its_targets_were_missed():
    """Origami Simulator's waterbomb base at 30 %: its panels cannot fold rigidly to
    the drawn angles; converged with every driven crease far off, and said so."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = foldcore.simulate(REAL + "bird-base-3d.fold", reading={"size": 100},
                                   thickening={"thickness": 0.5},
                                   solving={"fold_percent": 30, "max_iterations": 3000})
    binding = [str(w.message) for w in caught if w.category is RunWarning]
    assert result.converged
    (message,) = binding
    assert "miss their targets by more than 1°" in message and "bird-base-3d" in message


def test_no_progress_bar_without_a_terminal_or_with_quiet(hinge_file, monkeypatch):
    args = cli.build_parser().parse_args(["simulate", str(hinge_file)])
    assert cli._progress(args) is None  # pytest's stderr is not a terminal
    monkeypatch.setattr(cli.sys.stderr, "isatty", lambda: True, raising=False)
    bar = cli._progress(args)
    assert bar is not None
    bar.close()
    args.quiet = True
    assert cli._progress(args) is None


def test_ctrl_c_writes_the_last_iterate_marked_partial(hinge_file, tmp_path, capsys,
                                                       monkeypatch):
    step, calls = Simulation._step, []

    def interrupted_step(self):
        calls.append(1)
        if len(calls) == 30:
            raise KeyboardInterrupt
        return step(self)

    monkeypatch.setattr(Simulation, "_step", interrupted_step)
    out, report = tmp_path / "o.fold", tmp_path / "r.json"
    code = cli.main(["simulate", str(hinge_file), "--subdivisions", "4", "--solver", "paper",
                     "-o", str(out), "--report", str(report)])
    assert code == interrupts.EXIT_SIGINT
    (line,) = capsys.readouterr().err.splitlines()
    assert "interrupted (SIGINT) after 29 iterations" in line and str(out) in line
    fold, rep = json.loads(out.read_text()), json.loads(report.read_text())
    assert fold["foldcore:partial"] is True
    assert rep["partial"] is True and rep["reason"] == "interrupted"
    assert rep["iterations"] == 29 and rep["converged"] is False
    assert rep["timings_s"]["total"] > rep["timings_s"]["setup"]  # the run's time counts
    assert 0.0 < rep["fold_angles_deg"][0] < 90.0  # part way
    with pytest.raises(Interrupted) as info:
        calls.clear()
        foldcore.simulate(hinge_file, thickening={"subdivisions": 4},
                          solving={"solver": "paper"})
    assert info.value.result.iterations == 29 and info.value.written == {}
    assert np.isfinite(info.value.result.positions).all()


def test_ctrl_c_while_the_finished_result_is_written_completes_it(hinge_file, tmp_path,
                                                                  capsys, monkeypatch):
    """A first Ctrl-C while a converged result's outputs are written (SIGINT sent from
    inside the writer) lets them finish: the files are whole, not partial, and the
    command says so and exits 130."""
    import os
    import signal

    from foldcore import outputs

    write = outputs.write_result

    def interrupted_write(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGINT)
        return write(*args, **kwargs)

    monkeypatch.setattr(outputs, "write_result", interrupted_write)
    out, report = tmp_path / "o.fold", tmp_path / "r.json"
    code = cli.main(["simulate", str(hinge_file), "-o", str(out), "--report", str(report)])
    assert code == interrupts.EXIT_SIGINT
    (line,) = capsys.readouterr().err.splitlines()
    assert "while the finished result was written" in line and str(out) in line
    fold, rep = json.loads(out.read_text()), json.loads(report.read_text())
    assert "foldcore:partial" not in fold and rep["converged"] is True


def test_the_readme_snippet_renders(tmp_path, monkeypatch):
    """The README's library snippet runs as printed, and ``foldcore render`` accepts
    the result it writes (its old ``write_fold`` of achieved angles had no folded
    frame, and render refused it)."""
    import pathlib
    import re

    readme = (pathlib.Path(__file__).parents[1] / "README.md").read_text()
    library = readme.split("## Library", 1)[1]
    code = re.search(r"```python\n(.*?)```", library, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    assert json.loads((tmp_path / "hinge.json").read_text())["converged"] is True
    assert cli.main(["render", "hinge-folded.fold", "-o", "h.png", "--size", "160x120"]) == 0
    assert (tmp_path / "h.png").stat().st_size > 0


def test_a_crease_past_flat_reads_back_and_keeps_its_side(tmp_path):
    """Measured angles keep their side (``on_assigned_side``): a valley at 180.54° is
    kept in the report, written within FOLD's range, and render/export read it back
    (a mountain written +179.46° would contradict its assignment)."""
    import dataclasses

    from folded import scene
    from foldcore.result_file import read_result
    from foldcore.outputs import write_result

    pattern, mesh, result = scene("hinge")
    crease = int(pattern.creases[0])
    angles = result.fold_angles_deg.copy()
    assert pattern.assignments[crease] == "V"
    angles[crease] = 180.54
    past = dataclasses.replace(result, fold_angles_deg=angles)
    out, report = tmp_path / "past.fold", tmp_path / "past.json"
    write_result(past, pattern, mesh, 1.0, {}, fold=out, report=report)
    assert json.loads(out.read_text())["edges_foldAngle"][crease] == 180.0
    assert json.loads(report.read_text())["fold_angles_deg"][crease] == 180.54
    read_result(out)  # no contradiction raised


def test_the_report_gives_the_effective_targets_at_the_fold_percent(hinge_file, tmp_path):
    """The crane at 30 % reported target_angles_deg 180 (the file's, not the run's)."""
    report = tmp_path / "r.json"
    foldcore.simulate(hinge_file, thickening={"subdivisions": 4}, solving={"fold_percent": 30},
                      outputs={"report": report})
    rep = json.loads(report.read_text())
    assert rep["target_angles_deg"][0] == pytest.approx(27.0)  # 30 % of 90°
    assert rep["actuation"]["creases"][0]["target_deg"] == pytest.approx(27.0)


def test_elastic_cells_cut_every_face_into_rings_and_fold_a_compatible_target(tmp_path):
    """--elastic-cells MM: every face in rings of ~MM mm cells (rebuilt from the result
    file), recorded in the report. The FOLD project's diagonal fold (one crease, two
    triangles) is compatible, so elastic panels meet its target as rigid ones do —
    to the tolerance's angle, 1e-8 × size / cell size ≈ 1e-4° at most."""
    from foldcore.result_file import read_result

    report = tmp_path / "diag.json"
    done = foldcore.job.fold(REAL + "diagonal-cp.fold", reading={"size": 100.0},
                             thickening={"thickness": 0.5, "elastic_cells": 10.0},
                             solving={"fold_percent": 90, "max_iterations": 20_000},
                             outputs={"fold": tmp_path / "diag.fold", "report": report})
    faces = done.pattern.faces
    assert set(done.mesh.elastic) == set(range(len(faces)))
    assert all(kind == "rings" and n >= 2 for kind, n in done.mesh.elastic.values())
    assert done.result.converged
    crease = done.pattern.creases
    assert np.abs(done.result.fold_angles_deg[crease]).max() == pytest.approx(162.0, abs=1e-4)
    assert json.loads(report.read_text())["settings"]["elastic_cells_mm"] == 10.0
    back = read_result(tmp_path / "diag.fold")
    assert back.mesh.elastic == done.mesh.elastic


def test_a_crease_folded_to_the_other_side_is_counted_and_said():
    """A driven crease that ended on the other side of flat (by more than the miss
    tolerance) counts in ``wrong_side`` and in the binding warning."""
    from types import SimpleNamespace

    from foldcore.outputs import MISS_WARNING_DEG, actuation_entries, run_summary

    pattern = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=60.0, width=2.0)
    edges = np.full(pattern.n_edges, np.nan)
    crease = int(pattern.creases[0])
    targets, achieved = edges.copy(), edges.copy()
    targets[crease] = 60.0
    for angle, wrong in ((-2.0 * MISS_WARNING_DEG, 1), (-0.5 * MISS_WARNING_DEG, 0), (30.0, 0)):
        achieved[crease] = angle
        result = SimpleNamespace(target_angles_deg=targets, fold_angles_deg=achieved,
                                 converged=True, iterations=1, reason="converged",
                                 timings_s={"total": 0.1})
        assert actuation_entries(result, pattern)["wrong_side"] == wrong
        _, said = run_summary(result, pattern, "hinge.fold", 100)
        assert len(said) == 1 and ("1 folded to the other side" in said[0]) == bool(wrong)
        assert "thickening.elastic_cells lets the panels bend" in said[0]
    _, said = run_summary(result, pattern, "hinge.fold", 100, model="elastic")
    assert "with elastic panels" in said[0] and "elastic_cells" not in said[0]
