"""A fold-percent path at the cost of its increments (issue 17, item 3).

Thin Miura 8 × 8 (81 pattern vertices, the size of MERLIN2's Miura example;
``accuracy.miura(8)``: a = 20 mm, H = 0.02 mm, W = 3H, one zig-zag crease
driven to its angle at tilt 30°, the rest passive), default strategy:

* ``one_fold``: one ``Simulation.run(tolerance=1e-8)`` from flat to 100 %;
* ``path``: :func:`foldcore.animate.fold_sweep` over 200 increments
  (0.5 %, 1 %, …, 100 %), each frame to the same tolerance, with the
  predictor (each frame starts from the extrapolation of the previous two)
  and without it.

Reported: wall seconds (setup excluded), iterations, whether every frame
converged, the final largest angle error against the closed form, and the
path's cost in single folds. Warm numba cache, ``RUNS`` interleaved rounds
(one fold, path with, path without), medians; the share of the cores other
processes used is recorded. Writes bench/results/paths.json; ``--table``
prints the README's line.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

RESULTS = HERE / "results"
RUNS = 3
FRAMES = 200
TOLERANCE = 1e-8


def scene():
    import accuracy

    from foldcore import thicken

    pattern, thickness, expected, creases = accuracy.miura(8)
    return pattern, thicken(pattern, thickness), expected, creases


def one_fold() -> dict:
    from foldcore.simulation import Simulation

    pattern, mesh, expected, creases = scene()
    sim = Simulation(mesh, pattern)
    start = time.perf_counter()
    result = sim.run(tolerance=TOLERANCE)
    return {"seconds": time.perf_counter() - start, "iterations": int(result.iterations),
            "converged": bool(result.converged),
            "error_deg": float(np.abs(result.fold_angles_deg[creases] - expected).max())}


def path(predict: bool) -> dict:
    from foldcore.animate import fold_sweep, percent_schedule
    from foldcore.simulation import Simulation

    pattern, mesh, expected, creases = scene()
    sim = Simulation(mesh, pattern)
    percents = percent_schedule(FRAMES, start=100.0 / FRAMES)
    start = time.perf_counter()
    results = fold_sweep(sim, percents, tolerance=TOLERANCE, predict=predict, progress=False)
    seconds = time.perf_counter() - start
    counts = np.diff([0] + [r.iterations for r in results])
    return {"seconds": seconds, "iterations": int(results[-1].iterations),
            "converged": all(r.converged for r in results),
            "iterations_per_frame_max": int(counts.max()),
            "iterations_per_frame_median": float(np.median(counts)),
            "error_deg": float(np.abs(results[-1].fold_angles_deg[creases] - expected).max())}


def table(path_json: Path = RESULTS / "paths.json") -> str:
    from _meta import markdown_table

    d = json.loads(path_json.read_text())
    rows = []
    for name, label in (("one_fold", "one fold, flat → 100 %"),
                        ("path_predicted", f"{FRAMES}-increment path, predictor"),
                        ("path_plain", f"{FRAMES}-increment path, no predictor")):
        r = d[name]
        ratio = r["seconds"] / d["one_fold"]["seconds"]
        rows.append([label, f"{r['seconds']:.2f} s", str(r["iterations"]),
                     "yes" if r["converged"] else "no", f"{r['error_deg']:.2g}°",
                     f"{ratio:.1f}"])
    return markdown_table(["run", "wall", "iterations", "all converged", "error",
                           "× one fold"], rows)


def main() -> None:
    from _meta import machine_meta, median_run
    from scaling import others_busy

    one_fold(), path(True)  # warm-up (numba cache loads, first-call costs)
    busy = others_busy()
    rows = {"one_fold": [], "path_predicted": [], "path_plain": []}
    for _ in range(RUNS):
        rows["one_fold"].append(one_fold())
        rows["path_predicted"].append(path(True))
        rows["path_plain"].append(path(False))
        print({k: round(v[-1]["seconds"], 2) for k, v in rows.items()}, flush=True)
    data = {"meta": {**machine_meta(), "date": time.strftime("%Y-%m-%d"), "runs": RUNS,
                     "frames": FRAMES, "tolerance": TOLERANCE, "others_busy_before": busy,
                     "others_busy_after": others_busy()},
            **{k: median_run(v) for k, v in rows.items()}}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "paths.json").write_text(json.dumps(data, indent=1))
    print(table())


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--table":
        print(table())
    else:
        main()
