"""When a run stops: the run's counters, what a strategy reports after each step,
and the one convergence test that turns reports into a verdict.

Like PETSc's SNES convergence test, the test is pluggable
(``Simulation(convergence=...)``): every strategy reports to it after each
step (:class:`Report`), and it decides whether the run ends ``converged``,
``stalled`` or goes on. A strategy with its own optimality measure (the
rigid-body strategy's stopping rule, ``newton``'s) says whether its state
is settled; a strategy without one (the local/global maps) is judged by the
equilibrium probe of the paper's model (:class:`foldcore.probe.EquilibriumProbe`).
A small step alone is never a verdict: `docs/architecture.md#a-small-step-is-not-a-verdict`.
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class Progress:
    """The counters of a simulation's runs, which strategies and measures may read.

    Attributes
    ----------
    iterations : int
        Steps taken since the simulation was made.
    energies : list of float
        The energy before each step, mm⁵.
    runs : int
        Calls of ``Simulation.run`` so far (a run's stages share one number).
    stage : str or None
        The stage of the run in progress: ``"branch"``, ``"run"`` or None.
    """

    iterations: int = 0
    energies: list = field(default_factory=list)
    runs: int = 0
    stage: str | None = None

    def record(self, energy: float) -> None:
        """One step taken, with the energy before it (mm⁵)."""
        self.energies.append(energy)
        self.iterations += 1


@dataclass(frozen=True)
class Report:
    """What a strategy says of its last step.

    Attributes
    ----------
    moved : float
        The step's largest vertex move, mm.
    settled : bool or None
        The strategy's own optimality measure: the state is an equilibrium of
        its model within the run's limit. None: the strategy has none, the
        equilibrium probe judges.
    stalled : bool
        The steps are at the strategy's resolution (no budget would help).
    plain_map : bool
        The steps are the paper's plain map, whose rate the probe measures: a
        run that cannot reach the equilibrium in its budget at that rate stalls.
    residual : float or None
        The strategy's own estimate of the distance left / the pattern's size.
    """

    moved: float
    settled: bool | None = None
    stalled: bool = False
    plain_map: bool = False
    residual: float | None = None


class ConvergenceTest:
    """The default verdict of a run (module docstring); subclass and override
    :meth:`check` for another (call ``super().check`` to keep this one's).

    Parameters
    ----------
    model : foldcore.model.Model
    progress : Progress
    """

    def __init__(self, model, progress: Progress):
        from .probe import EquilibriumProbe

        self.probe = EquilibriumProbe(model, progress)

    @property
    def residual(self) -> float:
        """The last estimated distance to the equilibrium / the pattern's size (NaN:
        none this stage)."""
        return self.probe.residual

    def check(self, report: Report, limit: float, steps_left: int) -> str | None:
        """``"converged"``, ``"stalled"`` or None (go on) after a step of a run whose
        limit is ``limit`` mm (tolerance × size) with ``steps_left`` in its budget."""
        if report.residual is not None:
            self.probe.residual = report.residual
        settled = report.settled
        if settled is None:
            settled = self.probe.settled(report.moved, limit)
        if settled:
            return "converged"
        if report.stalled:
            return "stalled"
        if report.plain_map and self.probe.hopeless(limit, steps_left):
            return "stalled"
        return None

    def at_budget(self) -> str:
        """The reason of a run whose budget ran out: ``"stalled"`` where its last check
        found the equilibrium farther than the limit, else ``"budget"``."""
        return "stalled" if self.probe.failed else "budget"

    def begin_run(self) -> None:
        """A run starts (its stages each call :meth:`new_stage`)."""
        self.probe.begin_run()

    def new_stage(self) -> None:
        self.probe.new_run()

    def targets_changed(self) -> None:
        self.probe.targets_changed()
