"""Rigid-body strategy: panels as rigid bodies, Levenberg–Marquardt on the hinge energy.

Why: the paper's local/global map moves a long panel only through its thin
hinge faces, so its iteration count grows with (panel length / thickness)²
(DESIGN.md). Here every rigid panel is a rigid body (rotation R_p, centroid
c_p; its vertices follow exactly), so a panel's rotation is one unknown of the
step whatever its length. The unknowns are

* per free panel: an incremental rotation ω_p (exponential map) and a shift t_p;
* every vertex that belongs to no panel (hinge interior lines): its position;
* per hinge sub-strip: an incremental rotation ω_e of its target;
* per *passive* sub-strip: its bend angle φ_e, bounded to the interval its
  M/V assignment, floor and max angle allow (a hard bound: the wrong branch
  is not reachable, and a small pre-bend in the assigned direction picks the
  branch at the flat bifurcation).

The energy is the paper's, E = Σ_e w_e‖C x_e − R_e T_e(φ_e)‖² (+ position
targets), with the panels' terms identically zero. Each iteration linearises
the residuals in all unknowns (Gauss–Newton), solves the damped normal
equations (Levenberg–Marquardt, Marquardt scaling), keeps the step only if E
decreases, then refits every strip's rotation exactly (Procrustes: the
paper's local step, which can only lower E).

The normal equations JᵀJ, Jᵀr are assembled strip by strip in numba
(:mod:`foldcore.rigid_normal`) on a pattern fixed per column layout, so the
factorisation reuses its symbolic analysis; J itself is never formed (the
sparse :meth:`RigidBodySolver._jacobian` remains as the tests' reference).

Units: mm, rad internally.
"""
from __future__ import annotations

import time
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from elements.bending_hinge import (FLOOR, MAX_ANGLE, SIGN, TARGET, bent_shapes, estimate_angles,
                                    shape_derivatives)
from .errors import SimulationError
from . import rigid_normal
from .linsolve import Factor
from .measure import best_rotations

SEED = 1e-2          # rad: pre-bend of a passive M/V strip that starts flat
LAMBDA_START = 1e-4  # initial Levenberg–Marquardt damping (relative to diag of JᵀJ)
LAMBDA_MIN = float(np.finfo(float).eps)  # smallest damping that still changes JᵀJ + λD
#   in floating point. A larger floor damps the sheet's softest mode: at 1e-12 a thin
#   Miura 50 × 50 ended in a linear tail, × 0.742 per step for 45 steps at ρ = 1
#   (λD ≈ 3 × its softest eigenvalue); 124 → 83 iterations.
LAMBDA_MAX = 1e12
LAMBDA_SETTLED = 1.0  # largest damping of an accepted step that may end a run
DAMPED_SHARE_MAX = 0.1  # largest share of the damping in an accepted step's predicted
#                         decrease that may end a run (RigidBodySolver.settled)
CHORD_FROM = 1e4  # a first accepted step ≤ this × the run's limit gets its distance left
#                   from the simplified correction (RigidBodySolver.distance_left)
CONTRACTION_MAX = 0.5  # largest ratio of two accepted steps' lengths from which the
#                        distance left is estimated (RigidBodySolver.distance_left)
LAMBDA_DOWN, LAMBDA_UP = 3.0, 5.0  # damping divided at most after an accepted step
#                                   (gain-ratio rule, RigidBodySolver._update_damping),
#                                   multiplied after a rejected one
ROUNDING = 64 * np.finfo(float).eps  # relative energy change that is rounding noise
BOUND_TOL = 1e-12    # rad: a bounded angle this close to its bound is on it
GEODESIC_H = 0.1     # finite-difference step of the geodesic acceleration (fraction of the step)
GEODESIC_MAX = 1.5   # acceleration kept only if |a| ≤ this × |v|
#: tail extrapolation (:meth:`RigidBodySolver._extrapolated`): two accepted velocities
#: this aligned (cosine), the later this share of the earlier (ratio range), give a
#: try of the step scaled by 1 / (1 − ratio), at most EXTRAPOLATE_MAX
EXTRAPOLATE_COS = 0.98
EXTRAPOLATE_RATIO = (0.3, 0.98)
EXTRAPOLATE_MAX = 20.0
MV_STIFFNESS = 1e3   # weight (× reference weight × W²) of the panels' M/V side rows; 0: off
MV_WALL = 1.0        # slope of an M/V row's way back past a flat fold (mv_side)
MV_SLACK = 1e-6      # rad a panel dihedral may cross to the wrong side before its row acts
#                      (flat panels cross zero by rounding; rows there would make paths
#                      depend on the last bit, e.g. on the length unit). Measured: at 1e-9
#                      the rows fired on nearly flat creases early in a fold from flat and
#                      LM crept (thin Miura 10 × 10, rigid: 120 iterations, 71 at 1e-7…3e-6;
#                      20 × 20 hybrid 214 → 99); at 1e-4 thin mode-B vertices fold mode A
#                      (tests/test_accuracy.py)


class State(NamedTuple):
    """Configuration: positions (N, 3) mm, panel rotations (P, 3, 3) and centroids
    (P, 3) mm, free vertices (F, 3) mm, strip target rotations (S, 3, 3), strip
    bend angles (S,) rad."""

    x: np.ndarray
    rot_p: np.ndarray
    c_p: np.ndarray
    y: np.ndarray
    rot_e: np.ndarray
    phi: np.ndarray


def skew(v: np.ndarray) -> np.ndarray:
    """(..., 3, 3) cross-product matrices [v]× of (..., 3) vectors."""
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def exp_so3(w: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotations exp([w]×) of (..., 3) rotation vectors (Rodrigues)."""
    angle = np.linalg.norm(w, axis=-1)[..., None, None]
    small = angle < 1e-8
    safe = np.where(small, 1.0, angle)
    a = np.where(small, 1.0 - angle ** 2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - angle ** 2 / 24.0, (1.0 - np.cos(safe)) / safe ** 2)
    k = skew(w)
    return np.eye(3) + a * k + b * (k @ k)


def log_so3(rot: np.ndarray) -> np.ndarray:
    """(..., 3) rotation vectors of (..., 3, 3) rotations (angles below π)."""
    cos = np.clip((np.trace(rot, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cos)
    axis = np.stack([rot[..., 2, 1] - rot[..., 1, 2], rot[..., 0, 2] - rot[..., 2, 0],
                     rot[..., 1, 0] - rot[..., 0, 1]], axis=-1)
    small = angle < 1e-8
    scale = np.where(small, 0.5 + angle ** 2 / 12.0, angle / (2.0 * np.sin(np.where(small, 1.0,
                                                                                      angle))))
    return axis * scale[..., None]


def mv_side(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(value, slope) of an M/V side row's shape at ``t`` (C,) rad, the panels'
    dihedral signed toward the crease's assigned side, in (−π, π].

    0 on the assigned side (t ≥ −``MV_SLACK``); t + ``MV_SLACK`` where a crease
    crosses to the other side (by up to ~90° at ``MV_WALL`` = 1); beyond, back
    to 0 at t = −π with slope ``MV_WALL``: a fold past flat costs its
    overshoot. Why the way back: −π and +π are one dihedral, a crease folded flat.
    A valley folded a hair past flat reads −π + ε, and a row there that acted
    as on a crease 180° the wrong way (√μ·(−π)) split the energy at every flat
    crease: Origami Simulator's Miura with graded arc widths folded flat (2-core
    Xeon guest, 2026-12-03, tolerance 1e-9) took
    108 coarse, 51 rigid and 19 newton steps (2.9 s) past that split, and 39
    (0.47 s) without the rows; with this shape 78 (0.65 s), the rows still
    steering the creases that start the wrong way. Why slope 1 past flat and
    not a stiff wall there: the stacked layers of a flat Miura need some
    panels a hair past flat; a graded Miura 4 × 4 (tests/test_flat_fold.py)
    stopped 13.4° short at slopes 1e6 and 1e8 and folds flat to 6e-9° at 1.
    Slope 1 still stops the chain scene's zig-zag creases at 180.006° (with
    no rows they fold on to 206°)."""
    t = np.ascontiguousarray(t, dtype=float).ravel()
    value, slope = np.empty_like(t), np.empty_like(t)
    rigid_normal.mv_side_many(t, MV_WALL, MV_SLACK, value, slope)
    return value, slope


def procrustes(current: np.ndarray, target: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations R minimising Σ‖(p − p̄) − R t‖² for centred targets.

    Parameters
    ----------
    current : (n, m, 3) current positions of each element's m vertices
    target : (n, m, 3) centred target shapes in their local frames
    """
    centred = current - current.mean(axis=1, keepdims=True)
    return best_rotations(np.einsum("nki,nkj->nij", centred, target))


class RigidBodySolver:
    """One Levenberg–Marquardt iteration per :meth:`step`, driven by a Simulation.

    Parameters
    ----------
    sim : Simulation
        Source of the mesh, the hinge parameters (targets read at every step,
        so ``set_fold_angles`` works between steps), position targets and the
        linear-solver backend. ``sim.x`` is updated in place of the paper step.
    """

    def __init__(self, sim):
        mesh = sim.mesh
        extra = set(mesh.groups) - {"rigid_panel", "bending_hinge"}
        if mesh.panel_group != "rigid_panel" or extra:
            raise SimulationError("solver 'rigid' needs rigid panels and bending hinges only "
                                  f"(mesh has {sorted(mesh.groups)}); use solver='paper'")
        self.sim = sim
        self.backend = sim.system.backend
        self._weights_read = None  # the Simulation's strip-weight array sqrt_w was taken from
        self._init_panels(mesh.groups["rigid_panel"], mesh.n_vertices, sim.x)
        self._init_strips(sim._hinges)
        self._init_mv_sides(mesh, sim.pattern)
        self.lam = LAMBDA_START
        self.jumped = self.follows_jump = False  # the last / the step before: extrapolated
        self.accepted, self.energy, self.decrease = False, np.inf, np.inf  # the last step's
        self.energy_after = np.inf  # E after the last step (the kept state's), mm⁵
        self.gain_ratio, self.damped_share = np.nan, 0.0  # the last step's (step)
        self.contraction = np.nan  # its length over the last accepted one's, this run
        self._previous_velocity = None  # the last accepted plain step's velocity
        self.slow_ratio = 0.0  # the largest ratio an extrapolation used this run (0: none)
        self._accepted_move = None  # mm, the run's last accepted step, if the last step
        self._chains = None  # place_interiors' batches, built on first use
        self.distance = np.inf  # mm, estimated distance left after the last step
        self.energy_scale = 0.0
        self._passive = None
        self._pinned = False
        self._ends = []  # the states two earlier runs ended in (a path's predictor)
        self._fitted = False
        self.solve_time = 0.0  # s spent factorising and solving (the rest is assembly)
        self._normal_factor = None  # of JᵀJ + λD, from the first step on a layout
        self._columns_ready = False  # the unknowns' columns (_columns)
        self.x = self._positions(self.rot_p, self.c_p, self.y)

    # ------------------------------------------------------------------ setup
    def _init_panels(self, panels, n, x) -> None:
        owner = np.full(n, -1, dtype=np.int64)
        for p in range(len(panels)):
            ids = panels.indices[panels.slots(p)]
            if (owner[ids] >= 0).any():
                raise SimulationError(f"solver 'rigid': panel {p} shares vertices with panel "
                                      f"{owner[ids].max()}; panels must be separate bodies")
            owner[ids] = p
        self.owner = owner
        self.on_panel = np.flatnonzero(owner >= 0)
        self.panel_of = owner[self.on_panel]  # (N,) the panel of each panel vertex
        self.free = np.flatnonzero(owner < 0)
        rest = self.sim.mesh.rest_positions
        centroid = np.zeros((len(panels), 3))
        np.add.at(centroid, owner[self.on_panel], rest[self.on_panel])
        centroid /= np.bincount(owner[self.on_panel], minlength=len(panels))[:, None]
        self.body = rest[self.on_panel] - centroid[owner[self.on_panel]]
        self.rot_p, self.c_p = self._fit_panels(panels, x)
        self.joint_weight = np.ones(len(self.on_panel))  # set by _init_strips
        self.y = x[self.free].copy()

    def _fit_panels(self, panels, x):
        """Rotations (P, 3, 3) and centroids (P, 3) of the panels' best rigid fit to x.

        Batched by panel size. :func:`foldcore.measure.element_rotations` (and
        the panels' own ``rest`` as body coordinates) give the same fit up to
        rounding, but the LM accept test compares energies at rounding level
        near convergence, and the thin vertex's iteration count moved with
        them (measured 25 → 37), so the measured arithmetic is kept.
        """
        sizes = np.diff(panels.indptr)
        rot, c = np.zeros((len(panels), 3, 3)), np.zeros((len(panels), 3))
        for m in np.unique(sizes):
            sel = np.flatnonzero(sizes == m)
            ids = np.stack([panels.indices[panels.slots(p)] for p in sel])
            body = self.body[np.searchsorted(self.on_panel, ids)]
            rot[sel] = procrustes(x[ids], body)
            c[sel] = x[ids].mean(axis=1)
        return rot, c

    def _init_strips(self, hinges) -> None:
        if hinges is None:
            raise SimulationError("solver 'rigid': the mesh has no hinges to fold")
        g = hinges.group
        if not np.all(np.diff(g.indptr) == 8):
            raise SimulationError("solver 'rigid': every hinge sub-strip must have 8 vertices")
        self.hinges = hinges
        slots = np.bincount(g.indices, minlength=self.sim.mesh.n_vertices)[self.on_panel]
        p = self.owner[self.on_panel]
        jointless = np.bincount(p, weights=slots, minlength=len(self.rot_p)) == 0
        self.joint_weight = np.where(jointless[p], 1.0, slots.astype(float))
        self.ids = g.indices.reshape(-1, 8)
        self._sync_weights()
        s = len(g)
        self.phi = np.zeros(s)
        self.k_strip = self.sim.mesh.subdivisions[g.source].astype(float)
        self.shape = np.zeros((8 * s, 3))
        self.d_shape = np.zeros((8 * s, 3))
        self._shape_scratch = np.zeros((8 * s, 3))
        self._shape_phi, self._d_shape_current = self.phi.copy(), False
        self._init_carriers(self.sim.mesh, self.sim.pattern)
        self.rot_e = np.tile(np.eye(3), (s, 1, 1))

    def _sync_weights(self) -> None:
        """Strip weights (√w) from the Simulation's current
        weights (actuation and stops change them: ``System.set_weights`` stores a
        new array, so a different array is the sign)."""
        weights = self.sim.system.weights[self.sim._hinge_index]
        if weights is self._weights_read:
            return
        self._weights_read = weights
        self.sqrt_w = np.sqrt(weights)

    def _init_carriers(self, mesh, pattern) -> None:
        """Blend weights that carry each free (hinge-interior) vertex with its two panels.

        A free vertex at fraction f of its hinge's width (0 at the left panel,
        1 at the right) follows (1 − f)·(left panel's motion) + f·(right
        panel's) plus its own displacement, so a large panel rotation moves
        the hinge with it instead of along a straight line (an O(L ω²) error
        on long creases that would throttle every step).
        """
        rest = mesh.rest_positions
        free_index = np.full(mesh.n_vertices, -1, dtype=np.int64)
        free_index[self.free] = np.arange(len(self.free))
        vert, panel, weight = [], [], []
        self.strip_side = np.zeros((len(self.ids), 2), dtype=np.int64)  # crease's panels
        side_weight = np.zeros((len(self.free), 2))  # each free vertex's blend weights
        for e, strips in mesh.strips_of_crease.items():
            ids = np.unique(self.ids[strips])
            side = [mesh.panel_of_face[f] for f in pattern.edge_faces[e]]
            self.strip_side[strips] = side
            inner = ids[free_index[ids] >= 0]
            dist = [np.linalg.norm(rest[inner, None, :2] - rest[None, ids[self.owner[ids] == p], :2],
                                   axis=2).min(axis=1) for p in side]
            f = dist[0] / (dist[0] + dist[1])
            vert += [inner, inner]
            panel += [np.full(len(inner), side[0]), np.full(len(inner), side[1])]
            weight += [1.0 - f, f]
            side_weight[free_index[inner]] = np.column_stack([1.0 - f, f])
        self.carry_vert = np.concatenate(vert) if vert else np.zeros(0, dtype=np.int64)
        self.carry_panel = np.concatenate(panel) if panel else np.zeros(0, dtype=np.int64)
        self.carry_weight = np.concatenate(weight) if weight else np.zeros(0)
        self.carry_slot = free_index[self.carry_vert]
        self._init_strip_motion(free_index, side_weight)

    def _init_strip_motion(self, free_index, side_weight) -> None:
        """Per strip vertex, the weight of each of its crease's two panels' motions
        (S, 8, 2) and its hinge-interior index (S, 8) (−1 on a panel): what
        :mod:`foldcore.rigid_normal` builds the strip rows from."""
        owner = self.owner[self.ids]
        alpha = np.stack([(owner == self.strip_side[:, b, None]).astype(float)
                          for b in range(2)], axis=2)
        stray = (owner >= 0) & (alpha.sum(axis=2) == 0)
        if stray.any():
            raise SimulationError(f"solver 'rigid': hinge sub-strip "
                                  f"{int(np.flatnonzero(stray.any(axis=1))[0])} touches a "
                                  "panel that is not one of its crease's two")
        self.strip_free = free_index[self.ids]
        inner = self.strip_free >= 0
        alpha[inner] = side_weight[self.strip_free[inner]]
        self.strip_alpha = alpha
        self._crease_rounds()

    def _crease_rounds(self) -> None:
        """Creases (strips grouped by source crease, CSR) in rounds of creases that share
        no panel (greedy colouring), so each round assembles in parallel."""
        source = self.hinges.group.source
        order = np.argsort(source, kind="stable")
        creases, first = np.unique(source[order], return_index=True)
        sides = self.strip_side[order[first]]
        used: dict = {}  # panel → colours of its creases so far
        colour = np.zeros(len(creases), dtype=np.int64)
        for c, (left, right) in enumerate(sides):
            taken = used.setdefault(left, set()) | used.setdefault(right, set())
            colour[c] = next(k for k in range(len(taken) + 1) if k not in taken)
            used[left].add(colour[c])
            used[right].add(colour[c])
        by_colour = np.argsort(colour, kind="stable")
        bounds = np.append(first, len(order))
        sizes = np.diff(bounds)[by_colour]
        self.crease_ptr = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        self.crease_strips = np.concatenate([order[bounds[c]:bounds[c + 1]] for c in by_colour]) \
            .astype(np.int64)
        self.rounds = np.searchsorted(colour[by_colour], np.arange(colour.max() + 2)) \
            .astype(np.int64)

    def _init_mv_sides(self, mesh, pattern) -> None:
        """M/V creases whose panels' dihedral is held on the assigned side (one-sided rows).

        The strips' angle bounds alone let the panels cross to the other side
        (the strips then strain): a thin degree-4 vertex assigned mode B folded
        mode A's way (measured). A row √μ·g(s·ρ) per M/V crease, ρ the panels'
        dihedral, s = +1 valley / −1 mountain, g = min(0, · + ``MV_SLACK``) near
        the assigned side and back to 0 at a flat fold (:func:`mv_side`), makes that
        cost; with ``passive_floor_deg`` > 0 (a pre-bend on the assigned side)
        the vertex then folds its assigned mode.
        """
        kinds = pattern.assignments
        crease = np.flatnonzero(((kinds == "M") | (kinds == "V"))
                                & (pattern.edge_faces[:, 1] >= 0))
        if MV_STIFFNESS <= 0:
            crease = crease[:0]
        self.mv_left = mesh.panel_of_face[pattern.edge_faces[crease, 0]]
        self.mv_right = mesh.panel_of_face[pattern.edge_faces[crease, 1]]
        self.mv_sign = np.where(kinds[crease] == "V", 1.0, -1.0)
        d2 = pattern.vertices[pattern.edges[crease, 1]] - pattern.vertices[pattern.edges[crease, 0]]
        self.mv_axis = np.column_stack([d2, np.zeros(len(crease))])
        self.mv_sqrt = np.sqrt(MV_STIFFNESS * self.sim.system.reference_weight) \
            * mesh.hinge_width[crease]

    def _mv_terms(self, rot_p):
        """(residual rows (C,), ∂ρ/∂ω of the left panel (C, 3)) of the M/V side rows
        (:func:`foldcore.rigid_normal.mv_terms`)."""
        value, grad = np.empty(len(self.mv_sign)), np.empty((len(self.mv_sign), 3))
        rigid_normal.mv_terms(rot_p, self.mv_left, self.mv_right, self.mv_axis, self.mv_sign,
                              self.mv_sqrt, MV_WALL, MV_SLACK, value, grad)
        return value, grad

    def _mv_rows(self, rot_p, n_columns: int):
        """(C, n_unknowns) Jacobian of the M/V rows: +∂ on the left panel's rotation
        columns, − on the right's (∂ρ/∂ω_L = d̂ = −∂ρ/∂ω_R, checked by differences)."""
        _, grad = self._mv_terms(rot_p)
        wrong = grad.any(axis=1)  # the other rows are 0 (no M/V crease on its wrong side: all)
        if not wrong.any():
            return sp.csr_matrix((len(self.mv_sign), n_columns))
        rows, cols, vals = [], [], []
        for panels, sign in ((self.mv_left, 1.0), (self.mv_right, -1.0)):
            col = self.panel_col[panels]
            moving = np.flatnonzero((col >= 0) & wrong)
            for k in range(3):
                rows.append(moving)
                cols.append(col[moving] + k)
                vals.append(sign * grad[moving, k])
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(len(self.mv_sign), n_columns))

    def _strip_position_jacobian(self):
        """Constant (24 S, 3 N) Jacobian of the strip residuals w.r.t. positions: √w·C ⊗ I₃."""
        s = len(self.ids)
        e, k, j, d = np.meshgrid(np.arange(s), np.arange(8), np.arange(8), np.arange(3),
                                 indexing="ij")
        rows = e * 24 + k * 3 + d
        cols = 3 * self.ids[e, j] + d
        vals = self.sqrt_w[e] * ((k == j) - 1.0 / 8.0)
        n = self.sim.mesh.n_vertices
        return sp.csr_matrix((vals.ravel(), (rows.ravel(), cols.ravel())), shape=(24 * s, 3 * n))

    def _layout(self, passive: np.ndarray) -> None:
        """The passive creases' angle unknowns; the column blocks of the unknowns
        (:meth:`_columns`) follow at the next linearisation.

        Why not the columns at once: a coarse twin hands its state to the mesh's
        engine (:meth:`adopt` reads the targets), after which the run may end
        without a step of it (:meth:`strips_placed_within`); the layout and the
        normal-matrix pattern of a thin Miura 50 × 50 (255 093 unknowns) were
        the run's peak memory there (RSS 386 → 490 MB)."""
        self.passive_ids = np.flatnonzero(passive)
        src = self.hinges.group.source[self.passive_ids]
        _, self.passive_of = np.unique(src, return_inverse=True)
        self.n_folds = int(self.passive_of.max()) + 1 if len(src) else 0
        self._passive = passive.copy()
        self._pinned = bool(self.sim._position_targets)
        self._columns_ready = False

    def _columns(self) -> None:
        """Column blocks of the unknowns: panels, free vertices, strip rotations, angles;
        the Jacobian maps and the normal matrix's pattern. Built once per layout."""
        if self._columns_ready:
            return
        n_panels = len(self.rot_p)
        fixed = -1
        if not self.sim._position_targets:  # no pins: one panel holds the rigid motion
            fixed = int(self.owner[0]) if self.owner[0] >= 0 else 0
        self.panel_col = np.full(n_panels, -1, dtype=np.int64)
        moving = np.flatnonzero(np.arange(n_panels) != fixed)
        self.panel_col[moving] = 6 * np.arange(len(moving))
        self.free_col = 6 * len(moving) + 3 * np.arange(len(self.free))
        self.rot_col = self.free_col[-1] + 3 if len(self.free) else 6 * len(moving)
        self.phi_col = self.rot_col + 3 * len(self.ids)
        self.n_unknowns = self.phi_col + self.n_folds
        self._map_pattern()
        self._strip_layout()
        self._normal_pattern()
        self._columns_ready = True

    def _strip_layout(self) -> None:
        """Local columns of each strip for :mod:`foldcore.rigid_normal`: its crease's
        moving panels (6 each), its hinge-interior vertices (3 each), its rotation
        (3), its crease's angle (1, passive creases only)."""
        s = len(self.ids)
        pcol = self.panel_col[self.strip_side]  # (S, 2)
        moving = pcol >= 0
        # blocks in increasing global column (rigid_normal's scatter walks columns in order)
        right_first = moving.all(axis=1) & (pcol[:, 1] < pcol[:, 0])
        first = np.where(right_first, 6 * moving[:, 1], 0)
        self.off_panel = np.where(moving, np.column_stack([first, 6 * (moving[:, 0] & ~right_first)]),
                                  -1).astype(np.int64)
        base = 6 * moving.sum(axis=1)
        inner = self.strip_free >= 0
        key = np.where(inner, self.strip_free, -1)
        rank = (inner[:, None, :] & (key[:, None, :] < key[:, :, None])).sum(axis=2)
        self.own_off = np.where(inner, base[:, None] + 3 * rank, -1).astype(np.int64)
        self.off_w = (base + 3 * inner.sum(axis=1)).astype(np.int64)
        fold_of = np.full(s, -1, dtype=np.int64)
        fold_of[self.passive_ids] = self.passive_of
        self.off_phi = np.where(fold_of >= 0, self.off_w + 3, -1).astype(np.int64)
        self.n_loc = (self.off_w + 3 + (fold_of >= 0)).astype(np.int64)
        cols = np.full((s, rigid_normal.MAX_LOCAL), -1, dtype=np.int64)
        kind = np.full((s, rigid_normal.MAX_LOCAL), -1, dtype=np.int64)
        rows = np.arange(s)
        for b in range(2):
            on = moving[:, b]
            for d in range(6):
                cols[rows[on], self.off_panel[on, b] + d] = pcol[on, b] + d
                if d >= 3:
                    kind[rows[on], self.off_panel[on, b] + d] = rigid_normal.TRANSLATION + d - 3
        strip, k = np.nonzero(inner)
        for d in range(3):
            cols[strip, self.own_off[strip, k] + d] = self.free_col[self.strip_free[strip, k]] + d
            kind[strip, self.own_off[strip, k] + d] = rigid_normal.TRANSLATION + d
            cols[rows, self.off_w + d] = self.rot_col + 3 * rows + d
            kind[rows, self.off_w + d] = rigid_normal.ROTATION + d
        on = fold_of >= 0
        cols[rows[on], self.off_phi[on]] = self.phi_col + fold_of[on]
        self.loc_cols, self._loc_kind = cols, kind

    def _normal_pattern(self) -> None:
        """Fixed CSC pattern of JᵀJ (rigid_normal's module docstring): indptr, indices,
        the slot of each diagonal entry; and a Factor to be refilled every step.

        Blocks beside the strips': each moving panel's 6 × 6 block (position
        targets), each M/V crease's two panel rotations; every column's
        diagonal comes with the pattern (first in its column).
        """
        n = self.n_unknowns
        width = rigid_normal.MAX_LOCAL
        panel = self.panel_col[self.panel_col >= 0]
        left, right = self.panel_col[self.mv_left], self.panel_col[self.mv_right]
        both = (left >= 0) & (right >= 0)
        blocks = [(panel[:, None] + np.arange(6), 6),
                  (np.column_stack([left[both, None] + np.arange(3),
                                    right[both, None] + np.arange(3)]), 6)]
        cols, n_loc, kind = [self.loc_cols], [self.n_loc], [self._loc_kind]
        for block, size in blocks:
            padded = np.full((len(block), width), -1, dtype=np.int64)
            padded[:, :size] = block
            cols.append(padded)
            n_loc.append(np.full(len(block), size, dtype=np.int64))
            kind.append(np.full((len(block), width), -1, dtype=np.int64))
        indptr, indices = rigid_normal.pattern_csc(
            np.concatenate(n_loc), np.concatenate(cols), np.concatenate(kind), n)
        # 32-bit indices, as CHOLMOD's int interface and SciPy take them: no copy per step
        index = np.int32 if indptr[-1] < np.iinfo(np.int32).max else np.int64
        self.csc_indptr, self.csc_indices = indptr.astype(index), indices.astype(index)
        self.diag_slot = self.csc_indptr[:-1].astype(np.int64)  # first in each column
        self._normal_factor = None

    def _map_pattern(self) -> None:
        """COO pattern of P = ∂x/∂(panel, free-vertex unknowns), (3N, n_q).

        Entries: every vertex moved by a panel (its own, or the two carrying a
        free vertex, with blend weights) gets weight·[−[a]× | I] in that
        panel's columns (a = x − c_p, filled per iteration); free vertices
        also get I in their own columns.
        """
        verts = np.concatenate([self.on_panel, self.carry_vert])
        panels = np.concatenate([self.owner[self.on_panel], self.carry_panel])
        weight = np.concatenate([np.ones(len(self.on_panel)), self.carry_weight])
        moving = self.panel_col[panels] >= 0
        self._m_vert, self._m_panel, self._m_weight = verts[moving], panels[moving], weight[moving]
        col0 = self.panel_col[self._m_panel]
        rows, cols = [], []
        for d in range(3):
            for c in range(3):  # −[a]× block, values per iteration
                rows.append(3 * self._m_vert + d)
                cols.append(col0 + c)
            rows.append(3 * self._m_vert + d)  # shift
            cols.append(col0 + 3 + d)
        for d in range(3):
            rows.append(3 * self.free + d)
            cols.append(self.free_col + d)
        self._p_rows = np.concatenate(rows)
        self._p_cols = np.concatenate(cols)
        self._n_q = self.rot_col

    # -------------------------------------------------------------- geometry
    def _positions(self, rot_p, c_p, y) -> np.ndarray:
        x = np.empty((self.sim.mesh.n_vertices, 3))
        rigid_normal.place_on_panels(rot_p, c_p, self.on_panel, self.panel_of, self.body, x)
        x[self.free] = y
        return x

    def _targets(self, rot_e):
        t = self.shape.reshape(-1, 8, 3)
        return np.einsum("sij,skj->ski", rot_e, t)

    def _update_shapes(self, phi) -> None:
        """The strips' bent shapes T(φ) at ``phi`` (S,) rad into ``self.shape``; their
        derivative dT/dφ is left for :meth:`_shape_derivatives`, which only a
        linearisation needs (most calls are energy evaluations: one bend per
        strip instead of three; OS Miura graded flat, 342 calls a fold)."""
        g = self.hinges.group
        bent_shapes(g.indptr, g.rest, self.hinges.params, phi, self.shape)
        self._shape_phi, self._d_shape_current = np.array(phi, dtype=float), False

    def _shape_derivatives(self) -> np.ndarray:
        """(S·8, 3) dT/dφ, mm/rad, at the angles of the last :meth:`_update_shapes`
        (computed on first use after it)."""
        if not self._d_shape_current:
            g = self.hinges.group
            shape_derivatives(g.indptr, g.rest, self.hinges.params, self._shape_phi,
                              self._shape_scratch, self.d_shape)
            self._d_shape_current = True
        return self.d_shape

    def _residual(self, x, rot_e):
        """(S, 8, 3) strip rows √w (x_k − x̄ − R_e t_k); the targets R_e t_k are kept in
        ``self._strip_targets``."""
        s = len(self.ids)
        self._strip_targets = np.empty((s, 8, 3))
        residual = np.empty((s, 8, 3))
        rigid_normal.strip_rows(self.ids, x, rot_e, self.shape.reshape(-1, 8, 3), self.sqrt_w,
                                self._strip_targets, residual)
        return residual

    def _pin_terms(self):
        """Position targets as (vertex ids (n,), √weights (n,), positions (n, 3)), or None."""
        sim = self.sim
        if not sim._position_targets:
            return None
        targets = sim._position_targets.values()
        return (np.concatenate([t.vertices for t in targets]),
                np.concatenate([np.full(len(t.vertices), np.sqrt(t.alpha * sim.system.reference_weight))
                                for t in targets]),
                np.concatenate([t.positions for t in targets]))

    def _residuals(self, state: State) -> np.ndarray:
        """r: strip residuals (24 S) then position-target rows; updates the shapes to state.phi."""
        self._update_shapes(state.phi)
        return self._residuals_at_shapes(state)

    def _residuals_at_shapes(self, state: State) -> np.ndarray:
        """:meth:`_residuals` with the strip shapes already those of ``state.phi``."""
        parts = [self._residual(state.x, state.rot_e).ravel()]
        pins = self._pin_terms()
        if pins is not None:
            v, w, p = pins
            parts.append((w[:, None] * (state.x[v] - p)).ravel())
        if len(self.mv_sign):
            parts.append(self._mv_terms(state.rot_p)[0])
        return np.concatenate(parts) if len(parts) > 1 else parts[0]

    def _pin_rows(self):
        """(3 n_pin, 3N) Jacobian rows of the position targets w.r.t. positions, or None."""
        pins = self._pin_terms()
        if pins is None:
            return None
        v, w, _ = pins
        cols = (3 * v[:, None] + np.arange(3)).ravel()
        return sp.csr_matrix((np.repeat(w, 3), (np.arange(3 * len(v)), cols)),
                             shape=(3 * len(v), 3 * self.sim.mesh.n_vertices))

    # ------------------------------------------------------------- iteration
    def _read_targets(self) -> None:
        """Angles of actuated strips from the hinge parameters; set up newly passive creases.

        A crease that becomes passive starts from the sum of its strips' Eq. 9
        estimates, spread evenly (one arc) and clamped to its interval; an M/V
        crease that starts flatter than the pre-bend ``SEED`` per strip gets
        it, in its assigned direction (once: afterwards its angle is an unknown).
        """
        params = self.hinges.params
        passive = np.isnan(params[:, TARGET])
        sign = params[:, SIGN]
        hi = np.where(sign < 0, -params[:, FLOOR], params[:, MAX_ANGLE])
        lo = np.where(sign > 0, params[:, FLOOR], -params[:, MAX_ANGLE])
        relayout = self._pinned != bool(self.sim._position_targets)  # which panel is fixed
        if self._passive is None or relayout or not np.array_equal(passive, self._passive):
            old = self._passive if self._passive is not None else np.zeros_like(passive)
            newly = passive & ~old
            estimate = np.zeros(len(self.phi))
            g = self.hinges.group
            estimate_angles(self.x, g.indptr, g.indices, estimate)
            self.phi[newly] = estimate[newly]
            self._layout(passive)
            fold = self._folds(self.phi)
            seed = np.sign(sign[self.passive_ids]) * SEED * self.k_strip[self.passive_ids]
            flat = np.abs(fold[self.passive_of]) < np.abs(seed)
            self.phi[self.passive_ids] = np.where(flat, seed, fold[self.passive_of]) \
                / self.k_strip[self.passive_ids]
        first = np.zeros(self.n_folds, dtype=np.int64)
        first[self.passive_of[::-1]] = self.passive_ids[::-1]
        self.lo, self.hi = lo[first] * self.k_strip[first], hi[first] * self.k_strip[first]
        self._set_folds(np.clip(self._folds(self.phi), self.lo, self.hi), self.phi)
        self.phi[~passive] = params[~passive, TARGET]

    def _folds(self, phi) -> np.ndarray:
        """(n_folds,) total bend angle of each passive crease, rad."""
        return np.bincount(self.passive_of, weights=phi[self.passive_ids],
                           minlength=self.n_folds)

    def _set_folds(self, folds, phi) -> None:
        """Spread each passive crease's angle evenly over its sub-strips (one arc)."""
        phi[self.passive_ids] = folds[self.passive_of] / self.k_strip[self.passive_ids]

    def _position_map(self, state: State):
        """P = ∂x/∂(panel, free-vertex unknowns) at a state, sparse (3N, n_q)."""
        a = state.x[self._m_vert] - state.c_p[self._m_panel]
        w = self._m_weight
        minus_skew = -skew(a) * w[:, None, None]
        p_vals = []
        for d in range(3):
            p_vals += [minus_skew[:, d, c] for c in range(3)] + [w]
        p_vals += [np.ones(len(self.free))] * 3
        n = self.sim.mesh.n_vertices
        return sp.csr_matrix((np.concatenate(p_vals), (self._p_rows, self._p_cols)),
                             shape=(3 * n, self._n_q))

    def _angle_columns(self, rot_e) -> np.ndarray:
        """(S, 8, 3) ∂(R T_k)/∂(crease angle) of passive strips (−R ∂T_k/∂φ / k), 0 else."""
        pas = self.passive_ids
        out = np.zeros((len(self.ids), 8, 3))
        d_shape = self._shape_derivatives().reshape(-1, 8, 3)
        out[pas] = np.einsum("sij,skj->ski", rot_e[pas], d_shape[pas]) \
            * (-1.0 / self.k_strip[pas])[:, None, None]
        return out

    def _extra_rows(self, state: State):
        """Sparse Jacobian of the rows after the strips' (position targets, then M/V side
        rows), or None when there are none."""
        parts = []
        pins = self._pin_rows()
        if pins is not None:
            n_hinge = 3 * len(self.ids) + self.n_folds
            parts.append(sp.hstack([pins @ self._position_map(state),
                                    sp.csr_matrix((pins.shape[0], n_hinge))]))
        if len(self.mv_sign):
            parts.append(self._mv_rows(state.rot_p, self.n_unknowns))
        if len(parts) < 2:
            return parts[0].tocsr() if parts else None
        return sp.vstack(parts).tocsr()

    def _linearise(self, state: State) -> "Linearisation":
        """JᵀJ (values on the fixed pattern), Jᵀr and r at a state, without forming J for
        the strips (:mod:`foldcore.rigid_normal`)."""
        self._columns()
        residual = self._residuals(state)
        s = len(self.ids)
        lin = Linearisation(self, state, residual, self._strip_targets,
                            self._angle_columns(state.rot_e), self._extra_rows(state))
        data = np.zeros(len(self.csc_indices))
        lin.grad = np.zeros(self.n_unknowns)
        missing = rigid_normal.assemble(
            *lin.strip_args, self.n_loc, residual[:24 * s].reshape(s, 8, 3), self.rounds,
            self.crease_ptr, self.crease_strips, self.csc_indptr, self.csc_indices, data, lin.grad)
        if lin.extra is not None and lin.extra.nnz:  # (all zero: adds nothing)
            lin.grad += lin.extra.T @ residual[24 * s:]
            coo = sp.tril(lin.extra.T @ lin.extra, format="coo")  # the stored triangle
            missing += rigid_normal.add_entries(self.csc_indptr, self.csc_indices, data,
                                                coo.row.astype(np.int64),
                                                coo.col.astype(np.int64), coo.data)
        if missing:
            raise SimulationError(f"solver 'rigid': {missing} normal-matrix entries outside "
                                  "the layout's pattern (a bug: please report it)")
        lin.normal = data
        return lin

    def _jacobian(self, state: State):
        """Sparse J (rows: strip residuals, pins, M/V rows) and r: the reference the
        assembled normal equations are tested against (not used by the step)."""
        self._columns()
        residual = self._residuals(state)
        rot_e = state.rot_e
        targets = self._targets(rot_e)
        s = len(self.ids)
        jr = (self.sqrt_w[:, None, None, None] * skew(targets)).reshape(s, 24, 3)
        rows_r = np.arange(24 * s).reshape(s, 24)
        rot_block = sp.csr_matrix((jr.ravel(),
                                   (np.repeat(rows_r.ravel(), 3),
                                    np.broadcast_to(3 * np.arange(s)[:, None, None]
                                                    + np.arange(3), (s, 24, 3)).ravel())),
                                  shape=(24 * s, 3 * s))
        pas = self.passive_ids
        d_t = self._angle_columns(rot_e)[pas] * self.sqrt_w[pas, None, None]
        phi_block = sp.csr_matrix((d_t.ravel(),
                                   (rows_r[pas].ravel(), np.repeat(self.passive_of, 24))),
                                  shape=(24 * s, self.n_folds))
        strips = sp.hstack([self._strip_position_jacobian() @ self._position_map(state),
                            rot_block, phi_block])
        extra = self._extra_rows(state)
        jac = strips if extra is None else sp.vstack([strips, extra])
        return jac.tocsc(), residual

    def step(self) -> tuple[float, float]:
        """One Levenberg–Marquardt iteration with geodesic acceleration.

        The Gauss–Newton velocity v moves along the tangent of the set of
        unstrained configurations; on closed loops that set is curved and the
        stiff strips punish the O(|v|²) gap, which alone cuts the accepted
        step to ~√(H/L) rad (measured: ~1° per iteration on a thin degree-4
        vertex). The second-order correction a = −(JᵀJ + λD)⁻¹Jᵀr_vv, with the
        directional second derivative r_vv by finite differences along v and
        the same factorisation (Transtrum & Sethna, "Improvements to the
        Levenberg–Marquardt algorithm", 2012), bends the step v + a/2 along
        that set. The step is kept only if the energy decreases.

        Returns
        -------
        energy : float
            E before the step, mm⁵.
        moved : float
            Largest vertex displacement of the step tried, mm (accepted or not).
        """
        self._sync_weights()
        self._read_targets()
        self._columns()
        self._update_shapes(self.phi)
        if not self._fitted:  # strips' rotations start at their exact fit
            self.rot_e = np.empty((len(self.ids), 3, 3))
            rigid_normal.fit_strip_rotations(self.ids, self.x, self.shape.reshape(-1, 8, 3),
                                             self.rot_e)
            self._fitted = True
        start = self._state()
        lin = self._linearise(start)
        res, grad = lin.residual, lin.grad
        energy = float(res @ res)
        t0 = time.perf_counter()
        factor = self._factor(lin.normal, grad)
        velocity = factor.solve(-grad)
        self.solve_time += time.perf_counter() - t0
        trial = self._apply(start, velocity)
        j_velocity = lin.apply(velocity)
        if GEODESIC_MAX > 0:  # geodesic acceleration (Transtrum & Sethna 2012)
            h = GEODESIC_H
            probe = self._apply(start, h * velocity)
            res_h = self._residuals(probe)
            r_vv = 2.0 / h * ((res_h - res) / h - j_velocity)
            t0 = time.perf_counter()
            accel = factor.solve(-lin.apply_transpose(r_vv))
            self.solve_time += time.perf_counter() - t0
            if np.linalg.norm(accel) <= GEODESIC_MAX * np.linalg.norm(velocity):
                trial = self._apply(start, velocity + 0.5 * accel)
        moved = float(np.abs(trial.x - self.x).max())
        new_energy = self._trial_energy(trial)
        self.accepted, self.step_lam = new_energy <= energy, self.lam
        unresolved = not self.accepted and self._closer_within_rounding(
            trial, energy, new_energy, -float(grad @ velocity), factor)
        self.accepted |= unresolved
        model = float(j_velocity @ j_velocity)  # ‖Jv‖²
        predicted = -2.0 * float(grad @ velocity) - model  # = ‖Jv‖² + 2λ vᵀDv
        if unresolved:  # E cannot judge the model there: λ stays
            self.gain_ratio, self.damped_share = np.nan, 1.0 - model / max(predicted, 1e-300)
        elif predicted > 0:
            self.gain_ratio = (energy - new_energy) / predicted
            self.damped_share = 1.0 - model / predicted
        else:  # ≤ 0 only by rounding: no verdict on the model
            self.gain_ratio, self.damped_share = np.nan, 0.0
        jumped = False
        if self.accepted and not unresolved:
            trial, new_energy, jumped = self._extrapolated(start, velocity, trial, new_energy)
            if jumped:
                moved = float(np.abs(trial.x - self.x).max())
        self._previous_velocity = velocity if self.accepted and not jumped else None
        self.follows_jump, self.jumped = self.jumped, jumped
        if self.accepted:
            self._set_state(trial)
            last = self._accepted_move
            self.contraction = moved / last if last else np.nan
            self._accepted_move = moved
            if jumped:  # its length says nothing of the contraction: the next steps will
                self.contraction, self._accepted_move = np.nan, None
        else:
            self._update_shapes(self.phi)  # restore the shapes of the kept angles
            self.contraction, self._accepted_move = np.nan, None
        self._update_damping()
        self.decrease = energy - new_energy  # < 0 when rejected
        self.energy = energy
        self.energy_after = new_energy if self.accepted else energy  # not E − decrease: that
        #   rounds to 0 where the step took E from 1.9e-7 to 8e-24 (a sweep's frame)
        self.energy_scale = max(self.energy_scale, energy)
        return energy, moved

    def _gradient(self, state: State, residual: np.ndarray) -> np.ndarray:
        """Jᵀr (n_unknowns,) at ``state`` for its ``residual`` r, just computed (the strip
        targets it set are used); no normal matrix is assembled."""
        here = Linearisation(self, state, residual, self._strip_targets,
                             self._angle_columns(state.rot_e), self._extra_rows(state))
        return here.apply_transpose(residual)

    def _closer_within_rounding(self, trial: State, energy: float, new_energy: float,
                                decrement: float, factor: Factor) -> bool:
        """Whether a trial whose energy rose by no more than rounding (``ROUNDING`` × E,
        mm⁵) still came closer to the equilibrium: its Newton decrement g̃ᵀ(JᵀJ + λD)⁻¹g̃
        (g̃ = Jᵀr at the trial; one solve with the step's factorisation) is below the
        start's ``decrement`` (mm⁵). The shapes must be the trial's.

        Why: at a binding equilibrium the energy E left is far above zero, and E's
        rounding noise (positions ~100 mm against residuals of a few µm) hides
        the last steps' decrease: a thick Miura 6 × 6 driven flat (E = 0.071 mm⁵)
        rejected 14 Gauss–Newton steps in a row at ρ ≈ −10 and stopped 2.5e-7 mm
        from where the gradient still pointed, 8 × the limit of tolerance 1e-9
        from the equilibrium a run at 1e-13 reaches. The gradient still resolves
        what E no longer does."""
        if not new_energy - energy <= ROUNDING * energy:
            return False
        g = self._gradient(trial, self._residuals_at_shapes(trial))
        t0 = time.perf_counter()
        trial_decrement = float(g @ factor.solve(g))
        self.solve_time += time.perf_counter() - t0
        return trial_decrement < decrement

    def _extrapolated(self, start: State, velocity, trial: State, energy: float):
        """(state, energy, whether extrapolated): the accepted ``trial`` (at ``energy``),
        or the step scaled to the end of its geometric tail where that is lower.

        Where a residual is left (a binding equilibrium) Gauss–Newton converges
        only linearly: the velocities keep their direction and shrink by a
        steady ratio r (Origami Simulator's Miura flat: r = 0.92 over 200
        steps), so the distance left is |v| r / (1 − r) along v. When two
        accepted velocities are aligned within ``EXTRAPOLATE_COS`` and r is in
        ``EXTRAPOLATE_RATIO``, the state moved by v / (1 − r) (at most
        ``EXTRAPOLATE_MAX`` v) is tried, one energy evaluation, and kept only
        if its energy is below the step's. Not in a branch stage nor after a
        damped step (λ > ``LAMBDA_SETTLED``): a sheet creeping out of flat
        takes aligned, steadily shrinking steps too, and a jump there changed
        a thin Miura 8 × 8 sweep's first frame (55 → 83 steps, the next frames
        3 → 7). After a jump the verdict bounds the distance left by r
        (:meth:`distance_left`, ``slow_ratio``): the contraction of the next
        steps sees the fast modes only. Measured (2-core Xeon guest,
        2026-12-03, default ``hybrid``, tolerance 1e-9): that Miura flat 288 →
        127 iterations (3.85 → 1.39 s), at W = 10H 100 → 51, the same angles
        to 1e-4°; the public patterns (``bench/real_patterns.py``, tolerance
        1e-8) 12 803 → 12 059 iterations in all, 30.3 → 24.7 s, none longer but
        the hypar at 30 % (662 → 669), misses equal to 5.2e-6°; compatible
        folds (the time-to-solution vertex, waterbomb, Miura 10 × 10 and
        20 × 20) take the same iterations (quadratic tails)."""
        previous = self._previous_velocity
        if (previous is None or previous.shape != velocity.shape or self.sim.stage == "branch"
                or self.step_lam > LAMBDA_SETTLED):
            return trial, energy, False
        lengths = np.linalg.norm(velocity), np.linalg.norm(previous)
        if not lengths[0] > 0 or not lengths[1] > 0:
            return trial, energy, False
        ratio = lengths[0] / lengths[1]
        aligned = float(velocity @ previous) / (lengths[0] * lengths[1])
        low, high = EXTRAPOLATE_RATIO
        if aligned <= EXTRAPOLATE_COS or not low <= ratio <= high:
            return trial, energy, False
        far = self._apply(start, min(1.0 / (1.0 - ratio), EXTRAPOLATE_MAX) * velocity)
        far_energy = self._trial_energy(far)
        if far_energy < energy:
            self.slow_ratio = max(self.slow_ratio, ratio)
            return far, far_energy, True
        self._update_shapes(trial.phi)  # the kept trial's shapes
        return trial, energy, False

    def _update_damping(self) -> None:
        """Next step's λ from how well the linear model predicted the last one.

        Accepted: λ × max(1/``LAMBDA_DOWN``, 1 − (2ρ − 1)³), ρ the gain ratio
        (actual decrease of E over the decrease the Gauss–Newton model predicts
        for the velocity step; Nielsen's rule, Madsen, Nielsen & Tingleff,
        "Methods for non-linear least squares problems", 2004, §3.2): λ falls
        by ``LAMBDA_DOWN`` where the model is exact (ρ ≈ 1), stays where it is
        half right (ρ ≈ ½) and rises, at most × 2, where it was poor (ρ < ½); an
        accepted step whose predicted decrease rounds to ≤ 0 leaves λ. Rejected:
        λ × ``LAMBDA_UP``. Why not a fixed ÷3 after every accepted step: on a
        thin Miura the step length cycled (accepted at ρ ≈ 1, accepted at
        ρ ≈ 0.4, rejected at ρ ≈ −10 …), a rejected step — a full factorisation
        — every third iteration; measured (hybrid, tolerance 1e-8): thin Miura
        10 × 10 71 → 52 iterations, 20 × 20 100 → 67, 8 × 8 66 → 44, Pehrson's
        vertex (W = 3H, H/R = 1e-3, mode A) 36 → 29, waterbomb 52 → 44; the
        thick mode-B vertex (H/R = 0.1) 81 → 82. Why not Nielsen's doubling
        factor after rejections: a kink in E (a bound, an M/V side row) rejects
        several steps in a row, and doubling raised λ to ~10³ there (that
        vertex: 125 iterations).
        """
        if not self.accepted:
            self.lam = min(self.lam * LAMBDA_UP, LAMBDA_MAX)
        elif np.isfinite(self.gain_ratio):  # accepted: ρ ≥ 0, the factor is ≤ 2
            shrink = max(1.0 / LAMBDA_DOWN, 1.0 - (2.0 * self.gain_ratio - 1.0) ** 3)
            self.lam = min(max(self.lam * shrink, LAMBDA_MIN), LAMBDA_MAX)

    def new_run(self) -> None:
        """A run starts: its energy scale (see :meth:`settled`) starts afresh and the
        damping at most at ``LAMBDA_START`` (one saturated at the end of the last
        run made the new run's first steps crawl, and look settled; a small one is
        kept: restarting from 1e-4 cost a fold-percent path's frames 10 of their 18
        steps, Miura 3 × 3)."""
        self.energy_scale = 0.0
        self.contraction, self._accepted_move = np.nan, None
        self._previous_velocity, self.slow_ratio = None, 0.0
        self.lam = min(self.lam, LAMBDA_START)

    def _rounding_energy(self) -> float:
        """Energy of strip residuals of ``ROUNDING`` × the pattern's size in every row
        (mm⁵): what rounding leaves of an energy that should vanish."""
        return 24.0 * float(self.sqrt_w @ self.sqrt_w) * (ROUNDING * self.sim.length_scale) ** 2

    def resync(self, x: np.ndarray) -> None:
        """Continue from positions ``x`` (N, 3) mm set since this engine last stepped
        (e.g. by an L-BFGS phase): panels refitted, strip rotations refitted at the
        next step; a no-op when ``x`` is the engine's own state."""
        if x is self.x or np.array_equal(x, self.x):
            return
        self._ends = []
        self.rot_p, self.c_p = self._fit_panels(self.sim.mesh.groups["rigid_panel"], x)
        self.y = x[self.free].copy()
        self.x = self._positions(self.rot_p, self.c_p, self.y)
        self._fitted = False
        self._previous_velocity, self.slow_ratio = None, 0.0

    def record_end(self) -> None:
        """Keep the state a run ended in (the last two: :meth:`predict`)."""
        self._ends = (self._ends + [self._state()])[-2:]

    def forget_ends(self) -> None:
        self._ends = []

    def predict(self, ratio: float) -> bool:
        """Extrapolate along the last two run ends: panel centroids and angles ≈ end₁ +
        ratio·(end₁ − end₀), rotations on their geodesic (exp(ratio·log(R₁R₀ᵀ))·R₁),
        hinge-interior vertices carried by their panels' motion from end₁ (as a
        step carries them). For a path in small increments (a fold-percent sweep)
        the next run starts near its answer. Why carried, not extrapolated
        linearly: the linear guess strains the strips by O(increment²); on a thin
        Miura 3 × 3 in 5 % frames the run started at E = 1.75e-4 (carried:
        1.2e-5) and its second step still moved 1.6e-5 × the size (carried: 5e-7).
        Returns whether it did (two ends kept and the engine still at the last)."""
        if len(self._ends) < 2 or not np.array_equal(self._ends[-1].x, self.x):
            return False
        old, new = self._ends
        turn = log_so3(new.rot_p @ np.transpose(old.rot_p, (0, 2, 1)))
        self.rot_p = exp_so3(ratio * turn) @ new.rot_p
        self.c_p = new.c_p + ratio * (new.c_p - old.c_p)
        self.y = self._carry(new, self.rot_p, self.c_p)
        self.phi = new.phi + ratio * (new.phi - old.phi)
        self.x = self._positions(self.rot_p, self.c_p, self.y)
        self._fitted = False
        self._previous_velocity, self.slow_ratio = None, 0.0
        return True

    @property
    def laid_out(self) -> bool:
        """Whether the unknowns' layout exists (built by the first step)."""
        return self._passive is not None

    def fold_edges(self) -> np.ndarray:
        """(n_folds,) pattern edge of each passive crease's angle unknown."""
        edges = np.zeros(self.n_folds, dtype=np.int64)
        edges[self.passive_of] = self.hinges.group.source[self.passive_ids]
        return edges

    def folds(self) -> np.ndarray:
        """(n_folds,) current bend of each passive crease, rad (order of :meth:`fold_edges`)."""
        return self._folds(self.phi)

    def adopt(self, rot_p, c_p, fold_of_edge, energy_scale: float = 0.0,
              lam: float = LAMBDA_START) -> None:
        """Continue from panels at rotations ``rot_p`` (P, 3, 3) and centroids ``c_p``
        (P, 3) mm, passive creases bent by ``fold_of_edge`` (E,) rad (per pattern
        edge; clamped to their intervals), hinge-interior vertices placed on their
        strips' bent shapes (:meth:`place_interiors`): the state another model of
        the same pattern reached (:mod:`foldcore.coarse`). ``energy_scale`` (mm⁵)
        is the run's largest energy so far (:meth:`settled`), ``lam`` its damping."""
        self._sync_weights()
        self._read_targets()  # the column layout and the angles' intervals
        self.rot_p, self.c_p = np.asarray(rot_p, float), np.asarray(c_p, float)
        folds = np.asarray(fold_of_edge, float)[self.fold_edges()]
        self._set_folds(np.clip(folds, self.lo, self.hi), self.phi)
        self.y = self.place_interiors()
        self.x = self._positions(self.rot_p, self.c_p, self.y)
        self._fitted, self._ends = False, []
        self.contraction, self._accepted_move = np.nan, None
        self._previous_velocity, self.slow_ratio = None, 0.0
        self.energy_scale = max(self.energy_scale, float(energy_scale))
        self.lam = min(float(lam), LAMBDA_START)

    def release_factor(self) -> None:
        """Free the normal matrix's factorisation (the next step analyses the pattern
        again). For a coarse twin at the end of a fold from rest: the mesh's
        certificate and any later run of the mesh need the memory, a sweep's
        next frame pays one analysis (measured at a thin Miura 50 × 50: peak
        RSS 330 → 316 MB; a 200-frame path as fast as before)."""
        self._normal_factor = None

    def strips_placed_within(self, limit: float) -> bool:
        """Whether every strip vertex lies within ``limit`` mm of its strip's bent shape
        (strip rotations fitted; the strips' rows of the residual over √w): the
        state is then an equilibrium of this model to that distance in every
        strip — for a state another model handed over (:meth:`adopt`), where that
        model's verdict holds for this one. Leaves the strip rotations fitted."""
        self._update_shapes(self.phi)
        rigid_normal.fit_strip_rotations(self.ids, self.x, self.shape.reshape(-1, 8, 3),
                                         self.rot_e)
        self._fitted = True
        residual = self._residual(self.x, self.rot_e)
        scale = np.where(self.sqrt_w > 0, self.sqrt_w, 1.0)
        return bool(np.abs(residual / scale[:, None, None]).max(initial=0.0) <= limit)

    def place_interiors(self) -> np.ndarray:
        """(n_free, 3) mm: hinge-interior vertices where the strips' bent shapes put
        them, strip after strip across each crease from the panel its first strip
        touches (each strip's known side — a panel's edge, then the line the strip
        before placed — fitted rigidly to its bent shape, the other side taken from
        it). Exact where the crease's strips meet its far panel too (arc and axis
        hinges bent alike: one arc, :mod:`foldcore.coarse`); the steps correct the
        rest. Vertices no chain reaches keep their current positions."""
        self._update_shapes(self.phi)
        shape = self.shape.reshape(-1, 8, 3)
        x = self._positions(self.rot_p, self.c_p, self.y)
        for batch, known, unknown in self._interior_chains():
            ids, bent = self.ids[batch], shape[batch]
            src, dst = (np.take_along_axis(ids, side, 1) for side in (known, unknown))
            t_src = np.take_along_axis(bent, known[:, :, None], 1)
            t_dst = np.take_along_axis(bent, unknown[:, :, None], 1)
            centre = t_src.mean(axis=1, keepdims=True)
            rigid_normal.place_sides(x, src, dst, t_src - centre, t_dst - centre)
        return x[self.free]

    def _interior_chains(self) -> list:
        """[(strips (b,), known local vertices (b, 4), unknown ones (b, 4))] per place
        in the creases' series of strips, for :meth:`place_interiors`; built once."""
        if self._chains is not None:
            return self._chains
        known = self.owner >= 0
        chains = [np.asarray(c) for c in self.sim.mesh.strips_of_crease.values()]
        self._chains = []
        for j in range(max((len(c) for c in chains), default=1) - 1):
            batch = np.array([c[j] for c in chains if len(c) > j + 1], dtype=np.int64)
            mask = known[self.ids[batch]]
            fit = mask.sum(axis=1) == 4  # a side known, the other to place
            batch, mask = batch[fit], mask[fit]
            order = np.argsort(~mask, axis=1, kind="stable")
            self._chains.append((batch, order[:, :4], order[:, 4:]))
            known[self.ids[batch]] = True
        return self._chains

    def settled(self, moved: float, tolerance: float) -> bool:
        """Whether the last step ends a run at relative ``tolerance``: it was accepted,
        the distance it leaves (:meth:`distance_left`: the step's length, or a bound
        from its contraction) is ≤ tolerance × the pattern's size, it lowered the
        energy by ≤ tolerance × the energy (or left no more than that), and the
        damping was neither large (λ ≤ ``LAMBDA_SETTLED``)
        nor the main part of the decrease the model predicted for it
        (``damped_share`` = 2λvᵀDv / (‖Jv‖² + 2λvᵀDv) ≤ ``DAMPED_SHARE_MAX``):
        a step short because λ held it back says nothing about the equilibrium.
        Measured: with the gain-ratio damping (:meth:`_update_damping`) a thin
        Miura 5 × 5 at H = 1e-5·a ended its branch stage after 4 steps at
        λ = 7e-6 (share 0.43) and stopped "converged" 60° short at the flat
        state (which a thin sheet's symmetry makes nearly stationary); with
        the share ≤ 0.1 it folds (251 iterations, 3.9e-5° off; the fixed ÷3
        damping took 400). On 15 vertex, Miura and waterbomb folds the share
        test changed no run.

        Why the energy too: a step's length alone is met by a stall. A thin Miura
        50 × 50 (H = 0.02 mm, size 1 010 mm) crept out of the flat state in steps
        of 1e-5 … 1e-3 mm for 100 iterations, each lowering E by far more than
        1e-8 E, and stopped "converged" 60° short at a 7.7e-6 mm step (limit
        1.0e-5 mm); its branch stage had stopped after 2 steps the same way.
        Where the energy vanishes (compatible targets) its decrease is rounding
        noise of the order of E itself, hence the floor tolerance² × the largest
        energy of the run (``energy_scale``, reset by :meth:`new_run`) plus the
        energy of rounding-sized residuals (:meth:`_rounding_energy`; a 5 % step
        of a fold-percent path ended at E = 6.7e-25 mm⁵ with tolerance² × its
        largest E = 8e-26). A
        rejected step ends a run only there, where its energy rose by no more
        than rounding (``ROUNDING`` × E), or where even the most damped step
        (λ = ``LAMBDA_MAX``, a scaled gradient step of ~1e-14 mm) raised it: a
        minimum no step can lower, e.g. the chain scene pushed against its stop,
        where the energy has a kink (34 rejected steps from λ = 1e-4 to get there).
        """
        limit = tolerance * self.sim.length_scale
        floor = tolerance ** 2 * self.energy_scale + self._rounding_energy()
        if self.accepted:  # a step damped to a crawl says nothing: λ must be small
            quiet = self.step_lam <= LAMBDA_SETTLED and self.damped_share <= DAMPED_SHARE_MAX
            energy_limit = tolerance * self.energy + floor
            if self.distance_left(moved, limit, energy_limit if quiet else None) > limit:
                return False
            left = self.energy_after  # ≥ any later decrease
            return bool(min(self.decrease, left) <= energy_limit and quiet)
        if self.distance_left(moved, limit) > limit:
            return False
        # rejected: at the energy's rounding floor, no descent at any damping, or an
        # undamped Gauss–Newton step within the limit that changed E by ≤ tolerance × E
        quiet = self.step_lam <= LAMBDA_SETTLED and self.damped_share <= DAMPED_SHARE_MAX
        return bool(self.energy <= floor or -self.decrease <= ROUNDING * self.energy
                    or self.step_lam >= LAMBDA_MAX
                    or (quiet and -self.decrease <= tolerance * self.energy + floor))

    def stalls(self, moved: float, relative: float) -> bool:
        """Whether the last step, of largest vertex move ``moved`` mm ≤ ``relative`` ×
        the pattern's size, was rejected with its energy within rounding
        (``ROUNDING`` × E) of the start's or at the rounding floor, or was
        accepted and did not contract (Θ ≥ 1, or unknown but not after an
        extrapolation; a move of rounding size, ``ROUNDING`` × the size, always
        stalls). Where the steps still shrink steadily the run is converging,
        however small they are: a thick Miura 6 × 6 driven flat at tolerance
        1e-13 took steps of 1e-8 mm contracting by 0.85 and was handed over to
        ``newton``, which wandered at that size to the budget."""
        size = self.sim.length_scale
        if moved > relative * size:
            return False
        if not self.accepted:  # neither lower nor closer (_closer_within_rounding)
            return bool(-self.decrease <= ROUNDING * self.energy
                        or self.energy <= self._rounding_energy())
        contracting = moved > ROUNDING * size and (self.contraction < 1.0 or self.jumped
                                                   or self.follows_jump)
        return not contracting

    def distance_left(self, moved: float, limit: float, energy_limit=None) -> float:
        """Estimated distance (mm) from the state after the last step (of largest
        vertex move ``moved`` mm) to the equilibrium, for a run whose limit is
        ``limit`` mm; stored as ``distance``. ``energy_limit`` (mm⁵, None: no
        correction is tried): the largest energy decrease, or energy, that
        ends the run (:meth:`settled`).

        After two accepted steps whose lengths contracted by Θ = ``contraction``
        ≤ ``CONTRACTION_MAX``, the steps still to come sum to ≤ Θ/(1 − Θ) × the
        last one's (the a-posteriori bound of a contracting iteration, Deuflhard,
        "Newton Methods for Nonlinear Problems", 2004, §2.1; for the quadratic
        convergence of Gauss–Newton on compatible targets it overestimates).
        After a first accepted step within ``CHORD_FROM`` × the limit, the
        simplified correction (:meth:`_simplified_correction`) is tried: when it
        lowers the energy to within ``energy_limit`` (or by no more than it),
        contracts and leaves a distance within the limit — when it ends the run
        — it is applied and its bound returned. Otherwise the step's own length,
        ``moved``: the distance before it. Once an extrapolation saw a slow mode
        (``slow_ratio`` r, :meth:`_extrapolated`), the bound is
        moved · Θ'/(1 − Θ') with Θ' = max(r, Θ) for the rest of the run.
        Why: a fold-percent path's frames (thin Miura 8 × 8, 0.5 % increments)
        took 3 steps each, a correction of ~1e-5 × the size, a second of
        ~1e-8 × it, just above the tolerance (1e-8), and a third of ~1e-11
        that only confirmed it; with Θ, 2 steps; with the simplified correction
        (a solve with the step's factorisation, no new one), 1. Applying it
        where it does not end the run is not done: Pehrson's thick mode-B vertex
        (H/R = 0.1) then took 446 steps instead of 81.
        """
        self.distance = moved
        theta = self.contraction
        if self.accepted and self.slow_ratio > 0.0:  # a slow mode was seen: its rate bounds
            theta = max(self.slow_ratio, theta if theta < 1.0 else 0.0)
            self.distance = moved * theta / (1.0 - theta)
        elif self.accepted and theta <= CONTRACTION_MAX:
            self.distance = moved * theta / (1.0 - theta)
        elif self.accepted and energy_limit is not None and limit < moved <= CHORD_FROM * limit:
            trial, energy, length = self._simplified_correction()
            theta = length / moved
            left = length * theta / (1.0 - theta) if theta < 1.0 else np.inf
            if (energy <= self.energy_after and theta <= CONTRACTION_MAX
                    and left <= limit and min(self.energy - energy, energy) <= energy_limit):
                self._set_state(trial)
                self.decrease, self.energy_after = self.energy - energy, energy
                self.distance = left
            else:
                self._update_shapes(self.phi)  # the kept state's shapes
        return self.distance

    def _simplified_correction(self):
        """(state, energy mm⁵, largest vertex move mm) of the simplified correction
        at the current state; not applied.

        v̄ = −(JᵀJ + λD)⁻¹ ∇E/2: the last step's factorisation, the gradient here
        (J's transpose and the residual at this state; one more solve, no
        factorisation; the simplified Newton correction by which Deuflhard's
        codes monitor convergence, for the gradient system ∇E = 0). After a
        step of length |v| it contracts by Θ = |v̄|/|v| and leaves ≤
        Θ/(1 − Θ)·|v̄|. The shapes are left at the correction's angles.

        Why J here and not the last step's: an undamped Gauss–Newton step v
        solves J₀ᵀ(r₀ + J₀v) = 0, so J₀ᵀ r(x₀ + v) vanishes to first order
        whatever is left; only where the residual vanishes (compatible targets)
        is that the gradient. At a binding equilibrium it is not: Origami
        Simulator's Miura flat (E = 385 mm⁵, tolerance 1e-9) stopped at
        134 iterations with a correction of 2e-9 mm after steps of 2e-3 mm
        still contracting by 0.92, its straight creases 0.012° from the
        equilibrium a tolerance of 1e-13 reaches."""
        state = self._state()
        gradient = self._gradient(state, self._residuals(state))
        t0 = time.perf_counter()
        v = self._normal_factor.solve(-gradient)
        self.solve_time += time.perf_counter() - t0
        trial = self._apply(state, v)
        energy = self._trial_energy(trial)
        return trial, energy, float(np.abs(trial.x - state.x).max())

    def _factor(self, normal: np.ndarray, grad) -> Factor:
        """Factorisation of JᵀJ + λ·diag(JᵀJ) (values ``normal`` on the fixed pattern,
        damped in place), angles on a bound they press against frozen; the symbolic
        analysis is reused."""
        diag = normal[self.diag_slot]
        diag = np.maximum(diag, 1e-12 * max(diag.max(), 1e-300))
        folds = self._folds(self.phi)
        g_fold = grad[self.phi_col:]
        blocked = ((folds <= self.lo + BOUND_TOL) & (g_fold > 0)) | \
                  ((folds >= self.hi - BOUND_TOL) & (g_fold < 0))
        damping = self.lam * diag
        damping[self.phi_col:][blocked] = 1e12 * diag[self.phi_col:][blocked]
        normal[self.diag_slot] += damping  # in place: the step needs the undamped no more
        n = self.n_unknowns
        matrix = sp.csc_matrix((normal, self.csc_indices, self.csc_indptr), shape=(n, n))
        if self._normal_factor is None:
            self._normal_factor = Factor(matrix, self.backend, stored="lower")
        else:
            self._normal_factor.refactor(matrix)
        return self._normal_factor

    def _state(self) -> State:
        return State(self.x, self.rot_p, self.c_p, self.y, self.rot_e, self.phi)

    def _set_state(self, state: State) -> None:
        self.x, self.rot_p, self.c_p, self.y, self.rot_e, self.phi = state

    def _apply(self, state: State, delta) -> State:
        """State moved by an increment of the unknowns (exponential maps for rotations)."""
        moving = self.panel_col >= 0
        w = np.zeros((len(state.rot_p), 6))
        w[moving] = delta[:6 * moving.sum()].reshape(-1, 6)
        rot_p, c_p = self._move_panels(state, w)
        y = self._carry(state, rot_p, c_p)
        if len(self.free):
            y += delta[self.free_col[0]:self.rot_col].reshape(-1, 3)
        s = len(self.ids)
        rot_e = np.empty_like(state.rot_e)
        rigid_normal.rotate_by(delta[self.rot_col:self.phi_col].reshape(s, 3), state.rot_e, rot_e)
        phi = state.phi.copy()
        self._set_folds(np.clip(self._folds(phi) + delta[self.phi_col:], self.lo, self.hi), phi)
        return State(self._positions(rot_p, c_p, y), rot_p, c_p, y, rot_e, phi)

    def _carry(self, state: State, rot_p, c_p) -> np.ndarray:
        """Free vertices moved by the blend of their panels' rigid motions (old → new)."""
        y = np.empty_like(state.y)
        rigid_normal.carry_free(self.carry_slot, self.carry_panel, self.carry_weight, state.y,
                                state.c_p, state.rot_p, rot_p, c_p, y)
        return y

    def _move_panels(self, state: State, w):
        """Rigid update of the panels that keeps their hinge vertices where the step put them.

        The linear step moves a panel vertex by ω × a + t (a from the panel's
        centroid); the exact rotation exp(ω) differs from it by O(|a| ω²),
        large on long panels. The shift is therefore chosen so the rigid
        motion matches the linear prediction in the least-squares sense at
        the panel's hinge-strip vertices (the joints), not at its centroid.
        """
        rot_p, c_p = np.empty_like(state.rot_p), np.empty_like(state.c_p)
        rigid_normal.move_panels(state.rot_p, state.c_p, w, self.panel_of, self.body,
                                 self.joint_weight, rot_p, c_p)
        return rot_p, c_p

    def _trial_energy(self, state: State) -> float:
        """Energy of a trial state after refitting its strips' rotations (Procrustes)."""
        self._update_shapes(state.phi)
        rigid_normal.fit_strip_rotations(self.ids, state.x, self.shape.reshape(-1, 8, 3),
                                         state.rot_e)
        residual = self._residuals_at_shapes(state)
        strips = 24 * len(self.ids)  # summed as before: the accept test is at rounding level
        return float((residual[:strips] ** 2).sum() + (residual[strips:] ** 2).sum())


class Linearisation:
    """The step's linear model at one state: r, Jᵀr, JᵀJ's values, and J·v / Jᵀu.

    The strips' rows come from :mod:`foldcore.rigid_normal` (no J is formed);
    the few rows after them (position targets, M/V side rows) are a small
    sparse matrix ``extra``.
    """

    def __init__(self, solver: RigidBodySolver, state: State, residual, targets, d_targets,
                 extra):
        self.residual, self.extra = residual, extra
        self.n_strip_rows = 24 * len(solver.ids)
        self.n_unknowns = solver.n_unknowns
        self.strip_args = (solver.ids, state.x, state.c_p, solver.strip_side, solver.off_panel,
                           solver.strip_alpha, solver.own_off, solver.off_w, solver.off_phi,
                           solver.loc_cols, solver.sqrt_w, targets, d_targets)
        self.grad = self.normal = None

    def apply(self, v: np.ndarray) -> np.ndarray:
        """J·v (rows as the residual) for an increment v (n_unknowns,)."""
        out = np.empty((self.n_strip_rows // 24, 8, 3))
        rigid_normal.apply_jacobian(*self.strip_args, v, out)
        if self.extra is None:
            return out.ravel()
        return np.concatenate([out.ravel(), self.extra @ v])

    def apply_transpose(self, u: np.ndarray) -> np.ndarray:
        """Jᵀ·u (n_unknowns,) for row values u (rows as the residual)."""
        grad = np.zeros(self.n_unknowns)
        m = self.n_strip_rows
        rigid_normal.apply_transpose(*self.strip_args, u[:m].reshape(-1, 8, 3), grad)
        if self.extra is not None:
            grad += self.extra.T @ u[m:]
        return grad
