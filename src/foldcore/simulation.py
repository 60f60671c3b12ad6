"""Simulation: the run driver — stages, steps, verdict, result (paper §3–4).

A :class:`Simulation` holds a :class:`foldcore.model.Model` (the state and
its local and global step), one strategy that moves it
(:mod:`foldcore.strategies`) and the convergence test the strategy reports
to (:mod:`foldcore.convergence`). Units at this API: mm for lengths and
positions, degrees for angles.
"""
from __future__ import annotations

import logging
import time

import numba
import numpy as np

from elements.bending_hinge import SIGN, TARGET

from . import strategies
from .actuation import BRANCH_FLOOR_DEG, BRANCH_TOLERANCE, DEFAULT_ACTUATION
from .convergence import ConvergenceTest, Progress
from .errors import SimulationError
from .limits import TOLERANCE
from .model import Model
from .model.model import BARE_SOLVE_REPEATS
from .result import Result
from .strategies import DEFAULT_SOLVER
from .threads import BLAS_GUARD_FROM, ThreadChooser, blas_on_one_thread, choose_threads

log = logging.getLogger(__name__)

#: Degrees on its assigned side every passive M/V crease must be for a sheet within
#: the branch floor to count as having left flat on its branch (no branch stage).
BRANCH_LEFT_DEG = 1e-3


class Simulation:
    """Fold a thick mesh: a model, a strategy that moves it, a test that stops it.

    Parameters
    ----------
    mesh : ThickMesh
    pattern : CreasePattern
        The pattern the mesh was made from (targets, assignments, measurement).
    solver : str
        Iteration strategy, a built-in (``"hybrid"``, the default, ``"paper"``,
        ``"anderson"``, ``"lbfgs"``, ``"rigid"``, ``"newton"``) or a registered
        name: `docs/guide/strategies.md`.
    backend : {"auto", "cholmod", "scipy"}
        Linear-solver backend.
    passive_floor_deg : float
        Fold magnitude (degrees per crease) a passive M/V hinge is given when
        its estimate has the wrong sign (§4.2 "a small value"); default 0.
    stop_stiffness : float
        Weight factor (≥ 1) of a passive sub-strip bent past its max angle: the
        joint closes and acts as a stop (each change of the stops refactors K).
    threads : int, optional
        numba threads of this simulation's kernels (default: one below a few
        hundred element-vertex slots, else whichever of one and all the recent
        steps found faster, :class:`foldcore.threads.ThreadChooser`).
    strain_limits : StrainLimits, optional
        Material limits of the hinges (:class:`foldcore.strain.StrainLimits`):
        the result lists the creases that failed. Checked at every iteration
        with ``solver="paper"`` (its iterates follow a quasi-static path), else
        where a result is taken.
    actuation : {"equal", "angle"}
        What an actuated crease is (:mod:`foldcore.actuation`).
    branch_floor_deg : float
        Branch selection by assignment (degrees ≥ 0, 0: off): a run from a flat
        sheet first folds with every passive M/V crease held this far on its
        assigned side, then releases them (:meth:`run`).
    options : dataclass, optional
        The strategy's options (its ``Options`` class, e.g.
        :class:`foldcore.strategies.rigid.RigidOptions`).
    convergence : type, optional
        The convergence test (a :class:`foldcore.convergence.ConvergenceTest`
        subclass), built with the model and the run's progress.
    contact : {"auto", "on", "off"}, bool or ContactSettings
        Panels no crease joins never pass through each other (:mod:`foldcore.contact`):
        ``"auto"`` (default) wherever the run can (``model.contact_off`` says why
        not), ``"on"`` (True, settings) or an error, ``"off"`` (False) unchecked.
    obstacles : sequence of foldcore.contact.Obstacle (fixed; they need contact)
    """

    def __init__(self, mesh, pattern, solver: str = DEFAULT_SOLVER, backend: str = "auto",
                 passive_floor_deg: float = 0.0, stop_stiffness: float = 1e3,
                 threads: int | None = None, strain_limits=None,
                 actuation: str = DEFAULT_ACTUATION,
                 branch_floor_deg: float = BRANCH_FLOOR_DEG, options=None,
                 convergence=ConvergenceTest, contact="auto", obstacles=()):
        start = time.perf_counter()
        try:
            strategy = strategies.get(solver)
        except KeyError as exc:
            raise SimulationError(exc.args[0]) from None
        if not (np.isfinite(branch_floor_deg) and branch_floor_deg >= 0):
            raise SimulationError(f"branch_floor_deg must be ≥ 0 degrees, got "
                                  f"{branch_floor_deg!r}")
        self.model = Model(mesh, pattern, backend, passive_floor_deg, stop_stiffness, actuation)
        self.solver, self.branch_floor_deg = solver, float(branch_floor_deg)
        self.threads = choose_threads(threads, len(self.model.slot_targets))
        # the user's count is kept; the default one adapts to the machine's load
        self._chooser = ThreadChooser(self.threads) if threads is None else None
        self._guard_blas = self.threads > 1 or 3 * mesh.n_vertices >= BLAS_GUARD_FROM
        self.progress = Progress()
        self.branch_iterations = 0  # iterations spent in branch stages (run docstring)
        self.model.timings["setup"] = time.perf_counter() - start
        self.convergence = convergence(self.model, self.progress)
        self._monitor = self._failure_monitor(strain_limits)
        self.model.contact = contact_model(self.model, strategy, contact, obstacles)
        self._bare_solve = None  # (K version, seconds) of the last bare-solve timing
        self.strategy = strategy(self.model, self.progress, options)  # moves model.x
        self.convergence.attach(self.strategy)
        self.model.subscribe(self._targets_changed)

    # ------------------------------------------------------------ the model
    @property
    def x(self) -> np.ndarray:
        """(N, 3) current vertex positions, mm."""
        return self.model.x

    positions = x

    @property
    def mesh(self):
        return self.model.mesh

    @property
    def pattern(self):
        return self.model.pattern

    @property
    def system(self):
        """K and its factor (:class:`foldcore.system.System`)."""
        return self.model.system

    @property
    def length_scale(self) -> float:
        """The pattern's larger extent, mm (tolerances are relative to it)."""
        return self.model.length_scale

    @property
    def iterations(self) -> int:
        return self.progress.iterations

    @property
    def energy_history(self) -> list:
        """The energy before each step so far, mm⁵."""
        return self.progress.energies

    @property
    def timings(self) -> dict:
        """Seconds spent so far: ``setup``, ``projection``, ``solve``, ``total``…"""
        return self.model.timings

    @property
    def thread_chooser(self):
        """The :class:`foldcore.threads.ThreadChooser` of a simulation whose thread count
        the user left to it (None when fixed)."""
        return self._chooser

    @property
    def runs(self) -> int:
        return self.progress.runs

    @property
    def stage(self) -> str | None:
        return self.progress.stage

    def set_fold_angles(self, angles) -> None:
        """Target fold angles (degrees, valley > 0): :meth:`Model.set_fold_angles`."""
        self.model.set_fold_angles(angles)

    def set_fold_percent(self, percent: float) -> None:
        """Scale every actuated target by ``percent``/100 (−100…100)."""
        self.model.set_fold_percent(percent)

    def set_stretch_ratios(self, ratios: dict) -> None:
        """Actuate stretch hinges: :meth:`Model.set_stretch_ratios`."""
        self.model.set_stretch_ratios(ratios)

    def add_position_target(self, vertices, positions=None, alpha: float = 1.0,
                            decay: float = 1.0, name: str | None = None) -> str:
        """Pull vertices toward positions (mm): :meth:`Model.add_position_target`."""
        return self.model.add_position_target(vertices, positions, alpha, decay, name)

    def move_position_target(self, name: str, positions) -> None:
        self.model.move_position_target(name, positions)

    def remove_position_target(self, name: str) -> None:
        self.model.remove_position_target(name)

    def set_positions(self, positions) -> None:
        """Start the next iteration from these vertex positions, (N, 3) mm; targets,
        stops and pins unchanged. Refused by ``solver="rigid"`` (its state is its
        panels' rigid motions); ``"hybrid"`` continues from them with L-BFGS."""
        x = self.model.checked_positions(positions)
        previous, self.model.x = self.model.x, x
        try:
            self.strategy.positions_set()
        except SimulationError:
            self.model.x = previous
            raise

    def predict(self, ratio: float) -> bool:
        """Start the next run from the extrapolation of the last two converged runs
        (state ≈ last + ``ratio`` × (last − the one before), rotations along their
        geodesics): a path's predictor. Only the rigid-body strategies keep those
        states; returns whether the state moved."""
        if not np.isfinite(ratio):
            raise SimulationError(f"predict: ratio must be finite, got {ratio!r}")
        return bool(self.strategy.predict(float(ratio)))

    def nearest_vertex(self, point) -> int:
        return self.model.nearest_vertex(point)

    def fold_angles(self) -> np.ndarray:
        """(E,) fold angles in degrees from the panels' mid-planes (NaN for B)."""
        return self.model.fold_angles()

    def strip_angles(self) -> np.ndarray:
        return self.model.strip_angles()

    def strip_strains(self) -> np.ndarray:
        return self.model.strip_strains()

    def stretch_ratios(self) -> np.ndarray:
        return self.model.stretch_ratios()

    def target_angles(self) -> np.ndarray:
        return self.model.target_angles()

    def hinge_misfits(self) -> np.ndarray:
        return self.model.hinge_misfits()

    def bare_solve_seconds(self, repeats: int = BARE_SOLVE_REPEATS) -> float:
        """Median seconds of one K⁻¹ solve (:meth:`Model.bare_solve_seconds`)."""
        return self.model.bare_solve_seconds(repeats)

    # ------------------------------------------------------------ iteration
    def step(self) -> float:
        """One iteration of the strategy; returns the largest vertex displacement (mm).
        BLAS runs on one thread meanwhile where it would compete with numba's."""
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
        self.progress.record(energy)
        if self._monitor is not None and self.solver == "paper":
            self._monitor.check(self.model.x, self.progress.iterations, self.model.fold_percent)
        self.model.pins.advance(self.progress.iterations)
        return moved

    def run(self, tolerance: float = 1e-8, max_iterations: int = 10_000, callback=None) -> Result:
        """Iterate until the convergence test finds the state settled within
        ``tolerance`` × the pattern's size (:mod:`foldcore.convergence`), the budget
        ends or the callback says stop.

        A run from a flat sheet with a crease driven and passive M/V creases has
        two stages: the branch stage (passive M/V creases held at least
        ``branch_floor_deg`` on their assigned side, to a relative step of
        ``BRANCH_TOLERANCE`` or the run's tolerance if looser), then the run
        itself with the floor released; both count in ``max_iterations``.

        Parameters
        ----------
        tolerance : float
            Relative stopping threshold (the pattern's larger extent, mm, is the scale),
            at most 1e-2 (:data:`foldcore.limits.TOLERANCE`: a looser one reads
            "converged" degrees short of the equilibrium); 0 runs the whole budget.
        max_iterations : int
        callback : callable(sim, moved_mm) -> bool or None, optional
            Called after each iteration; returning False stops the run.
        """
        if not 0 <= tolerance <= TOLERANCE[1]:
            raise SimulationError(f"{self.model.pattern.source}: tolerance must be in [0, "
                                  f"{TOLERANCE[1]:g}] (× the pattern's size), got {tolerance!r}")
        start = time.perf_counter()
        self.progress.runs += 1
        self.timings.setdefault("total", self.timings["setup"])
        budget, limit = int(max_iterations), tolerance * self.model.length_scale
        reason = "budget"  # unless the (released) stage ends otherwise
        self.convergence.begin_run()
        log.info("run %d: %s, fold percent %g, tolerance %g, budget %d", self.progress.runs,
                 self.solver, self.model.fold_percent, tolerance, budget)
        with blas_on_one_thread(self._guard_blas):
            try:
                branch_stage = self._starts_flat()
                if branch_stage:
                    self.progress.stage = "branch"
                    used, branch = self._branch_stage(budget, callback, limit)
                    budget -= used
                    if branch == "callback":
                        reason = branch
                self.progress.stage = "run"
                if budget > 0 and reason != "callback":
                    _, reason = self._stage(budget, callback, limit)
                elif branch_stage:
                    self.strategy.end_run()  # the run ends with its branch stage
            finally:  # an interrupted run's time counts too
                self.progress.stage = None
                self.timings["total"] += time.perf_counter() - start
        if self.model.system.factored:  # `rigid` never needs K
            self.timings["bare_solve"] = self._bare_solve_floor()
        result = self.result(reason == "converged", reason)
        log.info("run %d ended %s after %d iterations (residual %.2g, %.3g s)",
                 self.progress.runs, reason, result.iterations, result.residual,
                 time.perf_counter() - start)
        return result

    def _stage(self, budget: int, callback, limit: float) -> tuple[int, str]:
        """One bracketed stretch of strategy steps; returns (steps taken, reason)."""
        before = self.progress.iterations
        self.convergence.new_stage()
        self.strategy.begin_run()
        try:
            reason = self._iterate(budget, callback, limit)
        finally:
            self.strategy.end_run()
        return self.progress.iterations - before, reason

    def _iterate(self, budget: int, callback, limit: float) -> str:
        """Up to ``budget`` steps, each reported to the convergence test, until it ends
        the run or the callback says stop; returns the ``reason`` of :class:`Result`."""
        for used in range(1, budget + 1):
            moved = self._step()
            if not np.isfinite(moved):
                raise SimulationError(f"{self.model.pattern.source}: the iteration produced "
                                      "non-finite positions")
            if callback is not None and callback(self, moved) is False:
                return "callback"
            report = self.strategy.report(moved, limit)
            reason = self.convergence.check(report, limit, budget - used)
            if reason is not None:
                return reason
        return self.convergence.at_budget(limit)

    def _starts_flat(self) -> bool:
        """Whether this run needs the branch stage: a floor is set, some passive crease
        is M or V, some crease is driven away from flat, the sheet is still flat
        (every crease within the floor of 0°) and not yet on its branch (some
        passive M/V crease less than ``BRANCH_LEFT_DEG`` on its side): a sweep's
        later frames need no stage. Why: `docs/architecture.md#branch-selection`."""
        hinges = self.model.hinges
        if self.branch_floor_deg <= 0 or hinges is None:
            return False
        params, passive = hinges.params, self.model.passive
        assigned = passive & (params[:, SIGN] != 0.0)
        driven = ~passive & (params[:, TARGET] != 0.0)
        if not assigned.any() or not driven.any():
            return False
        angles = self.fold_angles()
        if not np.nanmax(np.abs(angles), initial=0.0) < self.branch_floor_deg:
            return False
        side = params[assigned, SIGN] * angles[hinges.group.source[assigned]]
        return not bool((side >= BRANCH_LEFT_DEG).all())

    def _branch_stage(self, budget: int, callback, limit: float) -> tuple[int, str]:
        """Fold from flat with every passive M/V crease held at least
        ``branch_floor_deg`` on its assigned side, to ``BRANCH_TOLERANCE`` (or the
        run's, if looser), then release the floor to the user's."""
        model = self.model
        floor = model.passive_floor_deg
        model.set_floor(max(floor, self.branch_floor_deg))
        log.info("branch stage: passive M/V creases held %g° on their assigned side",
                 self.branch_floor_deg)
        try:
            result = self._stage(budget, callback,
                                 max(limit, BRANCH_TOLERANCE * model.length_scale))
        finally:
            model.set_floor(floor)
        self.branch_iterations += result[0]
        log.info("branch stage ended %s after %d steps; floor released", result[1], result[0])
        return result

    def _bare_solve_floor(self) -> float:
        """:meth:`bare_solve_seconds`, timed once per factorisation of K."""
        version = self.model.system.version
        if self._bare_solve is None or self._bare_solve[0] != version:
            self._bare_solve = (version, self.bare_solve_seconds())
        return self._bare_solve[1]

    # ------------------------------------------------------------ the result
    def result(self, converged: bool, reason: str | None = None) -> Result:
        """Snapshot of the current state as a :class:`Result` (``reason`` defaults to
        ``"converged"`` or ``"none"`` by ``converged``). With strain limits and a
        strategy other than ``"paper"``, this is where the state is checked."""
        model = self.model
        if self._monitor is not None and self.solver != "paper":
            self._monitor.check(model.x, self.progress.iterations, model.fold_percent)
        timings = {k: float(v) for k, v in self.timings.items()}
        timings.setdefault("total", sum(timings.values()))
        contact = contact_summary(model)
        return Result(model.x.copy(), model.fold_angles(), model.strip_angles(),
                      np.array(self.progress.energies), self.progress.iterations, converged,
                      timings, model.strip_strains(),
                      list(self._monitor.failures) if self._monitor is not None else [],
                      model.target_angles(), model.hinge_misfits(),
                      reason or ("converged" if converged else "none"),
                      float(self.convergence.residual), contact,
                      position_target_entries(model, contact))

    @property
    def failures(self) -> list:
        """Creases that exceeded their strain limits so far (empty without limits)."""
        return [] if self._monitor is None else list(self._monitor.failures)

    def _targets_changed(self) -> None:
        """The problem changed: the strategy's history and the test's energies are stale."""
        self.strategy.targets_changed()
        self.convergence.targets_changed()

    def _failure_monitor(self, limits):
        hinges = self.model.hinges
        if limits is None or hinges is None:
            return None
        from .strain import FailureMonitor, StrainLimits

        if not isinstance(limits, StrainLimits):
            raise SimulationError(f"strain_limits must be a foldcore.strain.StrainLimits, "
                                  f"got {type(limits).__name__}")
        try:
            return FailureMonitor(hinges.group, limits, self.model.pattern.n_edges,
                                  self.model.mesh.segments)
        except ValueError as exc:
            raise SimulationError(str(exc)) from None


def contact_model(model, strategy, contact, obstacles=()):
    """The :class:`foldcore.contact.ContactModel` ``contact`` asks for, with
    ``obstacles`` (:class:`foldcore.contact.Obstacle`, which need contact).

    ``contact``: None or ``"auto"`` (the default): on where the run can keep panels
    apart, else off with the reason :func:`contact_unfit` gives kept in
    ``model.contact_off``; True, ``"on"`` or a
    :class:`foldcore.contact.ContactSettings`: on, and a SimulationError where it
    cannot be; False, ``"off"``: off. SimulationError where an obstacle touches a
    panel at the start."""
    obstacles = list(obstacles or ())
    if contact in (False, "off"):
        if obstacles:
            raise SimulationError("obstacles need contact: drop contact=False")
        model.contact_off = "turned off (contact='off')"
        return None
    auto = contact is None or contact == "auto"
    if auto and not obstacles:
        model.contact_off = contact_unfit(model, strategy)
        if model.contact_off:
            return None
        contact = True
    from .contact import ContactSettings

    settings = ContactSettings() if contact in (True, "on", None, "auto") else contact
    if not isinstance(settings, ContactSettings):
        raise SimulationError(f"contact must be 'auto', True, False or a "
                              f"foldcore.contact.ContactSettings, got {contact!r}")
    if not strategy.supports_contact:
        supported = [name for name in strategies.available()
                     if strategies.get(name).supports_contact]
        raise SimulationError(f"solver {strategy.name!r} does not keep panels apart; "
                              f"contact needs one of {supported}")
    if not model.mesh.thickness > 0:
        raise SimulationError("contact needs a sheet of thickness > 0")
    if model.mesh.panel_group != "rigid_panel" or _faces_split(model.mesh):
        raise SimulationError("contact needs one rigid panel per face (this mesh's faces "
                              "are elastic cells: drop the elastic cells or contact)")
    from .contact import ContactModel

    try:
        built = ContactModel(model.mesh, model.pattern, model.system.reference_weight,
                             settings, obstacles)
    except ImportError:
        raise SimulationError("contact needs the ipctk package: pip install 'foldcore[contact]'") \
            from None
    touching = built.obstacles_touching(model.x)
    if touching:
        face = model.mesh.groups[model.mesh.panel_group].source
        p, o = touching[0]
        raise SimulationError(f"obstacle {obstacles[o].name!r} touches or cuts the panel of "
                              f"face {int(face[p])} at the start ({len(touching)} panel(s)); "
                              f"move it clear of the sheet (its faces are at ±H/2 = "
                              f"±{0.5 * model.mesh.thickness:g} mm)")
    return built


#: Why the default contact is off where ipctk is missing (the command line says it).
NO_IPCTK = "the ipctk package is not installed (pip install 'foldcore[contact]')"


def contact_unfit(model, strategy) -> str | None:
    """Why the default contact is off for this run (None: it is on): a thin sheet, a
    strategy whose steps are not checked, faces split into elastic cells, cuts,
    hinges whose axis drifts off the crease, or no ipctk."""
    if not model.mesh.thickness > 0:
        return "a sheet without thickness"
    if not strategy.supports_contact:
        return f"solver {strategy.name!r} does not keep panels apart"
    if model.mesh.panel_group != "rigid_panel" or _faces_split(model.mesh):
        return "faces split into elastic cells"
    if len(model.pattern.copied_from):
        return "the sheet has cuts: the panels either side of a slit touch from the start"
    drifting = sorted(set(model.mesh.hinge_model) & {"arc", "eq8"})
    if drifting:
        return (f"{' and '.join(drifting)} hinges turn their panels about an axis off the "
                f"crease, past what contact leaves to a hinge (contact='on' checks them)")
    import importlib.util

    if importlib.util.find_spec("ipctk") is None:
        return NO_IPCTK
    return None


#: A position target "misses" beyond this share of the pattern's size (Result).
TARGET_MISS = 1e-3


def _faces_split(mesh) -> bool:
    """Whether a face of the pattern is more than one panel element (an elastic
    plate's cells): contact's solids are whole panels, and cells of one face, or
    of two faces a crease joins, would touch by construction."""
    source = np.asarray(mesh.groups[mesh.panel_group].source)
    return len(np.unique(source)) < len(source)


def position_target_entries(model, contact: dict | None) -> list | None:
    """:attr:`Result.position_targets` at the model's positions (None: no targets);
    ``contact``: :func:`contact_summary` there (its touching faces: panels within
    the barrier's reach, on an obstacle, or cutting the last step)."""
    targets = model.pins.targets
    if not targets:
        return None
    touching = bool(contact and (contact["touching_faces"] or contact["touching_creases"]))
    limit = TARGET_MISS * model.length_scale
    out = []
    for name, (worst, mean) in model.pins.misses(model.x).items():
        stopped = None if worst <= limit else ("contact" if touching else "pull")
        out.append({"name": name, "vertices": int(len(targets[name].vertices)),
                    "alpha": targets[name].alpha, "miss_mm": worst, "mean_miss_mm": mean,
                    "stopped_by": stopped})
    return out


def contact_summary(model) -> dict | None:
    """:attr:`Result.contact` at the model's positions (None without contact): parts
    named as the folded solid names them, a panel by its pattern face (an int), a
    hinge strip as ``{"crease": e}``."""
    contact = model.contact
    if contact is None:
        return None
    state = contact.state(model.x)
    solids = contact.solids
    face = model.mesh.groups[model.mesh.panel_group].source
    labels = [int(face[p]) for p in range(solids.n_panels)] + \
        [{"crease": int(e)} for e in solids.part_crease[solids.n_panels:]]
    forces = contact.forces(state)
    blocking = np.array(contact.blocking, dtype=np.int64).reshape(-1, 2)
    touching = np.unique(np.concatenate([state.pairs.ravel(), state.obstacle_pairs[:, 0],
                                         blocking.ravel()])).astype(np.int64)
    panels, strips = touching[touching < solids.n_panels], touching[touching >= solids.n_panels]
    obstacles = [] if contact.obstacles is None else contact.obstacles.obstacles
    pressed = contact.obstacle_forces(state)
    pairs = lambda found: [[labels[a], labels[b]] for a, b in found]  # noqa: E731
    return {"active_pairs": pairs(state.pairs),
            "blocking_pairs": pairs(blocking),
            "obstacles": [{"name": o.name,
                           "touching_faces": sorted(int(face[p]) for p, k in state.obstacle_pairs
                                                    if k == i and p < solids.n_panels),
                           "touching_creases": sorted(int(solids.part_crease[p])
                                                      for p, k in state.obstacle_pairs
                                                      if k == i and p >= solids.n_panels),
                           "force": pressed[i].tolist(),
                           "magnitude": float(np.linalg.norm(pressed[i]))}
                          for i, o in enumerate(obstacles)],
            "smallest_gap_mm": _smallest(np.concatenate([state.gaps, state.obstacle_gaps])),
            "activation_mm": contact.dhat, "stiffness": contact.kappa,
            "touching_faces": face[panels].tolist(),
            "touching_creases": solids.part_crease[strips].tolist(),
            "panel_forces": [{"face": int(face[p]), "force": forces[p].tolist(),
                              "magnitude": float(np.linalg.norm(forces[p]))} for p in panels],
            "strip_forces": [{"crease": int(solids.part_crease[p]), "force": forces[p].tolist(),
                              "magnitude": float(np.linalg.norm(forces[p]))} for p in strips]}


def _smallest(values: np.ndarray) -> float | None:
    return float(values.min()) if len(values) else None
