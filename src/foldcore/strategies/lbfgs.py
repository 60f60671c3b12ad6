"""``lbfgs``: L-BFGS on the paper's energy with K as the initial Hessian.

Liu, Bouaziz & Kavan 2017, "Quasi-Newton methods for real-time simulation of
hyperelastic materials": the two-loop recursion with H₀ = K⁻¹ (one K solve
per iteration) and an Armijo backtracking line search on E; when the search
fails the plain step is taken and the history forgotten. With contact
(``model.contact``) the barrier of panels no crease joins joins E and its
gradient, and every step, the line search's first and the plain one, is
shortened until the straight-line motion to it is collision-free
(:mod:`.vertex_contact`; joined panels are their hinge's to hold, as in
``newton``). Shared bookkeeping
and the energy's gradient: :mod:`.accelerated`. Where it serves and where it
does not: `docs/architecture.md#the-accelerated-maps`.
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from .accelerated import Accelerated
from .vertex_contact import VertexContact


@dataclass(frozen=True)
class LbfgsOptions:
    """Options of ``lbfgs``.

    Attributes
    ----------
    memory : int
        (s, y) pairs kept.
    armijo : float
        Sufficient-decrease constant of the line search.
    backtracks : int
        Halvings before the line search gives up (then the plain step is taken).
    """

    memory: int = 8
    armijo: float = 1e-4
    backtracks: int = 4


class Lbfgs(Accelerated):
    """L-BFGS on E with K⁻¹ as initial inverse Hessian and Armijo backtracking.

    ``step()`` returns (energy at the start point, largest move in mm).
    """

    name = "lbfgs"
    Options = LbfgsOptions
    supports_contact = True

    def __init__(self, model, progress, options=None):
        self.contact = VertexContact(model) if model.contact is not None else None
        self._touch = None  # (x, the contacts there) of the last point evaluated
        super().__init__(model, progress, options)

    def _forget(self) -> None:
        self._pairs = deque(maxlen=self.memory)
        self._at = None  # (energy, ½∇E) already evaluated at self.x

    def _evaluate(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        energy, rhs = self.model.local_step(x)
        grad = self.model.system.apply(x) - rhs  # ½∇E
        if self.contact is not None:
            touch = self.contact.state(x)
            self._touch = (x, touch)
            energy += touch.energy
            grad = grad + self.contact.gradient(touch).reshape(-1, 3)
        return energy, grad

    def _stiffened(self) -> bool:
        """IPC's adaptive κ at the current point (``ContactModel.stiffen``), on the
        contacts its evaluation found (the accepted trial's): True where κ changed
        (energies taken before are stale)."""
        if self.contact is None:
            return False
        kept = self._touch is not None and self._touch[0] is self.x
        touch = self._touch[1] if kept else self.contact.state(self.x)
        return self.contact.contact.stiffen(touch)

    def _free_share(self, direction: np.ndarray) -> float:
        """The share of the step x → x + direction whose straight-line motion brings no
        two panels (or a panel and an obstacle) into contact (1 without contact)."""
        if self.contact is None:
            return 1.0
        trial = self.x + direction
        free = self.contact.collision_free(self.x, trial)
        if free is trial:
            return 1.0
        return 0.0 if free is self.x else float(
            np.abs(free - self.x).max() / max(np.abs(direction).max(), 1e-300))

    def _advance(self) -> tuple[float, float]:
        if self._at is None or self._k_changed() or self._stiffened():
            self._at = self._evaluate(self.x)
            self._k_changed()
            self._pairs.clear()
        energy, grad = self._at
        direction = self._direction(grad)
        slope = float(np.vdot(grad, direction))
        if not slope < 0.0:  # not a descent direction: the plain step
            self._pairs.clear()
            direction = self._direction(grad)
            slope = float(np.vdot(grad, direction))
        x_new, at_new = self._line_search(energy, slope, direction)
        if x_new is None:  # no sufficient decrease: the plain step (its share free of contact)
            self.rejected += 1
            self._pairs.clear()
            plain = self._direction(grad)
            x_new = self.x + self._free_share(plain) * plain
            at_new = self._evaluate(x_new)
        s, y = x_new - self.x, at_new[1] - grad
        if float(np.vdot(s, y)) > 1e-12 * float(np.vdot(s, s)) * self.model.system.reference_weight:
            self._pairs.append((s, y, 1.0 / float(np.vdot(s, y))))
        moved = float(np.abs(s).max())
        self.x, self._at = x_new, at_new
        return energy, moved

    def _direction(self, grad: np.ndarray) -> np.ndarray:
        """−H grad by the two-loop recursion with H₀ = K⁻¹ (one K solve)."""
        q = -grad
        alphas = []
        for s, y, rho in reversed(self._pairs):
            a = rho * float(np.vdot(s, q))
            q = q - a * y
            alphas.append(a)
        r = self.model.global_step(q)
        for (s, y, rho), a in zip(self._pairs, reversed(alphas)):
            b = rho * float(np.vdot(y, r))
            r = r + (a - b) * s
        return r

    def _line_search(self, energy, slope, direction):
        """Armijo backtracking from step 1 (or the share of it free of contact);
        (x, (energy, ½∇E)) or (None, None)."""
        step = self._free_share(direction)
        if step == 0.0:
            return None, None
        for _ in range(self.options.backtracks + 1):
            x = self.x + step * direction
            at = self._evaluate(x)
            if at[0] <= energy + 2.0 * self.options.armijo * step * slope:
                return x, at
            step *= 0.5
        return None, None
