"""The ``foldcore`` logger: silent by default, on stderr with ``-v`` (stages, phase
hand-overs, factorisations, thread choices)."""
from __future__ import annotations

import logging

from foldcore import cli, patterns, thicken
from foldcore.simulation import Simulation


def test_the_library_says_nothing_unless_asked(hinge_file, capsys):
    """A NullHandler on "foldcore": no "No handlers could be found", no output."""
    assert any(isinstance(h, logging.NullHandler) for h in logging.getLogger("foldcore").handlers)
    assert cli.main(["simulate", str(hinge_file), "-q"]) == 0
    assert capsys.readouterr().err == ""


def test_verbose_logs_the_run_and_more_verbose_the_factorisations(hinge_file, capsys):
    assert cli.main(["simulate", str(hinge_file), "-q", "-v"]) == 0
    lines = capsys.readouterr().err.splitlines()
    assert any(line.startswith("foldcore: run 1: hybrid, fold percent 100") for line in lines)
    assert any("ended converged after" in line for line in lines)
    assert not any("factorised" in line for line in lines)  # debug detail: -vv only
    assert cli.main(["simulate", str(hinge_file), "-q", "-vv", "--solver", "paper",
                     "--max-iterations", "5"]) == 0
    assert any("K factorised" in line for line in capsys.readouterr().err.splitlines())
    assert not logging.getLogger("foldcore").handlers[1:]  # the CLI's handler is removed


def test_the_phases_of_a_hybrid_run_are_logged(caplog):
    """A waterbomb in elastic rings, creases driven to ±40° (no rigid folding motion
    meets them): the rigid-panel twin steps first and the cells take its state, then
    ``newton`` finishes; a flat sheet driven with passive M/V creases has a branch
    stage first."""
    import numpy as np

    pattern = patterns.waterbomb(radius=30.0, width=1.0)
    angles = np.full(pattern.n_edges, np.nan)
    angles[:6] = np.where(np.arange(6) % 2 == 0, -40.0, 40.0)
    pattern = pattern.replace(fold_angles=angles)
    mesh = thicken(pattern, 0.5, subdivisions=2, elastic="facets", cell_size=5.0)
    with caplog.at_level(logging.INFO, logger="foldcore"):
        Simulation(mesh, pattern).run(tolerance=1e-9, max_iterations=5_000)
    said = [r.getMessage() for r in caplog.records]
    assert any("rigid-panel twin steps first, then newton" in m for m in said)
    assert any("the cells take the rigid twin's state" in m for m in said)
    caplog.clear()
    vertex = patterns.degree4_vertex(radius=10.0, widths=[0.03] * 4, rho1=70.0)
    with caplog.at_level(logging.INFO, logger="foldcore"):
        Simulation(thicken(vertex, 0.01), vertex).run()
    said = [r.getMessage() for r in caplog.records]
    assert any(m.startswith("branch stage: passive M/V creases held 2°") for m in said)
    assert any(m.startswith("branch stage ended converged") for m in said)
