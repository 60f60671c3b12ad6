"""Options of the ``rigid`` strategy (its engine's tuning constants, in one place)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RigidOptions:
    """Tuning constants of the rigid-body strategy and its engine.

    Why each value: `docs/architecture.md#the-rigid-body-strategy`.

    Attributes
    ----------
    seed : float
        Pre-bend (rad per crease) of a passive M/V crease that starts flat, in
        its assigned direction: it picks the branch at the flat bifurcation.
    lambda_start : float
        Initial Levenberg–Marquardt damping, relative to diag(JᵀJ).
    lambda_min : float
        Smallest damping (one that still changes JᵀJ + λD in floating point;
        a larger floor damps the sheet's softest mode).
    lambda_max : float
        Largest damping.
    lambda_settled : float
        Largest damping of an accepted step that may end a run.
    lambda_down, lambda_up : float
        Damping divided at most after an accepted step (gain-ratio rule),
        multiplied after a rejected one.
    damped_share_max : float
        Largest share of the damping in an accepted step's predicted decrease
        that may end a run.
    chord_from : float
        A first accepted step ≤ this × the run's limit gets its distance left
        from the simplified correction.
    contraction_max : float
        Largest ratio of two accepted steps' lengths from which the distance
        left is estimated.
    geodesic_h : float
        Finite-difference step of the geodesic acceleration (fraction of the step).
    geodesic_max : float
        The acceleration is kept only if ‖a‖ ≤ this × ‖v‖ (0: no acceleration).
    extrapolate_cos : float
        Two accepted velocities at least this aligned (cosine) …
    extrapolate_ratio : (float, float)
        … the later this share of the earlier, give a try of the step scaled by
        1 / (1 − ratio), …
    extrapolate_max : float
        … at most this many times the step.
    mv_stiffness : float
        Weight (× reference weight × W²) of the panels' M/V side rows; 0: off.
    mv_wall : float
        Slope of an M/V row's way back past a flat fold.
    mv_slack : float
        rad a panel dihedral may cross to the wrong side before its row acts.
    coarse_start : bool
        Whether a run from the rest state starts on the mesh's coarse twin.
    rest_tol : float
        Relative distance from the rest positions that counts as the rest state.
    twin_stall : float
        Relative accepted step of the twin that hands over unsettled.
    """

    seed: float = 1e-2
    lambda_start: float = 1e-4
    lambda_min: float = float(np.finfo(float).eps)
    lambda_max: float = 1e12
    lambda_settled: float = 1.0
    lambda_down: float = 3.0
    lambda_up: float = 5.0
    damped_share_max: float = 0.1
    chord_from: float = 1e4
    contraction_max: float = 0.5
    geodesic_h: float = 0.1
    geodesic_max: float = 1.5
    extrapolate_cos: float = 0.98
    extrapolate_ratio: tuple = (0.3, 0.98)
    extrapolate_max: float = 20.0
    mv_stiffness: float = 1e3
    mv_wall: float = 1.0
    mv_slack: float = 1e-6
    coarse_start: bool = True
    rest_tol: float = 1e-9
    twin_stall: float = 1e-10
