"""What a run produced (:class:`Result`). Angles in degrees (valley > 0), positions mm."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: Why a run ended (``Result.reason``).
REASONS = ("converged", "stalled", "budget", "callback", "interrupted", "none")


@dataclass
class Result:
    """What a run produced. Angles in degrees (valley > 0), positions in mm.

    Attributes
    ----------
    positions : (N, 3) float
    fold_angles_deg : (E,) float, NaN for boundary edges
    strip_angles_deg : (S,) float, bend angle used by each hinge sub-strip
    energy : (iterations,) float, energy before each step, mm⁵
    iterations : int
    converged : bool, the run ended at an equilibrium of the strategy's model within
        the tolerance (``reason == "converged"``), not merely with a small step
    timings_s : dict, seconds: ``setup``, ``projection`` (element kernels or the
        rigid-body assembly), ``solve`` (rhs gather, factorisations and solves),
        ``total`` (setup + every run so far) and, after a run where K was
        factorised, ``bare_solve`` (one K⁻¹ solve: the cost floor)
    strip_strains : (S, 2) float, top and bottom surface strain of each hinge
        sub-strip from its current shape (:mod:`foldcore.strain`), dimensionless
    failures : list of dict, hinges that exceeded their strain limits (first
        iteration each; empty without ``strain_limits``)
    target_angles_deg : (E,) float, each crease's effective target at the run's
        fold percent (NaN: passive or boundary)
    hinge_misfit_mm : (S,) float, RMS distance (mm) of each hinge sub-strip's
        vertices from its rotated model shape: 0 where the hinge model is met,
        > 0 where the model binds
    reason : str, why the run ended: ``"converged"``; ``"stalled"`` (steps within
        the tolerance but the equilibrium not reached, or the strategy's steps at
        its resolution); ``"budget"`` (``max_iterations`` ran out); ``"callback"``
        (the callback returned False); ``"interrupted"`` (Ctrl-C); ``"none"`` for
        a snapshot taken outside a run
    residual : float, the estimated distance to the equilibrium at the end,
        relative to the pattern size (NaN if never measured in the run)
    contact : dict or None, what contact did at the end (None: contact off):
        ``active_pairs`` (every pair of parts within the barrier's reach, a panel
        named by its pattern face, a hinge strip as ``{"crease": e}``),
        ``blocking_pairs`` (the pairs that cut the last step short),
        ``smallest_gap_mm``, ``activation_mm`` (d̂), ``stiffness`` (κ, mm³),
        ``touching_faces`` and ``touching_creases`` (the panels and strips in
        those pairs or on an obstacle), ``panel_forces`` and ``strip_forces``
        (per touching part its face or crease and the contact force, −∂(κ Σ b)/∂x
        summed over its vertices, mm⁴), ``obstacles``
    position_targets : list of dict or None, per position target at the end:
        ``name``, ``vertices`` (count), ``alpha``, ``miss_mm`` and
        ``mean_miss_mm`` (its vertices' largest and mean distance from their
        targets) and ``stopped_by``: ``"contact"`` where it misses by more than
        :data:`foldcore.simulation.TARGET_MISS` of the pattern's size while
        panels touch, ``"pull"`` where it misses so with nothing touching (a
        compromise with the hinges or with other targets), else None
    """

    positions: np.ndarray
    fold_angles_deg: np.ndarray
    strip_angles_deg: np.ndarray
    energy: np.ndarray
    iterations: int
    converged: bool
    timings_s: dict = field(default_factory=dict)
    strip_strains: np.ndarray | None = None
    failures: list = field(default_factory=list)
    target_angles_deg: np.ndarray | None = None
    hinge_misfit_mm: np.ndarray | None = None
    reason: str = "none"
    residual: float = float("nan")
    contact: dict | None = None
    position_targets: list | None = None
