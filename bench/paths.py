"""A fold-percent path at the cost of its increments.

Thin Miura 8 × 8 (81 pattern vertices; ``accuracy.miura(8)``: a = 20 mm,
H = 0.02 mm, W = 3H, one zig-zag crease driven to its angle at facet tilt
30°, the rest passive), default strategy, tolerance 1e-8 (the command
line's):

* ``one_fold``: one ``Simulation.run`` from flat to 100 %;
* ``path_predicted`` / ``path_plain``: FRAMES increments (100/FRAMES %, …,
  100 %), each ``set_fold_percent`` then ``run`` to the same tolerance,
  continuing from the previous frame; with the predictor (after two
  converged frames each run starts from ``Simulation.predict``'s
  extrapolation of the last two, as ``foldcore simulate --animate`` does)
  and without it.

Reported: wall seconds of the runs (set-up excluded), iterations, whether
every frame converged, the final largest angle error against the closed form
(degrees) and the path's cost in single folds. Warm numba cache, one
warm-up round, then RUNS interleaved rounds (one fold, path with, path
without); medians. Writes bench/results/paths.json and .png.

Run: ``python bench/paths.py`` (~30 s) or ``--quick``; ``--table`` prints the
table of docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import time

import numpy as np

import _meta

RUNS, FRAMES, TOLERANCE = 3, 200, 1e-8
QUICK_RUNS, QUICK_FRAMES = 1, 20
ROWS = (("one_fold", "one fold, flat → 100 %"),
        ("path_predicted", "{frames}-increment path, predictor"),
        ("path_plain", "{frames}-increment path, no predictor"))


def scene():
    """(pattern, mesh, closed-form angles (C,) degrees, crease indices (C,))."""
    import accuracy
    from foldcore import thicken

    pattern, thickness, expected, creases = accuracy.miura(8)
    return pattern, thicken(pattern, thickness), expected, creases


def one_fold() -> dict:
    from foldcore import Simulation

    pattern, mesh, expected, creases = scene()
    sim = Simulation(mesh, pattern)
    start = time.perf_counter()
    result = sim.run(tolerance=TOLERANCE)
    return {"seconds": time.perf_counter() - start, "iterations": int(result.iterations),
            "converged": bool(result.converged),
            "error_deg": float(np.abs(result.fold_angles_deg[creases] - expected).max())}


def sweep(sim, percents, predict: bool) -> list:
    """One run per fold percent, continuing; with ``predict`` each run after two converged
    frames starts from the extrapolation of the last two (``Simulation.predict``)."""
    results, done = [], []  # done: percents of the last converged frames in a row
    for percent in percents:
        sim.set_fold_percent(float(percent))
        if predict and len(done) >= 2 and done[-1] != done[-2]:
            sim.predict((float(percent) - done[-1]) / (done[-1] - done[-2]))
        result = sim.run(tolerance=TOLERANCE)
        results.append(result)
        done = done[-1:] + [float(percent)] if result.converged else []
    return results


def path(predict: bool, frames: int) -> dict:
    from foldcore import Simulation

    pattern, mesh, expected, creases = scene()
    sim = Simulation(mesh, pattern)
    percents = np.linspace(100.0 / frames, 100.0, frames)
    start = time.perf_counter()
    results = sweep(sim, percents, predict)
    seconds = time.perf_counter() - start
    counts = np.diff([0] + [r.iterations for r in results])
    return {"seconds": seconds, "iterations": int(results[-1].iterations),
            "converged": all(r.converged for r in results),
            "iterations_per_frame_max": int(counts.max()),
            "iterations_per_frame_median": float(np.median(counts)),
            "error_deg": float(np.abs(results[-1].fold_angles_deg[creases] - expected).max())}


def table(data: dict) -> str:
    frames = data["meta"].get("frames", FRAMES)
    rows = []
    for key, label in ROWS:
        r = data[key]
        rows.append([label.format(frames=frames), f"{r['seconds']:.2f} s", str(r["iterations"]),
                     "yes" if r["converged"] else "no", f"{r['error_deg']:.2g}°",
                     f"{r['seconds'] / data['one_fold']['seconds']:.1f}"])
    return _meta.markdown_table(["run", "wall (median)", "iterations", "all converged",
                                 "error", "× one fold"], rows)


def plot(data: dict, path_png) -> None:
    plt = _meta.pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    frames = data["meta"].get("frames", FRAMES)
    labels = [label.format(frames=frames) for _, label in ROWS]
    for k, (key, _) in enumerate(ROWS):
        runs = data[key]["seconds_runs"]
        ax.barh(k, data[key]["seconds"], color=f"C{k}")
        ax.plot(runs, [k] * len(runs), "k.", ms=4)
    ax.set_yticks(range(len(ROWS)), labels, fontsize=8)
    ax.set_xlabel("wall seconds (bars: median; dots: each run)")
    ax.set_title("thin Miura 8 × 8, default strategy, tolerance 1e-8", fontsize=9)
    _meta.save(fig, path_png)


def main() -> None:
    args = _meta.parser(__doc__).parse_args()
    if _meta.stored("paths", args, table, plot):
        return
    runs, frames = (QUICK_RUNS, QUICK_FRAMES) if args.quick else (RUNS, FRAMES)
    record = _meta.Record("paths", args, runs=runs, warmup_rounds=1, frames=frames,
                          tolerance=TOLERANCE, others_busy_before=_meta.others_busy())
    rows = _meta.interleaved({"one_fold": one_fold,
                              "path_predicted": lambda: path(True, frames),
                              "path_plain": lambda: path(False, frames)}, runs)
    data = {key: _meta.median_run(rows[key]) for key, _ in ROWS}
    record.meta["others_busy_after"] = _meta.others_busy()
    record.write(data, plot)
    print(table({"meta": record.meta, **data}))


if __name__ == "__main__":
    main()
