"""The strategy protocol and registry (importable without numba or SciPy)."""
from __future__ import annotations

import importlib
from dataclasses import dataclass

from ..convergence import Report

SOLVERS = ("paper", "anderson", "lbfgs", "rigid", "hybrid", "newton")
_BUILTIN_MODULES = {"paper": "foldcore.strategies.paper",
                    "anderson": "foldcore.strategies.anderson",
                    "lbfgs": "foldcore.strategies.lbfgs",
                    "rigid": "foldcore.strategies.rigid",
                    "hybrid": "foldcore.strategies.hybrid",
                    "newton": "foldcore.strategies.newton"}
_REGISTRY: dict[str, type] = {}


@dataclass(frozen=True)
class NoOptions:
    """Options of a strategy that has none."""


class Strategy:
    """Base class of iteration strategies; subclasses register themselves by ``name``.

    A strategy advances the state of the model it is handed and reports each
    step to the run's convergence test (:meth:`report`); it never decides the
    run's verdict itself. Its tuning constants are its ``Options`` (a frozen
    dataclass, as scipy.optimize's per-method options).

    Parameters
    ----------
    model : foldcore.model.Model
        Positions ``model.x`` (N, 3) mm, the local and global step, K and its
        factor, the hinge group's parameters, pins and timings.
    progress : foldcore.convergence.Progress
        The runs' counters: iterations, energies, run number, stage.
    options : Options, optional
        This strategy's options (default: ``Options()``).
    """

    name: str = ""
    abstract: bool = False  # True in a class's own body: a base for others, not registered
    #: Whether the steps are the paper's plain map, whose rate the equilibrium probe
    #: measures: a run that cannot reach the equilibrium within its budget at that
    #: rate then ends at once, ``stalled``.
    plain_map: bool = False
    supports_contact: bool = False  # its steps keep panels apart (``model.contact``)
    #: Whether the strategy is a model of its own, asked for by name (``rigid``: panels
    #: exactly rigid), whose verdict is its own test's; the equilibrium certificate
    #: of the mesh judges every other (`docs/architecture.md#the-equilibrium-certificate`).
    own_model: bool = False
    Options = NoOptions

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.__dict__.get("abstract", False):
            return
        if not cls.name:
            raise TypeError(f"{cls.__qualname__} must set a non-empty `name`")
        _REGISTRY[cls.name] = cls

    def __init__(self, model, progress, options=None):
        from ..errors import SimulationError

        if options is None:
            options = self.Options()
        if not isinstance(options, self.Options):
            raise SimulationError(f"solver {self.name!r} takes options of type "
                                  f"{self.Options.__name__}, got {type(options).__name__}")
        self.model, self.progress, self.options = model, progress, options

    def step(self) -> tuple[float, float]:
        """One iteration: (energy before it in mm⁵, largest vertex move in mm);
        writes the new positions to ``model.x``."""
        raise NotImplementedError

    def report(self, moved: float, limit: float) -> Report:
        """What the last step (of largest move ``moved`` mm) says, for a run whose
        limit is ``limit`` mm (tolerance × size): its own verdict
        (:meth:`settled`), whether it stalled, whether it is the plain map."""
        return Report(moved, settled=self.settled(moved, limit), stalled=self.stalled,
                      plain_map=self.plain_map)

    def settled(self, moved: float, limit: float) -> bool | None:
        """The strategy's own optimality measure after a step of ``moved`` mm: whether
        the state is its model's equilibrium within ``limit`` mm. Default None: no
        measure of its own, the equilibrium probe of the paper's model judges."""
        return None

    def refused(self) -> bool:
        """The convergence test refused a state this strategy called settled: the
        model's equilibrium is farther than the run's limit
        (`docs/architecture.md#the-equilibrium-certificate`). Returns whether the
        strategy's steps go on toward it (default True: the test checks again when
        it next settles); False where they cannot (the run ends ``stalled``)."""
        return True

    @property
    def stalled(self) -> bool:
        """Whether the steps are at the strategy's resolution: they no longer change
        the energy beyond rounding and no longer shrink, so no budget would bring the
        run closer (default: never)."""
        return False

    def begin_run(self) -> None:
        """A stage of a run starts (a run from flat has a branch stage first)."""

    def end_run(self) -> None:
        """A stage ended (converged, out of budget, stopped or interrupted)."""

    def targets_changed(self) -> None:
        """Fold angles, position targets or pins changed: histories are stale."""
        self.restart()

    def positions_set(self) -> None:
        """``model.x`` was set from outside (``Simulation.set_positions``)."""
        self.restart()

    def restart(self) -> None:
        """Continue from ``model.x`` with no memory of earlier steps."""

    def predict(self, ratio: float) -> bool:
        """Move ``model.x`` to the extrapolation ``ratio`` × the step between the last
        two converged runs (a path's predictor); returns whether it did (default:
        never)."""
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


def unregister(name: str) -> None:
    """Forget a user strategy (tests); built-ins stay importable by name."""
    _REGISTRY.pop(name, None)
