"""Design studies on Dask: points per second against workers, the overhead per point
against direct runs, and the start-up cost of the embedded cluster.

Cases (the same points in every configuration):

* ``long``: Miura n × n driven by one crease (``patterns.miura_one_crease``,
  n = LONG_N, the widths' default), thickness 0.1 … 0.2 mm over LONG_POINTS
  values — folds of about a second or more, where the goal is ≤ 10 %
  overhead;
* ``short``: Pehrson's vertex (R = 20 mm, crease 1 → 70°; about 0.03 s per
  fold), thickness varied over SHORT_POINTS values — where the overhead per
  point shows.

Configurations, interleaved round by round over RUNS rounds (one warm-up round
first): ``direct`` — each point as ``foldcore.simulate`` of a FOLD file, one
after the other in this process, numba on every core (what a hand-written
loop does); ``direct_1t`` — the same on one thread, as a study's worker
runs; ``study_w1`` / ``study_w2`` — ``foldcore.study.sweep`` of the same
points on an embedded LocalCluster of 1 / 2 worker processes, cache off,
wall time of the whole call (cluster start, pattern shipped, workers warmed,
points folded, cluster closed); ``startup_w1`` / ``startup_w2`` — the same
call with one trivial point (a 2 × 2 Miura at 1 %), i.e. what a study costs
before and after its points.

Derived: ``overhead_per_point`` = (study_w1 − startup_w1 − direct_1t) /
direct_1t (one single-threaded worker does the one-thread loop's work; what
is left is Dask's per-point cost and the row's figures); ``points_per_s`` = points / study seconds, with
and without the start-up. Medians over the rounds; seconds throughout.

Run: ``python bench/study.py`` (~5 min) or ``--quick`` (fewer points, one
round); writes bench/results/study.json and .png; ``--table`` prints the
table of docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

import _meta

RUNS = 3
LONG_N, LONG_POINTS, SHORT_POINTS = 24, 8, 40
QUICK = {"runs": 1, "long": 4, "short": 10}
WORKERS = (1, 2)


def points(kind: str, count: int) -> tuple:
    """(pattern for the study, FOLD file for direct runs, points) of a case."""
    from foldcore import patterns
    from foldcore.io import write_fold

    folder = Path(tempfile.mkdtemp(prefix="foldcore-bench-study-"))
    if kind == "long":
        path = folder / "miura.fold"
        write_fold(path, patterns.miura_one_crease(LONG_N, LONG_N))
        pts = [{"thickness": float(h)} for h in np.linspace(0.1, 0.2, count)]
    else:
        path = folder / "vertex.fold"
        write_fold(path, patterns.degree4_vertex(radius=20.0, widths=[np.nan] * 4, rho1=70.0))
        pts = [{"thickness": float(h)} for h in np.linspace(0.05, 0.3, count)]
    return path, pts


def direct(path, pts: list, threads: int | None = None) -> float:
    """Seconds of ``foldcore.simulate`` of each point in turn (this process), numba and
    BLAS on ``threads`` threads (None: the defaults, all cores)."""
    import warnings

    import numba
    from threadpoolctl import threadpool_limits

    import foldcore
    from foldcore.study.points import option_groups

    before = numba.get_num_threads()
    numba.set_num_threads(threads or numba.config.NUMBA_NUM_THREADS)
    start = time.perf_counter()
    try:
        with warnings.catch_warnings(), threadpool_limits(threads):
            warnings.simplefilter("ignore")
            for point in pts:
                foldcore.simulate(path, **option_groups(point))
        return time.perf_counter() - start
    finally:
        numba.set_num_threads(before)


def studied(path, pts: list, workers: int) -> float:
    """Seconds of one ``foldcore.study.sweep`` call of the points."""
    from foldcore import study

    start = time.perf_counter()
    frame = study.sweep(path, points=pts, workers=workers, cache=None, progress=False,
                        continuation=False)
    seconds = time.perf_counter() - start
    assert (frame["error"] == "").all(), frame["error"].tolist()
    return seconds


def measure(kind: str, count: int, runs: int) -> dict:
    path, pts = points(kind, count)
    tiny = Path(path).with_name("tiny.fold")
    from foldcore import patterns
    from foldcore.io import write_fold

    write_fold(tiny, patterns.miura(2, 2))
    trivial = [{"thickness": 0.1, "fold-percent": 1}]
    cases = {"direct": lambda: direct(path, pts), "direct_1t": lambda: direct(path, pts, 1)}
    for w in WORKERS:
        cases[f"study_w{w}"] = lambda w=w: studied(path, pts, w)
        cases[f"startup_w{w}"] = lambda w=w: studied(tiny, trivial, w)
    seconds = _meta.interleaved(cases, runs, warmup=1)
    med = {name: _meta.median(v) for name, v in seconds.items()}
    out = {"points": count, "seconds": med, "seconds_runs": seconds,
           "direct_per_point_s": med["direct"] / count,
           "overhead_per_point": (med["study_w1"] - med["startup_w1"] - med["direct_1t"])
           / med["direct_1t"]}
    for w in WORKERS:
        out[f"points_per_s_w{w}"] = count / med[f"study_w{w}"]
        out[f"points_per_s_w{w}_after_startup"] = count / (med[f"study_w{w}"]
                                                          - med[f"startup_w{w}"])
    out["points_per_s_direct"] = count / med["direct"]
    print(f"  {kind}: direct {med['direct']:.2f} s (one thread {med['direct_1t']:.2f} s), "
          + ", ".join(
        f"w{w} {med[f'study_w{w}']:.2f} s (start-up {med[f'startup_w{w}']:.2f} s)"
        for w in WORKERS) + f"; overhead/point {out['overhead_per_point']:+.1%}", flush=True)
    return out


def plot(data: dict, path) -> None:
    plt = _meta.pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for ax, kind in zip(axes, ("long", "short")):
        case = data[kind]
        labels = ["direct"] + [f"{w} worker{'s' * (w > 1)}" for w in WORKERS]
        rates = [case["points_per_s_direct"]] + [case[f"points_per_s_w{w}"] for w in WORKERS]
        after = [case["points_per_s_direct"]] + [case[f"points_per_s_w{w}_after_startup"]
                                                 for w in WORKERS]
        x = np.arange(len(labels))
        ax.bar(x - 0.2, rates, 0.4, label="whole call (cluster start-up included)")
        ax.bar(x + 0.2, after, 0.4, label="start-up excluded")
        ax.set_xticks(x, labels)
        ax.set_ylabel("points per second")
        ax.set_title(f"{kind}: {case['points']} points, "
                     f"{case['direct_per_point_s']:.2g} s per direct fold")
        ax.legend(fontsize=7)
    _meta.save(fig, path)


def table(data: dict) -> str:
    header = ["case", "points", "direct s/point", "direct (all threads / one)", "1 worker",
              "2 workers", "start-up 1 / 2 workers", "overhead per point (1 worker)"]
    body = []
    for kind in ("long", "short"):
        c, s = data[kind], data[kind]["seconds"]
        body.append([kind, c["points"], _meta.sig(c["direct_per_point_s"]),
                     f"{s['direct']:.3g} / {s['direct_1t']:.3g} s", f"{s['study_w1']:.3g} s",
                     f"{s['study_w2']:.3g} s",
                     f"{s['startup_w1']:.3g} / {s['startup_w2']:.3g} s",
                     f"{c['overhead_per_point']:+.1%}"])
    return _meta.markdown_table(header, body)


def main() -> None:
    args = _meta.parser(__doc__).parse_args()
    if _meta.stored("study", args, table, plot):
        return
    q = QUICK if args.quick else {"runs": RUNS, "long": LONG_POINTS, "short": SHORT_POINTS}
    record = _meta.Record("study", args, runs=q["runs"], workers=list(WORKERS),
                          others_busy_before=_meta.others_busy())
    data = {kind: measure(kind, q[kind], q["runs"]) for kind in ("long", "short")}
    record.meta["others_busy_after"] = _meta.others_busy()
    record.write(data, plot)
    print(table(data))


if __name__ == "__main__":
    main()
