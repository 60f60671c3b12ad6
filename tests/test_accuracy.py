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
* Mode B chosen by the M/V assignment is selected once the panels' dihedrals
  are held on their assigned side (rigid strategy, ``rigid_body.MV_STIFFNESS``)
  and passive creases start pre-bent 2° that way (``passive_floor_deg``);
  without both the vertex folded mode A's way, against the assignment
  (measured). Its actuated crease falls further short (46.8° of 60° for
  Pehrson's sectors), the same hinge-model mismatch.
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


def folded(sectors, mode: str, rho1: float = 60.0, floor_deg: float = 0.0):
    pattern = patterns.degree4_vertex(sectors=sectors, radius=R, widths=[2 * H] * 4,
                                      mode=mode, rho1=rho1)
    mesh = thicken(pattern, H, subdivisions=4)
    sim = Simulation(mesh, pattern, solver="rigid", passive_floor_deg=floor_deg)
    result = sim.run(tolerance=1e-11, max_iterations=400)
    assert result.converged
    return pattern, result.fold_angles_deg[:4]


@pytest.mark.parametrize("sectors", SECTORS)
def test_mode_a_vertex_follows_the_degree4_relation(sectors):
    pattern, angles = folded(sectors, "A")
    closed = kinematics.degree4_deg(sectors[0], sectors[1], angles[0], "A")
    assert np.abs(angles - closed).max() < 0.1
    kinds = pattern.assignments[:4]
    assert (angles[kinds == "V"] > 0).all() and (angles[kinds == "M"] < 0).all()


@pytest.mark.parametrize("sectors", SECTORS)
def test_mode_b_vertex_folds_its_assigned_branch(sectors):
    """Mode B by the M/V assignment: with the panels' M/V side rows of the rigid
    strategy and a 2° pre-bend of passive creases on their assigned side
    (``passive_floor_deg``), the vertex folds mode B, not mode A's way."""
    pattern, angles = folded(sectors, "B", floor_deg=2.0)
    closed = kinematics.degree4_deg(sectors[0], sectors[1], angles[0], "B")
    assert np.abs(angles - closed).max() < 0.1
    kinds = pattern.assignments[:4]
    assert (angles[kinds == "V"] > 0).all() and (angles[kinds == "M"] < 0).all()
