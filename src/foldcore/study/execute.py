"""Running a study's paths on Dask distributed (or in this process).

The client is the user's (``client``), one connected to a running scheduler
(``scheduler="tcp://HOST:PORT"``), or an embedded :class:`distributed.LocalCluster`
of one single-threaded worker process per core (numba and BLAS on one thread
each: the points are the parallel work; its status page on a free port, not
8787, which another cluster may hold). Before the first point, the
pattern (bytes or generator) is scattered to every worker once and each
worker loads foldcore's compiled kernels once (:func:`foldcore.warmup.warm`).
Each continuation path is one task; rows are cached as they arrive, so a
study stopped by Ctrl-C or a lost worker resumes where it was. A task on a
worker that dies is run again elsewhere by the scheduler (up to its
``allowed-failures``); a point that fails is a row with its error.
"""
from __future__ import annotations

import logging
import os
import sys
from contextlib import contextmanager

from .task import run_path

log = logging.getLogger("foldcore.study")


def run_paths(source, points: list[dict], plan: list[list[int]], *, metric=None,
              keep: bool = False, continuation: bool = True, client=None,
              scheduler=None, workers=None, progress=None, on_rows=None) -> None:
    """Fold each path of ``plan`` (lists of indices into ``points``) and hand its rows
    to ``on_rows(indices, rows)`` as they arrive.

    Parameters
    ----------
    client : distributed.Client, optional
        Run on this client's cluster.
    scheduler : str, optional
        Address of a running scheduler (``tcp://HOST:PORT``).
    workers : int, optional
        Worker processes of the embedded LocalCluster (default: the cores this
        process may use); 0: fold in this process, without Dask.
    progress : bool or None
        A tqdm bar of points on stderr (None: only on a terminal).
    """
    bar = _bar(sum(map(len, plan)), progress)
    try:
        if workers == 0 and client is None and scheduler is None:
            _warm_worker()  # (else the first point's times would include loading kernels)
            for ids in plan:
                rows = run_path(source, [points[i] for i in ids], metric=metric, keep=keep,
                                continuation=continuation)
                on_rows(ids, rows)
                bar.update(len(ids))
            return
        with _client(client, scheduler, workers) as dask:
            _on_cluster(dask, source, points, plan, metric, keep, continuation, on_rows, bar)
    finally:
        bar.close()


def _on_cluster(dask, source, points, plan, metric, keep, continuation, on_rows, bar):
    from distributed import as_completed

    shipped = dask.scatter(source, broadcast=True, hash=False)
    metric = None if metric is None else ByValue(metric)
    dask.run(_warm_worker)
    log.info("study: %d paths on %d workers", len(plan),
             len(dask.scheduler_info(n_workers=-1)["workers"]))
    futures = {}
    for ids in plan:
        future = dask.submit(run_path, shipped, [points[i] for i in ids], metric=metric,
                             keep=keep, continuation=continuation, pure=False)
        futures[future] = ids
    try:
        for future in as_completed(futures):
            ids = futures[future]
            on_rows(ids, _rows_or_error(future, [points[i] for i in ids]))
            bar.update(len(ids))
    finally:
        dask.cancel(list(futures))


def _rows_or_error(future, points: list[dict]) -> list[dict]:
    """The task's rows, or a row per point with the error that lost them (e.g. the
    task's workers died more often than the scheduler allows)."""
    try:
        return future.result()
    except Exception as exc:
        from .task import error_text

        return [{**p, "error": f"lost: {error_text(exc)}"} for p in points]


class ByValue:
    """A metric shipped by value (cloudpickle), so one defined in the user's script or
    file runs on workers that cannot import it; called as the metric would be
    (:func:`foldcore.study.task.takes_point`), its ``watch`` passed on."""

    def __init__(self, function):
        import cloudpickle

        self.blob = cloudpickle.dumps(function)
        self.function = None

    def __getstate__(self):
        return {"blob": self.blob}

    def __setstate__(self, state):
        self.blob, self.function = state["blob"], None

    def loaded(self):
        if self.function is None:
            import cloudpickle

            self.function = cloudpickle.loads(self.blob)
        return self.function

    @property
    def watch(self):
        return getattr(self.loaded(), "watch", None)

    def __call__(self, fold, point):
        from .task import takes_point

        function = self.loaded()
        return function(fold, point) if takes_point(function) else function(fold)


def _warm_worker() -> float:
    """Load (or compile, on a cold cache) the default path's kernels in this worker."""
    from ..warmup import warm

    return warm()["seconds"]


@contextmanager
def _client(client, scheduler, workers):
    """The Dask client of a study: the user's, one on ``scheduler``, or an embedded
    LocalCluster's (closed on exit)."""
    if client is not None:
        yield client
        return
    from distributed import Client

    if scheduler is not None:
        with _reached(scheduler, lambda: Client(scheduler, timeout="30s")) as dask:
            yield dask
        return
    from distributed import LocalCluster

    n = workers or default_workers()
    one_thread = {name: "1" for name in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS",
                                         "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    with _reached("the embedded LocalCluster", lambda: LocalCluster(
            n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
            silence_logs=logging.ERROR, env=one_thread)) as cluster, Client(cluster) as dask:
        yield dask


@contextmanager
def _reached(where: str, connect):
    """``connect()``'s client or cluster, closed on exit; a StudyError naming ``where``
    if it cannot be started or reached."""
    from .points import StudyError

    try:
        made = connect()
    except (OSError, RuntimeError, TimeoutError, ValueError) as exc:
        raise StudyError(f"{where}: cannot start or reach the Dask cluster "
                         f"({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})") \
            from None
    with made:
        yield made


def default_workers() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def _bar(total: int, progress):
    from tqdm import tqdm

    shown = sys.stderr.isatty() if progress is None else bool(progress)
    return tqdm(total=total, unit="point", file=sys.stderr, disable=not shown,
                dynamic_ncols=True, leave=False)
