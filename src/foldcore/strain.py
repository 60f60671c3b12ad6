"""Surface strain of hinge sub-strips and material limits (paper §6.4, beyond it).

A sub-strip of width w = W/k and thickness H bent by φ (its share of the
crease's angle, valley > 0) stretches its faces by s(y) − 1, y = ±H/2 the
top/bottom face (the neutral surface y = 0 keeps its length):

* axis-true hinge (foldcore's default): the neutral axis has the length
  ℓ = max(w·f(kφ), H|φ|/2), f(θ) = (θ/2)/tan(θ/2)
  (:func:`elements.bending_hinge.axis_length`), so s(y) = (ℓ − φy)/w:
  ε = ℓ/w − 1 ∓ φH/(2w) — the whole strip shortens by 1 − f as it bends
  (θ = 90°: 21 %), which is what lets the panels turn about the crease;
* constant-length arc (the paper's Eq. 7): ℓ = w, s(y) = 1 − φ·y/w, so
  ε_top = −φH/(2w), ε_bottom = +φH/(2w);
* Eq. 8 trapezoid: s(y) = 1 − (2y/w)·tan(φ/2), so
  ε_top = −(H/w)·tan(φ/2), ε_bottom = +(H/w)·tan(φ/2).

Valley folds compress the top face and stretch the bottom one; mountain
folds the reverse. φ is the Eq. 9 estimate from the strip's current shape,
so the strain follows the mesh, not the target. A hinge *fails* when a face's
tension exceeds εt or its compression exceeds εc (both positive magnitudes,
dimensionless); :class:`FailureMonitor` records the first iteration at which
each crease does. Fold angle at failure: the crease's Σ φ of its sub-strips.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from elements.bending_hinge import (AXIS, EQ8, H, MODEL, SLACK, STRIPS, W, estimate_angles,
                                     slack_lengths)
from .hinges import neutral_length

TOP, BOTTOM = 0, 1


def strip_strains(params: np.ndarray, phi: np.ndarray, slack=None) -> np.ndarray:
    """(S, 2) surface strains (top, bottom) of sub-strips bent by ``phi`` (S,) rad.

    ``params`` (S, 9) are the hinge parameters (``HINGE_PARAMS``): width w,
    height H, the hinge model and its sub-strip count decide the formula
    (module docstring). ``slack`` (S,) mm: the neutral-axis lengths of slack
    strips (:func:`strains_at` measures them; default: their shortest).
    """
    ratio = params[:, H] / params[:, W]
    model = params[:, MODEL]
    bend = np.where(model == EQ8, ratio * np.tan(0.5 * phi), 0.5 * phi * ratio)
    axial = neutral_lengths(params, phi, slack) / params[:, W] - 1.0
    return np.column_stack([axial - bend, axial + bend])


def strains_at(hinge_group, positions: np.ndarray, phi=None) -> np.ndarray:
    """(S, 2) :func:`strip_strains` of ``hinge_group``'s sub-strips at ``positions``
    (N, 3) mm, bent by ``phi`` (S,) rad (default: their Eq. 9 estimates), slack
    strips' lengths measured."""
    params = hinge_group.params
    if phi is None:
        phi = estimated_strip_angles(hinge_group, positions)
    slack = None
    if np.any(params[:, MODEL] == SLACK):
        slack = np.empty(len(phi))
        slack_lengths(positions, hinge_group.indptr, hinge_group.indices, params, phi, slack)
    return strip_strains(params, phi, slack)


def neutral_lengths(params: np.ndarray, phi: np.ndarray, slack=None) -> np.ndarray:
    """(S,) neutral-axis length (mm) of sub-strips bent by ``phi`` (S,) rad, each
    crease's strips alike: 1/k of their crease's for axis hinges
    (:func:`foldcore.hinges.neutral_length`), ``slack`` (S,) for slack ones
    (default: the axis hinge's, their shortest), the width w for the others."""
    k = params[:, STRIPS]
    model = params[:, MODEL]
    axis = neutral_length("axis", k * params[:, W], params[:, H], k * phi) / k
    lengths = np.where((model == AXIS) | (model == SLACK), axis, params[:, W])
    if slack is not None:
        lengths = np.where(model == SLACK, slack, lengths)
    return lengths


def estimated_strip_angles(hinge_group, positions: np.ndarray) -> np.ndarray:
    """(S,) Eq. 9 bend angle (rad) of every sub-strip at ``positions`` (N, 3) mm."""
    out = np.zeros(len(hinge_group))
    estimate_angles(positions, hinge_group.indptr, hinge_group.indices, out)
    return out


@dataclass(frozen=True)
class StrainLimits:
    """Material limits of the hinges: largest tension and compression (> 0).

    Attributes
    ----------
    tension, compression : float or (E,) float
        Per crease (edge id) or for all, dimensionless strain magnitudes;
        ``inf`` disables a side.
    """

    tension: object = np.inf
    compression: object = np.inf

    def per_edge(self, n_edges: int) -> tuple[np.ndarray, np.ndarray]:
        """(E,) tension and compression limits, validated (positive, not NaN)."""
        out = []
        for name, value in (("tension", self.tension), ("compression", self.compression)):
            limit = np.broadcast_to(np.asarray(value, dtype=float), (n_edges,)).copy()
            if not (limit > 0).all():
                raise ValueError(f"strain limit {name} must be > 0 (inf to disable), "
                                 f"got {value!r}")
            out.append(limit)
        return out[0], out[1]


class FailureMonitor:
    """First iteration at which each crease's hinge exceeds its strain limits.

    Parameters
    ----------
    hinge_group : ElementGroup of ``bending_hinge``
    limits : StrainLimits
    n_edges : int
    segments : (E,) int, optional
        Strip segments along each crease (``ThickMesh.segments``; default 1):
        a failure's fold angle is its crease's series sum averaged over them.
    """

    def __init__(self, hinge_group, limits: StrainLimits, n_edges: int, segments=None):
        self.group = hinge_group
        self.segments = np.ones(n_edges) if segments is None else np.asarray(segments, float)
        tension, compression = limits.per_edge(n_edges)
        self.tension = tension[hinge_group.source]
        self.compression = compression[hinge_group.source]
        self.failures: list[dict] = []
        self._failed = set()

    def check(self, positions: np.ndarray, iteration: int, fold_percent: float) -> None:
        """Record creases whose sub-strips exceed a limit now (first time only)."""
        phi = estimated_strip_angles(self.group, positions)
        strain = strains_at(self.group, positions, phi)
        over_t = strain.max(axis=1) > self.tension
        over_c = -strain.min(axis=1) > self.compression
        for s in np.flatnonzero(over_t | over_c):
            edge = int(self.group.source[s])
            if edge in self._failed:
                continue
            self._failed.add(edge)
            mine = self.group.source == edge
            self.failures.append({
                "edge": edge, "iteration": int(iteration), "fold_percent": float(fold_percent),
                "mode": "tension" if over_t[s] else "compression",
                "strain": float(strain[s].max() if over_t[s] else strain[s].min()),
                "fold_angle_deg": float(np.degrees(phi[mine].sum() / self.segments[edge]))})
