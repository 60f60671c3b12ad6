"""Branch selection from flat, per hinge model, with and without the branch stage.

From the flat sheet a driven fold is at a bifurcation (a degree-4 vertex has
two branches; a Miura sheet many first-order flexes). foldcore's branch stage
(``Simulation(branch_floor_deg=...)``, :mod:`foldcore.actuation`) first holds
every passive M/V crease ≥ 2° on its assigned side. This measures, per hinge
model (axis, arc, eq8) and with the stage on (2°) and off (0°), under the
default strategy and actuation:

* degree-4 vertices 135/90/45/90, 150/60/30/120, 120/75/60/105 in modes A
  and B (R = 10 mm, H/R = 1e-3, W = 3H), crease 1 driven to 70°;
* Miura 5 × 5 thin (H = 1e-3·a, W = 3H) and 10 × 10 thick (H = 0.1·a,
  W = H), one zig-zag crease driven to its angle at facet tilt 30°.

Per run: whether every M/V crease ends on its assigned side (``on_branch``:
sign × angle ≥ −0.01°), the largest error against the closed form of the
assigned branch (degrees), iterations (of which in the branch stage),
convergence and wall seconds. One run each (warm cache); the machine's load
is recorded. Writes bench/results/branch.json; prints a table.
"""
from __future__ import annotations

import itertools
import json
import os
import time
from pathlib import Path

import numpy as np

from foldcore import kinematics, patterns, thicken
from foldcore.simulation import Simulation

from _meta import machine_meta
from scaling import others_busy

RESULTS = Path(__file__).parent / "results"
MODELS = ("axis", "arc", "eq8")
FLOORS = (2.0, 0.0)  # degrees: the default, off
SECTORS = ((135.0, 90.0, 45.0, 90.0), (150.0, 60.0, 30.0, 120.0), (120.0, 75.0, 60.0, 105.0))


def vertex(sectors, mode):
    h = 1e-2
    pattern = patterns.degree4_vertex(sectors=sectors, radius=10.0, widths=[3 * h] * 4,
                                      mode=mode, rho1=70.0)
    return (f"vertex {'/'.join(f'{s:g}' for s in sectors)} {mode}", pattern, h,
            kinematics.degree4_deg(sectors[0], sectors[1], 70.0, mode), np.arange(4))


def miura(n, h_over_a, w_over_h):
    h = h_over_a * 20.0
    pattern = patterns.miura_one_crease(n, n, width=w_over_h * h)
    creases = np.flatnonzero(patterns.miura_edge_kinds(n, n) != "boundary")
    return (f"Miura {n}x{n} H/a={h_over_a:g}", pattern, h,
            patterns.miura_fold_angles(n, n, 60.0, 30.0)[creases], creases)


def one(case, model, floor) -> dict:
    name, pattern, h, expected, creases = case
    sim = Simulation(thicken(pattern, h, hinge=model), pattern, branch_floor_deg=floor)
    start = time.perf_counter()
    result = sim.run(tolerance=1e-8, max_iterations=10_000)
    seconds = time.perf_counter() - start
    angles = result.fold_angles_deg[creases]
    sign = np.where(pattern.assignments[creases] == "V", 1.0,
                    np.where(pattern.assignments[creases] == "M", -1.0, 0.0))
    return {"case": name, "model": model, "branch_floor_deg": floor,
            "on_branch": bool((sign * angles >= -0.01).all()),
            "error_deg": float(np.abs(angles - expected).max()),
            "iterations": int(result.iterations), "branch_iterations": int(sim.branch_iterations),
            "converged": bool(result.converged), "seconds": seconds}


def main() -> None:
    cases = [vertex(s, m) for s, m in itertools.product(SECTORS, "AB")]
    cases += [miura(5, 1e-3, 3.0), miura(10, 0.1, 1.0)]
    one(cases[0], "axis", 2.0)  # warm-up
    load, busy = [os.getloadavg()[0]], others_busy()
    rows = []
    for case, model, floor in itertools.product(cases, MODELS, FLOORS):
        rows.append(one(case, model, floor))
        r = rows[-1]
        print(f"{r['case']:28s} {model:5s} floor {floor:g}: on branch {r['on_branch']!s:5s} "
              f"err {r['error_deg']:9.3g}° its {r['iterations']:5d} "
              f"({r['branch_iterations']} branch) {r['seconds']:.2f} s", flush=True)
    load.append(os.getloadavg()[0])
    meta = {**machine_meta(), "runs": 1, "load_average_1min": load, "others_busy_before": busy}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "branch.json").write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
