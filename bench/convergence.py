"""Error vs iterations and vs wall time, per strategy, on the convergence scenes.

Scenes (H, W, k in mm / count; the library's defaults otherwise: axis hinge,
equal-weight actuation, branch stage from flat):

* ``hinge_LpH{5,20,80,320}``: one hinge (H = 1, W = 2, k = 4, crease 10 long)
  between panels Lp long, target 90°. Error = |ρ − 90°| (a compatible
  target: the closed form is the target itself).
* ``vertex_thin_actuated``: degree-4 vertex 135/90/45/90, R = 10, H = 0.01
  (H/R = 1e-3), W = 0.02, k = 4, all four creases actuated to mode A of
  kinematics.md at ρ1 = 60°. Error = max over creases vs the closed form,
  and vs a reference converged with the rigid strategy to a 1e-13 step.
* ``pehrson_90`` / ``pehrson_flat``: Pehrson's vertex at the paper's
  dimensions (Ø152.4, H = 3.175, W = 16/4/8/4, k = 4), crease 1 actuated to
  90° / 180°, the others passive. Error = max over creases vs mode A of the
  closed form.
* ``waterbomb6_thin``: 6-crease waterbomb, H/R = 1e-3, majors actuated to
  90°; error vs the closed-form minor angle (kinematics.waterbomb_minor).
* ``miura{5,20}_{thin,thick}``: Miura n×n, a = b = 20, γ = 60°, H = 0.02
  (thin, H/a = 1e-3) or 1, W = 2H, k = 2; one interior zig-zag crease
  actuated to 60°, the rest passive; error = max over all creases vs
  kinematics.miura_angles at facet tilt 30°.

The rigid strategy and ``hybrid`` (the default: rigid steps, which end the
run once they meet its tolerance, else L-BFGS) stop at a step ≤ 1e-10 ×
extent, as a run at the default tolerance would end; the local/global
strategies run their whole budget (tolerance 0), because the step-size rule
stops slow strategies early (on the thin vertex L-BFGS "converged" after 40
iterations with 60° left, measured). Time = the strategy's own time (setup
+ projection + solve from ``Simulation.timings``), so measuring the error in
the callback does not count; each curve ends with the run's result (the
rigid-body strategies step the mesh's coarse twin and move the mesh only
where they hand over or end, so their curves are flat until then). Budget
per scene in SCENES (20 000 iterations, fewer on the Miura sheets; rigid:
200); the rigid and hybrid
curves are the median-time run of RUNS runs, the others one run; the first
round runs every strategy, one after another, the others rigid and hybrid
(warm numba cache: each strategy folds a small hinge first).
Writes bench/results/convergence.json and .png; ``--table`` prints the
table of docs/benchmarks.md from the JSON.

Run: ``python bench/convergence.py`` (~20 min) or ``--quick`` (two scenes,
small budgets, one run).
"""
from __future__ import annotations

import statistics

import numpy as np

from foldcore import Simulation, kinematics, patterns, thicken

import _meta

RUNS = 3
RIGID_BUDGET = 200
SOLVERS = ("hybrid", "rigid", "lbfgs", "anderson", "paper")
STYLE = {"paper": "C0-", "anderson": "C1-", "lbfgs": "C2-", "rigid": "C3.-", "hybrid": "C4.-"}
FLOOR_DEG = 1e-9  # a local/global run stops once this close (no curve below it is plotted)
THRESHOLDS = (1.0, 0.1, 0.01)  # degrees
PLOT_COLUMNS = 5
#: --quick: these scenes, this local/global budget, one run
QUICK_SCENES, QUICK_BUDGET = ("hinge_LpH5", "vertex_thin_actuated"), 300


def hinge_scene(ratio: float):
    pattern = patterns.single_hinge(panel_length=ratio, depth=10.0, angle=90.0, width=2.0)
    mesh = thicken(pattern, 1.0, subdivisions=4)
    return pattern, mesh, np.array([90.0]), [0]


def thin_vertex_scene():
    rho = kinematics.degree4_deg(135.0, 90.0, 60.0, "A")
    pattern = patterns.degree4_vertex(radius=10.0, widths=[0.02] * 4, mode="A", rho1=60.0)
    pattern = pattern.replace(fold_angles=list(rho) + [None] * (pattern.n_edges - 4))
    return pattern, thicken(pattern, 0.01, subdivisions=4), rho, [0, 1, 2, 3]


def pehrson_scene(rho1: float):
    pattern = patterns.degree4_vertex(mode="A", rho1=rho1)
    mesh = thicken(pattern, 3.175, subdivisions=4)
    return pattern, mesh, kinematics.degree4_deg(135.0, 90.0, rho1, "A"), [0, 1, 2, 3]


def miura_scene(n: int, thickness: float):
    """Miura n×n (a = b = 20, γ = 60°), W = 2H, k = 2; one interior zig-zag crease
    actuated to 60° (facet tilt θ = 30°), all others passive."""
    pattern = patterns.miura_one_crease(n, n, width=2.0 * thickness)
    expected = patterns.miura_fold_angles(n, n, 60.0, 30.0)
    creases = np.flatnonzero(patterns.miura_edge_kinds(n, n) != "boundary")
    return pattern, thicken(pattern, thickness, subdivisions=2), expected[creases], creases


def waterbomb_scene():
    """6-crease waterbomb, R = 50, H = 0.05 (H/R = 1e-3), W = 2H, k = 2: the three
    mountain (major) creases actuated to 90°, the valleys passive."""
    pattern = patterns.waterbomb(6, radius=50.0, major="M", width=0.1, major_angle=90.0)
    minor = float(kinematics.waterbomb_minor_deg(6, 90.0))
    expected = np.where(pattern.assignments[:6] == "M", -90.0, minor)
    return pattern, thicken(pattern, 0.05, subdivisions=2), expected, np.arange(6)


# name: (scene factory, iteration budget of the local/global strategies)
SCENES = {
    **{f"hinge_LpH{r}": ((lambda r=r: hinge_scene(float(r))), 20_000) for r in (5, 20, 80, 320)},
    "vertex_thin_actuated": (thin_vertex_scene, 20_000),
    "pehrson_90": (lambda: pehrson_scene(90.0), 20_000),
    "pehrson_flat": (lambda: pehrson_scene(180.0), 20_000),
    "waterbomb6_thin": (waterbomb_scene, 20_000),
    "miura5_thin": (lambda: miura_scene(5, 0.02), 5_000),
    "miura5_thick": (lambda: miura_scene(5, 1.0), 5_000),
    "miura20_thin": (lambda: miura_scene(20, 0.02), 1_000),
    "miura20_thick": (lambda: miura_scene(20, 1.0), 1_000),
}


def trace(scene, solver: str, budget: int, every: int = 1):
    """One run: per sampled iteration (iterations, strategy seconds, max error in degrees)."""
    pattern, mesh, expected, creases = scene
    sim = Simulation(mesh, pattern, solver=solver)
    points = []

    def record(s, moved):
        if s.iterations <= 100 or s.iterations % every == 0:
            t = s.timings
            err = float(np.abs(s.fold_angles()[creases] - expected).max())
            points.append((s.iterations, t["setup"] + t["projection"] + t["solve"], err))
            return err > FLOOR_DEG
        return None

    tolerance = 1e-10 if solver in ("rigid", "hybrid") else 0.0
    result = sim.run(tolerance=tolerance, max_iterations=budget, callback=record)
    return with_end(points, result, expected, creases), result, sim


def with_end(points: list, result, expected, creases) -> list:
    """``points`` ending with the run's result (its strategy seconds and error): the
    rigid-body strategies step a coarse twin and move the mesh, which the callback
    measures, only where they hand over or end."""
    t = result.timings_s
    end = (int(result.iterations), t["setup"] + t["projection"] + t["solve"],
           float(np.abs(result.fold_angles_deg[creases] - expected).max()))
    return points[:-1] + [end] if points and points[-1][0] == end[0] else points + [end]


def first_below(points, threshold):
    for it, t, err in points:
        if err <= threshold:
            return {"iterations": it, "seconds": t}
    return None


def measure_scene(name, make, budget, runs: int) -> dict:
    """Every strategy on one scene: the median-time run's curve and figures. Round 1
    runs every strategy, later rounds the rigid-body ones (RUNS in all)."""
    traces = {solver: [] for solver in SOLVERS}
    for round_ in range(runs):
        for solver in SOLVERS:
            rigid_like = solver in ("rigid", "hybrid")
            if round_ == 0 or rigid_like:
                traces[solver].append(trace(make(), solver,
                                            RIGID_BUDGET if solver == "rigid" else budget,
                                            every=1 if rigid_like else 20))
    rows = {}
    for solver in SOLVERS:
        totals = [tr[0][-1][1] for tr in traces[solver]]
        points, result, _ = traces[solver][int(np.argsort(totals)[len(totals) // 2])]
        rows[solver] = summary(points, result, totals)
        print(f"{name:22s} {solver:8s} its {result.iterations:6d} "
              f"err {points[-1][2]:.3g}° time {statistics.median(totals):.3f} s", flush=True)
    return rows


def summary(points: list, result, totals: list) -> dict:
    """A run's figures: iterations, final error, strategy seconds (and every run's),
    seconds per iteration over the first 100, to each threshold, its curve."""
    its = np.array([p[0] for p in points])
    secs = np.array([p[1] for p in points])
    first = its <= 100
    per_it = (float(np.median(np.diff(secs[first]) / np.diff(its[first])))
              if np.count_nonzero(first) > 2 else float("nan"))
    bare = result.timings_s.get("bare_solve")  # only where the run factorised K
    return {"iterations": result.iterations, "converged": result.converged,
            "final_error_deg": points[-1][2], "seconds": points[-1][1],
            "seconds_runs": totals, "seconds_per_iteration": per_it,
            "per_iteration_vs_bare_solve": per_it / bare if bare else None,
            "to_threshold": {f"{t:g}": first_below(points, t) for t in THRESHOLDS},
            "curve": points}


def reference(make):
    """A rigid run converged to a 1e-13 step: the thick model's own answer, beside the
    closed form."""
    pattern, mesh, expected, creases = make()
    sim = Simulation(mesh, pattern, solver="rigid")
    ref = sim.run(tolerance=1e-13, max_iterations=500)
    return {"reference_fold_angles_deg": ref.fold_angles_deg[creases].tolist(),
            "reference_iterations": ref.iterations, "reference_converged": ref.converged,
            "closed_form_deg": list(map(float, expected))}


def plot(document: dict, path) -> None:
    plt = _meta.pyplot()
    data = document["scenes"]
    names = list(data)
    cols = min(PLOT_COLUMNS, len(names))
    groups = -(-len(names) // cols)
    fig, axes = plt.subplots(2 * groups, cols, figsize=(3.2 * cols, 5.6 * groups),
                             squeeze=False)
    for j, name in enumerate(names):
        top, bottom = axes[2 * (j // cols), j % cols], axes[2 * (j // cols) + 1, j % cols]
        for solver, style in STYLE.items():
            pts = np.array(data[name][solver]["curve"])
            err = np.maximum(pts[:, 2], 1e-8)
            top.loglog(pts[:, 0], err, style, label=solver, ms=3)
            bottom.loglog(np.maximum(pts[:, 1], 1e-4), err, style, label=solver, ms=3)
        top.set_title(name, fontsize=9)
        top.set_xlabel("iterations")
        bottom.set_xlabel("strategy time, s")
        if j % cols == 0:
            top.set_ylabel("max fold-angle error, °")
            bottom.set_ylabel("max fold-angle error, °")
    for j in range(len(names), groups * cols):
        axes[2 * (j // cols), j % cols].axis("off")
        axes[2 * (j // cols) + 1, j % cols].axis("off")
    axes[0, 0].legend()
    _meta.save(fig, path)


def table(document: dict) -> str:
    """Per scene and strategy, iterations (strategy seconds) to 0.01°, or 'never' with
    the final error."""
    body = []
    for name, rows in document["scenes"].items():
        cells = [name]
        for solver in SOLVERS:
            hit = rows[solver]["to_threshold"]["0.01"]
            cells.append(f"{hit['iterations']} ({hit['seconds']:.2g} s)" if hit else
                         f"never ({rows[solver]['final_error_deg']:.3g}°)")
        body.append(cells)
    return _meta.markdown_table(["scene", *SOLVERS], body)


def main() -> None:
    args = _meta.parser(__doc__).parse_args()
    if _meta.stored("convergence", args, table, plot):
        return
    for solver in ("rigid", "paper", "anderson", "lbfgs"):  # warm-up: numba cache, first factor
        trace(hinge_scene(5.0), solver, 5)
    runs = 1 if args.quick else RUNS
    record = _meta.Record("convergence", args, runs_rigid=runs, runs_local_global=1,
                          tolerance={"rigid": 1e-10, "local_global": 0.0,
                                     "stop_below_deg": FLOOR_DEG},
                          budget_rigid=RIGID_BUDGET, others_busy_before=_meta.others_busy())
    data = {}
    for name, (make, budget) in SCENES.items():
        if args.quick and name not in QUICK_SCENES:
            continue
        budget = QUICK_BUDGET if args.quick else budget
        data[name] = measure_scene(name, make, budget, runs)
        data[name]["budget_local_global"] = budget
        if name.startswith("vertex"):
            data[name]["reference"] = reference(make)
    record.write({"scenes": data}, plot, indent=None)
    print(table({"scenes": data}))


if __name__ == "__main__":
    main()
