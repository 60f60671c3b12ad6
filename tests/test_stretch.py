"""Stretch hinges (§6.3): a strip stretched by λ across its width, λ^(−ν) along it.

Tolerances: between rigid panels the width is free (the panels just move
apart) but the panels' edges hold the strip's length, so its length ratio
lies between λ^(−ν) and 1; with panels 10⁶ times softer than volume-weighted
the strip is as good as isolated, its target is reachable, and it reaches
width λ and length λ^(−ν) to 1e-3 (the bound asked of it).
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from foldcore import patterns
from foldcore.errors import MeshError, SimulationError
from foldcore.simulation import Simulation
from foldcore.thickening import thicken

NU, LAMBDA = 0.3, 1.2


def hinge_mesh(**kwargs):
    pattern = patterns.single_hinge(panel_length=5.0, depth=10.0, width=2.0)
    return pattern, thicken(pattern, 1.0, stretch={0: NU}, **kwargs)


def stretched(pattern, mesh, ratio=LAMBDA):
    sim = Simulation(mesh, pattern)
    sim.set_stretch_ratios({0: ratio})
    result = sim.run(tolerance=1e-12, max_iterations=20_000)
    assert result.converged
    return sim.stretch_ratios()[0]


def test_a_mesh_with_vertices_in_no_element_is_refused():
    """The strip alone leaves the panels' vertices in no element: K is singular there."""
    pattern, mesh = hinge_mesh()
    strip_only = dataclasses.replace(mesh, groups={"stretch_hinge": mesh.groups["stretch_hinge"]})
    with pytest.raises(SimulationError, match=r"vertex \d+ belongs to no element"):
        Simulation(strip_only, pattern)


def test_rigid_panels_hold_the_length_soft_panels_do_not():
    pattern, mesh = hinge_mesh()
    width, length = stretched(pattern, mesh)
    assert width == pytest.approx(LAMBDA, abs=1e-3)
    assert LAMBDA ** -NU < length < 1.0
    pattern, soft = hinge_mesh(stiffness={"panel": 1e-6})
    width, length = stretched(pattern, soft)
    assert width == pytest.approx(LAMBDA, abs=1e-3)
    assert length == pytest.approx(LAMBDA ** -NU, abs=1e-3)


def test_passive_stretch_hinge_stays_at_rest_and_can_be_released():
    pattern, mesh = hinge_mesh()
    sim = Simulation(mesh, pattern)
    sim.run(tolerance=1e-12, max_iterations=100)
    np.testing.assert_allclose(sim.stretch_ratios(), [[1.0, 1.0]], atol=1e-9)
    sim.set_stretch_ratios({0: LAMBDA})
    sim.set_stretch_ratios({0: None})  # passive again: the target is the current width
    assert np.isnan(sim.model.stretch.params[0, 2])


def test_stretch_input_errors_name_the_edge():
    pattern, mesh = hinge_mesh()
    sim = Simulation(mesh, pattern)
    with pytest.raises(SimulationError, match="edge 0 is a stretch hinge"):
        sim.set_fold_angles({0: 30.0})
    with pytest.raises(SimulationError, match="edge 0: stretch ratio must be a positive"):
        sim.set_stretch_ratios({0: -1.0})
    with pytest.raises(SimulationError, match="edge 3 is not a stretch hinge"):
        sim.set_stretch_ratios({3: 1.1})
    with pytest.raises(MeshError, match="edge 2 is not a crease"):
        thicken(pattern, 1.0, stretch={2: NU})
    with pytest.raises(MeshError, match="Poisson ratio must be in"):
        thicken(pattern, 1.0, stretch={0: 0.7})
    actuated = pattern.replace(fold_angles=[30.0] + [None] * (pattern.n_edges - 1))
    with pytest.raises(MeshError, match="edge 0 has a fold-angle target"):
        thicken(actuated, 1.0, stretch={0: NU})
    with pytest.raises(SimulationError, match="rigid panels and bending hinges only"):
        Simulation(mesh, pattern, solver="rigid")
