"""Position targets: vertices pulled toward positions (paper Eq. 5–6)."""
from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from ..errors import SimulationError

ALPHA_UPDATE_EVERY = 10  # iterations between α-schedule updates (each costs a refactor)
ALPHA_DROP = 1e-6  # α below which a fading target is dropped


@dataclass
class PositionTarget:
    """Vertices pulled toward target positions with weight α (paper Eq. 5–6).

    ``alpha`` is dimensionless: α = 1 pins a vertex as stiffly as the mean
    element connection of a vertex. ``decay`` < 1 multiplies α every
    ``ALPHA_UPDATE_EVERY`` iterations (α goes from 1 toward 0 as the
    optimisation converges); below ``ALPHA_DROP`` the target is dropped.
    """

    vertices: np.ndarray
    positions: np.ndarray
    alpha: float = 1.0
    decay: float = 1.0


class Pins:
    """The model's position targets and the pin weights they put on K's diagonal.

    Without targets, vertex 0 is anchored with the reference weight: it fixes
    the free translation exactly (K alone is singular).

    Parameters
    ----------
    system : foldcore.system.System
    n_vertices : int
    """

    def __init__(self, system, n_vertices: int):
        self.system, self.n_vertices = system, n_vertices
        self._targets: dict[str, PositionTarget] = {}
        self.weights = np.zeros(n_vertices)
        self.update()

    @property
    def targets(self):
        """Read-only mapping name → :class:`PositionTarget`."""
        return MappingProxyType(self._targets)

    def vertex_ids(self, vertices) -> np.ndarray:
        """(n,) int64 vertex ids of a target, checked against the mesh."""
        ids = np.atleast_1d(np.asarray(vertices, dtype=np.int64))
        if ids.size == 0 or ids.min() < 0 or ids.max() >= self.n_vertices:
            raise SimulationError(f"position target: vertex ids must be in "
                                  f"0..{self.n_vertices - 1}")
        return ids

    def add(self, ids: np.ndarray, positions: np.ndarray, alpha: float, decay: float,
            name: str | None) -> str:
        """A new target on checked ``ids`` (:meth:`vertex_ids`) toward ``positions``
        (n, 3) or (3,) mm; returns its name."""
        pos = np.broadcast_to(positions, (len(ids), 3)).copy()
        if not np.isfinite(pos).all() or not (alpha > 0) or not (0 < decay <= 1):
            raise SimulationError("position target: positions must be finite, alpha > 0, "
                                  "0 < decay ≤ 1")
        name = name or f"target{len(self._targets)}"
        self._targets[name] = PositionTarget(ids, pos, float(alpha), float(decay))
        self.update()
        return name

    def move(self, name: str, positions) -> None:
        """New positions (mm) for an existing target (no refactor needed)."""
        target = self._targets[name]
        target.positions = np.broadcast_to(np.asarray(positions, float),
                                           target.positions.shape).copy()

    def remove(self, name: str) -> None:
        del self._targets[name]
        self.update()

    def update(self) -> None:
        """Pin weights (N,) mm³ from the targets' α, handed to K."""
        weights = np.zeros(self.n_vertices)
        for t in self._targets.values():
            np.add.at(weights, t.vertices, t.alpha * self.system.reference_weight)
        if not self._targets:  # anchor: fixes the free translation exactly
            weights[0] = self.system.reference_weight
        self.weights = weights
        self.system.set_pin_weights(weights)

    def add_terms(self, rhs: np.ndarray, x: np.ndarray) -> float:
        """Add the targets' terms to ``rhs`` (N, 3); returns their energy at ``x``, mm⁵."""
        if not self._targets:
            rhs[0] += self.weights[0] * x[0]
            return 0.0
        energy = 0.0
        for t in self._targets.values():
            w = t.alpha * self.system.reference_weight
            np.add.at(rhs, t.vertices, w * t.positions)
            energy += w * float(((x[t.vertices] - t.positions) ** 2).sum())
        return energy

    def misses(self, x: np.ndarray) -> dict:
        """{name: (largest, mean) distance (mm) of a target's vertices at x (N, 3) from
        their target positions}."""
        out = {}
        for name, t in self._targets.items():
            d = np.linalg.norm(x[t.vertices] - t.positions, axis=1)
            out[name] = (float(d.max()), float(d.mean()))
        return out

    def fading(self) -> bool:
        """Whether some target's α decays (a pull-and-release schedule)."""
        return any(t.decay < 1.0 for t in self._targets.values())

    def advance(self, iterations: int) -> bool:
        """Decay the fading targets' α every ``ALPHA_UPDATE_EVERY`` iterations, dropping
        those below ``ALPHA_DROP``; returns whether the weights changed."""
        if not self.fading() or iterations % ALPHA_UPDATE_EVERY:
            return False
        for name, t in list(self._targets.items()):
            t.alpha *= t.decay ** ALPHA_UPDATE_EVERY
            if t.alpha < ALPHA_DROP:
                del self._targets[name]
        self.update()
        return True
