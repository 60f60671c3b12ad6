"""Simulation: actuation, the local/global iteration and its result (paper §3–4).

Units at this API: mm for lengths and positions, degrees for angles.
"""
from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass, field

import numba
import numpy as np

import elements
from elements.bending_hinge import FLOOR, SIGN, TARGET, limit_excess
from . import strategies
from .actuation import (ACTUATION_STIFFNESS, ACTUATIONS, BRANCH_FLOOR_DEG, BRANCH_TOLERANCE,
                        DEFAULT_ACTUATION)
from .errors import SimulationError
from .measure import fold_angles
from .strategies import DEFAULT_SOLVER
from .system import System
from .threads import ThreadChooser, blas_on_one_thread
from .verdict import EquilibriumCheck

ALPHA_UPDATE_EVERY = 10  # iterations between α-schedule updates (each costs a refactor)
STOP_ENTER = 1e-3  # rad past its bound before a passive strip becomes a stop
STOP_LEAVE = 1e-3  # rad back inside its interval before a stop is released
# Element-vertex slots below which the kernels run on one thread. Measured on the
# 2-core Xeon, paper map, ms/iteration 1 vs 2 threads: Miura 2×2 (108 slots) 0.070 vs
# 0.063 quiet / 2.3 with the cores busy; 5×5 (936) 0.41 vs 0.28; 10×10 (4 076) 1.77 vs 1.09.
SERIAL_BELOW_SLOTS = 500
#: Degrees on its assigned side every passive M/V crease must be for a sheet within
#: the branch floor to count as having left flat on its branch (no branch stage).
BRANCH_LEFT_DEG = 1e-3
#: Vector length (3 × vertices) from which a serial simulation's steps hold BLAS to
#: one thread too: OpenBLAS threads its dot products of such vectors, and its spinning
#: threads made an L-BFGS step of a Miura 10 × 10 (3 356 vertices) cost 63× its quiet
#: median at the 95th percentile with the cores busy (bench/load.py).
BLAS_GUARD_FROM = 10_000
BARE_SOLVE_REPEATS = 5  # solves timed for the per-iteration cost floor


@dataclass
class PositionTarget:
    """Vertices pulled toward target positions with weight α (paper Eq. 5–6).

    ``alpha`` is dimensionless: α = 1 pins a vertex as stiffly as the mean
    element connection of a vertex. ``decay`` < 1 multiplies α every
    ``ALPHA_UPDATE_EVERY`` iterations (§3.2: α goes from 1 toward 0 as the
    optimisation converges); below ``1e-6`` the target is dropped.
    """

    vertices: np.ndarray
    positions: np.ndarray
    alpha: float = 1.0
    decay: float = 1.0


@dataclass
class Result:
    """What a run produced. Angles in degrees (valley > 0), positions in mm.

    Attributes
    ----------
    positions : (N, 3) float
    fold_angles_deg : (E,) float, NaN for boundary edges
    strip_angles_deg : (S,) float, bend angle used by each hinge sub-strip
    energy : (iterations,) float, energy before each global step, mm⁵
    iterations : int
    converged : bool, the run ended at an equilibrium of the strategy's model within
        the tolerance (``reason == "converged"``), not merely with a small step
    timings_s : dict with ``setup``, ``projection`` (element kernels), ``solve`` (the
        rhs gather, the K⁻¹ solve and, for ``paper``, taking its result and
        largest move), ``total`` (setup + every :meth:`Simulation.run` so far)
        and, after a :meth:`Simulation.run` where K was factorised (every
        strategy but the rigid-body phase, which never solves with K),
        ``bare_solve`` (one K⁻¹ solve, the floor) (seconds)
    strip_strains : (S, 2) float, top and bottom surface strain of each hinge
        sub-strip from its current shape (:mod:`foldcore.strain`), dimensionless
    failures : list of dict, hinges that exceeded their strain limits (first
        iteration each; empty without ``strain_limits``)
    target_angles_deg : (E,) float, the effective target of each crease at the
        run's fold percent (NaN: passive or boundary)
    hinge_misfit_mm : (S,) float, how far each hinge sub-strip is from its own
        model shape: the RMS distance (mm) of its vertices from its rotated
        target at ``positions`` — 0 where the hinge model is met, > 0 where
        the model binds (a vertex that cannot close, conflicting targets)
    reason : str, why the run ended: ``"converged"``; ``"stalled"`` (steps within the
        tolerance, or the plain map's rate too slow for the budget, but the
        equilibrium not reached: :mod:`foldcore.verdict`; or the strategy's steps
        at its resolution, :attr:`Strategy.stalled`); ``"budget"``
        (``max_iterations`` ran out); ``"callback"`` (the callback returned False);
        ``"interrupted"`` (Ctrl-C: :func:`foldcore.simulate` keeps the last iterate);
        ``"none"`` for a snapshot taken outside a run
    residual : float, the estimated distance to the equilibrium at the end, relative to
        the pattern size (dimensionless): the probe's estimate for the local/global
        strategies (:mod:`foldcore.verdict`), the last Levenberg–Marquardt step's
        length for ``rigid`` (and ``hybrid`` ending in its rigid phase); NaN if
        never measured in the run
    """

    positions: np.ndarray
    fold_angles_deg: np.ndarray
    strip_angles_deg: np.ndarray
    energy: np.ndarray
    iterations: int
    converged: bool
    timings_s: dict = field(default_factory=dict)
    strip_strains: np.ndarray | None = None
    failures: list = field(default_factory=list)
    target_angles_deg: np.ndarray | None = None
    hinge_misfit_mm: np.ndarray | None = None
    reason: str = "none"
    residual: float = float("nan")


class _GroupRun:
    """Run-time arrays of one element group: parameters, outputs, state.

    For a type with a ``prepare`` kernel (see :class:`elements.ElementType`),
    also the prepared target shapes, recomputed on the first projection after
    :meth:`set_params` changed the parameters (write them only through it).
    """

    def __init__(self, group, offset: int):
        self.group = group
        self.etype = elements.get(group.kind)
        self.params = np.array(group.params, dtype=np.float64, order="C")
        self.energy = np.zeros(len(group))
        self.state = np.zeros((len(group), len(self.etype.state)))
        self.slots = slice(offset, offset + len(group.indices))
        self._shapes = None  # prepared target shapes (nnz, 3), mm, allocated on first use
        self._prepared = False  # whether _shapes matches params

    def set_params(self, rows, column: int, values) -> None:
        """``params[rows, column] = values``; the prepared shapes follow on next use."""
        self.params[rows, column] = values
        self._prepared = False

    def project(self, x, targets, weights):
        self.project_into(x, targets[self.slots], self.energy, self.state)
        return float(self.energy @ weights)

    def project_into(self, x, out, energy, state) -> None:
        """Project every element at ``x`` into the given arrays (the rows of this
        group's targets, its residuals (n,) mm², its state), with the kernel the
        iterations use (``prepared_batch`` when the type has one)."""
        g, etype = self.group, self.etype
        if etype.prepared_batch is None:
            etype.batch(x, g.indptr, g.indices, g.rest, self.params, out, energy, state)
            return
        if not self._prepared:
            if self._shapes is None:
                self._shapes = np.zeros_like(g.rest)
            etype.prepare(g.indptr, g.rest, self.params, self._shapes)
            self._prepared = True
        etype.prepared_batch(x, g.indptr, g.indices, g.rest, self._shapes, self.params, out,
                             energy, state)


class Simulation:
    """Fold a thick mesh by alternating projections and global solves.

    Parameters
    ----------
    mesh : ThickMesh
    pattern : CreasePattern
        The pattern the mesh was made from (targets, assignments, measurement).
    solver : {"hybrid", "lbfgs", "paper", "anderson", "rigid"} or a registered name
        Iteration strategy (one module each in :mod:`foldcore.strategies`),
        default ``"hybrid"`` (why: :data:`foldcore.strategies.DEFAULT_SOLVER`):
        each ``run`` starts with ``"rigid"`` steps, ends there if they meet
        the tolerance, else continues with ``"lbfgs"`` from where they stop
        (bare :meth:`step` calls are L-BFGS steps; a mesh the rigid strategy
        cannot take runs L-BFGS alone, as does a run with a fading position
        target, ``decay`` < 1).
        ``energy_history`` joins the rigid phase's energy and the paper's.
        ``"paper"``: the paper's plain local/global map (every element a soft
        spring; iterations grow with panel length / thickness).
        ``"anderson"``/``"lbfgs"``: the same local step and K, accelerated
        (safeguarded Anderson; L-BFGS with K as initial Hessian); their
        ``iterations`` are outer iterations (a refused Anderson point or a
        line-search trial costs one more local step inside the same
        iteration). ``"rigid"``: rigid panels as rigid bodies, passive hinges
        bent as one arc whose angle is a bounded unknown, Levenberg–Marquardt
        with geodesic acceleration (:mod:`foldcore.rigid_body`); needs a mesh
        of rigid panels and bending hinges. Its ``iterations`` are outer
        Levenberg–Marquardt iterations (rejected steps included) and its
        ``timings_s["projection"]`` is the residual/Jacobian assembly.
    backend : str
        Linear-solver backend: ``"auto"``, ``"cholmod"`` or ``"scipy"``.
    passive_floor_deg : float
        Fold magnitude (degrees per crease) a passive M/V hinge is given when
        its estimate has the wrong sign (§4.2 "a small value"); default 0.
    branch_floor_deg : float
        Branch selection by assignment (degrees, ≥ 0; 0 turns it off;
        :mod:`foldcore.actuation`): a run that starts from a flat sheet with
        some crease driven first folds with every passive M/V crease held at
        least this far on its assigned side, then releases them (:meth:`run`).
        Default ``BRANCH_FLOOR_DEG`` (2°).
    stop_stiffness : float
        Weight multiplier (dimensionless, ≥ 1) of a passive sub-strip bent
        past its max angle by more than ``STOP_ENTER``: the joint closes and
        acts as a stop (the M/V side is left to the projection, see
        :func:`elements.bending_hinge.limit_excess`). The
        paper's projection alone (``1``) only sets the target at the bound, so
        a position target on a long lever bends a small hinge far past it.
        Each change of the set of stops costs one numeric refactor.
    strain_limits : StrainLimits, optional
        Material limits of the hinges (:class:`foldcore.strain.StrainLimits`);
        every sub-strip's surface strain is then checked and the result lists
        the creases that failed, with the iteration and fold percent of their
        first failure. With ``solver="paper"`` every iteration is checked (its
        iterations follow a quasi-static path, as in the paper's §6.4); the
        other strategies take long steps whose intermediate iterates are not
        physical states (measured: an ``lbfgs`` run of a hinge to 90° bent its
        strips past a 45° limit while its panels read 19°), so they are
        checked where a result is taken (the end of each ``run``, or
        :meth:`result`): sweep ``set_fold_percent`` to locate a first
        failure along a path.
    actuation : {"equal", "angle"}
        What an actuated crease is (:mod:`foldcore.actuation`): ``"equal"``
        (default, the paper's) — an actuated strip weighs what a passive one
        does, so where the model binds the actuated creases share the
        misfit; ``"angle"`` — actuated strips ``ACTUATION_STIFFNESS`` (10³)
        times stiffer, so their angles are met and the rest gives way.
    threads : int, optional
        numba threads for the kernels of this simulation (set at each step,
        so simulations in one process do not override each other). Default:
        one thread below ``SERIAL_BELOW_SLOTS`` element-vertex slots (a
        parallel launch costs more than it saves there, and on a busy machine
        a launch can wait milliseconds for a descheduled thread, measured),
        else up to numba's setting, each step with one thread or all of
        them, whichever the recent steps found faster
        (:class:`foldcore.threads.ThreadChooser`: on a shared machine the
        serial steps win).
    """

    def __init__(self, mesh, pattern, solver: str = DEFAULT_SOLVER, backend: str = "auto",
                 passive_floor_deg: float = 0.0, stop_stiffness: float = 1e3,
                 threads: int | None = None, strain_limits=None,
                 actuation: str = DEFAULT_ACTUATION,
                 branch_floor_deg: float = BRANCH_FLOOR_DEG):
        start = time.perf_counter()
        try:
            strategy = strategies.get(solver)
        except KeyError as exc:
            raise SimulationError(exc.args[0]) from None
        self.mesh, self.pattern, self.solver = mesh, pattern, solver
        self.x = mesh.rest_positions.copy()
        self._runs, offset = [], 0
        for g in mesh.groups.values():
            if len(g):
                self._runs.append(_GroupRun(g, offset))
                offset += len(g.indices)
        self.threads = self._choose_threads(threads, offset)
        # the user's count is kept; the default one adapts to the machine's load
        self._chooser = ThreadChooser(self.threads) if threads is None else None
        self._guard_blas = self.threads > 1 or 3 * mesh.n_vertices >= BLAS_GUARD_FROM
        self._check_every_vertex_used()
        if actuation not in ACTUATIONS:
            raise SimulationError(f"unknown actuation {actuation!r} (available: "
                                  f"{', '.join(ACTUATIONS)})")
        self.actuation = actuation
        if not (np.isfinite(branch_floor_deg) and branch_floor_deg >= 0):
            raise SimulationError(f"branch_floor_deg must be ≥ 0 degrees, got "
                                  f"{branch_floor_deg!r}")
        self.branch_floor_deg = float(branch_floor_deg)
        self.branch_iterations = 0  # iterations spent in branch stages (run docstring)
        self.runs = 0  # calls of run so far (a run's stages share one number)
        self.stage = None  # the stage of the run in progress: "branch", "run" or None
        self._targets = np.zeros((offset, 3))
        # column-major: CHOLMOD's own layout, so the solve copies nothing in
        self._rhs = np.zeros((mesh.n_vertices, 3), order="F")
        self._hinges = next((r for r in self._runs if r.group.kind == "bending_hinge"), None)
        self._stretch = next((r for r in self._runs if r.group.kind == "stretch_hinge"), None)
        self.system = None
        self._init_stops(stop_stiffness)
        self._fold_targets = np.array(pattern.fold_angles, dtype=float)
        self._fold_targets[pattern.assignments == "F"] = 0.0
        self._percent = 100.0
        if not (np.isfinite(passive_floor_deg) and passive_floor_deg >= 0):
            raise SimulationError(f"passive floor must be ≥ 0 degrees, got "
                                  f"{passive_floor_deg!r}")
        self._passive_floor_deg = float(passive_floor_deg)  # the user's, kept across stages
        self._set_floor(self._passive_floor_deg)
        self._apply_fold_targets()
        weights = [r.group.weights if r is not self._hinges else self._hinge_weights()
                   for r in self._runs]
        self.system = System([r.group for r in self._runs], mesh.n_vertices, backend, weights)
        self._position_targets: dict[str, PositionTarget] = {}
        self._update_pins()
        self.iterations = 0
        self.energy_history: list[float] = []
        self.timings = {"setup": time.perf_counter() - start, "projection": 0.0, "solve": 0.0}
        self.length_scale = float(np.ptp(pattern.vertices, axis=0).max())
        self._scratch = False  # True while a probe projects (no stop changes)
        self.equilibrium = EquilibriumCheck(self)  # the local/global strategies' verdict
        self._monitor = self._failure_monitor(strain_limits)
        self._bare_solve = None  # (K version, seconds) of the last bare-solve timing
        self._last_fold_angles = None  # (positions, angles) of the last fold_angles call
        self.strategy = strategy(self)  # the one thing that moves self.x

    # ------------------------------------------------------------- actuation
    def set_fold_angles(self, angles) -> None:
        """Set target fold angles (degrees, valley > 0) of creases.

        Parameters
        ----------
        angles : dict {edge id: angle or None} or (E,) array (NaN = passive)
            ``None``/NaN makes a crease passive. Boundary edges cannot be set.
        """
        items = angles.items() if isinstance(angles, dict) else enumerate(np.asarray(angles))
        new = self._fold_targets.copy()
        for e, angle in items:
            e = self._checked_crease(int(e))
            new[e] = self._checked_angle(e, angle)
        self._fold_targets = new
        self._apply_fold_targets()
        self._targets_changed()

    def set_stretch_ratios(self, ratios: dict) -> None:
        """Actuate stretch hinges (§6.3): ``{edge id: λ or None}``.

        λ > 0 is the width ratio of the crease's strip (its length follows
        λ^(−ν)); ``None`` makes it passive (free to stretch). Only creases made
        stretch hinges by ``thicken(..., stretch=...)`` take a ratio.
        """
        from elements.stretch_hinge import RATIO

        run = self._stretch
        for e, ratio in dict(ratios).items():
            rows = np.zeros(0, dtype=bool) if run is None else run.group.source == int(e)
            if not rows.any():
                raise SimulationError(f"edge {e} is not a stretch hinge (see thicken's "
                                      "'stretch' argument)")
            if ratio is not None and not (np.isfinite(ratio) and ratio > 0):
                raise SimulationError(f"edge {e}: stretch ratio must be a positive number, "
                                      f"got {ratio!r}")
            run.set_params(rows, RATIO, np.nan if ratio is None else float(ratio))
        self._targets_changed()

    def stretch_ratios(self) -> np.ndarray:
        """(T, 2) measured width and length ratios of each stretch strip (current / rest)."""
        if self._stretch is None:
            return np.zeros((0, 2))
        g = self._stretch.group
        ids = g.indices.reshape(len(g), 8)
        rest = self.mesh.rest_positions

        def mean_length(pos, pairs):
            return np.mean([np.linalg.norm(pos[ids[:, i]] - pos[ids[:, j]], axis=1)
                            for i, j in pairs], axis=0)

        across, along = ((0, 1), (3, 2), (4, 5), (7, 6)), ((0, 3), (1, 2), (4, 7), (5, 6))
        return np.column_stack([mean_length(self.x, across) / mean_length(rest, across),
                                mean_length(self.x, along) / mean_length(rest, along)])

    def set_fold_percent(self, percent: float) -> None:
        """Scale every actuated target by ``percent``/100 (−100…100, as in other tools)."""
        if not (np.isfinite(percent) and -100.0 <= percent <= 100.0):
            raise SimulationError(f"fold percent must be in [-100, 100], got {percent!r}")
        self._percent = float(percent)
        self._apply_fold_targets()
        self._targets_changed()

    def predict(self, ratio: float) -> bool:
        """Start the next run from the extrapolation of the last two converged runs:
        state ≈ last + ``ratio`` × (last − the one before), rotations along their
        geodesics — the predictor of a path in small increments (a fold-percent
        sweep: ratio = Δpercent_next / Δpercent_last, :func:`foldcore.animate.fold_sweep`).

        Only the rigid-body strategies (``rigid``, ``hybrid`` after a rigid phase
        that converged) keep those states; returns whether the state moved.
        """
        if not np.isfinite(ratio):
            raise SimulationError(f"predict: ratio must be finite, got {ratio!r}")
        return bool(self.strategy.predict(float(ratio)))

    def add_position_target(self, vertices, positions=None, alpha: float = 1.0,
                            decay: float = 1.0, name: str | None = None) -> str:
        """Pull vertices toward positions (mm); returns the target's name.

        ``positions`` defaults to the vertices' current positions (a pin).
        """
        ids = np.atleast_1d(np.asarray(vertices, dtype=np.int64))
        if ids.size == 0 or ids.min() < 0 or ids.max() >= self.mesh.n_vertices:
            raise SimulationError(f"position target: vertex ids must be in "
                                  f"0..{self.mesh.n_vertices - 1}")
        pos = self.x[ids].copy() if positions is None else np.asarray(positions, float)
        pos = np.broadcast_to(pos, (len(ids), 3)).copy()
        if not np.isfinite(pos).all() or not (alpha > 0) or not (0 < decay <= 1):
            raise SimulationError("position target: positions must be finite, alpha > 0, "
                                  "0 < decay ≤ 1")
        name = name or f"target{len(self._position_targets)}"
        self._position_targets[name] = PositionTarget(ids, pos, float(alpha), float(decay))
        self._update_pins()
        self._targets_changed()
        return name

    def move_position_target(self, name: str, positions) -> None:
        """New positions (mm) for an existing target (no refactor needed)."""
        target = self._position_targets[name]
        target.positions = np.broadcast_to(np.asarray(positions, float),
                                           target.positions.shape).copy()
        self._targets_changed()

    def remove_position_target(self, name: str) -> None:
        """Stop pulling the vertices of a target."""
        del self._position_targets[name]
        self._update_pins()
        self._targets_changed()

    def set_positions(self, positions) -> None:
        """Start the next iteration from these vertex positions, (N, 3) mm.

        For restarting from a saved or perturbed state; the targets, stops and
        pins are unchanged. Not available with ``solver="rigid"``, whose state
        is its panels' rigid motions; with ``"hybrid"`` the next run continues
        from them with L-BFGS (no rigid phase, which would refit the panels).
        """
        x = np.asarray(positions, dtype=float)
        if x.shape != self.x.shape or not np.isfinite(x).all():
            raise SimulationError(f"positions must be a finite ({self.mesh.n_vertices}, 3) "
                                  f"array of mm, got shape {x.shape}")
        previous, self.x = self.x, np.ascontiguousarray(x.copy())
        try:
            self.strategy.positions_set()
        except SimulationError:
            self.x = previous
            raise

    def nearest_vertex(self, point) -> int:
        """Id of the mesh vertex closest to a 3D point (mm), current positions."""
        return int(np.argmin(np.linalg.norm(self.x - np.asarray(point, float), axis=1)))

    # ------------------------------------------------------------- iteration
    def step(self) -> float:
        """One iteration of the strategy; returns the largest vertex displacement (mm).

        With more than one numba thread, or vectors long enough for BLAS to
        thread them (``BLAS_GUARD_FROM``), BLAS runs on one thread meanwhile
        (:mod:`foldcore.threads`).
        """
        with blas_on_one_thread(self._guard_blas):
            return self._step()

    def _step(self) -> float:
        if self._chooser is None:
            numba.set_num_threads(self.threads)
            energy, moved = self.strategy.step()
        else:
            threads = self._chooser.next()
            numba.set_num_threads(threads)
            start = time.perf_counter()
            energy, moved = self.strategy.step()
            self._chooser.record(threads, time.perf_counter() - start)
        self.energy_history.append(energy)
        self.iterations += 1
        if self._monitor is not None and self.solver == "paper":
            self._monitor.check(self.x, self.iterations, self._percent)
        self._advance_alpha()
        return moved

    def local_step(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """Project every element at ``x`` and gather the right-hand side.

        Parameters
        ----------
        x : (N, 3) float, mm
            Positions to project at (need not be ``self.x``).

        Returns
        -------
        energy : float
            E(x) = Σ w‖C S x − R T‖² + pin terms, mm⁵, with the projections at x.
        rhs : (N, 3) float
            b(x) = Σ w Sᵀ R T + pin terms (an internal buffer: copy to keep it).
            With K fixed, ∇E(x) = 2 (K x − b(x)) and the global step is K⁻¹ b(x).
        """
        t0 = time.perf_counter()
        energy = sum(run.project(x, self._targets, w)
                     for run, w in zip(self._runs, self.system.weights))
        if not self._scratch:
            self._update_stops(x)
        t1 = time.perf_counter()
        rhs = self.system.rhs(self._targets, self._rhs)
        energy += self._add_pin_terms(rhs, x)
        self.timings["projection"] += t1 - t0
        self.timings["solve"] += time.perf_counter() - t1
        return energy, rhs

    @contextmanager
    def scratch_projections(self):
        """Within: :meth:`local_step` leaves the stops as they are and, on leaving, every
        group's energies and state are restored (a probe of the map, :mod:`foldcore.verdict`,
        must not change the model it checks)."""
        saved = [(run.energy.copy(), run.state.copy()) for run in self._runs]
        self._scratch = True
        try:
            yield
        finally:
            self._scratch = False
            for run, (energy, state) in zip(self._runs, saved):
                run.energy[:], run.state[:] = energy, state

    def global_step(self, rhs: np.ndarray) -> np.ndarray:
        """K⁻¹ rhs, (N, 3) mm, C-contiguous; its time counts as solve time."""
        t0 = time.perf_counter()
        out = np.ascontiguousarray(self.system.factor.solve(rhs))
        self.timings["solve"] += time.perf_counter() - t0
        return out

    def run(self, tolerance: float = 1e-8, max_iterations: int = 10_000, callback=None) -> Result:
        """Iterate until the strategy settles at an equilibrium within ``tolerance``
        (steps ≤ ``tolerance`` × pattern size and, for the local/global strategies,
        the probe of :mod:`foldcore.verdict` finding the equilibrium that close; the
        rigid-body strategies' own test, :meth:`foldcore.rigid_body.RigidBodySolver.settled`).

        From a flat sheet (every crease within ``branch_floor_deg`` of 0°) with
        a crease driven and passive M/V creases, the run has two stages: the
        branch stage (passive M/V creases held ≥ ``branch_floor_deg`` on their
        assigned side, to a relative step of ``BRANCH_TOLERANCE`` or the run's
        tolerance if looser), then the run itself from there with the floor
        released. Both count in ``max_iterations`` and in ``iterations``
        (``branch_iterations`` counts the first). A run from a folded state is
        a single stage. ``Result.reason`` says why the run ended, ``Result.residual``
        how far from the equilibrium it was estimated to be.

        Parameters
        ----------
        tolerance : float
            Relative stopping threshold (dimensionless; the pattern's larger
            extent in mm is the scale).
        max_iterations : int
        callback : callable(sim, moved_mm) -> bool or None, optional
            Called after each iteration; returning False stops the run. It runs
            with BLAS on one thread when the simulation uses several numba
            threads (:mod:`foldcore.threads`).
        """
        start = time.perf_counter()
        self.runs += 1
        self.timings.setdefault("total", self.timings["setup"])
        budget, limit = int(max_iterations), tolerance * self.length_scale
        reason = "budget"  # unless the (released) stage ends otherwise
        self.equilibrium.begin_run()
        with blas_on_one_thread(self._guard_blas):
            try:
                branch_stage = self._starts_flat()
                if branch_stage:
                    self.stage = "branch"
                    used, branch = self._branch_stage(budget, callback, limit)
                    budget -= used
                    if branch == "callback":
                        reason = branch
                self.stage = "run"
                if budget > 0 and reason != "callback":
                    _, reason = self._stage(budget, callback, limit)
                elif branch_stage:
                    self.strategy.end_run()  # the run ends with its branch stage
            finally:
                self.stage = None
        self.timings["total"] += time.perf_counter() - start
        if self.system.factored:  # a rigid-body run never needs K (System.factor)
            self.timings["bare_solve"] = self._bare_solve_floor()
        return self.result(reason == "converged", reason)

    def _stage(self, budget: int, callback, limit: float) -> tuple[int, str]:
        """One bracketed stretch of strategy steps (:meth:`_iterate`); returns
        (steps taken, why it ended: the ``reason`` of :class:`Result`)."""
        before = self.iterations
        self.equilibrium.new_run()
        self.strategy.begin_run()
        try:
            reason = self._iterate(budget, callback, limit)
        finally:
            self.strategy.end_run()
        return self.iterations - before, reason

    def _starts_flat(self) -> bool:
        """Whether this run needs the branch stage: a floor is set, some passive crease
        is M or V, some crease is driven away from flat, and the sheet is still flat
        (every crease within the floor of 0°, measured from the panels) and not yet on
        its branch (some passive M/V crease less than ``BRANCH_LEFT_DEG`` on its side).
        Why the last: a 200-frame sweep of a thin Miura 8 × 8 ran the stage at every
        frame up to 3.5 % (angles up to 2.1°, under the 2° floor's reach), 35, 17,
        8, 4… of each frame's 44, 26, 18, 14… steps, though the first frame had
        already chosen the branch."""
        if self.branch_floor_deg <= 0 or self._hinges is None:
            return False
        params = self._hinges.params
        assigned = self._passive & (params[:, SIGN] != 0.0)
        driven = ~self._passive & (params[:, TARGET] != 0.0)
        if not assigned.any() or not driven.any():
            return False
        angles = self.fold_angles()
        if not np.nanmax(np.abs(angles), initial=0.0) < self.branch_floor_deg:
            return False
        # a sheet that already left flat on its branch (every passive M/V crease on its
        # assigned side: a fold-percent sweep's first frame did) needs no stage
        side = params[assigned, SIGN] * angles[self._hinges.group.source[assigned]]
        return not bool((side >= BRANCH_LEFT_DEG).all())

    def _branch_stage(self, budget: int, callback, limit: float) -> tuple[int, str]:
        """Fold from flat with every passive M/V crease held at least
        ``branch_floor_deg`` on its assigned side, to ``BRANCH_TOLERANCE`` (or the
        run's, if looser), then release the floor to the user's (why:
        :mod:`foldcore.actuation`)."""
        floor = self._passive_floor_deg
        self._set_floor(max(floor, self.branch_floor_deg))
        self._targets_changed()
        try:
            result = self._stage(budget, callback,
                                 max(limit, BRANCH_TOLERANCE * self.length_scale))
        finally:
            self._set_floor(floor)
            self._targets_changed()
        self.branch_iterations += result[0]
        return result

    def _iterate(self, budget: int, callback, limit: float) -> str:
        """Up to ``budget`` steps, until the strategy is settled (:meth:`Strategy.settled`:
        a step within ``limit`` mm at an equilibrium), the callback says stop, or the
        plain map's rate says the budget cannot reach the equilibrium; returns the
        ``reason`` of :class:`Result`. A run whose budget ends is not settled,
        however small its last step (``"stalled"`` if its steps were within the limit
        but its last check found the equilibrium farther, else ``"budget"``)."""
        for used in range(1, budget + 1):
            moved = self._step()
            if not np.isfinite(moved):
                raise SimulationError(f"{self.pattern.source}: the iteration produced "
                                      "non-finite positions")
            if callback is not None and callback(self, moved) is False:
                return "callback"
            if self.strategy.settled(moved, limit):
                return "converged"
            if self.strategy.stalled:
                return "stalled"
            if self.strategy.plain_map and self.equilibrium.hopeless(limit, budget - used):
                return "stalled"
        return "stalled" if self.equilibrium.failed else "budget"

    def _bare_solve_floor(self) -> float:
        """:meth:`bare_solve_seconds`, timed once per factorisation of K (a sweep of
        runs, e.g. an animation, would otherwise pay its solves every run)."""
        if self._bare_solve is None or self._bare_solve[0] != self.system.version:
            self._bare_solve = (self.system.version, self.bare_solve_seconds())
        return self._bare_solve[1]

    def bare_solve_seconds(self, repeats: int = BARE_SOLVE_REPEATS) -> float:
        """Median time (s) of one K⁻¹ solve of an (N, 3) column-major right-hand side
        (the layout the iterations hand the solver): the cost floor.

        ``Result.timings_s["bare_solve"]``; the report divides the mean
        iteration time by it (``per_iteration_vs_bare_solve``).
        """
        rhs = np.asfortranarray(self.x)  # the layout the iterations hand CHOLMOD
        times = []
        for _ in range(int(repeats)):
            t0 = time.perf_counter()
            self.system.factor.solve(rhs)
            times.append(time.perf_counter() - t0)
        return float(np.median(times))

    # ------------------------------------------------------------- measuring
    @property
    def positions(self) -> np.ndarray:
        """(N, 3) current vertex positions, mm."""
        return self.x

    def fold_angles(self) -> np.ndarray:
        """(E,) fold angles in degrees from the panels' mid-planes (NaN for B, and for
        every edge of a mesh without panels)."""
        panels = self.mesh.groups.get(self.mesh.panel_group)
        if panels is None or not len(panels):
            return np.full(self.pattern.n_edges, np.nan)
        last = self._last_fold_angles  # a run's start measures where the last run ended
        if last is None or not np.array_equal(last[0], self.x):
            last = self._last_fold_angles = (self.x.copy(), fold_angles(self.pattern, self.mesh,
                                                                        self.x))
        return last[1].copy()

    def strip_angles(self) -> np.ndarray:
        """(S,) bend angle (degrees) each hinge sub-strip used in the last projection."""
        if self._hinges is None:
            return np.zeros(0)
        return np.degrees(self._hinges.state[:, 0])

    def strip_strains(self) -> np.ndarray:
        """(S, 2) top/bottom surface strain of each sub-strip at the current shape."""
        if self._hinges is None:
            return np.zeros((0, 2))
        from .strain import estimated_strip_angles, strip_strains

        g = self._hinges.group
        return strip_strains(g.params, estimated_strip_angles(g, self.x))

    def result(self, converged: bool, reason: str | None = None) -> Result:
        """Snapshot of the current state as a :class:`Result` (``reason`` defaults to
        ``"converged"`` or ``"none"`` by ``converged``).

        With strain limits and a strategy other than ``"paper"``, this is
        where the current state is checked (``run`` ends with it; a loop of
        bare ``step`` calls is checked when it takes its result).
        """
        if self._monitor is not None and self.solver != "paper":
            self._monitor.check(self.x, self.iterations, self._percent)
        timings = {k: float(v) for k, v in self.timings.items()}
        timings.setdefault("total", sum(timings.values()))
        return Result(self.x.copy(), self.fold_angles(), self.strip_angles(),
                      np.array(self.energy_history), self.iterations, converged, timings,
                      self.strip_strains(),
                      list(self._monitor.failures) if self._monitor is not None else [],
                      self.target_angles(), self.hinge_misfits(),
                      reason or ("converged" if converged else "none"),
                      float(self.equilibrium.residual))

    def target_angles(self) -> np.ndarray:
        """(E,) effective target of every crease in degrees (valley > 0): its fold
        angle × the fold percent; NaN for passive creases and boundary edges."""
        out = self._fold_targets * self._percent / 100.0
        out[self.pattern.assignments == "B"] = np.nan
        return out

    def hinge_misfits(self) -> np.ndarray:
        """(S,) RMS distance (mm) of each hinge sub-strip's vertices from its rotated
        model shape at the current positions (a fresh projection into scratch
        arrays: the simulation's own state is untouched)."""
        if self._hinges is None:
            return np.zeros(0)
        run = self._hinges
        residual = np.zeros(len(run.group))
        run.project_into(self.x, np.zeros_like(run.group.rest), residual,
                         np.zeros_like(run.state))
        return np.sqrt(np.maximum(residual, 0.0) / np.diff(run.group.indptr))

    # --------------------------------------------------------------- private
    def _targets_changed(self) -> None:
        """Targets moved: the strategy's history (energies, gradients) is stale."""
        self.strategy.targets_changed()
        self.equilibrium.targets_changed()

    def _check_every_vertex_used(self) -> None:
        """A vertex in no element has no equation: K would be singular there."""
        used = np.zeros(self.mesh.n_vertices, dtype=bool)
        for run in self._runs:
            used[run.group.indices] = True
        if not used.all():
            raise SimulationError(f"vertex {int(np.argmin(used))} belongs to no element "
                                  f"({int((~used).sum())} such vertices): the mesh's groups "
                                  "must cover every vertex")

    def _failure_monitor(self, limits):
        if limits is None or self._hinges is None:
            return None
        from .strain import FailureMonitor, StrainLimits

        if not isinstance(limits, StrainLimits):
            raise SimulationError(f"strain_limits must be a foldcore.strain.StrainLimits, "
                                  f"got {type(limits).__name__}")
        try:
            return FailureMonitor(self._hinges.group, limits, self.pattern.n_edges,
                                  self.mesh.segments)
        except ValueError as exc:
            raise SimulationError(str(exc)) from None

    @staticmethod
    def _choose_threads(threads, slots: int) -> int:
        if threads is None:
            return 1 if slots < SERIAL_BELOW_SLOTS else numba.config.NUMBA_NUM_THREADS
        if not (isinstance(threads, (int, np.integer)) and
                1 <= threads <= numba.config.NUMBA_NUM_THREADS):
            raise SimulationError(f"threads must be an integer in "
                                  f"1..{numba.config.NUMBA_NUM_THREADS}, got {threads!r}")
        return int(threads)

    def _checked_crease(self, e: int) -> int:
        if not 0 <= e < self.pattern.n_edges:
            raise SimulationError(f"edge {e} does not exist (0..{self.pattern.n_edges - 1})")
        if self.pattern.assignments[e] == "B":
            raise SimulationError(f"edge {e} is a boundary edge and has no hinge")
        if self._stretch is not None and (self._stretch.group.source == e).any():
            raise SimulationError(f"edge {e} is a stretch hinge: set its stretch ratio "
                                  "(set_stretch_ratios), not a fold angle")
        return e

    def _checked_angle(self, e: int, angle) -> float:
        if angle is None or np.isnan(angle):
            return np.nan
        kind, limit = self.pattern.assignments[e], self.pattern.max_angles[e]
        if kind == "M" and angle > 0 or kind == "V" and angle < 0 or abs(angle) > limit:
            raise SimulationError(f"edge {e}: target {angle:g}° is not allowed for a "
                                  f"{kind!r} crease with max angle {limit:g}°")
        return float(angle)

    def _apply_fold_targets(self) -> None:
        if self._hinges is None:
            return
        src = self._hinges.group.source
        k = self.mesh.subdivisions[src]
        target = np.radians(self._fold_targets[src] * self._percent / 100.0) / k
        self._hinges.set_params(slice(None), TARGET, target)
        self._passive = np.isnan(target)
        self._sync_hinge_weights()

    def _hinge_weights(self) -> np.ndarray:
        """(S,) hinge strip weights, mm³: their volume weights × the stop factor on
        stops × ``ACTUATION_STIFFNESS`` on actuated strips under ``actuation="angle"``."""
        g = self._hinges.group
        factor = np.where(self.stops, self._stop_factor, 1.0)
        if self.actuation == "angle":
            factor = factor * np.where(self._passive, 1.0, ACTUATION_STIFFNESS)
        return factor * g.weights

    def _sync_hinge_weights(self) -> None:
        """Hand the current hinge weights to K (a numeric refactor if they changed)."""
        if self.system is not None and self._hinges is not None:
            self.system.set_weights(self._hinge_index, self._hinge_weights())

    def _init_stops(self, stop_stiffness: float) -> None:
        if not (np.isfinite(stop_stiffness) and stop_stiffness >= 1.0):
            raise SimulationError(f"stop_stiffness must be a finite number ≥ 1, "
                                  f"got {stop_stiffness!r}")
        self._stop_factor = float(stop_stiffness)
        self.stops = np.zeros(0, dtype=bool)
        if self._hinges is not None:
            self._hinge_index = self._runs.index(self._hinges)
            self.stops = np.zeros(len(self._hinges.group), dtype=bool)
            self._excess = np.zeros(len(self._hinges.group))

    def _update_stops(self, x: np.ndarray) -> None:
        """Stiffen passive strips bent past their max angle at ``x``; release them once
        back inside."""
        if self._stop_factor == 1.0 or self._hinges is None:
            return
        if not self._passive.any() and not self.stops.any():
            return  # all actuated: no estimate to check (stops only on passive strips)
        g = self._hinges.group
        limit_excess(x, g.indptr, g.indices, self._hinges.params, self._excess)
        excess = np.where(self._passive, self._excess, -np.inf)
        stops = np.where(self.stops, excess > -STOP_LEAVE, excess > STOP_ENTER)
        if np.array_equal(stops, self.stops):
            return
        self.stops = stops
        self._sync_hinge_weights()

    def _set_floor(self, floor_deg: float) -> None:
        if self._hinges is not None:
            k = self.mesh.subdivisions[self._hinges.group.source]
            self._hinges.set_params(slice(None), FLOOR, np.radians(floor_deg) / k)

    def _update_pins(self) -> None:
        weights = np.zeros(self.mesh.n_vertices)
        for t in self._position_targets.values():
            np.add.at(weights, t.vertices, t.alpha * self.system.reference_weight)
        if not self._position_targets:  # anchor: fixes the free translation exactly
            weights[0] = self.system.reference_weight
        self._pin_weights = weights
        self.system.set_pin_weights(weights)

    def _add_pin_terms(self, rhs: np.ndarray, x: np.ndarray) -> float:
        if not self._position_targets:
            rhs[0] += self._pin_weights[0] * x[0]
            return 0.0
        energy = 0.0
        for t in self._position_targets.values():
            w = t.alpha * self.system.reference_weight
            np.add.at(rhs, t.vertices, w * t.positions)
            energy += w * float(((x[t.vertices] - t.positions) ** 2).sum())
        return energy

    def _advance_alpha(self) -> None:
        decaying = [t for t in self._position_targets.values() if t.decay < 1.0]
        if not decaying or self.iterations % ALPHA_UPDATE_EVERY:
            return
        for name, t in list(self._position_targets.items()):
            t.alpha *= t.decay ** ALPHA_UPDATE_EVERY
            if t.alpha < 1e-6:
                del self._position_targets[name]
        self._update_pins()
