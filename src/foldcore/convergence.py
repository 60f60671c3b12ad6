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

Neither is a strategy's own test: before a run ends ``converged`` its state
must pass the equilibrium certificate of the model the user asked for, every
element of the mesh (:class:`foldcore.certificate.Certificate`), and so does
the state a run's budget ends at. A state the certificate refuses is not
converged: the probe's strategies go on (their probe waits), a strategy with
its own measure is asked whether its steps go on (``Strategy.refused``:
``hybrid`` hands over to its finishing strategy) or the run ends ``stalled``.
A strategy that is a model of its own, asked for by name (``rigid``: panels
exactly rigid; ``Strategy.own_model``), keeps its own test's verdict
(`docs/architecture.md#the-equilibrium-certificate`).
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

    Attributes
    ----------
    probe : foldcore.probe.EquilibriumProbe
    certificate : foldcore.certificate.Certificate
    strategy : foldcore.strategies.Strategy or None
        The strategy whose settled states the test certifies (:meth:`attach`).
    """

    def __init__(self, model, progress: Progress):
        from .certificate import Certificate
        from .probe import EquilibriumProbe

        self.probe = EquilibriumProbe(model, progress)
        self.certificate = Certificate(model)
        self.strategy = None
        self.moved = 0.0  # the last reported step's largest move, mm
        self._before = self._last = None  # the states before and after the last step
        self._model, self._progress = model, progress

    def attach(self, strategy) -> None:
        """The strategy the run's reports come from: asked whether it goes on where
        the certificate refuses a state it called settled."""
        self.strategy = strategy

    @property
    def last_step(self):
        """The last reported step, (N, 3) mm (None before the run's first): a direction
        along which the certificate checks that E does not fall beyond the limit."""
        return None if self._before is None else self._last - self._before

    @property
    def residual(self) -> float:
        """The last estimated distance to the equilibrium / the pattern's size (NaN:
        none this stage)."""
        return self.probe.residual

    def check(self, report: Report, limit: float, steps_left: int) -> str | None:
        """``"converged"``, ``"stalled"`` or None (go on) after a step of a run whose
        limit is ``limit`` mm (tolerance × size) with ``steps_left`` in its budget."""
        self._before, self._last = self._last, self._model.x.copy()
        if report.residual is not None:
            self.probe.residual = report.residual
        self.moved = report.moved
        settled = report.settled
        probed = settled is None
        if probed:
            settled = self.probe.settled(report.moved, limit)
        if settled:
            if not self.applies() or self.certified(limit):
                return "converged"
            if probed:  # the probe's strategies go on; its next check waits
                self.probe.refuse(self.certificate.residual)
            elif not (self.strategy is not None and self.strategy.refused()):
                return "stalled"  # the strategy's steps cannot leave its own equilibrium
        stalled = report.stalled or (report.plain_map and self.probe.hopeless(limit, steps_left))
        if stalled:  # steps at their resolution may have reached the equilibrium
            return "converged" if not settled and self.applies() and self.certified(limit) \
                else "stalled"
        return None

    def applies(self) -> bool:
        """Whether the certificate judges this state: not at a branch stage's end (not
        the run's), nor of a strategy that is a model of its own (``own_model``:
        ``rigid``), nor where contact acts (a barrier term within reach, or the last
        step cut short): the strategies keep panels apart by rules of their own
        (`docs/architecture.md#the-equilibrium-certificate`)."""
        contact = self._model.contact
        if self._progress.stage == "branch" or getattr(self.strategy, "own_model", False):
            return False
        return contact is None or not (contact.blocking or
                                       contact.state(self._model.x).active)

    def certified(self, limit: float) -> bool:
        """Whether the model's state passes the equilibrium certificate at ``limit`` mm;
        its residual becomes the test's."""
        passed = self.certificate.check(limit, self.last_step)
        self.probe.residual = self.certificate.residual
        return passed

    def at_budget(self, limit: float | None = None) -> str:
        """The reason of a run whose budget ran out: ``"converged"`` where its state
        passes the certificate at ``limit`` mm and its last step moved it by no more
        than that, else ``"stalled"`` where its last check found the equilibrium
        farther than the limit, else ``"budget"``. A state the strategy is still
        moving beyond the limit (the step, / size, is then the residual) is not
        where it stays, whatever the certificate's linearisation predicts: that
        linearisation holds a passive strip's bend as stiff as an actuated one, so
        at a binding vertex, whose passive strips follow the map's steps,
        ``newton`` crawls toward an equilibrium hundreds of limits away in steps
        of one or two limits, each lowering E, while the certificate's step stays
        within the limit (`docs/architecture.md#the-equilibrium-certificate`)."""
        failed = self.probe.failed
        if limit is not None and self.moved > limit:  # its residual: the last step
            self.probe.residual = self.moved / self._model.length_scale
        elif limit is not None and self.applies() and self.certified(limit):
            return "converged"
        return "stalled" if failed else "budget"

    def begin_run(self) -> None:
        """A run starts (its stages each call :meth:`new_stage`)."""
        self.moved = 0.0
        self._before, self._last = None, self._model.x.copy()
        self.probe.begin_run()

    def new_stage(self) -> None:
        self.probe.new_run()

    def targets_changed(self) -> None:
        self.probe.targets_changed()
