"""The hinge group's controls: fold targets, fold percent, floors, stops, weights."""
from __future__ import annotations

import numpy as np

from elements.bending_hinge import FLOOR, TARGET, limit_excess

from ..actuation import ACTUATION_STIFFNESS, ACTUATIONS
from ..errors import SimulationError

STOP_ENTER = 1e-3  # rad past its bound before a passive strip becomes a stop
STOP_LEAVE = 1e-3  # rad back inside its interval before a stop is released


class HingeControls:
    """What the model's bending-hinge strips are driven by.

    Each crease's target is its fold angle × the fold percent, spread evenly
    over its k sub-strips; a NaN target makes a strip passive. Passive strips
    bent past their max angle become stops (their weight × ``stop_stiffness``)
    and the actuation sets the actuated strips' weights
    (:mod:`foldcore.actuation`). Why stops: `docs/architecture.md#stops`.

    Parameters
    ----------
    state : GroupState or None
        The bending-hinge group (None: a mesh without one; targets are then
        only kept for :meth:`target_angles`).
    mesh, pattern
        The thick mesh and its crease pattern.
    actuation : {"equal", "angle"}
    stop_stiffness : float
        Weight factor of a stop, ≥ 1 (1: no stops).

    Attributes
    ----------
    fold_targets : (E,) float
        Each crease's target at 100 %, degrees (NaN: passive; 0 for flat "F" edges).
    percent : float
        The fold percent the targets are scaled by.
    passive : (S,) bool
        Strips without a target.
    stops : (S,) bool
        Strips acting as stops.
    """

    def __init__(self, state, mesh, pattern, actuation: str, stop_stiffness: float):
        if actuation not in ACTUATIONS:
            raise SimulationError(f"unknown actuation {actuation!r} (available: "
                                  f"{', '.join(ACTUATIONS)})")
        if not (np.isfinite(stop_stiffness) and stop_stiffness >= 1.0):
            raise SimulationError(f"stop_stiffness must be a finite number ≥ 1, "
                                  f"got {stop_stiffness!r}")
        self.state, self.mesh, self.pattern = state, mesh, pattern
        self.actuation = actuation
        self.stop_factor = float(stop_stiffness)
        n = 0 if state is None else len(state.group)
        self.stops = np.zeros(n, dtype=bool)
        self._excess = np.zeros(n)
        self.passive = np.zeros(n, dtype=bool)
        self.fold_targets = np.array(pattern.fold_angles, dtype=float)
        self.fold_targets[pattern.assignments == "F"] = 0.0
        self.percent = 100.0

    def apply(self) -> None:
        """Write the strips' targets (rad per sub-strip) from the fold targets and
        the percent; passive where NaN."""
        if self.state is None:
            return
        src = self.state.group.source
        k = self.mesh.subdivisions[src]
        target = np.radians(self.fold_targets[src] * self.percent / 100.0) / k
        self.state.set_params(slice(None), TARGET, target)
        self.passive = np.isnan(target)

    def weights(self) -> np.ndarray:
        """(S,) strip weights, mm³: their volume weights × the stop factor on stops ×
        ``ACTUATION_STIFFNESS`` on actuated strips under ``actuation="angle"``."""
        g = self.state.group
        factor = np.where(self.stops, self.stop_factor, 1.0)
        if self.actuation == "angle":
            factor = factor * np.where(self.passive, 1.0, ACTUATION_STIFFNESS)
        return factor * g.weights

    def update_stops(self, x: np.ndarray) -> bool:
        """Stiffen passive strips bent past their max angle at ``x`` (N, 3) mm, release
        them once back inside; returns whether the set of stops changed."""
        if self.stop_factor == 1.0 or self.state is None:
            return False
        if not self.passive.any() and not self.stops.any():
            return False  # all actuated: no estimate to check (stops only on passive strips)
        g = self.state.group
        limit_excess(x, g.indptr, g.indices, self.state.params, self._excess)
        excess = np.where(self.passive, self._excess, -np.inf)
        stops = np.where(self.stops, excess > -STOP_LEAVE, excess > STOP_ENTER)
        if np.array_equal(stops, self.stops):
            return False
        self.stops = stops
        return True

    def set_floor(self, floor_deg: float) -> None:
        """Every crease's passive floor (degrees on its assigned side), over its strips."""
        if self.state is not None:
            k = self.mesh.subdivisions[self.state.group.source]
            self.state.set_params(slice(None), FLOOR, np.radians(floor_deg) / k)

    def crease_floors(self) -> np.ndarray:
        """(E,) each crease's floor, rad over the whole crease (NaN: no strip)."""
        out = np.full(self.pattern.n_edges, np.nan)
        if self.state is not None:
            src = self.state.group.source
            out[src] = self.state.params[:, FLOOR] * self.mesh.subdivisions[src]
        return out

    def set_crease_floors(self, floors: np.ndarray) -> None:
        """Floors per crease (E,) rad, spread over each crease's k strips."""
        src = self.state.group.source
        self.state.set_params(slice(None), FLOOR,
                              floors[src] / self.mesh.subdivisions[src].astype(float))

    def target_angles(self) -> np.ndarray:
        """(E,) effective target of every crease in degrees (valley > 0): its fold
        angle × the fold percent; NaN for passive creases and boundary edges."""
        out = self.fold_targets * self.percent / 100.0
        out[self.pattern.assignments == "B"] = np.nan
        return out

    def checked_crease(self, e: int, stretch) -> int:
        """``e`` if it is a crease whose fold angle may be set (else SimulationError)."""
        if not 0 <= e < self.pattern.n_edges:
            raise SimulationError(f"edge {e} does not exist (0..{self.pattern.n_edges - 1})")
        if self.pattern.assignments[e] == "B":
            raise SimulationError(f"edge {e} is a boundary edge and has no hinge")
        if stretch is not None and (stretch.group.source == e).any():
            raise SimulationError(f"edge {e} is a stretch hinge: set its stretch ratio "
                                  "(set_stretch_ratios), not a fold angle")
        return e

    def checked_angle(self, e: int, angle) -> float:
        """``angle`` (degrees) if allowed for crease ``e``'s assignment and max angle."""
        if angle is None or np.isnan(angle):
            return np.nan
        kind, limit = self.pattern.assignments[e], self.pattern.max_angles[e]
        if kind == "M" and angle > 0 or kind == "V" and angle < 0 or abs(angle) > limit:
            raise SimulationError(f"edge {e}: target {angle:g}° is not allowed for a "
                                  f"{kind!r} crease with max angle {limit:g}°")
        return float(angle)
