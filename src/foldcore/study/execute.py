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
:func:`session` keeps one client, shipped pattern and warm workers for many
batches of paths (an optimisation's, :mod:`foldcore.study.optimize`).
"""
from __future__ import annotations

import logging
import os
import sys
from contextlib import contextmanager

from .task import run_path

log = logging.getLogger("foldcore.study")
#: Dask's setting that has a nanny start its worker with ``MALLOC_TRIM_THRESHOLD_``
#: (65536): glibc then returns freed memory at once and maps every large array
#: afresh, which slows a fold down (part of the per-point overhead that
#: ``bench/study.py`` measures); the embedded cluster unsets it (None), a cluster
#: started by hand can by configuration (docs/guide/studies.md).
TRIM = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"


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
    bar = progress_bar(sum(map(len, plan)), progress)
    try:
        with session(source, client=client, scheduler=scheduler, workers=workers) as where:
            where.run(points, plan, metric=metric, keep=keep, continuation=continuation,
                      on_rows=on_rows, bar=bar)
    finally:
        bar.close()


@contextmanager
def session(source, *, client=None, scheduler=None, workers=None):
    """A :class:`Session` folding ``source``'s points for as many batches as its
    caller runs (:mod:`foldcore.study.optimize`): one client, the pattern shipped
    and the workers warmed once. Arguments as :func:`run_paths`'s."""
    if workers == 0 and client is None and scheduler is None:
        yield Session(source)
        return
    with _client(client, scheduler, workers) as dask:
        yield Session(source, dask)


class Session:
    """Where a study's paths fold: a Dask client with the source scattered to every
    worker and each worker's kernels loaded, or this process (``dask`` None)."""

    def __init__(self, source, dask=None):
        self.source, self.dask = source, dask
        self.shipped = source
        if dask is None:
            _warm_worker()  # (else the first point's times would include loading kernels)
        else:
            self.shipped = dask.scatter(source, broadcast=True, hash=False)
            dask.run(_warm_worker)

    @property
    def workers(self) -> int:
        """Workers the cluster has now (1 in this process)."""
        if self.dask is None:
            return 1
        return len(self.dask.scheduler_info(n_workers=-1)["workers"])

    def run(self, points: list[dict], plan: list[list[int]], *, metric=None,
            keep: bool = False, continuation: bool = True, on_rows=None, bar=None) -> None:
        """Fold each path of ``plan`` and hand its rows to ``on_rows(indices, rows)``
        as they arrive; a path that raises is a row per point with its error."""
        if self.dask is None:
            for ids in plan:
                path = [points[i] for i in ids]
                try:
                    rows = run_path(self.source, path, metric=metric, keep=keep,
                                    continuation=continuation)
                except Exception as exc:  # a failing path is rows, never the end
                    rows = _error_rows(path, exc, "")
                on_rows(ids, rows)
                if bar is not None:
                    bar.update(len(ids))
            return
        self._on_cluster(points, plan, None if metric is None else ByValue(metric), keep,
                         continuation, on_rows, bar)

    def _on_cluster(self, points, plan, metric, keep, continuation, on_rows, bar):
        from distributed import as_completed

        log.info("study: %d paths on %d workers", len(plan), self.workers)
        # Dask's memory manager drops the broadcast's extra copies while no task needs
        # them, and then every task goes where the one copy is: copy it back first.
        self.dask.replicate([self.shipped])
        futures = {}
        for ids in plan:
            future = self.dask.submit(run_path, self.shipped, [points[i] for i in ids],
                                      metric=metric, keep=keep, continuation=continuation,
                                      pure=False)
            futures[future] = ids
        try:
            for future in as_completed(futures):
                ids = futures[future]
                on_rows(ids, _rows_or_error(future, [points[i] for i in ids]))
                if bar is not None:
                    bar.update(len(ids))
        finally:
            self.dask.cancel(list(futures))


def _rows_or_error(future, points: list[dict]) -> list[dict]:
    """The task's rows, or a row per point with the error that lost them (e.g. the
    task's workers died more often than the scheduler allows)."""
    try:
        return future.result()
    except Exception as exc:
        return _error_rows(points, exc, "lost: ")


def _error_rows(points: list[dict], exc: BaseException, prefix: str) -> list[dict]:
    """A row per point, each with the error that ended its path."""
    from .task import error_text

    return [{**p, "error": f"{prefix}{error_text(exc)}"} for p in points]


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
    from dask import config as dask_config
    from distributed import LocalCluster

    n = workers or default_workers()
    one_thread = {name: "1" for name in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS",
                                         "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    # (its workers' logs at CRITICAL: a heartbeat racing the scheduler's close logs an
    # error with a traceback; a point's own failure is its row's error)
    start = lambda: LocalCluster(  # noqa: E731
        n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
        silence_logs=logging.CRITICAL, env=one_thread)
    with dask_config.set({TRIM: None}), _reached("the embedded LocalCluster", start) \
            as cluster, Client(cluster) as dask:
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


def progress_bar(total: int, progress, unit: str = "point"):
    """A tqdm bar on stderr (``progress`` None: only on a terminal)."""
    from tqdm import tqdm

    shown = sys.stderr.isatty() if progress is None else bool(progress)
    return tqdm(total=total, unit=unit, file=sys.stderr, disable=not shown,
                dynamic_ncols=True, leave=False)
