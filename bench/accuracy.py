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
for Miura 20 × 20).

Each sweep is a design study (:func:`foldcore.study.sweep`): the patterns are
the study's generators (:func:`vertex_pattern`, :func:`miura_pattern`), the model, strategy,
actuation, thickness and budget its points, the error its metric
(:class:`Error`). Each round folds every point of a sweep once, in this process
(``workers=0``: one fold at a time, so no other fold disturbs a timing), so the
rounds interleave the configurations. The ``size`` sweep's metric also records
error vs strategy time (set-up + projection + solve of ``Simulation.timings``)
along each run (``trace``, ending with the run's result, as in
``convergence.py``). Writes bench/results/accuracy.json and .png.

Run: ``python bench/accuracy.py`` (~10 min) or ``--quick``; ``--table`` prints
the table of docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import itertools

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
MIURA_H = 1e-3 * A  # mm: the thin Miura's thickness
STYLE = {"axis": "C0", "arc": "C3", "eq8": "C2"}
MARKER = {"hybrid": "o-", "rigid": "s--", "lbfgs": "^:"}


def vertex(width_over_h: float, h_over_r: float, mode: str = "A"):
    """Pehrson's vertex, crease 1 → 70°: (pattern, thickness mm, closed form (4,), creases)
    (the other benchmarks' case)."""
    expected, creases = closed_form({"mode": mode})
    return vertex_pattern(width_over_h, h_over_r, mode), h_over_r * R, expected, creases


def miura(n: int):
    """Thin Miura n × n, one zig-zag crease driven: (pattern, H, closed form, creases)."""
    expected, creases = closed_form({"n": n})
    return miura_pattern(n), MIURA_H, expected, creases


def vertex_pattern(w_over_h: float, h_over_r: float, mode: str = "A"):
    """Pehrson's vertex, crease 1 → 70°, hinge width W/H × H (the study's generator)."""
    from foldcore import patterns

    thickness = h_over_r * R
    return patterns.degree4_vertex(radius=R, widths=[w_over_h * thickness] * 4, mode=mode,
                                   rho1=70.0)


def miura_pattern(n: int):
    """Thin Miura n × n, one zig-zag crease driven (the study's generator)."""
    from foldcore import patterns

    return patterns.miura_one_crease(n, n, a=A, b=A, width=3 * MIURA_H)


def closed_form(point: dict):
    """(expected angles (°), creases) of a point of either generator."""
    from foldcore import kinematics, patterns

    if "n" in point:
        n = point["n"]
        creases = np.flatnonzero(patterns.miura_edge_kinds(n, n) != "boundary")
        return patterns.miura_fold_angles(n, n, 60.0, 30.0)[creases], creases
    return kinematics.degree4_deg(135.0, 90.0, 70.0, point["mode"]), np.arange(4)


class Error:
    """The study's metric: the largest |achieved − closed form| over the creases (°),
    the hinges' largest misfit (mm) and, when ``trace_every``, the error against
    strategy time along the run (``trace``: (iteration, s, °), the first 100
    iterations and every ``trace_every``-th, ending with the result)."""

    def __init__(self, trace_every: int = 0):
        self.trace_every, self.seen = trace_every, []

    def watch(self, sim, moved):
        if self.trace_every and (sim.iterations <= 100
                                 or sim.iterations % self.trace_every == 0):
            t = sim.timings
            self.seen.append((sim.iterations, t["setup"] + t["projection"] + t["solve"],
                              sim.fold_angles()))

    def __call__(self, fold, point):
        from convergence import with_end

        expected, creases = closed_form(point)
        result = fold.result
        out = {"error_deg": float(np.abs(result.fold_angles_deg[creases] - expected).max()),
               "largest_misfit_mm": float(result.hinge_misfit_mm.max())}
        if self.trace_every:
            trace = [(it, s, float(np.abs(angles[creases] - expected).max()))
                     for it, s, angles in self.seen]
            out["trace"] = with_end(trace, result, expected, creases)
        self.seen = []
        return out


def configs(q: dict, n: int | None = None) -> list[dict]:
    """Model × strategy (× actuation for the width sweep) as study options."""
    out = [{"hinge": m, "solver": s, "actuation": "equal",
            "max-iterations": 2_000 if (n or 0) >= 20 and s == "lbfgs" else BUDGET}
           for m, s in itertools.product(q["models"], q["strategies"])]
    return out


def study_points(q: dict) -> dict:
    """The points of each sweep: {sweep: (generator, [point, …], trace_every)}."""
    width = [{"w_over_h": r, "h_over_r": 1e-3, "mode": "A", "thickness": 1e-3 * R, **c}
             for r in q["width"] for c in configs(q)
             + [{"hinge": m, "solver": "hybrid", "actuation": "angle",
                 "max-iterations": BUDGET} for m in q["models"]]]
    thickness = [{"w_over_h": 3.0, "h_over_r": r, "mode": mode, "thickness": r * R, **c}
                 for r, mode in itertools.product(q["thickness"], "AB") for c in configs(q)]
    size = [{"n": n, "thickness": MIURA_H, **c} for n in q["sizes"] for c in configs(q, n)]
    return {"width": (vertex_pattern, width), "thickness": (vertex_pattern, thickness),
            "size": (miura_pattern, size)}


def run_study(generator, points: list, runs: int, traced: bool) -> list:
    """``runs`` rounds of the study (each round every point once, in this process:
    timings undisturbed by other workers); per point the median-``run_s`` round's row
    with every round's ``seconds_runs``."""
    from foldcore import study

    rounds = [study.sweep(generator, points=points, metric=Error(10 if traced else 0),
                          workers=0, cache=None, continuation=False, progress=False)
              for _ in range(runs)]
    rows = []
    for i, point in enumerate(points):
        runs_ = [r.iloc[i].to_dict() for r in rounds]
        assert all(r["error"] == "" for r in runs_), runs_[0]["error"]
        rows.append({**point, **_row(_meta.median_run(
            [{**r, "seconds": r["run_s"]} for r in runs_]))})
    return rows


def _row(r: dict) -> dict:
    """A study row in this benchmark's words (JSON: plain numbers)."""
    out = {"error_deg": float(r["error_deg"]), "iterations": int(r["iterations"]),
           "converged": bool(r["converged"]), "seconds": float(r["seconds"]),
           "seconds_runs": [float(x) for x in r["seconds_runs"]],
           "largest_misfit_mm": float(r["largest_misfit_mm"]), "model": r["hinge"],
           "strategy": r["solver"]}
    if isinstance(r.get("trace"), list):
        out["trace"] = [list(map(float, p)) for p in r["trace"]]
    return out


def sweeps(q: dict) -> dict:
    """The three sweeps with the settings ``q`` (full or QUICK), each a study."""
    out = {}
    for name, (generator, points) in study_points(q).items():
        big = [p for p in points if p.get("n", 0) >= 20]
        small = [p for p in points if p.get("n", 0) < 20]
        rows = run_study(generator, small, q["runs"], name == "size") if small else []
        rows += run_study(generator, big, 1, True) if big else []
        for row in rows:
            print(f"  {name} {row['model']:5s} {row['strategy']:7s} {row['actuation']:6s} "
                  f"err {row['error_deg']:.3g}° its {row['iterations']:5d} "
                  f"{row['seconds']:.3f} s", flush=True)
        out[name] = [{("width_over_h" if k == "w_over_h" else k): v for k, v in r.items()
                      if k not in ("hinge", "solver", "thickness", "max-iterations")}
                     for r in rows]
    return out


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
    """Error (°) / wall time (s) per case and column; ✗: the run did not converge
    (stalled, or at its budget): its error is that of its last iterate."""
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
            cells.append(f"{rows[0]['error_deg']:.2g}°{'' if rows[0]['converged'] else ' ✗'} / "
                         f"{rows[0]['seconds']:.2g} s" if rows else "—")
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
    warm = [{"w_over_h": 3.0, "h_over_r": 1e-3, "mode": "A", "thickness": 1e-3 * R,
             **c, "max-iterations": 5} for c in configs(q)]
    run_study(vertex_pattern, warm, 1, False)
    record = _meta.Record("accuracy", args, runs=q["runs"], runs_miura_20=1,
                          tolerance=TOLERANCE, budget=BUDGET, budget_lbfgs_miura_20=2_000,
                          others_busy_before=_meta.others_busy())
    data = sweeps(q)
    record.write(data, plot, indent=None)
    print(table(data))


if __name__ == "__main__":
    main()
