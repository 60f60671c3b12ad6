"""``foldcore sweep`` and ``foldcore optimize``: design studies from the command line
(:func:`foldcore.study.sweep`, :func:`foldcore.study.optimize`).

``foldcore sweep PATTERN --set NAME=V1,V2,… [--set …] -o results.csv|.parquet``
folds every combination of the values (or the points of ``--points CSV``) on
Dask: an embedded LocalCluster (``--workers N``, default one per core) or a
running scheduler (``--scheduler tcp://HOST:PORT``). PATTERN is a file or a
built-in generator's name (``miura``: ``--set n=4 --set gamma=50,60``).
``--plots DIR`` and ``--report OUT.html`` add what a designer reads
(:mod:`foldcore.study.report`).
``foldcore optimize PATTERN --vary NAME=LOW:HIGH [--set NAME=V] --minimize COLUMN
-o history.csv`` searches the range for the point whose fold minimises (or
``--maximize``) a column of its row, one fold per trial, and prints the best
point in one line. Exit codes as ``simulate``: 2 with one line for bad input
(before any fold), 130 on Ctrl-C (the finished points are cached: the same
command resumes).
Importing this module imports neither Dask nor pandas.
"""
from __future__ import annotations

import argparse
import sys
import time

from ..errors import FoldcoreError

EXIT_SIGINT = 130


def add_to(sub) -> None:
    """Add ``sweep`` and ``optimize`` to the command line's subparsers."""
    from .source import GENERATORS

    sweep = sub.add_parser("sweep", help="fold a pattern over a grid of option values "
                                         "(a design study, on Dask)")
    sweep.add_argument("pattern", help="crease pattern file, or a generator: "
                                       + ", ".join(GENERATORS))
    sweep.add_argument("--set", action="append", default=[], metavar="NAME=V1,V2,…",
                       help="values of an option (thickness, hinge-width, fold-percent, "
                            "solver, … as simulate's flags without --) or of the "
                            "generator's parameters; every combination is a point")
    sweep.add_argument("--points", metavar="CSV", help="the points as a CSV file "
                                                       "(header: names; a row per point)")
    sweep.add_argument("-o", "--output", required=True,
                       help="the table: .csv, or .parquet (pyarrow)")
    sweep.add_argument("--hinges", help="hinge file of an OBJ/STL pattern")
    add_execution(sweep)
    sweep.add_argument("--keep", metavar="DIR", help="write each point's result FOLD "
                                                     "here (column result_fold)")
    sweep.add_argument("--from-flat", action="store_true",
                       help="fold every point from the flat sheet (default: points equal "
                            "but for --set fold-percent continue one from the other)")
    sweep.add_argument("--metric", metavar="FILE.py:FUNCTION",
                       help="your metric of each fold: FUNCTION(fold) → number or dict "
                            "(columns), from a Python file or module:function")
    sweep.add_argument("--plots", metavar="DIR",
                       help="a PNG of each figure against each swept parameter, in DIR "
                            "(matplotlib)")
    sweep.add_argument("--report", metavar="OUT.html",
                       help="one self-contained HTML page: summary, plots, table; with "
                            "--keep, a picture of each folded solid linking to its view "
                            "page (in OUT_files/)")
    add_optimize(sub)


def add_optimize(sub) -> None:
    """Add ``optimize`` to the command line's subparsers."""
    from .optimize import SAMPLERS
    from .source import GENERATORS

    opt = sub.add_parser("optimize", help="search option values for the fold that minimises "
                                          "or maximises a figure (a design study, on Dask)")
    opt.add_argument("pattern", help="crease pattern file, or a generator: "
                                     + ", ".join(GENERATORS))
    opt.add_argument("--vary", action="append", required=True,
                     metavar="NAME=LOW:HIGH[:log|:STEP]",
                     help="a range to search (an option, e.g. hinge-width=0.2:2 mm, or a "
                          "generator's parameter; integers for an integer name), or "
                          "NAME=V1,V2,… to choose among")
    opt.add_argument("--set", action="append", default=[], metavar="NAME=V",
                     help="a fixed value (an option or a generator's parameter)")
    goal = opt.add_mutually_exclusive_group(required=True)
    goal.add_argument("--minimize", metavar="COLUMN",
                      help="the row's column to minimise (largest_strain, miss_max_deg, … "
                           "or a --metric column)")
    goal.add_argument("--maximize", metavar="COLUMN", help="the row's column to maximise")
    opt.add_argument("--at-most", action="append", default=[], metavar="COLUMN=MOST",
                     help="a constraint: a feasible trial's COLUMN is at most MOST (and it "
                          "converged, always)")
    opt.add_argument("--trials", type=_count, default=40, metavar="N",
                     help="folds in all (default 40)")
    opt.add_argument("--seed", type=int, default=0, help="the sampler's seed (default 0)")
    opt.add_argument("--sampler", choices=SAMPLERS, default="tpe",
                     help="tpe (default), random, or qmc (scrambled Sobol)")
    opt.add_argument("--batch", type=_count, metavar="N",
                     help="trials folded together (default: the cluster's workers)")
    opt.add_argument("-o", "--output", required=True,
                     help="the history, a row per trial: .csv, or .parquet (pyarrow)")
    opt.add_argument("--hinges", help="hinge file of an OBJ/STL pattern")
    opt.add_argument("--metric", metavar="FILE.py:FUNCTION",
                     help="your metric of each fold: FUNCTION(fold) → number or dict "
                          "(columns), from a Python file or module:function")
    add_execution(opt)


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def add_execution(parser) -> None:
    """Where a study runs and what it keeps (sweep, optimize)."""
    parser.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                        help="run on this Dask scheduler's workers (default: an embedded "
                             "LocalCluster)")
    parser.add_argument("--workers", type=_workers, metavar="N",
                        help="worker processes of the embedded cluster (default: one per "
                             "core; 0: no cluster, this process)")
    parser.add_argument("--cache", metavar="DIR", help="finished points, for resuming "
                                                       "(default: ~/.cache/foldcore/study)")
    parser.add_argument("--no-cache", action="store_true",
                        help="neither read nor write finished points")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no progress bar and no summary line")


def _workers(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= 1024:
        raise argparse.ArgumentTypeError(f"expected an integer in 0..1024, got {text!r}")
    return value


def run_sweep(args) -> int:
    """Run ``foldcore sweep``; raises FoldcoreError on bad input."""
    from ..destinations import check_destinations
    from . import points as pts
    from .report import REPORT_SUFFIXES, check_folders, report_folder, write_plots, write_report
    from .sweep import sweep
    from .table import TABLE_SUFFIXES, write_table

    if bool(args.set) == bool(args.points):
        raise pts.StudyError("give the points with --set NAME=V1,V2,… or --points CSV "
                             "(one of them)")
    check_destinations({"-o": args.output, "--report": args.report},
                       inputs=(args.pattern, args.points, args.hinges),
                       suffixes={"-o": TABLE_SUFFIXES, "--report": REPORT_SUFFIXES})
    pages = report_folder(args.report) if args.report and args.keep else None
    check_folders({"--plots": args.plots,
                   f"--report {args.report}: its view pages' folder": pages})
    grid = dict(map(pts.parse_set, args.set)) if args.set else None
    if grid is not None and len(grid) < len(args.set):
        raise pts.StudyError("a name is given to --set twice")
    points = pts.read_points(args.points) if args.points else None
    start = time.perf_counter()
    try:
        frame = sweep(args.pattern, grid, points, hinges=args.hinges,
                      metric=load_metric(args.metric) if args.metric else None,
                      **execution(args), keep=args.keep, continuation=not args.from_flat)
    except KeyboardInterrupt:
        print("foldcore: interrupted (SIGINT); the points that finished are cached: the "
              "same command folds only the others", file=sys.stderr)
        return EXIT_SIGINT
    write_table(frame, args.output)
    plots = write_plots(frame, args.plots) if args.plots else None
    if args.report:
        write_report(frame, args.report, pattern_label=args.pattern, plots=plots,
                     thumbnails=args.keep is not None)
    if not args.quiet:
        print(summary(frame, time.perf_counter() - start, args.output), file=sys.stderr)
    say_failures(frame)
    return 0


def say_failures(frame) -> None:
    """A warning line if points failed: how many, and the first one's error."""
    failed = frame[frame["error"] != ""]
    if len(failed):
        print(f"foldcore: warning: {len(failed)} of {len(frame)} points failed (column "
              f"error; row {failed.index[0]}: {failed['error'].iloc[0]})", file=sys.stderr)


def run_optimize(args) -> int:
    """Run ``foldcore optimize``; raises FoldcoreError on bad input."""
    from ..destinations import check_destinations
    from .optimize import optimize, parse_bound, parse_fixed, parse_vary
    from .points import StudyError
    from .table import TABLE_SUFFIXES, write_table

    check_destinations({"-o": args.output}, inputs=(args.pattern, args.hinges),
                       suffixes={"-o": TABLE_SUFFIXES})
    space, fixed = dict(map(parse_vary, args.vary)), dict(map(parse_fixed, args.set))
    limits = dict(map(parse_bound, args.at_most))
    if len(space) < len(args.vary) or len(fixed) < len(args.set):
        raise StudyError("a name is given to --vary or --set twice")
    start = time.perf_counter()
    try:
        found = optimize(args.pattern, space, args.minimize or args.maximize, fixed=fixed,
                         trials=args.trials, minimize=args.minimize is not None,
                         sampler=args.sampler, seed=args.seed, constraints=limits,
                         metric=load_metric(args.metric) if args.metric else None,
                         hinges=args.hinges, batch=args.batch, **execution(args))
    except KeyboardInterrupt:
        print("foldcore: interrupted (SIGINT); the trials that finished are cached: the "
              "same command replays them and folds only the others", file=sys.stderr)
        return EXIT_SIGINT
    write_table(found.history, args.output)
    if not args.quiet:
        print(f"foldcore: optimize: {found.line()}; {_tally(found.history)} in "
              f"{time.perf_counter() - start:.3g} s → {args.output}", file=sys.stderr)
    say_failures(found.history)
    return 0


def _tally(frame) -> str:
    """``N trials (F folded on W workers, C from the cache, X failed, I infeasible)``."""
    failed = int((frame["objective"].isna()).sum())
    cached = frame["cached"].fillna(False).astype(bool)
    workers = frame.loc[~cached, "worker"].nunique()
    infeasible = int((~frame["feasible"].astype(bool)).sum()) - failed
    return (f"{len(frame)} trials ({int((~cached).sum())} folded on {workers} "
            f"worker{'s' if workers != 1 else ''}, {int(cached.sum())} from the cache, "
            f"{failed} failed, {infeasible} infeasible)")


def execution(args) -> dict:
    """The study's execution options from the flags."""
    return {"scheduler": args.scheduler, "workers": args.workers,
            "cache": None if args.no_cache else (args.cache or "default"),
            "progress": False if args.quiet else None}


def summary(frame, seconds: float, output) -> str:
    """One line: points, folded / cached / failed, workers, time, the table's path."""
    failed = int((frame["error"] != "").sum())
    cached = int(frame["cached"].fillna(False).sum())
    workers = frame.loc[~frame["cached"].fillna(False), "worker"].nunique()
    return (f"foldcore: sweep: {len(frame)} points ({len(frame) - cached - failed} folded on "
            f"{workers} worker{'s' if workers != 1 else ''}, {cached} from the cache, "
            f"{failed} failed) in "
            f"{seconds:.3g} s → {output}")


def load_metric(spec: str):
    """The function of ``FILE.py:FUNCTION`` or ``module:FUNCTION`` (shipped to the
    workers by value when it comes from a file)."""
    import importlib
    import importlib.util
    from pathlib import Path

    where, _, name = spec.rpartition(":")
    if not where or not name:
        raise FoldcoreError(f"--metric {spec!r}: expected FILE.py:FUNCTION or module:FUNCTION")
    try:
        if where.endswith(".py"):
            spec_ = importlib.util.spec_from_file_location(f"foldcore_metric_{Path(where).stem}",
                                                           where)
            module = importlib.util.module_from_spec(spec_)
            sys.modules[spec_.name] = module  # (cloudpickle ships a registered module)
            spec_.loader.exec_module(module)
            import cloudpickle
            cloudpickle.register_pickle_by_value(module)
        else:
            module = importlib.import_module(where)
    except (OSError, ImportError, SyntaxError) as exc:
        raise FoldcoreError(f"--metric {spec}: cannot load {where}: {exc}") from None
    function = getattr(module, name, None)
    if not callable(function):
        raise FoldcoreError(f"--metric {spec}: {where} has no function {name!r}")
    return function


#: Command name → function, for the command line's dispatch.
COMMANDS = {"sweep": run_sweep, "optimize": run_optimize}
