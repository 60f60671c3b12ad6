"""Fold-angle error against the closed forms vs W/H, thickness and sheet size, per
hinge model and strategy, and error vs strategy time.

Ground truth: ``reference/kinematics.md`` (rigid origami, :mod:`foldcore.kinematics`),
which a thick model should approach wherever its hinges let the panels turn
about the creases.

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
2 000). Wall time = ``Simulation.run`` (set-up excluded), warm numba cache
(one warm-up fold per model and strategy first), median of RUNS runs (one
for Miura 20 × 20), the configurations of one case interleaved round by
round. The ``size`` sweep also records error vs strategy time (set-up +
projection + solve of ``Simulation.timings``) along each run (``trace``,
ending with the run's result, as in ``convergence.py``).
Writes bench/results/accuracy.json and .png.

Run: ``python bench/accuracy.py`` (~10 min) or ``--quick``; ``--table`` prints
the table of docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import itertools
import time

import numpy as np

import _meta

RUNS = 3
MODELS = ("axis", "arc", "eq8")
STRATEGIES = ("hybrid", "rigid", "lbfgs")
TOLERANCE, BUDGET = 1e-8, 10_000
WIDTH_RATIOS = (0.3, 1.0, 3.0, 10.0, 30.0)
THICKNESS_RATIOS = (1e-3, 1e-2, 1e-1)
MIURA_SIZES = (5, 10, 20)
#: --quick: one value per sweep, two models and strategies, one run
QUICK = {"runs": 1, "models": ("axis", "arc"), "strategies": ("hybrid", "rigid"),
         "width": (3.0,), "thickness": (1e-2,), "sizes": (5,)}
R, A = 10.0, 20.0  # mm: vertex disc radius, Miura facet side
STYLE = {"axis": "C0", "arc": "C3", "eq8": "C2"}
MARKER = {"hybrid": "o-", "rigid": "s--", "lbfgs": "^:"}


def vertex(width_over_h: float, h_over_r: float, mode: str = "A"):
    """Pehrson's vertex, crease 1 → 70°: (pattern, thickness mm, closed form (4,), creases)."""
    from foldcore import kinematics, patterns

    thickness = h_over_r * R
    pattern = patterns.degree4_vertex(radius=R, widths=[width_over_h * thickness] * 4,
                                      mode=mode, rho1=70.0)
    return pattern, thickness, kinematics.degree4_deg(135.0, 90.0, 70.0, mode), np.arange(4)


def miura(n: int):
    """Thin Miura n × n, one zig-zag crease driven: (pattern, H, closed form, creases)."""
    from foldcore import patterns

    thickness = 1e-3 * A
    pattern = patterns.miura_one_crease(n, n, a=A, b=A, width=3 * thickness)
    creases = np.flatnonzero(patterns.miura_edge_kinds(n, n) != "boundary")
    return pattern, thickness, patterns.miura_fold_angles(n, n, 60.0, 30.0)[creases], creases


def fold(scene, model: str, strategy: str, actuation: str = "equal", budget: int = BUDGET,
         trace_every: int = 0) -> dict:
    """One run: error (degrees), iterations, convergence, wall seconds, misfit, trace."""
    from foldcore import Simulation, thicken

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
    if trace_every:
        from convergence import with_end

        trace = with_end(trace, result, expected, creases)
    return {"error_deg": error, "iterations": int(result.iterations),
            "converged": bool(result.converged), "seconds": seconds,
            "largest_misfit_mm": float(result.hinge_misfit_mm.max()), "trace": trace}


def measure_case(scene, configs: list, runs: int, **where) -> list:
    """The configurations (model, strategy, actuation, budget, trace_every) of one
    scene, interleaved over ``runs`` rounds: per configuration its median-time run
    (``trace`` only where traced) with every run's seconds, and ``where``."""
    cases = {c: (lambda c=c: fold(scene, c[0], c[1], c[2], c[3], c[4])) for c in configs}
    rows = []
    for (model, strategy, actuation, _, traced), runs_ in _meta.interleaved(
            cases, runs, warmup=0).items():
        row = _meta.median_run(runs_)
        if not traced:
            row.pop("trace")
        rows.append({**where, **row, "model": model, "strategy": strategy,
                     "actuation": actuation})
        print(f"  {where} {model:5s} {strategy:7s} {actuation:6s} err {row['error_deg']:.3g}° "
              f"its {row['iterations']:5d} {row['seconds']:.3f} s", flush=True)
    return rows


def sweeps(q: dict) -> dict:
    """The three sweeps with the settings ``q`` (full or QUICK)."""
    pairs = list(itertools.product(q["models"], q["strategies"]))
    width, thickness, size = [], [], []
    for ratio in q["width"]:
        configs = [(m, s, "equal", BUDGET, 0) for m, s in pairs]
        configs += [(m, "hybrid", "angle", BUDGET, 0) for m in q["models"]]
        width += measure_case(vertex(ratio, 1e-3), configs, q["runs"], width_over_h=ratio)
    for ratio, mode in itertools.product(q["thickness"], "AB"):
        configs = [(m, s, "equal", BUDGET, 0) for m, s in pairs]
        thickness += measure_case(vertex(3.0, ratio, mode), configs, q["runs"],
                                  h_over_r=ratio, mode=mode)
    for n in q["sizes"]:
        configs = [(m, s, "equal", 2_000 if (n >= 20 and s == "lbfgs") else BUDGET,
                    10 if s != "lbfgs" else 50) for m, s in pairs]
        size += measure_case(miura(n), configs, 1 if n >= 20 else q["runs"], n=n)
    return {"width": width, "thickness": thickness, "size": size}


def plot(data: dict, path) -> None:
    plt = _meta.pyplot()
    floor = 1e-10
    fig, axes = plt.subplots(2, 2, figsize=(12, 9))
    panels = (("width", "width_over_h", "W / H (Pehrson, mode A, H/R = 1e-3)", {}),
              ("thickness", "h_over_r", "H / R (Pehrson, mode A, W = 3H)", {"mode": "A"}),
              ("size", "n", "Miura n × n (thin, one crease driven)", {}))
    for ax, (name, key, label, only) in zip(axes.flat, panels):
        for model, strategy in itertools.product(MODELS, STRATEGIES):
            rows = [r for r in data[name] if r["model"] == model and r["strategy"] == strategy
                    and r["actuation"] == "equal" and all(r[k] == v for k, v in only.items())]
            if rows:
                ax.loglog([r[key] for r in rows], [max(r["error_deg"], floor) for r in rows],
                          MARKER[strategy], color=STYLE[model], label=f"{model} / {strategy}",
                          ms=4)
        for model in MODELS if name == "width" else ():
            rows = [r for r in data[name] if r["model"] == model and r["actuation"] == "angle"]
            if rows:
                ax.loglog([r[key] for r in rows], [max(r["error_deg"], floor) for r in rows],
                          "x-.", color=STYLE[model], label=f"{model} / hybrid, angle", ms=5)
        ax.set_xlabel(label)
        ax.set_ylabel("max fold-angle error, °")
        ax.axhline(0.01, color="grey", lw=0.5)
    axes[0, 0].legend(fontsize=6, ncol=2)
    ax = axes[1, 1]
    sizes = sorted({r["n"] for r in data["size"]})
    traced = 10 if 10 in sizes else sizes[-1]
    for row in data["size"]:
        if row["n"] == traced and row.get("trace"):
            pts = np.array(row["trace"])
            ax.loglog(np.maximum(pts[:, 1], 1e-3), np.maximum(pts[:, 2], floor),
                      MARKER[row["strategy"]][1:], color=STYLE[row["model"]],
                      label=f"{row['model']} / {row['strategy']}")
    ax.set_xlabel(f"strategy time, s (Miura {traced} × {traced})")
    ax.set_ylabel("max fold-angle error, °")
    ax.axhline(0.01, color="grey", lw=0.5)
    ax.legend(fontsize=6, ncol=2)
    _meta.save(fig, path)


def table(data: dict) -> str:
    """Error (°) / wall time (s) per case and column."""
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
        if any(c != "—" for c in cells[1:]):
            body.append(cells)
    return _meta.markdown_table(header, body)


def main() -> None:
    args = _meta.parser(__doc__).parse_args()
    if _meta.stored("accuracy", args, table, plot):
        return
    q = QUICK if args.quick else {"runs": RUNS, "models": MODELS, "strategies": STRATEGIES,
                                  "width": WIDTH_RATIOS, "thickness": THICKNESS_RATIOS,
                                  "sizes": MIURA_SIZES}
    for model, strategy in itertools.product(q["models"], q["strategies"]):  # warm-up
        fold(vertex(3.0, 1e-3), model, strategy, budget=5)
    record = _meta.Record("accuracy", args, runs=q["runs"], runs_miura_20=1,
                          tolerance=TOLERANCE, budget=BUDGET, budget_lbfgs_miura_20=2_000,
                          others_busy_before=_meta.others_busy())
    data = sweeps(q)
    record.write(data, plot, indent=None)
    print(table(data))


if __name__ == "__main__":
    main()
