"""Set-up and per-iteration cost vs mesh size: Miura-ori n × n, paper solver.

Scene: ``patterns.miura(n, n, a=10, b=10, gamma=60)`` (mm, degrees), every
crease actuated to its zero-thickness rigid-fold angle at facet tilt 30°
(``patterns.miura_fold_angles``), thickened with H = 1 mm (0.1 of the 10 mm
panel edge), hinge width W = 2 mm, k = 4 sub-strips per crease. n ∈ SIZES,
grown until one size takes more than STOP_AFTER_S of wall time in all (or
fails).

Each size runs in its own fresh subprocess (``--child n``), so the peak
resident memory (``ru_maxrss``, which covers CHOLMOD's allocations) is that
size's alone. In it:

* warm-up: a 2 × 2 Miura through the whole pipeline and a few steps (numba
  kernels loaded from the cache, imports done); ``rss_baseline_mb`` is the
  peak RSS then;
* set-up, SETUP_RUNS repeats, the median of each part (seconds): ``pattern``
  (``patterns.miura``), ``actuate`` (``pattern.replace(fold_angles=...)``,
  which re-validates), ``thicken``, ``simulation`` (``Simulation(mesh,
  pattern, solver="paper")``) and ``first_step`` (its first ``step()``,
  which assembles and factorises K, then iterates once); ``total`` is their
  sum;
* iterations: after WARM_ITERATIONS steps, ITERATIONS steps one by one
  (at least MIN_ITERATIONS, fewer past ITERATION_BUDGET_S): ``step`` (wall
  time of ``Simulation.step``), ``projection`` (the element kernels) and
  ``solve`` (the right-hand side's gather, the K⁻¹ solve and taking its
  result) from the growth of ``Simulation.timings`` over the step; then
  ``bare_solve``, one K⁻¹ solve of an (N, 3) right-hand side
  (``Result.timings_s["bare_solve"]`` of a one-iteration ``run``, a median of
  repeats). ``step_vs_bare_solve`` is the ratio of the two, measured in the
  same process; ``per_iteration_min_s`` (fastest step) is kept beside the
  medians as the least-disturbed figure.
* memory: peak RSS (MB) after set-up and at the end; ``kb_per_vertex`` =
  (peak − baseline) / thick-mesh vertices.

Before each size the parent waits (up to QUIET_WAIT_S) until other jobs use
< QUIET_BELOW of the cores, and records ``others_busy_during`` (the share of
all cores other processes used while the size ran). Exponents: log-log least
squares of time vs thick-mesh vertices over the sizes with n ≥ FIT_FROM_N.
``--threads`` gives every Simulation that many numba threads (default: the
library's choice); ``--child n`` prints one size's JSON row.

Run: ``python bench/scaling.py`` (all sizes: ~25 min and 8 GB at 400 × 400 on
2 cores), ``--sizes 5 10 20`` (a subset) or ``--quick``; writes
bench/results/scaling.json and .png; ``--table`` prints the table of
docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time

import numpy as np

import _meta

SIZES = (5, 10, 20, 50, 100, 150, 200, 300, 400)
QUICK_SIZES = (5, 10)
STOP_AFTER_S = 600.0       # stop growing once one size took longer than this (wall, total)
CHILD_TIMEOUT_S = 1800.0
EDGE, GAMMA, TILT = 10.0, 60.0, 30.0     # mm, degrees, degrees
THICKNESS, WIDTH, SUBDIVISIONS = 1.0, 2.0, 4
SETUP_RUNS = 3
SETUP_BUDGET_S = 90.0      # fewer set-up repeats once this much set-up time was spent
WARM_ITERATIONS = 3
ITERATIONS = 30            # steps timed; at least MIN_ITERATIONS
MIN_ITERATIONS = 20
ITERATION_BUDGET_S = 120.0
QUICK = {"setup_runs": 1, "iterations": 10, "min_iterations": 5}
FIT_FROM_N = 10
QUIET_BELOW, QUIET_WAIT_S = 0.25, 300.0  # before each size, wait for other jobs to calm down
SETUP_PARTS = ("pattern", "actuate", "thicken", "simulation", "first_step", "total")
ITERATION_PARTS = ("step", "projection", "solve")


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: KiB


# ------------------------------------------------------------------ child
def setup_once(n: int, threads):
    """One timed set-up; returns (seconds per part, mesh, pattern, simulation)."""
    from foldcore import Simulation, patterns, thicken

    t = {}
    t["pattern"], pattern = _meta.timed(lambda: patterns.miura(n, n, a=EDGE, b=EDGE,
                                                               gamma=GAMMA))
    t["actuate"], pattern = _meta.timed(lambda: pattern.replace(
        fold_angles=patterns.miura_fold_angles(n, n, GAMMA, TILT)))
    t["thicken"], mesh = _meta.timed(lambda: thicken(pattern, THICKNESS, hinge_width=WIDTH,
                                                     subdivisions=SUBDIVISIONS))
    t["simulation"], sim = _meta.timed(lambda: Simulation(mesh, pattern, solver="paper",
                                                          threads=threads))
    t["first_step"], _ = _meta.timed(sim.step)
    t["total"] = sum(t.values())
    return t, mesh, pattern, sim


def one_step(sim) -> dict:
    """Wall seconds of one step, and its projection and solve from ``sim.timings``."""
    before = dict(sim.timings)
    seconds, _ = _meta.timed(sim.step)
    return {"step": seconds, **{k: sim.timings[k] - before[k] for k in ("projection", "solve")}}


def child(n: int, threads, q: dict) -> dict:
    """One size (module docstring); a JSON-ready row."""
    start, load_start = time.perf_counter(), os.getloadavg()[0]
    _, mesh, pattern, sim = setup_once(2, threads)  # warm-up: imports, numba cache, shapely
    for _ in range(WARM_ITERATIONS):
        sim.step()
    del mesh, pattern, sim
    baseline = peak_rss_mb()
    runs, sim, spent = [], None, 0.0
    while len(runs) < q["setup_runs"] and (not runs or spent < SETUP_BUDGET_S):
        sim = mesh = pattern = None  # free the previous repeat before the next peak
        t, mesh, pattern, sim = setup_once(n, threads)
        runs.append(t)
        spent += t["total"]
    setup = {k: _meta.median(r[k] for r in runs) for k in SETUP_PARTS}
    after_setup = peak_rss_mb()
    for _ in range(WARM_ITERATIONS):
        sim.step()
    steps, t_iter = [], time.perf_counter()
    while len(steps) < q["iterations"] and (len(steps) < q["min_iterations"]
                                            or time.perf_counter() - t_iter < ITERATION_BUDGET_S):
        steps.append(one_step(sim))
    bare = sim.run(tolerance=0.0, max_iterations=1).timings_s["bare_solve"]
    per_iteration = {k: _meta.median(s[k] for s in steps) for k in ITERATION_PARTS}
    per_iteration_min = {k: min(s[k] for s in steps) for k in ITERATION_PARTS}
    per_iteration["bare_solve"] = per_iteration_min["bare_solve"] = bare
    peak = peak_rss_mb()
    return {
        "n": n, "pattern_vertices": int(pattern.n_vertices),
        "pattern_edges": int(pattern.n_edges), "thick_vertices": int(mesh.n_vertices),
        "elements": {k: len(g) for k, g in mesh.groups.items()},
        "setup_s": setup, "setup_runs": runs, "per_iteration_s": per_iteration,
        "per_iteration_min_s": per_iteration_min, "iterations_timed": len(steps),
        "step_vs_bare_solve": per_iteration["step"] / bare,
        "rss_baseline_mb": baseline, "rss_after_setup_mb": after_setup, "peak_rss_mb": peak,
        "kb_per_vertex": 1024.0 * (peak - baseline) / mesh.n_vertices,
        "child_seconds": time.perf_counter() - start,
        "load_average_1min": [load_start, os.getloadavg()[0]]}


# ------------------------------------------------------------------ parent
def run_child(n: int, threads, quick: bool) -> dict | None:
    """One size in a fresh interpreter, with the machine's load around it; None if it
    failed or timed out."""
    quiet = _meta.wait_for_quiet(QUIET_BELOW, 0.0 if quick else QUIET_WAIT_S)
    start, busy0 = time.perf_counter(), _meta.busy_seconds()
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    argv = [sys.executable, __file__, "--child", str(n), str(threads or 0)]
    try:
        proc = subprocess.run(argv + (["--quick"] if quick else []), capture_output=True,
                              text=True, timeout=CHILD_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        print(f"n={n}: timed out after {CHILD_TIMEOUT_S:.0f} s", flush=True)
        return None
    if proc.returncode != 0:
        print(f"n={n}: failed (rc {proc.returncode}): {proc.stderr[-2000:]}", flush=True)
        return None
    row = json.loads(proc.stdout.strip().splitlines()[-1])
    row["wall_s"] = time.perf_counter() - start
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    own = cpu1.ru_utime + cpu1.ru_stime - cpu0.ru_utime - cpu0.ru_stime
    row["others_busy_before"] = quiet
    row["others_busy_during"] = max(0.0, (_meta.busy_seconds() - busy0 - own)
                                    / (row["wall_s"] * os.cpu_count()))
    return row


def fit(rows, key_fn) -> dict:
    sel = [r for r in rows if r["n"] >= FIT_FROM_N]
    if len(sel) < 2:
        return {"exponent": None, "sizes": [r["n"] for r in sel]}
    x = np.log([r["thick_vertices"] for r in sel])
    y = np.log([key_fn(r) for r in sel])
    slope, intercept = np.polyfit(x, y, 1)
    return {"exponent": float(slope), "prefactor_s": float(np.exp(intercept)),
            "sizes": [r["n"] for r in sel]}


def exponents(rows) -> dict:
    out = {}
    for block, prefix in (("setup_s", "setup_"), ("per_iteration_s", "per_iteration_"),
                          ("per_iteration_min_s", "per_iteration_min_")):
        for k in rows[0][block] if rows else ():
            out[prefix + k] = fit(rows, lambda r, k=k, b=block: r[b][k])
    out["peak_rss_above_baseline"] = fit(rows, lambda r: r["peak_rss_mb"] - r["rss_baseline_mb"])
    return out


def plot(data: dict, path) -> None:
    plt = _meta.pyplot()
    rows, fits = data["rows"], data["exponents"]
    verts = np.array([r["thick_vertices"] for r in rows])
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5))
    for j, part in enumerate(rows[0]["setup_s"]):
        e = fits.get("setup_" + part, {}).get("exponent")
        left.loglog(verts, [r["setup_s"][part] for r in rows], "k*-" if part == "total"
                    else f"C{j}o-", ms=4, label=f"{part} (∝ N^{e:.2f})" if e is not None else part)
    left.set_title("set-up parts (median of repeats)")
    left.set_ylabel("seconds")
    for j, part in enumerate(rows[0]["per_iteration_s"]):
        e = fits.get("per_iteration_" + part, {}).get("exponent")
        right.loglog(verts, [r["per_iteration_s"][part] for r in rows],
                     "k*-" if part == "step" else f"C{j}o-", ms=4,
                     label=f"{part} (∝ N^{e:.2f})" if e is not None else part)
    for r in rows:
        right.annotate(f"n={r['n']}\n×{r['step_vs_bare_solve']:.2f}",
                       (r["thick_vertices"], r["per_iteration_s"]["step"]), fontsize=7,
                       xytext=(4, -16), textcoords="offset points")
    right.set_title("per iteration, paper solver (median); ×: step / bare solve")
    right.set_ylabel("seconds per iteration")
    for ax in (left, right):
        ax.set_xlabel("thick-mesh vertices N")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"Miura n×n, a = b = {EDGE:g} mm, H = {THICKNESS:g} mm, W = {WIDTH:g} mm, "
                 f"k = {SUBDIVISIONS}, all creases actuated; exponents over n ≥ {FIT_FROM_N}",
                 fontsize=10)
    _meta.save(fig, path)


def table(data: dict) -> str:
    """Per size: thick vertices, set-up, step, bare solve, their ratio, memory."""
    rows = [[f"{r['n']} × {r['n']}", f"{r['thick_vertices']:,}",
             _meta.sig(r["setup_s"]["total"]), _meta.sig(r["per_iteration_s"]["step"] * 1e3),
             _meta.sig(r["per_iteration_s"]["bare_solve"] * 1e3),
             f"{r['step_vs_bare_solve']:.2f}", f"{r['peak_rss_mb']:.0f}",
             f"{r['kb_per_vertex']:.2f}"] for r in data["rows"]]
    return _meta.markdown_table(["Miura", "thick vertices N", "set-up (s)", "step (ms)",
                                 "bare solve (ms)", "step / bare solve", "peak RSS (MB)",
                                 "kB / thick vertex"], rows)


def main() -> None:
    p = _meta.parser(__doc__)
    p.add_argument("--sizes", type=int, nargs="+", default=None, help="n of the n × n sheets")
    p.add_argument("--threads", type=int, default=None, help="numba threads per Simulation")
    args = p.parse_args()
    if _meta.stored("scaling", args, table, plot):
        return
    sizes = args.sizes or (QUICK_SIZES if args.quick else SIZES)
    q = QUICK if args.quick else {"setup_runs": SETUP_RUNS, "iterations": ITERATIONS,
                                  "min_iterations": MIN_ITERATIONS}
    record = _meta.Record(
        "scaling", args, sizes_requested=list(sizes), threads=args.threads or "default",
        scene={"pattern": "miura", "a_mm": EDGE, "b_mm": EDGE, "gamma_deg": GAMMA,
               "actuated": "all creases, rigid-fold angles at facet tilt 30°",
               "thickness_mm": THICKNESS, "hinge_width_mm": WIDTH,
               "subdivisions": SUBDIVISIONS, "solver": "paper"},
        **q, warm_iterations=WARM_ITERATIONS, fit_from_n=FIT_FROM_N, stop_after_s=STOP_AFTER_S,
        quiet_below=QUIET_BELOW, quiet_wait_s=QUIET_WAIT_S,
        units={"time": "s", "memory": "MB (2^20 bytes), ru_maxrss"})
    rows = []
    for n in sizes:
        row = run_child(n, args.threads, args.quick)
        if row is None:
            break
        rows.append(row)
        s, it = row["setup_s"], row["per_iteration_s"]
        print(f"n={n:4d} N={row['thick_vertices']:8d} set-up {s['total']:8.3f} s "
              f"step {it['step'] * 1e3:9.3f} ms bare {it['bare_solve'] * 1e3:8.3f} ms "
              f"×{row['step_vs_bare_solve']:.2f} peak {row['peak_rss_mb']:.0f} MB "
              f"wall {row['wall_s']:.0f} s others busy {row['others_busy_during']:.0%}",
              flush=True)
        if row["wall_s"] > STOP_AFTER_S:
            print(f"n={n} took {row['wall_s']:.0f} s > {STOP_AFTER_S:.0f} s: stop growing",
                  flush=True)
            break
    data = {"exponents": exponents(rows), "rows": rows}
    record.write(data, plot)
    print(table(data))


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:  # --child n [threads] [--quick]: one size's JSON row
        numbers = [a for a in sys.argv[2:] if not a.startswith("--")]
        threads = int(numbers[1]) if len(numbers) > 1 and int(numbers[1]) else None
        q = QUICK if "--quick" in sys.argv else {"setup_runs": SETUP_RUNS,
                                                 "iterations": ITERATIONS,
                                                 "min_iterations": MIN_ITERATIONS}
        print(json.dumps(child(int(numbers[0]), threads, q)), flush=True)
    else:
        main()
