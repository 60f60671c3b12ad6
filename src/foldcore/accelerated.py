"""Accelerated local/global strategies: safeguarded Anderson and K-preconditioned L-BFGS.

Both drive the paper's own local step (:meth:`Simulation.local_step`: project
every element at x, gather b(x)) and its prefactored K; they only choose the
next x differently. With the projections held fixed the energy is the
quadratic E(x) = tr(xᵀKx) − 2 tr(xᵀb) + const, so

* ∇E(x) = 2 (K x − b(x)), and the paper's step G(x) = K⁻¹ b(x) is the
  K-preconditioned gradient step x − ½ K⁻¹ ∇E of unit length;
* ``anderson`` (Walker & Ni 2011; Peng et al. 2018, "Anderson acceleration for
  geometry optimization and physics simulation") extrapolates the fixed-point
  map G from its last ``memory`` residuals f = G(x) − x, and keeps the
  accelerated point only if its energy is below the previous one — else it
  falls back to the plain step from the last accepted point and forgets;
* ``lbfgs`` (Liu, Bouaziz & Kavan 2017, "Quasi-Newton methods for real-time
  simulation of hyperelastic materials") runs L-BFGS with K as the initial
  Hessian (one K solve per iteration in the two-loop recursion) and an Armijo
  backtracking line search on E; when the search fails it takes the plain
  step and forgets.

A change of K (stops closing, pins decaying) or of the targets (new fold
angles, a moved position target: b(x) changes, K does not) makes the history
stale: both forget it (:meth:`restart`, called by the Simulation). The passive hinges' Eq. 9 targets depend on x in a way no energy
derives from, so E is only approximately a potential of the map; the
safeguards are what keep the iteration monotone where it can be.
Positions are (N, 3) mm; the three coordinates share K, so inner products
run over all 3N entries.
"""
from __future__ import annotations

from collections import deque

import numpy as np

ANDERSON_MEMORY = 5  # residuals kept (Peng et al. use 5–6)
LBFGS_MEMORY = 8  # (s, y) pairs kept
ARMIJO = 1e-4  # sufficient-decrease constant of the line search
BACKTRACKS = 4  # halvings before the line search gives up
LSTSQ_RCOND = 1e-10  # relative cut-off of the Anderson least-squares solve


class _Strategy:
    """Common bookkeeping: the simulation's positions, local step and K version."""

    def __init__(self, sim):
        self.sim = sim
        self.x = sim.x
        self.rejected = 0  # accelerated points refused (Anderson) / failed line searches (L-BFGS)
        self._version = sim.system.version
        self._forget()

    def restart(self, x: np.ndarray) -> None:
        """Continue from positions ``x`` (N, 3) mm with an empty history."""
        self.x = x
        self._forget()

    def _forget(self) -> None:
        """Drop the history (each strategy knows its own)."""
        raise NotImplementedError

    def _k_changed(self) -> bool:
        version = self.sim.system.version
        changed, self._version = version != self._version, version
        return changed


class AndersonSolver(_Strategy):
    """Safeguarded type-II Anderson acceleration of x ← G(x) = K⁻¹ b(x).

    ``step()`` returns (energy at the point used, largest |G(x) − x| in mm).
    """

    def __init__(self, sim, memory: int = ANDERSON_MEMORY):
        self.memory = int(memory)
        super().__init__(sim)

    def _forget(self) -> None:
        self._dg = deque(maxlen=self.memory)
        self._df = deque(maxlen=self.memory)
        self._prev = None  # (g, f) of the previous iteration
        self._last = None  # (energy, G(x)) of the last accepted point

    def step(self) -> tuple[float, float]:
        sim = self.sim
        energy, rhs = sim.local_step(self.x)
        changed = self._k_changed()
        if self._last is not None and not changed and not energy <= self._last[0]:
            self.rejected += 1  # accelerated point raised E: plain step from the last one
            self.x = self._last[1]
            self._forget()
            energy, rhs = sim.local_step(self.x)
            changed = self._k_changed()
        if changed:
            self._forget()
        g = sim.global_step(rhs)
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
        gamma = np.linalg.lstsq(df, f.ravel(), rcond=LSTSQ_RCOND)[0]
        return g - (np.column_stack(self._dg) @ gamma).reshape(g.shape)


class LbfgsSolver(_Strategy):
    """L-BFGS on E with K⁻¹ as initial inverse Hessian and Armijo backtracking.

    ``step()`` returns (energy at the start point, largest move in mm).
    """

    def __init__(self, sim, memory: int = LBFGS_MEMORY):
        self.memory = int(memory)
        super().__init__(sim)

    def _forget(self) -> None:
        self._pairs = deque(maxlen=self.memory)
        self._at = None  # (energy, ½∇E) already evaluated at self.x

    def _evaluate(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        energy, rhs = self.sim.local_step(x)
        return energy, self.sim.system.apply(x) - rhs  # ½∇E

    def step(self) -> tuple[float, float]:
        if self._at is None or self._k_changed():
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
        if x_new is None:  # no sufficient decrease: the plain step, unchecked
            self.rejected += 1
            self._pairs.clear()
            x_new = self.x + self._direction(grad)
            at_new = self._evaluate(x_new)
        s, y = x_new - self.x, at_new[1] - grad
        if float(np.vdot(s, y)) > 1e-12 * float(np.vdot(s, s)) * self.sim.system.reference_weight:
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
        r = self.sim.global_step(q)
        for (s, y, rho), a in zip(self._pairs, reversed(alphas)):
            b = rho * float(np.vdot(y, r))
            r = r + (a - b) * s
        return r

    def _line_search(self, energy, slope, direction):
        """Armijo backtracking from step 1; (x, (energy, ½∇E)) or (None, None)."""
        step = 1.0
        for _ in range(BACKTRACKS + 1):
            x = self.x + step * direction
            at = self._evaluate(x)
            if at[0] <= energy + 2.0 * ARMIJO * step * slope:
                return x, at
            step *= 0.5
        return None, None
