"""Shared part of the accelerated local/global strategies (``anderson``, ``lbfgs``).

Both drive the paper's own local step (:meth:`Model.local_step`: project every
element at x, gather b(x)) and its prefactored K; they only choose the next x
differently. With the projections held fixed the energy is the quadratic
E(x) = tr(xᵀKx) − 2 tr(xᵀb) + const, so ∇E(x) = 2 (K x − b(x)), and the
paper's step G(x) = K⁻¹ b(x) is the K-preconditioned gradient step
x − ½ K⁻¹ ∇E of unit length.

A change of K (stops closing, pins decaying) or of the targets makes a
history stale: both forget it (:meth:`Strategy.restart`). The passive
hinges' Eq. 9 targets depend on x in a way no energy derives from, so E is
only approximately a potential of the map; the safeguards keep the iteration
monotone where it can be. Positions are (N, 3) mm; the three coordinates
share K, so inner products run over all 3N entries.
"""
from __future__ import annotations

from .base import Strategy


class Accelerated(Strategy):
    """Common bookkeeping of the accelerated maps: the positions they iterate
    from, a rejection count and the version of K their history belongs to."""

    abstract = True

    def __init__(self, model, progress, options=None):
        super().__init__(model, progress, options)
        self.memory = int(self.options.memory)
        self.x = model.x
        self.rejected = 0  # accelerated points refused (Anderson) / failed line searches (L-BFGS)
        self._version = model.system.version
        self._forget()

    def restart(self) -> None:
        """Continue from ``model.x`` with an empty history."""
        self.x = self.model.x
        self._forget()

    def step(self) -> tuple[float, float]:
        energy, moved = self._advance()
        self.model.x = self.x
        return energy, moved

    def _advance(self) -> tuple[float, float]:
        """The strategy's own iteration on ``self.x``: (energy, largest move mm)."""
        raise NotImplementedError

    def _forget(self) -> None:
        """Drop the history (each strategy knows its own)."""
        raise NotImplementedError

    def _k_changed(self) -> bool:
        version = self.model.system.version
        changed, self._version = version != self._version, version
        return changed
