"""One fold from a file to its outputs — what ``foldcore simulate`` does, as a call.

>>> result = foldcore.simulate("crane.fold", thickness=0.5, sheet_size=200,
...                            fold_percent=30, output="crane-30.fold")  # doctest: +SKIP

Reads the pattern (:mod:`foldcore.io`, Origami Simulator's conventions:
:mod:`foldcore.io.conventions`), checks every output path before any work
(:mod:`foldcore.destinations`), thickens, runs the simulation at the fold
percent (or along an animation's sweep) and writes the outputs all or nothing
(:mod:`foldcore.outputs`). Warnings the run calls for — nothing driven, or
converged with its targets missed — are :class:`foldcore.errors.RunWarning`.
Every option is the command line's, with the same defaults and units (mm,
degrees); the command line adds only its messages and exit codes.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

from .actuation import BRANCH_FLOOR_DEG, DEFAULT_ACTUATION
from .strategies import DEFAULT_SOLVER


@dataclass(frozen=True)
class Loaded:
    """A pattern file read: the pattern and the file-level values thicken() takes."""

    pattern: object  # CreasePattern
    thickness: float | None  # mm, the file's foldcore:thickness
    stiffness: dict | None
    hinge: list | None


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during the run: the last iterate was written as a partial result
    (``foldcore:partial`` in the FOLD file, ``reason: "interrupted"`` in the
    report) to ``written`` (option name → path); ``result`` is that iterate."""

    def __init__(self, result, written: dict):
        super().__init__()
        self.result, self.written = result, written


@dataclass
class Fold:
    """A finished fold: what the command line reports from."""

    pattern: object  # CreasePattern
    mesh: object  # ThickMesh
    simulation: object  # Simulation
    result: object  # Result
    settings: dict  # recorded in the report
    summary: str  # one line: verdict, iterations, time, miss


def load(path, *, hinges=None, reading=None) -> Loaded:
    """Read a FOLD or SVG file, or an OBJ/STL mesh with its hinge file
    (:func:`foldcore.io.read_file`, which chooses the reader by suffix)."""
    from .io import read_file

    read = read_file(path, hinges=hinges, reading=reading)
    return Loaded(read.pattern, read.thickness, read.stiffness, read.hinge)


def simulate(path, *, thickness: float | None = None, hinge_width: float | None = None,
             subdivisions="auto", fold_percent: float = 100.0, solver: str = DEFAULT_SOLVER,
             tolerance: float = 1e-8, max_iterations: int = 10_000, hinge: str | None = None,
             actuation: str = DEFAULT_ACTUATION, branch_floor: float = BRANCH_FLOOR_DEG,
             hinges=None, mv_passive: bool = False, trust_assignment: bool = False,
             scale: float | None = None, sheet_size: float | None = None,
             elastic_cells: float | None = None, output=None, report=None, render=None,
             animate=None, series=None, frames: int = 20, fps: float = 10.0, callback=None):
    """Fold the pattern file at ``path`` and write the outputs asked for; the Result.

    Parameters
    ----------
    path : str or os.PathLike
        ``.fold``, or ``.obj``/``.stl`` with a hinge file (``hinges``, default
        PATH.hinges).
    thickness : float, optional
        Sheet thickness H, mm (default: the file's ``foldcore:thickness``).
    hinge_width : float, optional
        Hinge width W of every crease, mm (default: the file's, else Eq. 7).
    subdivisions : int or "auto"
    fold_percent : float
        Every target angle × this / 100, in [−100, 100].
    solver, tolerance, max_iterations, hinge, actuation, branch_floor
        As :class:`foldcore.Simulation` and its ``run`` (``branch_floor``: degrees).
    mv_passive, trust_assignment, scale, sheet_size
        How the file is read (:class:`foldcore.io.Reading`; ``sheet_size``: mm).
    elastic_cells : float, optional
        Elastic panels: every face cut into rings of cells about this long, mm
        (``thicken(elastic="facets", cell_size=...)``), so panels bend and
        stretch where the targets ask for it; default rigid panels. ``hybrid``
        folds such a mesh from rest with rigid panels first, then finishes with
        ``newton`` (:mod:`foldcore.strategies.hybrid`).
    output, report, render, animate : path, optional
        Result FOLD, JSON report, PNG render, GIF/MP4 of the sweep from 0 to
        ``fold_percent`` in ``frames`` frames at ``fps`` (the last frame's run is
        the result).
    series : path, optional
        The same sweep as one FOLD file, a frame per fold percent (achieved angles
        and the folded solid, :func:`foldcore.outputs.series_frame`).
    callback : callable(sim, moved_mm) -> bool or None, optional
        Called after each iteration (:meth:`Simulation.run`); False stops the run.

    Returns
    -------
    Result

    Raises
    ------
    Interrupted
        Ctrl-C (KeyboardInterrupt) during the run: the last iterate is written to
        the outputs asked for, marked partial, then this is raised (a
        KeyboardInterrupt). A second Ctrl-C while writing leaves no file.
    """
    return fold(path, **{k: v for k, v in locals().items() if k != "path"}).result


def fold(path, **options) -> Fold:
    """:func:`simulate`, keeping what the command line reports from (a :class:`Fold`)."""
    import os

    from .destinations import check_destinations
    from .errors import RunWarning, SimulationError
    from .io import Reading
    from .limits import check_inputs
    from .outputs import run_summary, write_result
    from .simulation import Simulation
    from .thickening import thicken

    o = _with_defaults(options)
    source = os.fspath(path)
    if o["max_iterations"] < 1:
        raise SimulationError(f"--max-iterations must be ≥ 1, got {o['max_iterations']}")
    reading = Reading(mv_without_angle="passive" if o["mv_passive"] else "fold",
                      trust_assignment=o["trust_assignment"], scale=o["scale"],
                      size=o["sheet_size"])
    loaded = load(source, hinges=o["hinges"], reading=reading)
    check_inputs(loaded.pattern, o["thickness"], o["hinge_width"], loaded.stiffness)
    thickness = o["thickness"] or loaded.thickness
    if thickness is None:
        raise SimulationError(f"{source}: no thickness: pass --thickness H (mm) "
                              "or set foldcore:thickness in the file")
    check_destinations({"-o": o["output"], "--report": o["report"], "--render": o["render"],
                        "--animate": o["animate"], "--series": o["series"]},
                       inputs=(source, o["hinges"]),
                       suffixes={"--render": (".png",), "--series": (".fold",)})
    if o["animate"]:  # (an animation interrupted writes nothing: its frames are a sweep)
        from .animate import check_output
        check_output(o["animate"])          # a missing encoder fails before any work
    cells = o["elastic_cells"]
    mesh = thicken(loaded.pattern, thickness, o["hinge_width"], o["subdivisions"],
                   hinge=o["hinge"] or loaded.hinge, stiffness=loaded.stiffness,
                   elastic="facets" if cells else None, cell_size=cells)
    sim = Simulation(mesh, loaded.pattern, solver=o["solver"], actuation=o["actuation"],
                     branch_floor_deg=o["branch_floor"])
    interrupted, sweep = False, None
    if o["animate"]:
        sweep = _animate(sim, o)
    elif o["series"]:
        sweep = _sweep(sim, o)
    if sweep is not None:
        result = sweep[-1][1]
    else:
        sim.set_fold_percent(o["fold_percent"])
        try:
            result = sim.run(tolerance=o["tolerance"], max_iterations=o["max_iterations"],
                             callback=o["callback"])
        except KeyboardInterrupt:  # the last complete iterate is a result too
            result, interrupted = sim.result(False, "interrupted"), True
    summary, said = run_summary(result, loaded.pattern, source, o["fold_percent"],
                                elastic=bool(mesh.elastic))
    for text in said:
        warnings.warn(text, RunWarning, stacklevel=3)
    settings = {"pattern": source, **{k: o[k] for k in ("fold_percent", "solver", "tolerance",
                                                        "max_iterations", "subdivisions")}}
    settings.update(thickness_mm=thickness, hinge=sorted(set(mesh.hinge_model) - {""}),
                    actuation=o["actuation"], branch_floor_deg=o["branch_floor"],
                    elastic_cells_mm=cells,
                    backend=sim.system.backend)
    outputs = {"-o": o["output"], "--report": o["report"], "--render": o["render"]}
    write_result(result, loaded.pattern, mesh, thickness, settings, fold=o["output"],
                 report=o["report"], png=o["render"], partial=interrupted,
                 series=o["series"], sweep=sweep)
    if interrupted:
        raise Interrupted(result, {k: v for k, v in outputs.items() if v})
    return Fold(loaded.pattern, mesh, sim, result, settings, summary)


def defaults() -> dict:
    """:func:`simulate`'s options (its keyword-only parameters) and their defaults; the
    command line passes its own arguments of these names."""
    import inspect

    return {name: p.default for name, p in inspect.signature(simulate).parameters.items()
            if p.kind is p.KEYWORD_ONLY}


def _with_defaults(options: dict) -> dict:
    """``options`` over :func:`simulate`'s defaults; an unknown name is a TypeError."""
    known = defaults()
    unknown = set(options) - set(known)
    if unknown:
        raise TypeError(f"simulate() got unexpected options {sorted(unknown)}")
    return {**known, **options}


def _animate(sim, o: dict) -> list:
    """Fold ``sim`` from 0 to the fold percent in ``frames`` steps, write the movie;
    [(percent, Result)] of every frame (:func:`_said_unconverged`)."""
    from .animate import animate, percent_schedule

    percents = percent_schedule(o["frames"], o["fold_percent"])
    movie = animate(sim, percents, o["animate"], fps=o["fps"], tolerance=o["tolerance"],
                    max_iterations=o["max_iterations"])
    return _said_unconverged(list(zip(map(float, percents), movie.results)))


def _sweep(sim, o: dict) -> list:
    """:func:`_animate` without the pictures (``--series`` alone)."""
    from .animate import fold_sweep, percent_schedule

    percents = percent_schedule(o["frames"], o["fold_percent"])
    results = fold_sweep(sim, percents, tolerance=o["tolerance"],
                         max_iterations=o["max_iterations"], progress=False)
    return _said_unconverged(list(zip(map(float, percents), results)))


def _said_unconverged(sweep: list) -> list:
    """``sweep``, after a RunWarning counting its unconverged intermediate frames."""
    from .errors import RunWarning

    unconverged = sum(not r.converged for _, r in sweep[:-1])
    if unconverged:
        warnings.warn(f"{unconverged} of {len(sweep) - 1} intermediate frames of the sweep "
                      "not converged", RunWarning, stacklevel=4)
    return sweep
