"""Self-contact of a thin sheet: its triangles never pass through each other.

A thin sheet (:mod:`foldcore.sheet`) has no thickness, so Origami Simulator's
model lets its facets pass through each other where the targets ask for it (a
crease folded past 180°, a layer pushed through another). With contact, IPC's
barrier (Li et al., "Incremental Potential Contact", 2020, through ``ipctk``)
acts between every two triangles, edges and vertices that share no vertex,
closer than d̂: κ Σ b(d) joins the sheet's energy, its gradient and its
PSD-projected Hessian join Newton's, and every step is shortened to the share
of it that continuous collision detection finds free (Tight-Inclusion CCD,
conservative: additive CCD let a step cross on Origami Simulator's
``rose.svg``, whose flat sheet has features 1.2e-5 of its size apart), so no
iterate ever crosses. d̂ stands for the sheet's
thickness, which a thin sheet leaves out: a share of its size, smaller where
two features of the flat sheet already lie closer (the flat sheet must start
outside the barrier).

Two triangles that share an edge are never checked against each other here
(every feature of one shares a vertex with the other); the solver keeps them
apart by refusing a step that turns their hinge through ±180°
(:class:`foldcore.sheet.SheetSolver`).

Units: the sheet's normalised frame (its bounding radius is 1); the report
gives gaps in mm.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import SimulationError
from .barrier import load_ipctk, needs_stiffening

#: d̂ of a thin sheet, a share of its bounding radius (0.1 %: 0.1 mm on a 10 cm sheet).
SHEET_ACTIVATION = 1e-3
#: d̂ is at most this share of the smallest distance of two features of the flat sheet
#: that share no vertex.
FLAT_CLEARANCE = 0.5
#: A step is checked in pieces that move no vertex more than this (a share of the
#: bounding radius): the broad phase pairs every two features whose swept boxes
#: meet, and checked whole, the long first Newton steps of Origami Simulator's
#: ``rose.svg`` (2 858 triangles) at 60 % grew the run past 7.9 GB.
MAX_SWEEP = 0.1
#: Tight-Inclusion CCD's tolerance (ipctk's default 1e-6). Looser, it still never lets
#: a step cross (its time of impact is a lower bound) but stops sooner; on Origami
#: Simulator's byu solar file at 90 % 1e-3 took the fold from 8.6 to 2.6 s and
#: on its Miura at 90 % from 1.3 to 1.1 s (1e-2: 1.7 s on both).
CCD_TOLERANCE = 1e-3


@dataclass
class SheetTouch:
    """The sheet's contacts at one set of positions.

    Attributes
    ----------
    energy : float, κ Σ b, the sheet's energy units
    gap : float, smallest distance of two features within d̂ (normalised; inf: none)
    pairs : int, primitive pairs within d̂
    """

    energy: float
    gap: float
    pairs: int
    _collisions: object = None
    _gradient: np.ndarray | None = None

    @property
    def active(self) -> bool:
        return self.pairs > 0


class SheetContact:
    """The barrier and collision-free steps of a thin sheet's triangles.

    Parameters
    ----------
    flat : (N, 3) float, the flat sheet, normalised
    triangles : (T, 3) int, the sheet's triangles
    force : float, the sheet's force scale (:func:`foldcore.sheet.solve.unit_force`):
        κ is set so that the barrier pushes with about this force at half of d̂

    Raises
    ------
    SimulationError
        Where two features that share no vertex touch in the flat sheet (a cut's
        two sides): no d̂ keeps the flat sheet outside the barrier; where ipctk is
        not installed.
    """

    def __init__(self, flat: np.ndarray, triangles: np.ndarray, force: float):
        try:
            ipctk = load_ipctk()
        except ImportError:
            raise SimulationError("contact needs the ipctk package, which is not "
                                  "installed (pip install 'foldcore[contact]')") from None
        faces = np.ascontiguousarray(triangles, dtype=np.int32)
        self.mesh = ipctk.CollisionMesh(np.asfortranarray(flat, dtype=float),
                                        ipctk.edges(faces), faces)
        apart = self._flat_distance(flat)
        if not apart > 0.0:
            raise SimulationError(
                "contact needs the flat sheet's triangles apart, and here two of them "
                "that share no vertex touch (the two sides of a cut or slit, or vertices "
                "drawn on top of each other): fold it without contact")
        self.dhat = min(SHEET_ACTIVATION, FLAT_CLEARANCE * apart)
        self.kappa = float(force) / self.dhat
        self._kappa_start, self._last_gap = self.kappa, np.inf
        self._ccd = ipctk.TightInclusionCCD(tolerance=CCD_TOLERANCE)
        self._potential = ipctk.BarrierPotential(self.dhat, self.kappa)

    def _flat_distance(self, flat: np.ndarray) -> float:
        """Smallest distance of two features of the flat sheet that share no vertex
        (within ``SHEET_ACTIVATION``; that share where none is closer)."""
        ipctk = load_ipctk()
        collisions = ipctk.NormalCollisions()
        x = np.asfortranarray(flat, dtype=float)
        collisions.build(self.mesh, x, SHEET_ACTIVATION)
        if not len(collisions):
            return SHEET_ACTIVATION / FLAT_CLEARANCE
        return float(np.sqrt(collisions.compute_minimum_distance(self.mesh, x)))

    def touch(self, x: np.ndarray) -> SheetTouch:
        """The contacts at positions x (N, 3), normalised."""
        ipctk = load_ipctk()
        x = np.asfortranarray(x)
        collisions = ipctk.NormalCollisions()
        collisions.build(self.mesh, x, self.dhat)
        if not len(collisions):
            return SheetTouch(0.0, np.inf, 0)
        gap = float(np.sqrt(collisions.compute_minimum_distance(self.mesh, x)))
        return SheetTouch(float(self._potential(collisions, self.mesh, x)), gap,
                          len(collisions), collisions)

    @property
    def stiffening(self) -> float:
        """κ relative to its start (:meth:`stiffen`)."""
        return self.kappa / self._kappa_start

    def gradient(self, touch: SheetTouch, x: np.ndarray) -> np.ndarray:
        """(3N,) ∂(κ Σ b)/∂x at the touch's positions x (kept with the touch)."""
        if not touch.active:
            return np.zeros(x.size)
        if touch._gradient is None:
            touch._gradient = self._potential.gradient(touch._collisions, self.mesh,
                                                       np.asfortranarray(x))
        return touch._gradient

    def hessian(self, touch: SheetTouch, x: np.ndarray) -> sp.csc_matrix | None:
        """(3N, 3N) PSD-projected ∂²(κ Σ b)/∂x² (each term's block clamped), or None
        where nothing touches."""
        if not touch.active:
            return None
        ipctk = load_ipctk()
        return sp.csc_matrix(self._potential.hessian(
            touch._collisions, self.mesh, np.asfortranarray(x),
            ipctk.PSDProjectionMethod.CLAMP))

    def free_share(self, x0: np.ndarray, x1: np.ndarray) -> float:
        """The largest share t ∈ [0, 1] of the straight-line step x0 → x1 that no two
        triangles cross on (Tight-Inclusion CCD, with its conservative margin),
        checked in pieces that move no vertex more than ``MAX_SWEEP``."""
        ipctk, d = load_ipctk(), x1 - x0
        reach = float(np.abs(d).max()) if d.size else 0.0
        pieces = max(1, int(np.ceil(reach / MAX_SWEEP)))
        for k in range(pieces):
            a, b = k / pieces, (k + 1) / pieces
            start = x0 + a * d if k else x0
            end = x1 if k == pieces - 1 else x0 + b * d
            t = float(ipctk.compute_collision_free_stepsize(
                self.mesh, np.asfortranarray(start), np.asfortranarray(end),
                narrow_phase_ccd=self._ccd))
            if t < 1.0:
                return a + t * (b - a)
        return 1.0

    def stiffen(self, touch: SheetTouch) -> bool:
        """IPC's adaptive stiffness: κ doubles where the smallest gap is below
        ``TIGHT_GAP`` × d̂ and shrinking (up to ``MAX_STIFFENING`` × its start); True
        when it changed (energies taken before are stale)."""
        last, self._last_gap = self._last_gap, touch.gap
        if not needs_stiffening(touch.gap, last, self.dhat, self.kappa, self._kappa_start):
            return False
        self.kappa *= 2.0
        self._potential = load_ipctk().BarrierPotential(self.dhat, self.kappa)
        return True

    def node_forces(self, touch: SheetTouch, x: np.ndarray) -> np.ndarray:
        """(N,) length of the contact force on each node."""
        return np.linalg.norm(self.gradient(touch, x).reshape(-1, 3), axis=1)
