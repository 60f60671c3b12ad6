"""What a worker does: fold one continuation path of a study's points into rows.

A path is a list of points equal but for their fold percent (:func:`foldcore.study.
points.paths`). Its first point is folded exactly as ``foldcore simulate`` folds
it (the same :func:`foldcore.job.prepare`, the same ``Simulation.run`` from the
flat sheet), so its figures equal a direct run's. Each further point continues
from the previous point's result (:func:`foldcore.animate.fold_sweep`), the
column ``start`` saying so; its ``iterations`` and ``run_s`` are its own.
A point that fails is a row with its ``error``: the rest of the path is
still folded, each from the flat sheet if the failure left no state.
"""
from __future__ import annotations

import math
import time
import warnings

from .points import option_groups


def run_path(source, points: list[dict], *, metric=None, keep: bool = False,
             continuation: bool = True) -> list[dict]:
    """Rows of a path's points, in order.

    Parameters
    ----------
    source : PatternFile or Generator
        What is folded (:mod:`foldcore.study.source`).
    points : list of dict
        Points equal but for ``fold-percent``, in the order to fold them.
    metric : callable(Fold[, point]) -> float or dict, optional
        The user's metric of each fold (:class:`foldcore.job.Fold`; with a second
        positional parameter it also gets the point); a float is the column
        ``metric``, a dict its own columns. If it has a ``watch(sim, moved_mm)``
        method, that is called after each iteration of the run (e.g. to record a
        convergence trace; it must return None or True to go on).
    keep : bool
        Add ``result_fold`` (the result FOLD's bytes) to each row.
    continuation : bool
        Fold each point after the first from the previous one's result; False:
        each from the flat sheet (every row then equals its direct run).

    Returns
    -------
    list of dict, one row per point: the point, the figures
    (:func:`foldcore.study.figures.figures`), ``wall_s``, ``start``, ``worker``,
    ``error`` (empty when the point folded).
    """
    worker = worker_address()
    rows, state = [], None
    for point in points:
        start = time.perf_counter()
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            path = None
            try:
                path, hinges = source.materialise(_generator_parameters(source, point))
                row, state = _fold_point(path, hinges, point, state if continuation else None,
                                         metric, keep)
            except Exception as exc:  # a failing point is a row, never the end of the study
                row, state = {"error": error_text(exc)}, None
        named = _named(source, path)
        rows.append({**point, **row, "wall_s": time.perf_counter() - start,
                     "worker": worker, "error": named(row.get("error", "")),
                     "warnings": "; ".join(dict.fromkeys(named(str(w.message))
                                                         for w in said))})
    return rows


def _named(source, path):
    """A message with the worker's copy of the pattern (``path``) named as the user
    named it."""
    import os

    from .points import in_names

    if path is None:
        return in_names
    return lambda text: in_names(text.replace(path, source.label)
                                 .replace(os.path.dirname(path) + "/", ""))


def _fold_point(path: str, hinges, point: dict, state, metric, keep: bool):
    """(row, state) of one point of the pattern file at ``path``; ``state`` (job,
    loaded, thickness, mesh, sim) carries a path from one point to the next."""
    from ..job import Fold, Job, prepare, run_settings
    from .figures import figures

    job = Job.make(path, hinges, **option_groups(point))
    if state is None:
        loaded, thickness, mesh, sim = prepare(job)
        start, before = "flat", 0
    else:
        loaded, thickness, mesh, sim = state[1:5]
        start, before = f"fold-percent {state[0].solving.fold_percent:g}", sim.iterations
    s = job.solving
    sim.set_fold_percent(s.fold_percent)
    began = time.perf_counter()
    result = sim.run(tolerance=s.tolerance, max_iterations=s.budget(),
                     callback=getattr(metric, "watch", None))
    row = {**figures(result, loaded.pattern, mesh), "run_s": time.perf_counter() - began}
    row.update(iterations=sim.iterations - before, start=start, error="",
               **({} if state is None else {"setup_s": 0.0}))
    settings = run_settings(job, thickness, mesh, sim)
    done = Fold(loaded.pattern, mesh, sim, result, settings, "")
    if metric is not None:
        row.update(_metric_columns(metric, done, point, taken={*point, *row}))
    if keep:
        row["result_fold"] = _result_bytes(done, thickness)
    return row, (job, loaded, thickness, mesh, sim)


def _generator_parameters(source, point: dict) -> dict:
    names = set(source.parameters)
    return {k: v for k, v in point.items() if k in names}


def _metric_columns(metric, done, point: dict, taken=()) -> dict:
    """The metric's columns; its failure, or a column named as one the row has
    (``taken``: the point's names, the figures), is the row's ``metric_error``."""
    from .figures import FIGURES, RESERVED, TRAILING

    try:
        value = metric(done, point) if takes_point(metric) else metric(done)
    except Exception as exc:
        return {"metric_error": error_text(exc)}
    if not isinstance(value, dict):
        return {"metric": float(value) if value is not None else math.nan}
    columns = {str(k): v for k, v in value.items()}
    clash = sorted(set(columns) & ({*taken, *FIGURES, *TRAILING, *RESERVED}))
    if clash:
        return {"metric_error": f"the metric's column {clash[0]!r} is a column of the row "
                                "already (a point's name, a figure or the study's own): "
                                "rename it"}
    return columns


def takes_point(metric) -> bool:
    """Whether the metric is ``metric(fold, point)`` rather than ``metric(fold)``."""
    import inspect

    try:
        params = inspect.signature(metric).parameters.values()
    except (TypeError, ValueError):
        return False
    positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    return len(positional) >= 2 or any(p.kind == p.VAR_POSITIONAL for p in params)


def _result_bytes(done, thickness: float) -> bytes:
    """The result FOLD ``foldcore simulate -o`` would write, as bytes."""
    import tempfile
    from pathlib import Path

    from ..outputs import write_result

    with tempfile.TemporaryDirectory(prefix="foldcore-keep-") as folder:
        path = Path(folder) / "result.fold"
        write_result(done.result, done.pattern, done.mesh, thickness, done.settings,
                     fold=path)
        return path.read_bytes()


def error_text(exc: BaseException) -> str:
    """One line: the library's own message, or the exception's type and message."""
    from ..errors import FoldcoreError
    from .points import in_names

    text = str(exc).splitlines()[0] if str(exc) else ""
    if isinstance(exc, FoldcoreError):
        return in_names(text)
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def worker_address() -> str:
    """The Dask worker running this task (its address), or ``"local"`` outside one."""
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return "local"
