"""Fold-angle error against the closed forms vs W/H, thickness and sheet size, per
hinge model and strategy, and error vs wall time (issue 16).

Ground truth: ``reference/kinematics.md`` (rigid origami), which a thick model
should approach wherever its hinges let the panels turn about the creases.

* ``width``: Pehrson's vertex (135/90/45/90), mode A, crease 1 driven to 70°,
  the others passive, R = 10 mm, H = 0.01 mm (H/R = 1e-3), W/H = 0.3 … 30.
* ``thickness``: the same vertex at W = 3H, H/R = 1e-3 … 0.1, modes A and B.
* ``size``: Miura n × n (a = b = 20 mm, γ = 60°), thin (H = 0.02 mm, W = 3H),
  one interior zig-zag crease driven to its angle at facet tilt 30°, the
  rest passive; n = 5, 10, 20.

Error = largest |achieved − closed form| over the creases (degrees; panel
mid-planes). Every run uses the library's defaults but for what is varied:
hinge model (axis, arc, eq8), strategy (hybrid, rigid, lbfgs), actuation
(equal; the width sweep also angle-controlled, under hybrid); tolerance 1e-8
(the command line's), budget 10 000 iterations (lbfgs on Miura 20 × 20:
2 000). Wall time = ``Simulation.run`` (setup excluded), warm numba cache,
median of ``RUNS`` runs (one run for Miura 20 × 20), the runs of one
configuration back to back; the machine's load is recorded. The ``size``
sweep also records error vs strategy time along each run (``trace``).
Writes bench/results/accuracy.json and .png; ``--table`` prints the README's
table from the JSON.
"""
from __future__ import annotations

import itertools
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from foldcore import kinematics, patterns, thicken
from foldcore.simulation import Simulation

from _meta import machine_meta, markdown_table, median_run
from scaling import others_busy

RESULTS = Path(__file__).parent / "results"
RUNS = 3
MODELS = ("axis", "arc", "eq8")
STRATEGIES = ("hybrid", "rigid", "lbfgs")
TOLERANCE, BUDGET = 1e-8, 10_000
WIDTH_RATIOS = (0.3, 1.0, 3.0, 10.0, 30.0)
THICKNESS_RATIOS = (1e-3, 1e-2, 1e-1)
MIURA_SIZES = (5, 10, 20)
R, A = 10.0, 20.0  # mm: vertex disc radius, Miura facet side
STYLE = {"axis": "C0", "arc": "C3", "eq8": "C2"}
MARKER = {"hybrid": "o-", "rigid": "s--", "lbfgs": "^:"}


def vertex(width_over_h: float, h_over_r: float, mode: str = "A"):
    """Pehrson's vertex, crease 1 → 70°: (pattern, thickness mm, closed form (4,), creases)."""
    thickness = h_over_r * R
    pattern = patterns.degree4_vertex(radius=R, widths=[width_over_h * thickness] * 4,
                                      mode=mode, rho1=70.0)
    return pattern, thickness, kinematics.degree4_deg(135.0, 90.0, 70.0, mode), np.arange(4)


def miura(n: int):
    """Thin Miura n × n, one zig-zag crease driven: (pattern, H, closed form, creases)."""
    thickness = 1e-3 * A
    pattern = patterns.miura_one_crease(n, n, a=A, b=A, width=3 * thickness)
    creases = np.flatnonzero(patterns.miura_edge_kinds(n, n) != "boundary")
    return pattern, thickness, patterns.miura_fold_angles(n, n, 60.0, 30.0)[creases], creases


def fold(scene, model: str, strategy: str, actuation: str = "equal", budget: int = BUDGET,
         trace_every: int = 0):
    """One run: error (degrees), iterations, convergence, wall seconds, trace."""
    pattern, thickness, expected, creases = scene
    mesh = thicken(pattern, thickness, hinge=model)
    sim = Simulation(mesh, pattern, solver=strategy, actuation=actuation)
    trace = []

    def record(s, moved):
        if s.iterations <= 100 or s.iterations % trace_every == 0:
            t = s.timings
            error = float(np.abs(s.fold_angles()[creases] - expected).max())
            trace.append((s.iterations, t["setup"] + t["projection"] + t["solve"], error))

    start = time.perf_counter()
    result = sim.run(tolerance=TOLERANCE, max_iterations=budget,
                     callback=record if trace_every else None)
    seconds = time.perf_counter() - start
    error = float(np.abs(result.fold_angles_deg[creases] - expected).max())
    return {"error_deg": error, "iterations": int(result.iterations),
            "converged": bool(result.converged), "seconds": seconds,
            "branch_iterations": int(sim.branch_iterations),
            "largest_misfit_mm": float(result.hinge_misfit_mm.max()), "trace": trace}


def measured(scene, model, strategy, actuation="equal", runs=RUNS, **kw) -> dict:
    """Median-time run of ``runs`` (its error, iterations, …) and every run's seconds."""
    rows = [fold(scene, model, strategy, actuation, **kw) for _ in range(runs)]
    row = median_run(rows)
    out = {k: v for k, v in row.items() if k != "trace" or kw.get("trace_every")}
    out.update(model=model, strategy=strategy, actuation=actuation)
    print(f"  {model:5s} {strategy:7s} {actuation:6s} err {row['error_deg']:.3g}° "
          f"its {row['iterations']:5d} {row['seconds']:.3f} s", flush=True)
    return out


def width_sweep() -> list:
    rows = []
    for ratio in WIDTH_RATIOS:
        print(f"W/H = {ratio:g}", flush=True)
        for model, strategy in itertools.product(MODELS, STRATEGIES):
            rows.append({"width_over_h": ratio, **measured(vertex(ratio, 1e-3), model, strategy)})
        for model in MODELS:
            rows.append({"width_over_h": ratio,
                         **measured(vertex(ratio, 1e-3), model, "hybrid", "angle")})
    return rows


def thickness_sweep() -> list:
    rows = []
    for ratio, mode in itertools.product(THICKNESS_RATIOS, "AB"):
        print(f"H/R = {ratio:g}, mode {mode}", flush=True)
        for model, strategy in itertools.product(MODELS, STRATEGIES):
            rows.append({"h_over_r": ratio, "mode": mode,
                         **measured(vertex(3.0, ratio, mode), model, strategy)})
    return rows


def size_sweep() -> list:
    rows = []
    for n in MIURA_SIZES:
        print(f"Miura {n} x {n}", flush=True)
        for model, strategy in itertools.product(MODELS, STRATEGIES):
            budget = 2_000 if (n >= 20 and strategy == "lbfgs") else BUDGET
            rows.append({"n": n, **measured(miura(n), model, strategy,
                                            runs=1 if n >= 20 else RUNS, budget=budget,
                                            trace_every=10 if strategy != "lbfgs" else 50)})
    return rows


def plot(data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    floor = 1e-10
    fig, axes = plt.subplots(2, 2, figsize=(12, 9))
    sweeps = (("width", "width_over_h", "W / H (Pehrson, mode A, H/R = 1e-3)", {}),
              ("thickness", "h_over_r", "H / R (Pehrson, mode A, W = 3H)", {"mode": "A"}),
              ("size", "n", "Miura n × n (thin, one crease driven)", {}))
    for ax, (name, key, label, only) in zip(axes.flat, sweeps):
        for model, strategy in itertools.product(MODELS, STRATEGIES):
            rows = [r for r in data[name] if r["model"] == model and r["strategy"] == strategy
                    and r["actuation"] == "equal" and all(r[k] == v for k, v in only.items())]
            ax.loglog([r[key] for r in rows], [max(r["error_deg"], floor) for r in rows],
                      MARKER[strategy], color=STYLE[model], label=f"{model} / {strategy}", ms=4)
        if name == "width":
            for model in MODELS:
                rows = [r for r in data[name] if r["model"] == model and r["actuation"] == "angle"]
                ax.loglog([r[key] for r in rows], [max(r["error_deg"], floor) for r in rows],
                          "x-.", color=STYLE[model], label=f"{model} / hybrid, angle", ms=5)
        ax.set_xlabel(label)
        ax.set_ylabel("max fold-angle error, °")
        ax.axhline(0.01, color="grey", lw=0.5)
    axes[0, 0].legend(fontsize=6, ncol=2)
    ax = axes[1, 1]
    for row in data["size"]:
        if row["n"] != 10:
            continue
        pts = np.array(row["trace"])
        ax.loglog(np.maximum(pts[:, 1], 1e-3), np.maximum(pts[:, 2], floor),
                  MARKER[row["strategy"]][1:], color=STYLE[row["model"]],
                  label=f"{row['model']} / {row['strategy']}")
    ax.set_xlabel("strategy time, s (Miura 10 × 10)")
    ax.set_ylabel("max fold-angle error, °")
    ax.axhline(0.01, color="grey", lw=0.5)
    ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    for model, strategy in itertools.product(MODELS, STRATEGIES):  # warm-up: numba cache
        fold(vertex(3.0, 1e-3), model, strategy, budget=5)
    load = [os.getloadavg()[0]]
    busy = others_busy()
    data = {"width": width_sweep(), "thickness": thickness_sweep(), "size": size_sweep()}
    load.append(os.getloadavg()[0])
    meta = {**machine_meta(), "runs": RUNS, "runs_miura_20": 1, "tolerance": TOLERANCE,
            "budget": BUDGET, "budget_lbfgs_miura_20": 2_000,
            "load_average_1min": load, "others_busy_before": busy}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "accuracy.json").write_text(json.dumps({"meta": meta, **data}))
    plot(data, RESULTS / "accuracy.png")


def table(path: Path = RESULTS / "accuracy.json") -> str:
    """Markdown table of the JSON: error (°) / wall time (s) per case and column."""
    data = json.loads(path.read_text())
    columns = [("axis", "hybrid", "equal"), ("axis", "rigid", "equal"),
               ("axis", "lbfgs", "equal"), ("arc", "hybrid", "equal"),
               ("arc", "hybrid", "angle"), ("eq8", "hybrid", "equal")]
    cases = [("width", f"Pehrson A, W/H = {r:g}", {"width_over_h": r}) for r in WIDTH_RATIOS]
    cases += [("thickness", f"Pehrson {m}, H/R = {r:g}", {"h_over_r": r, "mode": m})
              for r in THICKNESS_RATIOS for m in "AB"]
    cases += [("size", f"Miura {n} × {n}", {"n": n}) for n in MIURA_SIZES]
    header = ["case"] + [f"{m} / {s}" + (", angle" if a == "angle" else "")
                         for m, s, a in columns]
    body = []
    for sweep, label, where in cases:
        cells = [label]
        for model, strategy, actuation in columns:
            rows = [r for r in data[sweep] if r["model"] == model and r["strategy"] == strategy
                    and r["actuation"] == actuation and all(r[k] == v for k, v in where.items())]
            cells.append(f"{rows[0]['error_deg']:.2g}° / {rows[0]['seconds']:.2g} s" if rows
                         else "—")
        body.append(cells)
    return markdown_table(header, body)


if __name__ == "__main__":
    if "--table" in sys.argv[1:]:
        print(table())
    else:
        main()
