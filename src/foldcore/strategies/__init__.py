"""Iteration strategies: one module each, behind one small protocol (STYLE.md §14).

A :class:`foldcore.Simulation` holds the model — geometry, element groups,
actuation, pins and the current positions ``sim.x`` — and hands itself to
one strategy, which only moves the state. Built in:

* ``paper`` — the paper's local/global map (:mod:`.paper`).
* ``anderson`` — the same map with safeguarded Anderson acceleration
  (:mod:`.anderson`).
* ``lbfgs`` — L-BFGS on the local/global energy, K as initial Hessian
  (:mod:`.lbfgs`).
* ``rigid`` — rigid panels as rigid bodies, Levenberg–Marquardt with geodesic
  acceleration (:mod:`.rigid`, engine in :mod:`foldcore.rigid_body`).
* ``hybrid`` — a composite: each run starts with ``rigid`` steps, ends
  there once they meet the tolerance, else continues with ``newton``
  (``lbfgs`` on meshes it refuses) from where they stop; a mesh whose
  elastic faces are all cut into rings starts on its rigid-panel twin and
  finishes with ``newton``; other meshes
  ``rigid`` cannot take (bars, plates, other element types) run ``lbfgs``
  (:mod:`.hybrid`).
* ``newton`` — Gauss–Newton / Levenberg–Marquardt on every vertex, each
  step corrected by the paper's map (:mod:`.newton`): for elastic cells.

The protocol (:class:`Strategy`): ``step()`` advances ``sim.x`` by one
iteration and returns (energy before, largest move in mm); ``settled(moved,
limit)`` says whether a run may stop after a step that moved ``moved`` mm —
by default only when the equilibrium probe agrees (:mod:`foldcore.verdict`:
a small step alone is not a verdict; a composite may change phase there
instead); ``begin_run()`` /
``end_run()`` bracket every :meth:`Simulation.run` (``end_run`` also when
it is interrupted); ``targets_changed()`` / ``positions_set()`` tell it that
the model changed under it. A user strategy is a subclass in any module
(registered by class definition, like element types); the names below are
importable without numba or SciPy, for the command line.
"""
from __future__ import annotations

import importlib

SOLVERS = ("paper", "anderson", "lbfgs", "rigid", "hybrid", "newton")
_BUILTIN_MODULES = {name: f"foldcore.strategies.{name}" for name in SOLVERS}
_REGISTRY: dict[str, type] = {}

#: The default strategy (bench/convergence, bench/accuracy, README tables):
#: ``hybrid``. Its rigid phase brings long panels and closed loops to the
#: rigid-body model's equilibrium in a few iterations whatever the panel
#: length (single hinge to 0.01° in 3–8 iterations at Lp/H = 5–320, where
#: ``lbfgs`` alone needs 29–1 960 and ``paper`` 10 280 and never; thin
#: vertices, the waterbomb and Miura sheets up to 20 × 20 from flat, where
#: the local/global strategies mostly do not fold within 20 000 iterations)
#: and ends the run there; L-BFGS takes over where that phase cannot
#: settle, and runs alone on meshes it cannot take (elastic cells, other
#: element types).
DEFAULT_SOLVER = "hybrid"


class Strategy:
    """Base class of iteration strategies; subclasses register themselves by ``name``.

    Parameters
    ----------
    sim : Simulation
        The model to advance: its positions ``sim.x`` (N, 3) mm, its local
        step (:meth:`Simulation.local_step`), global step and factor of K,
        its hinge parameters, pins and timings.
    """

    name: str = ""
    abstract: bool = False  # True in a class's own body: a base for others, not registered
    #: Whether the steps are the paper's plain map, whose rate the equilibrium probe
    #: measures (:mod:`foldcore.verdict`): then a run that cannot reach the equilibrium
    #: within its budget at that rate ends at once, ``stalled``.
    plain_map: bool = False

    @property
    def stalled(self) -> bool:
        """Whether the steps are at the strategy's resolution: they no longer change the
        energy beyond rounding and no longer shrink, so no budget would bring the
        run closer; the run then ends ``stalled`` (default: never)."""
        return False

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.__dict__.get("abstract", False):
            return
        if not cls.name:
            raise TypeError(f"{cls.__qualname__} must set a non-empty `name`")
        _REGISTRY[cls.name] = cls

    def __init__(self, sim):
        self.sim = sim

    def step(self) -> tuple[float, float]:
        """One iteration: (energy before it in mm⁵, largest vertex move in mm);
        writes the new positions to ``sim.x``."""
        raise NotImplementedError

    def settled(self, moved: float, limit: float) -> bool:
        """Whether a run may stop after a step that moved ``moved`` mm (limit: the
        run's tolerance × pattern size, mm). Default: the step is within the limit
        and the equilibrium probe finds the state that close to the paper model's
        equilibrium (:class:`foldcore.verdict.EquilibriumCheck`, ``sim.equilibrium``)."""
        return self.sim.equilibrium.settled(moved, limit)

    def begin_run(self) -> None:
        """A :meth:`Simulation.run` starts."""

    def end_run(self) -> None:
        """A run ended (converged, out of budget, stopped or interrupted)."""

    def targets_changed(self) -> None:
        """Fold angles, position targets or pins changed: histories are stale."""
        self.restart()

    def positions_set(self) -> None:
        """``sim.x`` was set from outside (:meth:`Simulation.set_positions`)."""
        self.restart()

    def restart(self) -> None:
        """Continue from ``sim.x`` with no memory of earlier steps."""

    def predict(self, ratio: float) -> bool:
        """Move ``sim.x`` to the extrapolation ``ratio`` × the step between the last
        two converged runs (a path's predictor, :meth:`Simulation.predict`);
        returns whether it did (default: never)."""
        return False

    @property
    def phase(self) -> str:
        """Name of the strategy that takes the next step (a composite's current phase)."""
        return self.name


def get(name: str) -> type:
    """Strategy class by name, importing a built-in module on first use.

    Raises
    ------
    KeyError
        If no built-in or registered strategy has that name.
    """
    if name not in _REGISTRY and name in _BUILTIN_MODULES:
        importlib.import_module(_BUILTIN_MODULES[name])
    try:
        return _REGISTRY[name]
    except KeyError:
        raise KeyError(f"unknown solver {name!r} (available: "
                       f"{', '.join(available())})") from None


def available() -> list[str]:
    """Built-in and registered strategy names."""
    return list(SOLVERS) + sorted(set(_REGISTRY) - set(SOLVERS))
