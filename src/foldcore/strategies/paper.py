"""``paper``: the paper's local/global map (§3), x ← K⁻¹ b(x).

Every element is projected at x (the local step, in parallel), the weighted
targets are gathered into b(x), and the prefactored K gives the new
positions (the global step). Monotone in the energy, but it moves a long
panel only through its thin hinge faces, so its iteration count grows with
(panel length / thickness)²: `docs/architecture.md#why-more-than-the-papers-map`.
"""
from __future__ import annotations

import time

import numpy as np

from ..system import take_solution
from .base import Strategy


class PaperMap(Strategy):
    """One local step then one global solve per :meth:`step`."""

    name = "paper"
    plain_map = True

    def step(self) -> tuple[float, float]:
        model = self.model
        energy, rhs = model.local_step(model.x)
        t0 = time.perf_counter()
        solution = model.system.factor.solve(rhs)
        new_x = np.empty(model.x.shape)
        moved = float(take_solution(solution, model.x, new_x))
        model.timings["solve"] += time.perf_counter() - t0
        model.x = new_x
        return energy, moved
