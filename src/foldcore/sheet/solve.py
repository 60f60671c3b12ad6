"""The static equilibrium of a :class:`~.build.Sheet` at a fold percent, by Newton's method.

Origami Simulator reaches its shape by damped dynamics, thousands of explicit
steps; the shape it settles to is a minimum of the sheet's energy, which
Newton's method reaches in tens of steps. Each step solves
``(H + μ D) Δx = −g`` (H the sparse Hessian, a CHOLMOD factor reused
symbolically from step to step; D its diagonal's magnitudes plus their
median, Marquardt's scaling), with a backtracking line search on the
energy. μ (Levenberg–Marquardt) keeps the matrix positive definite away from
the minimum (the Hessian of a hinge far from its target is indefinite) and
fixes the six rigid motions, which the energy does not see; it shrinks as
steps succeed, so the last steps are Newton's, quadratically convergent.

With ``contact`` the sheet's triangles never pass through each other: IPC's
barrier joins the energy and every step is shortened to the share of it that
no two triangles cross on (:mod:`foldcore.contact.sheet`); two triangles that
share an edge, which the barrier leaves out, by a trial refused where it turns
their hinge through ±180°.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..limits import SHEET_BUDGET
from ..linsolve import Factor, not_positive_definite
from .build import HINGE, TRIANGLE, Sheet, corner_angles, tip_heights
from .kernels import SLIVER, evaluate, fold_angles

TOLERANCE = 1e-8       # largest relative force imbalance at equilibrium (SheetSolver.residual)
MU_START, MU_FLOOR, MU_CEILING = 1e-3, 1e-9, 1e12
ARMIJO, HALVINGS = 1e-4, 40
ROUNDOFF = 1e-13  # energy changes below this share of the energy are rounding


@dataclass
class SheetFold:
    """A settled (or not) thin sheet.

    Attributes
    ----------
    positions : (N, 3) float, mm
    fold_angles_deg : (E,) float, each pattern edge's fold angle, degrees,
        valley > 0; NaN on the boundary
    target_angles_deg : (E,) float, each crease's target at the fold percent,
        degrees; NaN where no spring drives it (passive, boundary)
    hinge_angles : (H,) float, radians, every hinge of the sheet (facets included)
    iterations : int, Newton steps taken
    converged : bool, the largest force fell below the tolerance
    reason : str, ``"converged"``, ``"stalled"`` (no step lowers the energy),
        ``"budget"``, ``"callback"`` or ``"interrupted"``
    residual : float, the largest relative force imbalance at a node at the end
        (:attr:`SheetSolver.residual`)
    energy : float, normalised units
    timings_s : dict, seconds: ``solve`` (the Newton steps); the caller may add
        ``setup`` and ``total``
    sliver_corners : int, triangle corners closed below
        :data:`~.kernels.SLIVER` of their rest angle at the end: held open by the
        sliver barrier, where the facet would otherwise collapse
    contact : dict or None, with self-contact: ``activation_mm`` (d̂),
        ``active_pairs`` (primitive pairs within d̂ at the end), ``smallest_gap_mm``
        (None where none is within d̂), ``stiffness`` (κ at the end, relative to its
        start); None without
    """

    positions: np.ndarray
    fold_angles_deg: np.ndarray
    target_angles_deg: np.ndarray
    hinge_angles: np.ndarray
    iterations: int
    converged: bool
    reason: str
    residual: float
    energy: float
    timings_s: dict
    sliver_corners: int = 0
    contact: dict | None = None


class Assembly:
    """Where each element's gradient and Hessian entries go in the global ones."""

    def __init__(self, sheet: Sheet):
        n = 3 * len(sheet.flat)
        sizes = sheet.sizes
        dofs = np.full((len(sizes), 12), -1, dtype=np.int64)
        for a in range(4):
            used = sizes > a
            for c in range(3):
                dofs[used, 3 * a + c] = 3 * sheet.nodes[used, a] + c
        self.n = n
        used = np.arange(4)[None, :] < sizes[:, None]
        self.node_take = np.flatnonzero(used.ravel())
        self.node_rows = sheet.nodes[used]
        self.gradient_rows = dofs[dofs >= 0]
        self.gradient_take = np.flatnonzero((dofs >= 0).ravel())
        pair = (dofs[:, :, None] >= 0) & (dofs[:, None, :] >= 0)
        rows = np.broadcast_to(dofs[:, :, None], pair.shape)[pair]
        cols = np.broadcast_to(dofs[:, None, :], pair.shape)[pair]
        self.hessian_take = np.flatnonzero(pair.ravel())
        keys, self.slot = np.unique(cols * n + rows, return_inverse=True)
        self.indices = keys % n
        self.indptr = np.searchsorted(keys // n, np.arange(n + 1))
        self.diagonal = np.flatnonzero(self.indices == np.repeat(np.arange(n),
                                                                 np.diff(self.indptr)))

    def gradient(self, element_gradients: np.ndarray) -> np.ndarray:
        """(3N,) global gradient of (M, 12) element gradients."""
        values = element_gradients.ravel()[self.gradient_take]
        return np.bincount(self.gradient_rows, weights=values, minlength=self.n)

    def node_force_sums(self, element_gradients: np.ndarray) -> np.ndarray:
        """(N,) Σ over elements of the length of each one's force on the node."""
        per_node = np.linalg.norm(element_gradients.reshape(len(element_gradients), 4, 3),
                                  axis=2).ravel()
        return np.bincount(self.node_rows, weights=per_node[self.node_take],
                           minlength=self.n // 3)

    def hessian_values(self, element_hessians: np.ndarray) -> np.ndarray:
        """CSC data of the global Hessian of (M, 12, 12) element Hessians."""
        values = element_hessians.ravel()[self.hessian_take]
        return np.bincount(self.slot, weights=values, minlength=len(self.indices))

    def matrix(self, data: np.ndarray) -> sp.csc_matrix:
        return sp.csc_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))


class Energy:
    """The sheet's energy at one fold percent, with its gradient and Hessian."""

    def __init__(self, sheet: Sheet, fold_percent: float):
        self.sheet = sheet
        self.rest = sheet.rest.copy()
        self.is_hinge = sheet.kinds == HINGE
        self.rest[self.is_hinge, 0] *= fold_percent / 100.0
        self.reference = np.zeros(len(sheet.kinds))
        m = len(sheet.kinds)
        self.energies = np.empty(m)
        self.gradients = np.zeros((m, 12))
        self.hessians = np.zeros((m, 12, 12))

    def __call__(self, x: np.ndarray, want_hessian: bool = False) -> float:
        s = self.sheet
        evaluate(x, s.nodes, s.sizes, s.kinds, s.stiffness, self.rest, self.reference,
                 self.energies, self.gradients, self.hessians, want_hessian)
        return float(self.energies.sum())

    def hinge_angles(self, x: np.ndarray) -> np.ndarray:
        """(H,) every hinge's angle at x, radians, unwrapped near its reference."""
        hinge_nodes = self.sheet.nodes[self.is_hinge]
        out = np.empty(len(hinge_nodes))
        fold_angles(x, hinge_nodes, self.reference[self.is_hinge], out)
        return out

    def settle_references(self, x: np.ndarray) -> None:
        """Unwrap every hinge's angle from here on near its angle at x."""
        self.reference[self.is_hinge] = self.hinge_angles(x)


def fold_sheet(sheet: Sheet, fold_percent: float = 100.0, start: np.ndarray | None = None,
               tolerance: float = TOLERANCE, max_iterations: int = SHEET_BUDGET,
               backend: str = "auto", pattern_edges: int | None = None,
               contact: bool = False) -> SheetFold:
    """Settle ``sheet`` at ``fold_percent`` (of every crease's target), from flat or
    from ``start`` (V, 3) mm, one per pattern vertex; see the module docstring and
    :class:`SheetSolver`."""
    solver = SheetSolver(sheet, fold_percent, start, backend, pattern_edges, contact)
    return solver.run(tolerance, max_iterations)


class SheetSolver:
    """Newton's method on a :class:`~.build.Sheet`'s energy, one step at a time.

    Parameters
    ----------
    sheet : Sheet
    fold_percent : float, every crease's target × this / 100
    start : (V, 3) float, mm, one per pattern vertex, optional; default the flat sheet
    backend : {"auto", "cholmod", "scipy"}, the sparse factorisation
    pattern_edges : int, optional, the pattern's edge count (``fold_angles_deg``'s
        length; default the largest edge id the sheet uses + 1)
    contact : bool, keep the triangles from passing through each other
        (:mod:`foldcore.contact.sheet`; needs ipctk); default False, Origami
        Simulator's model

    ``x`` (N, 3, normalised) and ``iterations`` hold the last accepted iterate, so
    a run stopped by Ctrl-C still gives its :meth:`result`.
    """

    def __init__(self, sheet: Sheet, fold_percent: float = 100.0,
                 start: np.ndarray | None = None, backend: str = "auto",
                 pattern_edges: int | None = None, contact: bool = False):
        self.sheet, self.backend, self.pattern_edges = sheet, backend, pattern_edges
        self.energy = Energy(sheet, fold_percent)
        self.assembly = Assembly(sheet)
        self.x = sheet.flat.copy() if start is None else sheet.from_mm(start)
        self.energy.settle_references(self.x)
        self.iterations, self.seconds = 0, 0.0
        self.unit_force = unit_force(sheet)
        self.contact = None
        if contact:
            from ..contact.sheet import SheetContact

            self.contact = SheetContact(sheet.flat, sheet.triangles, self.unit_force)
        self.touch = self._trial_touch = None  # contacts at x, at the last trial
        self._evaluate()

    def _evaluate(self) -> None:
        """Energy, gradient and the elements' Hessians (and the contacts) at x."""
        self.value = self.energy(self.x, want_hessian=True)
        self.gradient = self.assembly.gradient(self.energy.gradients)
        if self.contact is not None:
            self.touch = self.contact.touch(self.x)
            self.value += self.touch.energy
            self.gradient = self.gradient + self.contact.gradient(self.touch, self.x)

    def _through_flat(self, trial: np.ndarray) -> bool:
        """Whether a hinge turns through ±180° from x to the trial: its two facets,
        which contact never checks against each other, would pass through each
        other."""
        return bool(np.any(np.abs(self.energy.hinge_angles(trial)) >= np.pi))

    def _trial_energy(self, trial: np.ndarray) -> float:
        """The energy at a trial point (with its contacts); inf where a hinge turns
        through flat with contact on."""
        if self.contact is not None and self._through_flat(trial):
            return np.inf
        value = self.energy(trial)
        if self.contact is not None:
            self._trial_touch = self.contact.touch(trial)
            value += self._trial_touch.energy
        return value

    def _trial_force(self, trial: np.ndarray) -> float:
        """The largest gradient entry at the trial last evaluated."""
        gradient = self.assembly.gradient(self.energy.gradients)
        if self.contact is not None:
            gradient = gradient + self.contact.gradient(self._trial_touch, trial)
        return float(np.max(np.abs(gradient)))

    @property
    def residual(self) -> float:
        """The largest force imbalance at a node, relative to the forces meeting there:
        max over nodes of |Σₑ fₑ| / (Σₑ |fₑ| + F₁), fₑ each element's force on the
        node, F₁ :func:`unit_force` (so a sheet at rest, all forces zero, is judged
        against its springs' scale). A node where a sliver triangle's springs
        pull with forces of 10³ is settled when they cancel to 10⁻⁵; a node of
        ordinary triangles needs the same digits of its own forces."""
        if not len(self.gradient):
            return 0.0
        meeting = self.assembly.node_force_sums(self.energy.gradients)
        if self.contact is not None:
            meeting = meeting + self.contact.node_forces(self.touch, self.x)
        imbalance = np.linalg.norm(self.gradient.reshape(-1, 3), axis=1)
        return float(np.max(imbalance / (meeting + self.unit_force)))

    def run(self, tolerance: float = TOLERANCE, max_iterations: int = SHEET_BUDGET,
            callback=None) -> SheetFold:
        """Steps until the largest force is below ``tolerance`` (``"converged"``), no
        step lowers the energy (``"stalled"``), ``max_iterations`` steps
        (``"budget"``) or ``callback(solver)`` returns False (``"callback"``)."""
        t0 = time.perf_counter()
        mu, factor, reason = MU_START, None, "budget"
        try:
            for _ in range(max_iterations):
                if self.residual < tolerance:
                    reason = "converged"
                    break
                mu, factor, moved = self._step(mu, factor)
                if moved is None:
                    reason = "stalled"
                    break
                if callback is not None and callback(self) is False:
                    reason = "callback"
                    break
            else:
                if self.residual < tolerance:
                    reason = "converged"
        finally:
            self.seconds += time.perf_counter() - t0
        return self.result(reason)

    def _step(self, mu, factor):
        """(μ, factor, x or None): one damped Newton step, μ raised until one lowers
        the energy (None when none does)."""
        if self.contact is not None and self.contact.stiffen(self.touch):
            self._evaluate()  # κ doubled: E and its gradient anew
        data = self.assembly.hessian_values(self.energy.hessians)
        diagonal = np.abs(data[self.assembly.diagonal])
        scale = diagonal + max(float(np.median(diagonal)), 1e-300)
        extra = None if self.contact is None else self.contact.hessian(self.touch, self.x)
        while True:
            step, factor, mu = _regularised_step(self.assembly, data, self.gradient, mu, scale,
                                                 factor, self.backend, extra)
            if step is None:
                return mu, factor, None
            share = 1.0 if self.contact is None else \
                self.contact.free_share(self.x, self.x + step.reshape(-1, 3))
            moved, value, full = _line_search(self._trial_energy, self._trial_force, self.x,
                                              self.value, self.gradient, step, share)
            if moved is not None:
                break
            mu *= 10.0
            if mu >= MU_CEILING:
                return mu, factor, None
        self.x, self.iterations = moved, self.iterations + 1
        self.energy.settle_references(self.x)
        self._evaluate()
        return (max(mu / 3.0, MU_FLOOR) if full else min(mu * 4.0, MU_CEILING)), factor, moved

    def result(self, reason: str) -> SheetFold:
        """The current iterate as a :class:`SheetFold` ending for ``reason``."""
        fold = _fold(self.sheet, self.energy, self.x, self.iterations, reason, self.residual,
                     self.value, self.seconds, self.pattern_edges)
        if self.contact is not None:
            fold.contact = self._contact_report()
        return fold

    def _contact_report(self) -> dict:
        """:attr:`SheetFold.contact` at x."""
        radius, touch, c = self.sheet.radius, self.touch, self.contact
        return {"activation_mm": c.dhat * radius, "active_pairs": int(touch.pairs),
                "smallest_gap_mm": touch.gap * radius if touch.active else None,
                "stiffness": c.stiffening}


def unit_force(sheet: Sheet) -> float:
    """The force scale of the sheet's springs: the median over its sprung hinges of
    the force a 1-radian miss puts on a hinge's tip, k / h (h the tip's height
    over the hinge in the flat sheet), normalised units; 1 without springs."""
    hinges = sheet.nodes[sheet.kinds == HINGE]
    if not len(hinges):
        return 1.0
    k = sheet.stiffness[sheet.kinds == HINGE]
    return float(np.median(k / tip_heights(sheet.flat, hinges).min(axis=1)))


def _regularised_step(assembly: Assembly, data, gradient, mu, scale, factor, backend,
                      extra=None):
    """(step, factor, μ): the solution of (H + μ·diag(scale)) Δ = −g, raising μ until the
    matrix factors; (None, factor, μ) when it never does. ``extra``: a sparse matrix
    added to H (the contacts'), whose pattern changes from step to step: the
    factor is then analysed anew and not kept."""
    while mu < MU_CEILING:
        shifted = data.copy()
        shifted[assembly.diagonal] += mu * scale
        matrix = assembly.matrix(shifted)
        if extra is not None:
            matrix, factor = (matrix + extra).tocsc(), None
        try:
            if factor is None:
                factor = Factor(matrix, backend)
            else:
                factor.refactor(matrix)
            step = -factor.solve(gradient)
            if np.all(np.isfinite(step)):
                return step, (None if extra is not None else factor), mu
        except not_positive_definite():
            factor = None
        mu *= 10.0
    return None, factor, mu


def _line_search(energy, largest_force, x, value, gradient, step, share: float = 1.0):
    """(x + t·step, its energy, t == ``share``) for the largest t = share · 2⁻ᵏ meeting
    Armijo's condition, or, where the energy's change is below its rounding
    (:data:`ROUNDOFF`), lowering the largest force instead; (None, value, False)
    when no t does. ``energy(trial)`` gives the energy at a trial,
    ``largest_force(trial)`` its largest gradient entry after that; ``share``
    the step's collision-free share (1 without contact)."""
    slope = float(gradient @ step)
    if slope >= 0.0 or share <= 0.0:
        return None, value, False
    t = share
    flat_step = step.reshape(-1, 3)
    force = float(np.max(np.abs(gradient)))
    for _ in range(HALVINGS):
        trial = x + t * flat_step
        trial_value = energy(trial)
        if trial_value <= value + ARMIJO * t * slope:
            return trial, trial_value, t == share
        if abs(trial_value - value) <= ROUNDOFF * abs(value) and \
                largest_force(trial) < force:
            return trial, trial_value, t == share  # below the energy's rounding: the forces
        t *= 0.5
    return None, value, False


def _fold(sheet: Sheet, energy: Energy, x, iterations, reason, residual, value, seconds,
          pattern_edges) -> SheetFold:
    angles = np.empty(len(sheet.hinges))
    fold_angles(x, sheet.hinges, _hinge_references(sheet, energy), angles)
    count = pattern_edges if pattern_edges is not None else int(sheet.hinge_edge.max()) + 1
    per_edge, targets = np.full(count, math.nan), np.full(count, math.nan)
    named = sheet.hinge_edge >= 0
    per_edge[sheet.hinge_edge[named]] = np.degrees(angles[named])
    driven = named & (sheet.hinge_elements >= 0)
    targets[sheet.hinge_edge[driven]] = np.degrees(
        energy.rest[sheet.hinge_elements[driven], 0])
    alias = sheet.edge_alias[:count]
    per_edge[:len(alias)], targets[:len(alias)] = per_edge[alias], targets[alias]
    return SheetFold(sheet.to_mm(x), per_edge, targets, angles, iterations,
                     reason == "converged", reason, residual, value, {"solve": seconds},
                     sliver_corners=sliver_corners(sheet, x))


def sliver_corners(sheet: Sheet, x: np.ndarray) -> int:
    """How many triangle corners of the sheet at ``x`` (N, 3) are closed below
    :data:`~.kernels.SLIVER` of their rest angle (the sliver barrier's range)."""
    triangles = sheet.kinds == TRIANGLE
    angles = corner_angles(x[sheet.nodes[triangles][:, :3]])
    return int(np.count_nonzero(angles < SLIVER * sheet.rest[triangles]))


def _hinge_references(sheet: Sheet, energy: Energy) -> np.ndarray:
    """Per hinge of the sheet, the unwrapping reference (0 for unsprung hinges)."""
    out = np.zeros(len(sheet.hinges))
    sprung = sheet.hinge_elements >= 0
    out[sprung] = energy.reference[sheet.hinge_elements[sprung]]
    return out
