"""A sweep: every point of a study folded, one row each (:func:`sweep`)."""
from __future__ import annotations

import math
from pathlib import Path

from .cache import Cache, point_key
from .figures import FIGURES, TRAILING
from .points import (StudyError, check, fold_percent, grid as grid_points,
                     paths as continuation_paths)

#: Figures that are counts or flags (kept so with a failed point's missing values).
_KINDS = {"converged": "boolean", "binding": "boolean", "cached": "boolean",
          "iterations": "Int64", "driven": "Int64", "fractured": "Int64",
          "contact_pairs": "Int64", "touching_panels": "Int64"}


def sweep(pattern, grid: dict | None = None, points: list | None = None, *, hinges=None,
          metric=None, client=None, scheduler=None, workers=None, keep=None,
          cache="default", continuation: bool = True, progress=None):
    """Fold ``pattern`` at every point of a grid or list; a table, one row per point.

    Parameters
    ----------
    pattern : path, generator name or callable
        A pattern file (FOLD, SVG, OBJ/STL), the name of a built-in generator
        (:data:`foldcore.study.source.GENERATORS`, e.g. ``"miura"``), or a function
        returning a :class:`foldcore.CreasePattern`.
    grid : dict {name: list of values}, optional
        Every combination is a point. Names: ``simulate``'s options
        (:data:`foldcore.study.points.OPTIONS`: ``thickness``, ``hinge-width`` mm,
        ``fold-percent``, ``solver``, ``contact``, …) and the generator's parameters.
    points : list of dict, optional
        Points given one by one (e.g. :func:`foldcore.study.points.read_points`).
    hinges : path, optional
        Hinge file of an OBJ/STL pattern.
    metric : callable(Fold[, point]) -> float or dict, optional
        Evaluated on the worker after each fold (:class:`foldcore.job.Fold`: pattern,
        mesh, simulation, result; and the point, if it takes a second argument); a
        float becomes the column ``metric``, a dict its own columns; its optional
        ``watch(sim, moved_mm)`` is called after each iteration
        (:func:`foldcore.study.task.run_path`). Shipped to the workers by value
        (cloudpickle).
    client, scheduler, workers
        Where it runs (:func:`foldcore.study.execute.run_paths`): a
        ``distributed.Client``, a scheduler's address, or an embedded LocalCluster
        of ``workers`` processes (default: one per core; 0: this process).
    keep : path, optional
        Folder for each point's result FOLD (``point-NNNN.fold``, the column
        ``result_fold``); created if missing.
    cache : path, "default" or None
        Folder of finished rows (:mod:`foldcore.study.cache`); a rerun folds only
        the points not in it. None: no cache.
    continuation : bool
        Points equal but for their fold percent are folded as one path on one
        worker, each from the previous result (column ``start``); False: each from
        the flat sheet, every row then equal to its direct ``foldcore simulate``.
    progress : bool or None
        A progress bar on stderr (None: on a terminal only).

    Returns
    -------
    pandas.DataFrame
        Columns: the points' names, :data:`FIGURES` (mm, degrees, seconds:
        ``wall_s`` the whole point on its worker — reading, thickening, run,
        figures, metric —, ``run_s`` its ``Simulation.run``; the others as
        :func:`foldcore.study.figures.figures`), the metric's, then :data:`TRAILING`.
        ``error`` is empty where the point folded.
    """
    from .execute import run_paths
    from .source import source_of

    source = source_of(pattern, hinges)
    todo = _points(grid, points, source.parameters)
    plan = continuation_paths(todo) if continuation else [[i] for i in range(len(todo))]
    store = Cache.at(cache)
    keys = _keys(source.key(), todo, plan, metric)
    keep_dir = _keep_folder(keep)
    rows, missing = _from_cache(store, keys, plan, keep_dir)

    def arrived(ids, new_rows):
        for i, row in zip(ids, new_rows):
            fold = row.pop("result_fold", None)
            if not row.get("error"):
                store.put(keys[i], row, fold)
            rows[i] = _kept({**row, "cached": False}, fold, keep_dir, i)

    if missing:
        run_paths(source, todo, missing, metric=metric, keep=keep_dir is not None,
                  continuation=continuation, client=client, scheduler=scheduler,
                  workers=workers, progress=progress, on_rows=arrived)
    return table(rows, list(todo[0]) if todo else [])


def _from_cache(store, keys: list, plan: list, keep_dir) -> tuple[list, list]:
    """(rows, paths still to fold): the rows of every path found whole in the cache
    (with its result FOLD, when kept), None for the others."""
    rows: list = [None] * len(keys)
    missing = []
    for ids in plan:
        hits = [store.get(keys[i]) for i in ids]
        if all(h is not None and (keep_dir is None or h[1] is not None) for h in hits):
            for i, (row, fold) in zip(ids, hits):
                rows[i] = _kept({**row, "cached": True}, fold, keep_dir, i)
        else:
            missing.append(ids)
    return rows, missing


def _points(grid, points, parameters) -> list[dict]:
    if (grid is None) == (points is None):
        raise StudyError("give a grid or a list of points (one of them)")
    todo = grid_points(grid) if grid is not None else list(points)
    if not todo:
        raise StudyError("the study has no point")
    return check(todo, parameters)


def _keys(source_key: str, todo: list, plan: list, metric) -> list[str]:
    """Each point's cache key, with the fold percents its path ran before it."""
    keys = [""] * len(todo)
    for ids in plan:
        before = []
        for i in ids:
            keys[i] = point_key(source_key, todo[i], list(before), metric)
            before.append(fold_percent(todo[i]))
    return keys


def _keep_folder(keep):
    if keep is None:
        return None
    folder = Path(keep)
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def _kept(row: dict, fold: bytes | None, keep_dir, index: int) -> dict:
    """``row`` with ``result_fold`` the path its FOLD was written to (kept studies)."""
    from ..files import write_bytes

    path = ""
    if keep_dir is not None and fold is not None:
        path = str(keep_dir / f"point-{index:04d}.fold")
        write_bytes(path, fold)
    return {**row, "result_fold": path}


def table(rows: list[dict], names: list[str]):
    """The rows as a DataFrame, columns in the documented order (NaN for a figure a
    row lacks: a failed point's)."""
    import pandas as pd

    names = list(dict.fromkeys(n for row in rows for n in row if n in names)) or names
    extra = [c for row in rows for c in row
             if c not in names and c not in FIGURES and c not in TRAILING]
    columns = names + list(FIGURES) + list(dict.fromkeys(extra)) + list(TRAILING)
    text = ("start", "worker", "result_fold", "warnings", "error")
    frame = pd.DataFrame([{c: row.get(c, "" if c in text else math.nan) for c in columns}
                          for row in rows], columns=columns)
    for name, kind in _KINDS.items():  # nullable: a failed point's figures are missing
        frame[name] = frame[name].astype(kind)
    return frame
