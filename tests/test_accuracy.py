"""Thin-limit accuracy against the closed forms of kinematics.md (issue 4, item 3).

What the thick model can and cannot be held to, measured:

* The *relation* between the four fold angles of a flat-foldable degree-4
  vertex holds: the panels' relative rotations compose to the identity
  whatever the hinges' offsets, so the three driven angles follow the closed
  form at the achieved ρ1 (H/R = 1e-3: within 0.005°; bound 0.1°, the issue's).
* The actuated angle itself falls short of its target by ~1.7° (mode A, 60°):
  a bent strip turns its panels about an axis O(W) off its crease, the four
  offsets around a vertex do not meet, and the resulting strain scales with W
  like the strips themselves, so it does not vanish in the thin limit. Not
  asserted here; see README ("Numbers").
* Mode B chosen by the M/V assignment is not selected: the passive creases
  fold mode A's way, against their assignment (strict xfail below, so fixing
  it turns the suite red until the test is promoted).
"""
from __future__ import annotations

import numpy as np
import pytest

from foldcore import kinematics, patterns
from foldcore.simulation import Simulation
from foldcore.thickening import thicken

R = 10.0            # mm
H = R * 1e-3        # thin limit of the issue: H/R ≤ 1e-3
SECTORS = [(135.0, 90.0, 45.0, 90.0),    # Pehrson
           (150.0, 60.0, 30.0, 120.0),
           (120.0, 75.0, 60.0, 105.0)]


def folded(sectors, mode: str, rho1: float = 60.0):
    pattern = patterns.degree4_vertex(sectors=sectors, radius=R, widths=[2 * H] * 4,
                                      mode=mode, rho1=rho1)
    mesh = thicken(pattern, H, subdivisions=4)
    result = Simulation(mesh, pattern, solver="rigid").run(tolerance=1e-11, max_iterations=300)
    assert result.converged
    return pattern, result.fold_angles_deg[:4]


@pytest.mark.parametrize("sectors", SECTORS)
def test_mode_a_vertex_follows_the_degree4_relation(sectors):
    pattern, angles = folded(sectors, "A")
    closed = kinematics.degree4_deg(sectors[0], sectors[1], angles[0], "A")
    assert np.abs(angles - closed).max() < 0.1
    kinds = pattern.assignments[:4]
    assert (angles[kinds == "V"] > 0).all() and (angles[kinds == "M"] < 0).all()


@pytest.mark.xfail(strict=True, reason="mode B is not selected by the M/V assignment yet: "
                                       "passive creases fold mode A's way (issue 4)")
@pytest.mark.parametrize("sectors", SECTORS[:1])
def test_mode_b_vertex_follows_its_branch(sectors):
    pattern, angles = folded(sectors, "B")
    closed = kinematics.degree4_deg(sectors[0], sectors[1], angles[0], "B")
    assert np.abs(angles - closed).max() < 0.1
