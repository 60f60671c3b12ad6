"""``anderson``: the paper's map with safeguarded Anderson acceleration.

Walker & Ni 2011; Peng et al. 2018, "Anderson acceleration for geometry
optimization and physics simulation": the fixed-point map G(x) = K⁻¹ b(x)
is extrapolated from its last ``memory`` residuals f = G(x) − x, and the
accelerated point is kept only if its energy is below the previous one —
else the plain step from the last accepted point is taken and the history
forgotten. Shared bookkeeping and the energy's gradient:
:mod:`.accelerated`. Where it serves and where it does not:
`docs/architecture.md#the-accelerated-maps`.
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from .accelerated import Accelerated


@dataclass(frozen=True)
class AndersonOptions:
    """Options of ``anderson``.

    Attributes
    ----------
    memory : int
        Residuals kept (Peng et al. use 5–6).
    lstsq_rcond : float
        Relative cut-off of the Anderson least-squares solve.
    """

    memory: int = 5
    lstsq_rcond: float = 1e-10


class Anderson(Accelerated):
    """Safeguarded type-II Anderson acceleration of x ← G(x) = K⁻¹ b(x).

    ``step()`` returns (energy at the point used, largest |G(x) − x| in mm).
    """

    name = "anderson"
    Options = AndersonOptions

    def _forget(self) -> None:
        self._dg = deque(maxlen=self.memory)
        self._df = deque(maxlen=self.memory)
        self._prev = None  # (g, f) of the previous iteration
        self._last = None  # (energy, G(x)) of the last accepted point

    def _advance(self) -> tuple[float, float]:
        model = self.model
        energy, rhs = model.local_step(self.x)
        changed = self._k_changed()
        if self._last is not None and not changed and not energy <= self._last[0]:
            self.rejected += 1  # accelerated point raised E: plain step from the last one
            self.x = self._last[1]
            self._forget()
            energy, rhs = model.local_step(self.x)
            changed = self._k_changed()
        if changed:
            self._forget()
        g = model.global_step(rhs)
        f = g - self.x
        self._last = (energy, g)
        self.x = self._extrapolate(g, f)
        return energy, float(np.abs(f).max())

    def _extrapolate(self, g: np.ndarray, f: np.ndarray) -> np.ndarray:
        """g − ΔG γ with γ = argmin ‖f − ΔF γ‖ over the stored differences."""
        if self._prev is not None:
            self._dg.append((g - self._prev[0]).ravel())
            self._df.append((f - self._prev[1]).ravel())
        self._prev = (g, f)
        if not self._df:
            return g
        df = np.column_stack(self._df)
        gamma = np.linalg.lstsq(df, f.ravel(), rcond=self.options.lstsq_rcond)[0]
        return g - (np.column_stack(self._dg) @ gamma).reshape(g.shape)
