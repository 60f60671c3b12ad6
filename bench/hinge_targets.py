"""Single hinge (panels 5 H long, k = 4): exact-arc vs Eq. 8 targets, paper solver.

For each target angle and each bending target: iterations to converge
(step ≤ 1e-9 × extent), achieved fold angle error measured from the panels'
mid-planes (degrees), the residual energy at convergence (mm⁵; zero for a
compatible target) and the wall time (median of RUNS after one warm-up run).
Writes bench/results/hinge_targets.json and .png.
"""
from __future__ import annotations

import json
import statistics
import time
from pathlib import Path

from foldcore import patterns, thicken
from foldcore.simulation import Simulation

from _meta import machine_meta

TARGETS = (30.0, 90.0, 150.0, 180.0)
RUNS = 3
RESULTS = Path(__file__).parent / "results"


def one_run(target: float, model: str):
    pattern = patterns.single_hinge(panel_length=5.0, depth=2.0, angle=target, width=2.0)
    mesh = thicken(pattern, 1.0, subdivisions=4, hinge=model)
    start = time.perf_counter()
    result = Simulation(mesh, pattern, solver="paper").run(tolerance=1e-9, max_iterations=100_000)
    return result, time.perf_counter() - start


def measure() -> list[dict]:
    one_run(90.0, "arc")  # warm-up: numba cache load, first factorisation
    rows = []
    for model in ("arc", "eq8"):
        for target in TARGETS:
            times, result = [], None
            for _ in range(RUNS):
                result, seconds = one_run(target, model)
                times.append(seconds)
            rows.append({"target_deg": target, "target_shape": model,
                         "iterations": result.iterations, "converged": result.converged,
                         "error_deg": float(abs(result.fold_angles_deg[0] - target)),
                         "final_energy": float(result.energy[-1]),
                         "wall_s_median": statistics.median(times),
                         "wall_s_runs": times})
            print(rows[-1]["target_shape"], target, rows[-1]["iterations"],
                  f"{rows[-1]['error_deg']:.2e}°", f"{rows[-1]['wall_s_median']:.2f} s", flush=True)
    return rows


def plot(rows, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for shape, marker in (("arc", "o"), ("eq8", "s")):
        sel = [r for r in rows if r["target_shape"] == shape]
        ax.scatter([r["wall_s_median"] for r in sel], [r["error_deg"] for r in sel],
                   marker=marker, label=shape)
        for r in sel:
            ax.annotate(f"{r['target_deg']:.0f}°", (r["wall_s_median"], r["error_deg"]),
                        fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xlabel("wall time to converge, s (median)")
    ax.set_ylabel("|fold angle − target|, degrees")
    ax.set_yscale("log")
    ax.set_title("single hinge, Lp/H = 5, k = 4, paper solver, tol 1e-9")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    rows = measure()
    RESULTS.mkdir(exist_ok=True)
    meta = {**machine_meta(), "runs": RUNS}
    (RESULTS / "hinge_targets.json").write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))
    plot(rows, RESULTS / "hinge_targets.png")


if __name__ == "__main__":
    main()
