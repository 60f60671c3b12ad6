"""One fold from a file to its outputs — what ``foldcore simulate`` does, as a call.

>>> result = foldcore.simulate("crane.fold", reading={"size": 200},
...                            thickening={"thickness": 0.5}, solving={"fold_percent": 30},
...                            outputs={"fold": "crane-30.fold"})  # doctest: +SKIP

Reads the pattern (:mod:`foldcore.io`, Origami Simulator's conventions:
:mod:`foldcore.io.conventions`), checks every output path before any work
(:mod:`foldcore.destinations`), thickens, runs the simulation at the fold
percent (or along an animation's sweep) and writes the outputs (the data files
all or nothing, then the picture); a pattern with no thickness folds as a thin
sheet instead (:mod:`foldcore.sheet_job`)
(:mod:`foldcore.outputs`). Warnings the run calls for — nothing driven, or
converged with its targets missed — are :class:`foldcore.errors.RunWarning`.
Every option is in one of four groups (:mod:`foldcore.options`), with the
command line's defaults and units (mm, degrees); the command line maps its
flags to them and adds only its messages and exit codes.
"""
from __future__ import annotations

import warnings
from contextlib import contextmanager
from dataclasses import dataclass

from .errors import RunWarning
from .options import OptionError


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during the run: the last iterate was written as a partial result
    (``foldcore:partial`` in the FOLD file, ``reason: "interrupted"`` in the
    report) to ``written`` (``outputs.field`` → path); ``result`` is that iterate.
    ``partial`` False: the Ctrl-C came while a finished result was being written,
    which was completed first."""

    def __init__(self, result, written: dict, partial: bool = True):
        super().__init__()
        self.result, self.written, self.partial = result, written, partial


@dataclass
class Fold:
    """A finished fold: what the command line reports from."""

    pattern: object  # CreasePattern
    mesh: object  # ThickMesh
    simulation: object  # Simulation
    result: object  # Result
    settings: dict  # recorded in the report
    summary: str  # one line: verdict, iterations, time, miss


def simulate(path, *, hinges=None, reading=None, thickening=None, solving=None,
             outputs=None, callback=None):
    """Fold the pattern file at ``path`` and write the outputs asked for; the Result.

    Parameters
    ----------
    path : str or os.PathLike
        ``.fold``, ``.svg``, ``.cp``, ``.opx``, or ``.obj``/``.stl`` with a hinge file
        (:func:`foldcore.io.read_file`).
    hinges : path, optional
        Hinge file of an OBJ/STL pattern (default: PATH.hinges).
    reading : foldcore.io.Reading or dict, optional
        How the file is read (conventions, scaling; :mod:`foldcore.io.conventions`).
    thickening : foldcore.options.Thickening or dict, optional
        Thickness, hinge widths and models, sub-strips, elastic cells (mm).
    solving : foldcore.options.Solving or dict, optional
        Fold percent, strategy, tolerance, budget, actuation, branch floor.
    outputs : foldcore.options.Outputs or dict, optional
        Result FOLD, JSON report, PNG render, animation, series (paths; checked
        before any work; the data files written all or nothing, then the PNG:
        an OutputError naming it if it cannot be rendered, the others kept).
    callback : callable(sim, moved_mm) -> bool or None, optional
        Called after each iteration (:meth:`Simulation.run`); False stops the run.

    Returns
    -------
    Result, or :class:`foldcore.sheet.SheetFold` when the pattern has no thickness
    (folded as a thin sheet, Origami Simulator's model: :mod:`foldcore.sheet_job`)

    Raises
    ------
    OptionError
        An option outside what it accepts (named ``group.field``).
    Interrupted
        Ctrl-C (KeyboardInterrupt) during the run: the last iterate is written to
        the outputs asked for, marked partial, then this is raised (a
        KeyboardInterrupt). A second Ctrl-C while writing leaves no file.
    """
    return fold(path, hinges=hinges, reading=reading, thickening=thickening, solving=solving,
                outputs=outputs, callback=callback).result


@dataclass(frozen=True)
class Job:
    """One fold's inputs: the pattern file, its hinge file, the four option groups."""

    source: str
    hinges: object
    reading: object
    thickening: object
    solving: object
    outputs: object

    @classmethod
    def make(cls, path, hinges=None, reading=None, thickening=None, solving=None,
             outputs=None) -> "Job":
        """The groups checked (dicts made groups; OptionError naming ``group.field``)."""
        import os

        from .io import Reading
        from .options import Outputs, Solving, Thickening, as_group

        return cls(os.fspath(path), hinges, as_group(Reading, reading, "reading"),
                   as_group(Thickening, thickening, "thickening"),
                   as_group(Solving, solving, "solving"),
                   as_group(Outputs, outputs, "outputs"))


def fold(path, *, hinges=None, reading=None, thickening=None, solving=None, outputs=None,
         callback=None, on_start=None) -> Fold:
    """:func:`simulate`, keeping what the command line reports from (a :class:`Fold`);
    ``on_start()`` is called once the pattern is read and the model built, before the
    run (the command line prints the reading's warnings there, not after the run)."""
    from .outputs import run_summary, write_result

    job = Job.make(path, hinges, reading, thickening, solving, outputs)
    loaded, thickness = _prepared(job)
    if thickness is None:
        return _fold_thin(job, loaded, on_start, callback)
    mesh, sim = _simulation(job, loaded, thickness)
    if on_start is not None:
        on_start()
    out, s = job.outputs, job.solving
    interrupted, sweep = False, None
    if out.animate:
        sweep = _animate(sim, s, out)
    elif out.series:
        sweep = _sweep(sim, s, out)
    if sweep is not None:
        result = sweep[-1][1]
    else:
        sim.set_fold_percent(s.fold_percent)
        try:
            result = sim.run(tolerance=s.tolerance, max_iterations=s.budget(),
                             callback=callback)
        except KeyboardInterrupt:  # the last complete iterate is a result too
            result, interrupted = sim.result(False, "interrupted"), True
    summary, said = run_summary(result, loaded.pattern, job.source, s.fold_percent,
                                model="elastic" if mesh.elastic else "rigid")
    from .simulation import NO_IPCTK  # imported with the Simulation above

    if sim.model.contact_off == NO_IPCTK:
        said = [f"{job.source}: contact off: {sim.model.contact_off}; panels may pass "
                f"through each other", *said]
    for text in said:
        warnings.warn(text, RunWarning, stacklevel=3)
    settings = run_settings(job, thickness, mesh, sim)
    with interrupts_deferred() as late:
        write_result(result, loaded.pattern, mesh, thickness, settings, fold=out.fold,
                     report=out.report, png=out.render, partial=interrupted,
                     series=out.series, sweep=sweep)
    if interrupted or late:
        raise Interrupted(result, _written(out), partial=interrupted)
    return Fold(loaded.pattern, mesh, sim, result, settings, summary)


def _fold_thin(job, loaded, on_start, callback) -> Fold:
    """:func:`fold` of a pattern with no thickness: a thin sheet (:mod:`foldcore.sheet_job`)."""
    from .sheet_job import check_thin, run_thin, thin_settings, thin_summary, write_thin

    check_thin(job)
    sheet, solver, result, interrupted, sweep = run_thin(job, loaded, on_start, callback)
    if sweep is not None:
        _said_unconverged(sweep)
    summary, settings = thin_summary(job, loaded.pattern, result), thin_settings(job)
    with interrupts_deferred() as late:
        write_thin(job, loaded.pattern, sheet, result, settings, interrupted, sweep)
    if interrupted or late:
        raise Interrupted(result, _written(job.outputs), partial=interrupted)
    return Fold(loaded.pattern, sheet, solver, result, settings, summary)


def _written(out) -> dict:
    """``outputs.field`` → path of the outputs asked for that a run writes."""
    return {k: v for k, v in out.paths().items() if v and k in
            ("outputs.fold", "outputs.report", "outputs.render", "outputs.series")}


@contextmanager
def interrupts_deferred():
    """A block a first Ctrl-C does not break: the outputs of a result already
    computed are written whole, then the interrupt is raised by the caller (the
    yielded list is non-empty if one came). A second Ctrl-C breaks it (the files
    being written are then removed, :func:`foldcore.files.all_or_nothing`).
    Outside the main thread (no signal handlers there) the block runs as it is."""
    import signal
    import threading

    received: list = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return

    def defer(signum, frame):
        if received:
            raise KeyboardInterrupt
        received.append(signum)

    previous = signal.signal(signal.SIGINT, defer)
    try:
        yield received
    finally:
        signal.signal(signal.SIGINT, previous)


def prepare(job: Job) -> tuple:
    """(loaded, thickness, mesh, sim) of a job: the file read (:class:`foldcore.io.FoldFile`),
    its thickness (mm), the thick mesh and its :class:`foldcore.Simulation` at the flat
    state; everything that can fail on the inputs fails before the mesh is built."""
    loaded, thickness = _prepared(job)
    if thickness is None:
        raise OptionError(f"{job.source}: no thickness: give thickening.thickness (mm) "
                          "or set foldcore:thickness in the file")
    return (loaded, thickness, *_simulation(job, loaded, thickness))


def _prepared(job: Job):
    """The pattern read and its thickness (mm), every output path checked: all that can
    fail on the inputs fails here, before any work."""
    from .destinations import check_destinations
    from .files import check_input
    from .io import read_file
    from .limits import check_inputs

    t = job.thickening
    loaded = read_file(job.source, hinges=job.hinges, reading=job.reading)
    check_inputs(loaded.pattern, t.thickness, t.hinge_width, loaded.stiffness,
                 t.elastic_cells, job.solving.ground)
    thickness = t.thickness or loaded.thickness
    ground = job.solving.ground
    if ground is not None and thickness is not None and not ground < -0.5 * thickness:
        raise OptionError(f"{job.source}: solving.ground = {ground:g} mm is not below the "
                          f"flat sheet, whose bottom face is at z = {-0.5 * thickness:g} mm "
                          "(the ground faces up and holds the sheet from below)")
    for path in job.solving.obstacles:  # read after thickening: checked now
        check_input(path)
    check_destinations(job.outputs.paths(), inputs=(job.source, job.hinges),
                       suffixes={"outputs.render": (".png",), "outputs.series": (".fold",)})
    if job.outputs.animate:  # (an animation interrupted writes nothing: its frames are a sweep)
        from .animate import check_output
        check_output(job.outputs.animate)  # a missing encoder fails before any work
    return loaded, thickness


def _simulation(job: Job, loaded, thickness: float):
    """(mesh, Simulation) of the job's pattern (``loaded``: the file read,
    :class:`foldcore.io.FoldFile`)."""
    from .simulation import Simulation
    from .thickening import thicken

    t, s = job.thickening, job.solving
    cells = t.elastic_cells
    mesh = thicken(loaded.pattern, thickness, t.hinge_width, t.subdivisions,
                   hinge=t.hinge or loaded.hinge, stiffness=loaded.stiffness,
                   elastic="facets" if cells else None, cell_size=cells)
    sim = Simulation(mesh, loaded.pattern, solver=s.solver, actuation=s.actuation,
                     branch_floor_deg=s.branch_floor, options=s.strategy_options,
                     contact=s.contact_asked, obstacles=_obstacles(s, loaded.pattern))
    return mesh, sim


def _obstacles(s, pattern) -> list:
    """The run's :class:`foldcore.contact.Obstacle` list: the mesh files, then the ground
    (a square 20 × the pattern's size under its centre)."""
    if not (s.obstacles or s.ground is not None):
        return []
    from .contact import Obstacle, read_obstacle

    out = [read_obstacle(path) for path in s.obstacles]
    if s.ground is not None:
        lo, hi = pattern.vertices.min(axis=0), pattern.vertices.max(axis=0)
        centre = 0.5 * (lo + hi)
        out.append(Obstacle.plane((centre[0], centre[1], s.ground), (0.0, 0.0, 1.0),
                                  size=20.0 * float((hi - lo).max()), name="ground"))
    return out


def run_settings(job: Job, thickness: float, mesh, sim) -> dict:
    """What the report records of the run's settings."""
    s, t = job.solving, job.thickening
    return {"pattern": job.source, "fold_percent": s.fold_percent, "solver": s.solver,
            "tolerance": s.tolerance, "max_iterations": s.budget(),
            "subdivisions": t.subdivisions, "thickness_mm": thickness,
            "hinge": sorted(set(mesh.hinge_model) - {""}), "actuation": s.actuation,
            "branch_floor_deg": s.branch_floor, "elastic_cells_mm": t.elastic_cells,
            "contact": "off" if sim.model.contact is None else "on",
            **({"contact_off": sim.model.contact_off} if sim.model.contact is None else {}),
            "obstacles": list(s.obstacles), "ground_mm": s.ground,
            "backend": sim.system.backend}


def _animate(sim, s, out) -> list:
    """Fold ``sim`` from 0 to the fold percent in ``frames`` steps, write the movie;
    [(percent, Result)] of every frame (:func:`_said_unconverged`)."""
    from .animate import animate, percent_schedule

    percents = percent_schedule(out.frames, s.fold_percent)
    movie = animate(sim, percents, out.animate, fps=out.fps, tolerance=s.tolerance,
                    max_iterations=s.budget())
    return _said_unconverged(list(zip(map(float, percents), movie.results)))


def _sweep(sim, s, out) -> list:
    """:func:`_animate` without the pictures (a series alone)."""
    from .animate import fold_sweep, percent_schedule

    percents = percent_schedule(out.frames, s.fold_percent)
    results = fold_sweep(sim, percents, tolerance=s.tolerance,
                         max_iterations=s.budget(), progress=False)
    return _said_unconverged(list(zip(map(float, percents), results)))


def _said_unconverged(sweep: list) -> list:
    """``sweep``, after a RunWarning counting its unconverged intermediate frames."""
    from .errors import RunWarning

    unconverged = sum(not r.converged for _, r in sweep[:-1])
    if unconverged:
        warnings.warn(f"{unconverged} of {len(sweep) - 1} intermediate frames of the sweep "
                      "not converged", RunWarning, stacklevel=4)
    return sweep
