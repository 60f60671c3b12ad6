"""The model a strategy drives: positions, element groups, targets, pins, stops, K.

Units at this API: mm for lengths and positions, degrees for angles.
"""
from __future__ import annotations

import time
from contextlib import contextmanager

import numpy as np

from ..errors import SimulationError
from ..measure import fold_angles
from ..system import System
from .groups import check_every_vertex_used, group_states
from .hinges import HingeControls
from .pins import Pins

BARE_SOLVE_REPEATS = 5  # solves timed for the per-iteration cost floor


class Model:
    """Geometry, actuation and state of one thick mesh, and its local and global step.

    Strategies (:mod:`foldcore.strategies`) move :attr:`x` through this public
    surface; what changes the problem (fold targets, floors, position
    targets, stretch ratios) is announced to the subscribers
    (:meth:`subscribe`), so a strategy's history never outlives its targets.

    Parameters
    ----------
    mesh : ThickMesh
    pattern : CreasePattern
        The pattern the mesh was made from (targets, assignments, measurement).
    backend : {"auto", "cholmod", "scipy"}
        Linear-solver backend of K.
    passive_floor_deg : float
        Fold magnitude (degrees per crease) a passive M/V hinge is given when its
        estimate has the wrong sign (paper §4.2, "a small value"); ≥ 0.
    stop_stiffness : float
        Weight factor (≥ 1) of a passive strip bent past its max angle
        (:class:`~foldcore.model.hinges.HingeControls`).
    actuation : {"equal", "angle"}
        What an actuated crease is (:mod:`foldcore.actuation`).

    Attributes
    ----------
    x : (N, 3) float
        Current positions, mm (strategies assign a new array or write in place).
    groups : list of GroupState
        Run-time arrays of each element group, in the order of K's groups.
    hinges, stretch : GroupState or None
        The bending-hinge and stretch-hinge groups, if any.
    slot_targets : (nnz, 3) float
        Every element slot's projected target at the last local step, mm.
    system : foldcore.system.System
        K, its factor, its current weights.
    controls : HingeControls
        Fold targets, percent, floors, stops of the hinge group.
    pins : Pins
        Position targets and pin weights.
    length_scale : float
        The pattern's larger extent, mm (tolerances are relative to it).
    timings : dict
        Seconds spent in ``setup``, ``projection`` (element kernels) and ``solve``
        (rhs gather and K⁻¹ solves); strategies add theirs.
    """

    def __init__(self, mesh, pattern, backend: str = "auto", passive_floor_deg: float = 0.0,
                 stop_stiffness: float = 1e3, actuation: str = "equal"):
        self.mesh, self.pattern = mesh, pattern
        self.x = mesh.rest_positions.copy()
        self.groups, n_slots = group_states(mesh)
        check_every_vertex_used(self.groups, mesh.n_vertices)
        self.hinges = next((g for g in self.groups if g.group.kind == "bending_hinge"), None)
        self.stretch = next((g for g in self.groups if g.group.kind == "stretch_hinge"), None)
        self.controls = HingeControls(self.hinges, mesh, pattern, actuation, stop_stiffness)
        self.slot_targets = np.zeros((n_slots, 3))
        # column-major: CHOLMOD's own layout, so the solve copies nothing in
        self._rhs = np.zeros((mesh.n_vertices, 3), order="F")
        if not (np.isfinite(passive_floor_deg) and passive_floor_deg >= 0):
            raise SimulationError(f"passive floor must be ≥ 0 degrees, got "
                                  f"{passive_floor_deg!r}")
        self.passive_floor_deg = float(passive_floor_deg)
        self.controls.set_floor(self.passive_floor_deg)
        self.controls.apply()
        self.hinge_index = None if self.hinges is None else self.groups.index(self.hinges)
        weights = [g.group.weights if g is not self.hinges else self.controls.weights()
                   for g in self.groups]
        self.system = System([g.group for g in self.groups], mesh.n_vertices, backend, weights)
        self.pins = Pins(self.system, mesh.n_vertices)
        self.length_scale = float(np.ptp(pattern.vertices, axis=0).max())
        self.timings = {"setup": 0.0, "projection": 0.0, "solve": 0.0}
        self.contact = None  # a foldcore.contact.ContactModel where panels must not cross
        self.contact_off = None  # why contact is off (None: on, or not decided yet)
        self._subscribers = []
        self._scratch = False  # True while a probe projects (no stop changes)
        self._last_fold_angles = None  # (positions, angles) of the last fold_angles call

    # ------------------------------------------------------------- changes
    def subscribe(self, callback) -> None:
        """Call ``callback()`` whenever the problem changes (targets, floors, pins)."""
        self._subscribers.append(callback)

    def _changed(self) -> None:
        for callback in self._subscribers:
            callback()

    @property
    def actuation(self) -> str:
        return self.controls.actuation

    @property
    def position_targets(self):
        """Read-only mapping name → :class:`~foldcore.model.pins.PositionTarget`."""
        return self.pins.targets

    @property
    def stops(self) -> np.ndarray:
        """(S,) bool: hinge strips acting as stops."""
        return self.controls.stops

    @property
    def passive(self) -> np.ndarray:
        """(S,) bool: hinge strips without a target."""
        return self.controls.passive

    # ----------------------------------------------------------- actuation
    def set_fold_angles(self, angles) -> None:
        """Set target fold angles (degrees, valley > 0) of creases.

        Parameters
        ----------
        angles : dict {edge id: angle or None} or (E,) array (NaN = passive)
            ``None``/NaN makes a crease passive. Boundary edges cannot be set.
        """
        items = angles.items() if isinstance(angles, dict) else enumerate(np.asarray(angles))
        new = self.controls.fold_targets.copy()
        for e, angle in items:
            e = self.controls.checked_crease(int(e), self.stretch)
            new[e] = self.controls.checked_angle(e, angle)
        self.controls.fold_targets = new
        self._apply_targets()
        self._changed()

    def set_fold_percent(self, percent: float) -> None:
        """Scale every actuated target by ``percent``/100 (−100…100, as in other tools)."""
        if not (np.isfinite(percent) and -100.0 <= percent <= 100.0):
            raise SimulationError(f"fold percent must be in [-100, 100], got {percent!r}")
        self.controls.percent = float(percent)
        self._apply_targets()
        self._changed()

    @property
    def fold_percent(self) -> float:
        return self.controls.percent

    def mirror_targets(self, other: "Model") -> None:
        """Take ``other``'s fold targets, fold percent and crease floors (a model of the
        same pattern with other sub-strips: a coarse twin); announces nothing."""
        self.controls.fold_targets = other.controls.fold_targets.copy()
        self.controls.percent = other.controls.percent
        self._apply_targets()
        self.controls.set_crease_floors(other.controls.crease_floors())

    def set_floor(self, floor_deg: float) -> None:
        """Every passive M/V crease held at least ``floor_deg`` degrees on its assigned
        side (a branch stage's floor, or the user's again)."""
        self.controls.set_floor(floor_deg)
        self._changed()

    def _apply_targets(self) -> None:
        self.controls.apply()
        self._sync_hinge_weights()

    def _sync_hinge_weights(self) -> None:
        """Hand the current hinge weights to K (a numeric refactor if they changed)."""
        if self.hinges is not None:
            self.system.set_weights(self.hinge_index, self.controls.weights())

    def set_stretch_ratios(self, ratios: dict) -> None:
        """Actuate stretch hinges (paper §6.3): ``{edge id: λ or None}``.

        λ > 0 is the width ratio of the crease's strip (its length follows
        λ^(−ν)); ``None`` makes it passive (free to stretch). Only creases made
        stretch hinges by ``thicken(..., stretch=...)`` take a ratio.
        """
        from elements.stretch_hinge import RATIO

        state = self.stretch
        for e, ratio in dict(ratios).items():
            rows = np.zeros(0, dtype=bool) if state is None else state.group.source == int(e)
            if not rows.any():
                raise SimulationError(f"edge {e} is not a stretch hinge (see thicken's "
                                      "'stretch' argument)")
            if ratio is not None and not (np.isfinite(ratio) and ratio > 0):
                raise SimulationError(f"edge {e}: stretch ratio must be a positive number, "
                                      f"got {ratio!r}")
            state.set_params(rows, RATIO, np.nan if ratio is None else float(ratio))
        self._changed()

    # ---------------------------------------------------------------- pins
    def add_position_target(self, vertices, positions=None, alpha: float = 1.0,
                            decay: float = 1.0, name: str | None = None) -> str:
        """Pull vertices toward positions (mm); returns the target's name.

        ``positions`` defaults to the vertices' current positions (a pin).
        """
        ids = self.pins.vertex_ids(vertices)
        pos = self.x[ids].copy() if positions is None else np.asarray(positions, float)
        name = self.pins.add(ids, pos, alpha, decay, name)
        self._changed()
        return name

    def move_position_target(self, name: str, positions) -> None:
        """New positions (mm) for an existing target (no refactor needed)."""
        self.pins.move(name, positions)
        self._changed()

    def remove_position_target(self, name: str) -> None:
        """Stop pulling the vertices of a target."""
        self.pins.remove(name)
        self._changed()

    # ------------------------------------------------------- local / global
    def local_step(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """Project every element at ``x`` and gather the right-hand side.

        Parameters
        ----------
        x : (N, 3) float, mm
            Positions to project at (need not be :attr:`x`).

        Returns
        -------
        energy : float
            E(x) = Σ w‖C S x − R T‖² + pin terms, mm⁵, with the projections at x.
        rhs : (N, 3) float
            b(x) = Σ w Sᵀ R T + pin terms (an internal buffer: copy to keep it).
            With K fixed, ∇E(x) = 2 (K x − b(x)) and the global step is K⁻¹ b(x).
        """
        t0 = time.perf_counter()
        energy = sum(g.project(x, self.slot_targets, w)
                     for g, w in zip(self.groups, self.system.weights))
        if not self._scratch and self.controls.update_stops(x):
            self._sync_hinge_weights()
        t1 = time.perf_counter()
        rhs = self.system.rhs(self.slot_targets, self._rhs)
        energy += self.pins.add_terms(rhs, x)
        self.timings["projection"] += t1 - t0
        self.timings["solve"] += time.perf_counter() - t1
        return energy, rhs

    @contextmanager
    def scratch_projections(self):
        """Within: :meth:`local_step` leaves the stops as they are and, on leaving,
        every group's energies and state are restored (a probe of the map must not
        change the model it checks)."""
        saved = [(g.energy.copy(), g.state.copy()) for g in self.groups]
        self._scratch = True
        try:
            yield
        finally:
            self._scratch = False
            for g, (energy, state) in zip(self.groups, saved):
                g.energy[:], g.state[:] = energy, state

    def global_step(self, rhs: np.ndarray) -> np.ndarray:
        """K⁻¹ rhs, (N, 3) mm, C-contiguous; its time counts as solve time."""
        t0 = time.perf_counter()
        out = np.ascontiguousarray(self.system.factor.solve(rhs))
        self.timings["solve"] += time.perf_counter() - t0
        return out

    def bare_solve_seconds(self, repeats: int = BARE_SOLVE_REPEATS) -> float:
        """Median time (s) of one K⁻¹ solve of an (N, 3) column-major right-hand side
        (the layout the iterations hand the solver): the cost floor of an iteration."""
        rhs = np.asfortranarray(self.x)
        times = []
        for _ in range(int(repeats)):
            t0 = time.perf_counter()
            self.system.factor.solve(rhs)
            times.append(time.perf_counter() - t0)
        return float(np.median(times))

    # ----------------------------------------------------------- measuring
    def checked_positions(self, positions) -> np.ndarray:
        """``positions`` as a finite (N, 3) float array of mm (else SimulationError)."""
        x = np.asarray(positions, dtype=float)
        if x.shape != self.x.shape or not np.isfinite(x).all():
            raise SimulationError(f"positions must be a finite ({self.mesh.n_vertices}, 3) "
                                  f"array of mm, got shape {x.shape}")
        return np.ascontiguousarray(x.copy())

    def nearest_vertex(self, point) -> int:
        """Id of the mesh vertex closest to a 3D point (mm), current positions."""
        return int(np.argmin(np.linalg.norm(self.x - np.asarray(point, float), axis=1)))

    def fold_angles(self) -> np.ndarray:
        """(E,) fold angles in degrees from the panels' mid-planes (NaN for B, and for
        every edge of a mesh without panels)."""
        panels = self.mesh.groups.get(self.mesh.panel_group)
        if panels is None or not len(panels):
            return np.full(self.pattern.n_edges, np.nan)
        last = self._last_fold_angles  # a run's start measures where the last run ended
        if last is None or not np.array_equal(last[0], self.x):
            last = self._last_fold_angles = (self.x.copy(),
                                             fold_angles(self.pattern, self.mesh, self.x))
        return last[1].copy()

    def target_angles(self) -> np.ndarray:
        """(E,) effective target of every crease, degrees (NaN: passive, boundary)."""
        return self.controls.target_angles()

    def strip_angles(self) -> np.ndarray:
        """(S,) bend angle (degrees) each hinge sub-strip used in the last projection."""
        if self.hinges is None:
            return np.zeros(0)
        return np.degrees(self.hinges.state[:, 0])

    def strip_strains(self) -> np.ndarray:
        """(S, 2) top/bottom surface strain of each sub-strip at the current shape."""
        if self.hinges is None:
            return np.zeros((0, 2))
        from ..strain import strains_at

        return strains_at(self.hinges.group, self.x)

    def hinge_misfits(self) -> np.ndarray:
        """(S,) RMS distance (mm) of each hinge sub-strip's vertices from its rotated
        model shape at the current positions (a fresh projection into scratch
        arrays: the model's own state is untouched)."""
        if self.hinges is None:
            return np.zeros(0)
        g = self.hinges
        residual = np.zeros(len(g.group))
        g.project_into(self.x, np.zeros_like(g.group.rest), residual, np.zeros_like(g.state))
        return np.sqrt(np.maximum(residual, 0.0) / np.diff(g.group.indptr))

    def stretch_ratios(self) -> np.ndarray:
        """(T, 2) measured width and length ratios of each stretch strip (current / rest)."""
        if self.stretch is None:
            return np.zeros((0, 2))
        g = self.stretch.group
        ids = g.indices.reshape(len(g), 8)
        rest = self.mesh.rest_positions

        def mean_length(pos, pairs):
            return np.mean([np.linalg.norm(pos[ids[:, i]] - pos[ids[:, j]], axis=1)
                            for i, j in pairs], axis=0)

        across, along = ((0, 1), (3, 2), (4, 5), (7, 6)), ((0, 3), (1, 2), (4, 7), (5, 6))
        return np.column_stack([mean_length(self.x, across) / mean_length(rest, across),
                                mean_length(self.x, along) / mean_length(rest, along)])
