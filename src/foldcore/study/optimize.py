"""Optimisation on a study's layer: the point that minimises (or maximises) one column
of a row, searched by Optuna, each trial one fold on Dask (:func:`optimize`).

>>> from foldcore import study
>>> found = study.optimize("miura", {"hinge-width": (0.2, 2.0)}, "miss_max_deg",
...                        fixed={"n": 3, "m": 3, "thickness": 0.2, "fold-percent": 60},
...                        constraints={"largest_strain": 0.6})  # doctest: +SKIP
>>> round(found.best["hinge-width"], 3), round(found.value, 2)      # doctest: +SKIP
(1.151, 29.09)

A 3 × 3 Miura of 0.2 mm sheet at 60 % (every crease driven to ±108°): the
narrower the hinge, the closer the creases come to their targets
(``miss_max_deg`` 18.6° at 0.3 mm, 33° at 2 mm), but the harder its surface
bends (``largest_strain`` 1, the inner face fully compressed, up to about
0.36 mm; 0.61 at 1.1 mm, 0.50 at 2 mm). Under a strain limit of 0.6 the
best hinge is the narrowest one that keeps to it: a sweep every 0.01 mm
gives 1.14 mm (29.01°); the 40 seeded trials above find 1.151 mm (29.09°).

A trial is a point: ``space``'s values drawn by the sampler, and ``fixed``. It
is folded by :func:`foldcore.study.task.run_path` from the flat sheet, as a
sweep's point alone in its path: its row is that sweep row (the same
columns, :func:`foldcore.study.sweep`) and shares its cache entry. Trials run
in batches (default: one trial per Dask worker): asked of the sampler
together (TPE's constant liar keeps them apart), folded in parallel, told in
trial order once the whole batch is back, so the points depend only on the
seed, the trials, the batch and the folds, never on which worker finished first.

What the sampler is told
------------------------
* A fold that failed (its ``error``), or whose objective or a constraint is not
  a number (NaN: ``largest_strain`` of a pattern without hinges, a metric that
  failed): the trial FAILED; the sampler leaves it out. It is a row all the same.
* A fold that did not converge: its value, and the violated constraint
  ``converged`` (1 > 0). A feasible trial has converged.
* ``constraints`` {column: most}: the column's value minus ``most`` (≤ 0 feasible).

TPE (the default) steers away from infeasible trials; ``"random"`` and
``"qmc"`` ignore constraints when they draw. The best point is the best
feasible trial's (the earliest of equal values); there is none when no trial
is feasible.

Finished trials go to the study cache (:mod:`foldcore.study.cache`): a rerun
of the same optimisation (same seed, trials, batch and space) asks the same
points and takes each from the cache, folding nothing again but the failed
ones (and starting no cluster when nothing is left to fold); a rerun with more
trials folds only the new ones.
"""
from __future__ import annotations

import logging
import math
from contextlib import contextmanager
from dataclasses import dataclass

from .cache import Cache, point_key
from .points import (OPTIONS, SWITCHES, StudyError, canonical, check, describe, parse_set,
                     parse_value, split_values)
from .sweep import FIGURES, TRAILING, table

log = logging.getLogger("foldcore.study")

#: Samplers :func:`optimize` knows by name (or pass an ``optuna.samplers`` object).
SAMPLERS = ("tpe", "random", "qmc")
#: Figures that are not numbers, so neither an objective nor a constraint.
_TEXT = ("reason",)
#: Most trials one optimisation may run.
MAX_TRIALS = 100_000


@dataclass(frozen=True)
class Dimension:
    """One varied name: a range (``low``…``high``, integers if ``integer``, on a log
    scale or a ``step`` grid) or a list of ``choices``."""

    name: str
    low: float | None = None
    high: float | None = None
    integer: bool = False
    log: bool = False
    step: float | None = None
    choices: tuple = ()

    def distribution(self):
        """The Optuna distribution the sampler draws this name from."""
        from optuna.distributions import (CategoricalDistribution, FloatDistribution,
                                          IntDistribution)

        if self.choices:
            return CategoricalDistribution(self.choices)
        if self.integer:
            return IntDistribution(self.low, self.high, log=self.log, step=self.step or 1)
        return FloatDistribution(self.low, self.high, log=self.log, step=self.step)

    def ends(self) -> list:
        """The values a check before any fold tries: the bounds, or every choice."""
        return list(self.choices) if self.choices else [self.low, self.high]


@dataclass(frozen=True)
class Optimum:
    """What :func:`optimize` found.

    Attributes
    ----------
    history : pandas.DataFrame
        One row per trial, in trial order: ``trial``, then a sweep's columns
        (:func:`foldcore.study.sweep`) with ``objective`` (the value the sampler
        was told; NaN for a failed trial) and ``feasible`` before the trailing ones.
    best : dict or None
        The best feasible trial's point (varied and fixed names); None if none is.
    value : float
        Its objective (the column's value: mm, degrees, … as the column's); NaN if none.
    trial : int or None
        Its trial number (the history's ``trial``).
    objective : str
        The column optimised.
    minimize : bool
        Whether smaller was better.
    """

    history: object
    best: dict | None
    value: float
    trial: int | None
    objective: str
    minimize: bool

    def line(self) -> str:
        """The best point in one line: ``least largest_strain 0.5 at hinge-width=2, …
        (trial 7)``."""
        if self.best is None:
            return f"no feasible trial among {len(self.history)}"
        point = ", ".join(f"{k}={_short(v)}" for k, v in self.best.items())
        return (f"{'least' if self.minimize else 'greatest'} {self.objective} "
                f"{_short(self.value)} at {point} (trial {self.trial})")


def _short(value) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def optimize(pattern, space: dict, objective: str, *, fixed: dict | None = None,
             trials: int = 40, minimize: bool = True, sampler="tpe", seed: int = 0,
             metric=None, constraints=None, hinges=None, client=None, scheduler=None,
             workers=None, cache="default", batch: int | None = None,
             progress=None) -> Optimum:
    """The point of ``space`` (with ``fixed``) whose fold minimises (or maximises) the
    column ``objective`` of its row, searched in ``trials`` folds.

    Parameters
    ----------
    pattern : path, generator name or callable
        What is folded, as for :func:`foldcore.study.sweep` (e.g. ``"miura"``).
    space : dict {name: range or list}
        The varied names (``simulate``'s options, :data:`foldcore.study.OPTIONS`,
        and the generator's parameters) in the command line's units (mm, degrees,
        percent): ``(low, high)`` drawn uniformly (integers for an integer name: a
        generator's int parameter like ``n``, ``max-iterations``), ``(low, high,
        "log")`` log-uniformly (low > 0), ``(low, high, step)`` on the grid low,
        low + step, …; a list ``[v1, v2, …]``: one of the values.
    objective : str
        The row's column to optimise: a figure (:data:`foldcore.study.FIGURES`,
        e.g. ``largest_strain``, ``miss_max_deg`` degrees, ``stack_height_mm``) or a
        column of ``metric``'s (checked when the first row arrives).
    fixed : dict {name: value}, optional
        The other names' values, the same in every trial.
    trials : int
        Folds in all (those taken from the cache included).
    minimize : bool
        False: maximise.
    sampler : {"tpe", "random", "qmc"} or optuna.samplers.BaseSampler
        How trials are drawn: Optuna's TPE (multivariate, constant liar), uniform
        random, or a scrambled Sobol sequence; all seeded with ``seed``.
    seed : int
        The same seed, trials, batch and space give the same points.
    metric : callable(Fold) -> float or dict, optional
        Computed on the worker after each fold, as for :func:`foldcore.study.sweep`.
    constraints : dict {column: most}, str or list of str, optional
        Columns that must be at most ``most`` (a name alone: at most 0) for a trial
        to be feasible; a converged fold is always required (module docstring).
    hinges, client, scheduler, workers, cache, progress
        As for :func:`foldcore.study.sweep` (``workers=0``: this process).
    batch : int, optional
        Trials folded together (default: the cluster's workers; 1 in this process).

    Returns
    -------
    Optimum
        The history (one row per trial) and the best feasible point.

    Raises
    ------
    StudyError
        Before any fold, for an unknown name, a name both varied and fixed, a
        range whose LOW is not below its HIGH, a value an option refuses at a
        range's end, an unknown column; when the first row arrives, for a
        column the metric does not give.
    """
    from .source import source_of

    source = source_of(pattern, hinges)
    dims, fixed = _checked(source, space, fixed)
    goal = Goal.of(objective, constraints, minimize, metric is not None)
    _check_counts(trials, batch)
    search = _Search(source, dims, fixed, goal, metric,
                     Cache.at(cache))
    search.run(_sampler(sampler, seed), trials, batch, progress,
               {"client": client, "scheduler": scheduler, "workers": workers})
    return search.result()


@dataclass(frozen=True)
class Goal:
    """The objective column, its direction and the constraints {column: most}."""

    objective: str
    constraints: dict
    minimize: bool

    @classmethod
    def of(cls, objective, constraints, minimize: bool, has_metric: bool) -> "Goal":
        """The goal, its columns checked (a metric's are checked on the first row)."""
        if isinstance(constraints, str):
            constraints = [constraints]
        if constraints is None:
            constraints = {}
        elif not isinstance(constraints, dict):
            constraints = {c: 0.0 for c in constraints}
        limits = {}
        for column, most in constraints.items():
            if isinstance(most, bool) or not isinstance(most, (int, float)) \
                    or not math.isfinite(most):
                raise StudyError(f"constraint {column}: its most must be a finite number, "
                                 f"got {most!r}")
            limits[str(column)] = float(most)
        for column in [objective, *limits]:
            if not isinstance(column, str) or column in _TEXT or column in TRAILING \
                    or (column not in FIGURES and not has_metric):
                numbers = [f for f in FIGURES if f not in _TEXT]
                raise StudyError(f"{column!r}: not a column to optimise (the figures: "
                                 f"{', '.join(numbers)}; or a metric's columns)")
        return cls(objective, limits, bool(minimize))

    def judge(self, row: dict, names=()):
        """(objective value, {constraint: value ≤ 0 if met}) of a row, or None when the
        trial failed (an error, a NaN, a metric that failed); ``names``: the point's."""
        if row.get("error"):
            return None
        values = {}
        for column in [self.objective, *self.constraints]:
            if column not in row:
                if row.get("metric_error"):
                    return None
                given = [c for c in row if c not in FIGURES and c not in TRAILING
                         and c not in names]
                raise StudyError(f"{column!r}: the rows have no such column (the metric's: "
                                 f"{', '.join(given) or 'none'})")
            values[column] = _number(row[column], column)
        if any(math.isnan(v) for v in values.values()):
            return None
        limits = {"converged": 0.0 if row.get("converged") else 1.0}
        limits.update({c: values[c] - most for c, most in self.constraints.items()})
        return values[self.objective], limits


def _number(value, column: str) -> float:
    """A cell as a float (a cached row's NaN is None, its infinities text)."""
    if value is None:
        return math.nan
    try:
        return float(value)
    except (TypeError, ValueError):
        raise StudyError(f"{column!r}: not a number ({value!r}): it cannot be "
                         "optimised") from None


class _Search:
    """The trials so far: asks a batch, folds what the cache lacks, tells the results."""

    def __init__(self, source, dims, fixed, goal, metric, store):
        self.source, self.dims, self.fixed, self.goal = source, dims, fixed, goal
        self.metric, self.store = metric, store
        self.distributions = {d.name: d.distribution() for d in dims}
        self.rows: list = []

    def run(self, sampler, trials: int, batch, progress, where: dict) -> None:
        """Ask, fold and tell batches until ``trials`` rows (``where``: client,
        scheduler, workers of :func:`foldcore.study.execute.session`). The cluster
        is started (or reached) at the first trial the cache lacks: a replay needs none."""
        from contextlib import ExitStack

        from .execute import progress_bar, session

        bar = progress_bar(trials, progress, unit="trial")
        opened: list = []
        with ExitStack() as stack, _quiet_optuna():
            stack.callback(bar.close)

            def folding():
                if not opened:
                    opened.append(stack.enter_context(session(self.source, **where)))
                return opened[0]

            import optuna

            study = optuna.create_study(
                direction="minimize" if self.goal.minimize else "maximize", sampler=sampler)
            size = batch or _workers(where, folding)
            while len(self.rows) < trials:
                bar.update(self.batch(study, folding, min(size, trials - len(self.rows))))

    def batch(self, study, folding, size: int) -> int:
        """Ask ``size`` trials, fold them (``folding()``: the Session), tell them in
        order."""
        asked = [study.ask(self.distributions) for _ in range(size)]
        points = [{**{d.name: t.params[d.name] for d in self.dims}, **self.fixed}
                  for t in asked]
        for trial, row in zip(asked, self.fold(folding, points)):
            self.tell(study, trial, row)
        return size

    def fold(self, folding, points: list[dict]) -> list[dict]:
        """Rows of ``points``: from the cache, or folded (each from the flat sheet)."""
        keys = [point_key(self.source.key(), p, [], self.metric) for p in points]
        rows: list = [None] * len(points)
        missing = []
        for i, key in enumerate(keys):
            hit = self.store.get(key)
            if hit is None:
                missing.append([i])
            else:
                rows[i] = {**points[i], **hit[0], "cached": True}

        def arrived(ids, new_rows):
            for i, row in zip(ids, new_rows):
                row.pop("result_fold", None)
                if not row.get("error"):
                    self.store.put(keys[i], row)
                rows[i] = {**row, "cached": False}

        if missing:
            folding().run(points, missing, metric=self.metric, continuation=False,
                          on_rows=arrived)
        return rows

    def tell(self, study, trial, row: dict) -> None:
        """Tell the sampler the trial's value and constraints (or that it failed)."""
        from optuna.trial import TrialState

        verdict = self.goal.judge(row, [d.name for d in self.dims] + list(self.fixed))
        if verdict is None:
            study.tell(trial, state=TrialState.FAIL)
            value, feasible = math.nan, False
        else:
            value, limits = verdict
            if hasattr(trial, "set_constraint"):  # Optuna ≥ 5; before, only the best
                for name, excess in limits.items():
                    trial.set_constraint(name, excess)
            study.tell(trial, value)
            feasible = all(v <= 0.0 for v in limits.values())
        log.info("optimize: trial %d (%s): %s %s%s", trial.number,
                 describe({d.name: row.get(d.name) for d in self.dims}),
                 self.goal.objective, _short(value), "" if feasible else " (infeasible)")
        self.rows.append({"trial": trial.number, **row, "objective": value,
                          "feasible": feasible})

    def result(self) -> Optimum:
        """The history table and the best feasible trial."""
        names = [d.name for d in self.dims] + list(self.fixed)
        frame = table(self.rows, names)
        columns = [c for c in frame.columns if c not in ("trial", "objective", "feasible")]
        at = columns.index(TRAILING[0])
        frame = frame[["trial", *columns[:at], "objective", "feasible", *columns[at:]]]
        best = None
        sign = 1.0 if self.goal.minimize else -1.0
        for row in self.rows:
            if row["feasible"] and (best is None
                                    or sign * row["objective"] < sign * best["objective"]):
                best = row
        if best is None:
            return Optimum(frame, None, math.nan, None, self.goal.objective,
                           self.goal.minimize)
        return Optimum(frame, {n: best[n] for n in names}, best["objective"], best["trial"],
                       self.goal.objective, self.goal.minimize)


def _checked(source, space: dict, fixed: dict | None) -> tuple[list, dict]:
    """The space's dimensions and the fixed values, checked before any fold: every name
    known and given once, every range's ends (or every choice) accepted."""
    if not isinstance(space, dict) or not space:
        raise StudyError("nothing to vary: give the space as {name: (low, high)}, "
                         "e.g. {'hinge-width': (0.2, 2.0)}")
    fixed = {canonical(k): v for k, v in (fixed or {}).items()}
    names = [canonical(k) for k in space]
    if len(set(names)) < len(names):
        raise StudyError(f"a name is varied twice: {', '.join(names)}")
    both = sorted(set(names) & set(fixed))
    if both:
        raise StudyError(f"{both[0]}: both varied and fixed")
    known = sorted(OPTIONS) + sorted(SWITCHES) + list(source.parameters)
    for name in [*names, *fixed]:
        if name not in known:
            raise StudyError(f"unknown name {name!r} (options and parameters: "
                             f"{', '.join(known)})")
    dims = [dimension(n, spec, _integral(source, n)) for n, spec in zip(names, space.values())]
    for end in _ends(dims):
        point = {**end, **fixed}
        try:
            check([point], source.parameters)
            if source.parameters:  # a generator's own checks (n ≥ 1, 0 < gamma < 90, …)
                source.materialise({k: v for k, v in point.items()
                                    if k in source.parameters})
        except StudyError as exc:
            raise StudyError(str(exc).replace("point 0 (", "at (", 1)) from None
    return dims, fixed


def _ends(dims: list) -> list[dict]:
    """Points the check tries: all lows, all highs, and each choice with the lows."""
    low = {d.name: d.ends()[0] for d in dims}
    out = [low, {d.name: d.ends()[-1] for d in dims}]
    for d in dims:
        out += [{**low, d.name: c} for c in d.choices[1:-1]]
    return out


def dimension(name: str, spec, integer: bool = False) -> Dimension:
    """A :class:`Dimension` of ``spec``: ``(low, high)``, ``(low, high, "log")``,
    ``(low, high, step)`` or a list of values; ``integer`` for an integer name."""
    if isinstance(spec, list):
        if len(spec) < 2 or len({repr(v) for v in spec}) < len(spec):
            raise StudyError(f"{name}: a list of choices needs two distinct values or more, "
                             f"got {spec!r}")
        if not all(isinstance(v, (bool, int, float, str)) for v in spec):
            raise StudyError(f"{name}: choices must be numbers, true/false or text")
        return Dimension(name, choices=tuple(spec))
    if not isinstance(spec, tuple) or len(spec) not in (2, 3):
        raise StudyError(f"{name}: expected (LOW, HIGH), (LOW, HIGH, 'log'), "
                         f"(LOW, HIGH, STEP) or a list of values, got {spec!r}")
    low, high = (_bound(name, v, integer) for v in spec[:2])
    if not low < high:
        raise StudyError(f"{name}: LOW {low:g} is not below HIGH {high:g}")
    third = spec[2] if len(spec) == 3 else None
    log_scale = third == "log"
    step = None if third is None or log_scale else _bound(name, third, integer)
    if log_scale and low <= 0:
        raise StudyError(f"{name}: a log range needs LOW > 0, got {low:g}")
    if step is not None and not 0 < step <= high - low:
        raise StudyError(f"{name}: STEP must be in (0, HIGH − LOW], got {third!r}")
    return Dimension(name, low, high, integer, log_scale, step)


def _bound(name: str, value, integer: bool):
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not math.isfinite(value):
        raise StudyError(f"{name}: {value!r} is not a finite number")
    if integer and value != int(value):
        raise StudyError(f"{name}: takes integers, got {value!r}")
    return int(value) if integer else float(value)


def _integral(source, name: str) -> bool:
    """Whether ``name`` takes integers: an option declared ``int``, or a generator
    parameter whose default (or annotation) is an int."""
    import dataclasses
    import inspect

    if name in OPTIONS:
        from ..io import Reading
        from ..options import Solving, Thickening

        group, field = OPTIONS[name]
        cls = {"thickening": Thickening, "solving": Solving, "reading": Reading}[group]
        kind = {f.name: f.type for f in dataclasses.fields(cls)}.get(field, "")
        return str(getattr(kind, "__name__", kind)).startswith("int")
    function = getattr(source, "function", None)
    if function is None:
        return False
    param = inspect.signature(function).parameters.get(name.replace("-", "_"))
    if param is None:
        return False
    default = param.default
    annotation = getattr(param.annotation, "__name__", param.annotation)
    return (isinstance(default, int) and not isinstance(default, bool)) \
        or str(annotation).startswith("int")


def _workers(where: dict, folding) -> int:
    """The default batch: the workers of the user's client, of the embedded cluster
    to be (without starting it), or of the scheduler's (reached); 1 in this process."""
    from .execute import default_workers

    if where["client"] is not None:
        return max(1, len(where["client"].scheduler_info(n_workers=-1)["workers"]))
    if where["scheduler"] is not None:
        return max(1, folding().workers)
    return 1 if where["workers"] == 0 else where["workers"] or default_workers()


def _check_counts(trials, batch) -> None:
    for what, value in (("trials", trials), ("batch", batch)):
        if value is None and what == "batch":
            continue
        if isinstance(value, bool) or not isinstance(value, int) \
                or not 1 <= value <= MAX_TRIALS:
            raise StudyError(f"{what} must be an integer in 1..{MAX_TRIALS}, got {value!r}")


def _sampler(sampler, seed: int):
    """The Optuna sampler of a name (:data:`SAMPLERS`), seeded; an object as given."""
    if not isinstance(sampler, str):
        return sampler
    if sampler not in SAMPLERS:
        raise StudyError(f"sampler {sampler!r}: expected one of {', '.join(SAMPLERS)}")
    from optuna import samplers

    if sampler == "tpe":
        return samplers.TPESampler(seed=seed)
    if sampler == "random":
        return samplers.RandomSampler(seed=seed)
    return samplers.QMCSampler(seed=seed, scramble=True, warn_independent_sampling=False,
                               warn_asynchronous_seeding=False)


@contextmanager
def _quiet_optuna():
    """Optuna without its per-trial log lines and experimental-feature warnings (the
    study logs its own trials on ``foldcore.study``); its verbosity restored after."""
    import warnings

    import optuna

    level = optuna.logging.get_verbosity()
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)
            yield
    finally:
        optuna.logging.set_verbosity(level)


def parse_vary(spec: str) -> tuple[str, object]:
    """``NAME=LOW:HIGH``, ``NAME=LOW:HIGH:log``, ``NAME=LOW:HIGH:STEP`` or
    ``NAME=V1,V2,…`` (a ``--vary``) → (name, range tuple or list of choices)."""
    name, eq, text = spec.partition("=")
    name = canonical(name)
    if not eq or not name or not text.strip():
        raise StudyError(f"--vary {spec!r}: expected NAME=LOW:HIGH (e.g. "
                         "hinge-width=0.2:2) or NAME=V1,V2,…")
    if ":" in text and not text.strip().startswith("["):
        parts = [p.strip() for p in text.split(":")]
        if len(parts) not in (2, 3) or not all(parts):
            raise StudyError(f"--vary {spec!r}: expected LOW:HIGH or LOW:HIGH:log|STEP")
        values = [parse_value(p) for p in parts]
        return name, tuple(values)
    choices = [parse_value(v) for v in split_values(text)]
    if len(choices) < 2:
        raise StudyError(f"--vary {spec!r}: one value is not a range: give LOW:HIGH, "
                         "V1,V2,… or fix it with --set")
    return name, choices


def parse_fixed(spec: str) -> tuple[str, object]:
    """``NAME=V`` (an optimisation's ``--set``: one value) → (name, value)."""
    name, values = parse_set(spec)
    if len(values) != 1:
        raise StudyError(f"--set {spec!r}: one value each (vary a name with --vary)")
    return name, values[0]


def parse_bound(spec: str) -> tuple[str, float]:
    """``COLUMN=MOST`` (an ``--at-most``) → (column, most)."""
    column, eq, text = spec.partition("=")
    value = parse_value(text) if eq else None
    if not column.strip() or isinstance(value, bool) or not isinstance(value, (int, float)):
        raise StudyError(f"--at-most {spec!r}: expected COLUMN=NUMBER "
                         "(e.g. largest_strain=0.6)")
    return column.strip(), float(value)
