"""Time to a converged fold, per strategy and size, beside the bare solve.

What a user waits for: wall time and iterations from the thick mesh to a fold
that meets the accuracy benchmark's tolerance (largest angle error ≤ 0.01°
against the closed form), and the peak memory of the process.

Cases (the accuracy and convergence benchmarks' definitions, imported from
them):

* ``miura{n}``: thin Miura n × n (a = b = 20 mm, γ = 60°, H = 0.02 mm,
  W = 3H), one interior zig-zag crease driven to its angle at facet tilt
  30°, the rest passive; n = 10, 20, 50.
* ``vertex``: Pehrson's vertex (135/90/45/90), R = 10 mm, H = 0.01 mm,
  W = 3H, mode A, crease 1 → 70°, the others passive.
* ``waterbomb``: the 6-crease waterbomb, R = 50 mm, H = 0.05 mm (H/R =
  1e-3), W = 2H, k = 2, the three mountain creases → −90°, valleys passive.

Each run is a fresh process (``--probe``) with the library's defaults but the
strategy (hybrid, rigid, lbfgs): ``Simulation(mesh, pattern,
solver=…).run(tolerance=1e-8, max_iterations=budget)``, the command line's
tolerance; budget 10 000 (lbfgs 2 000: it never reaches these folds from
flat). Reported: wall time of ``run`` (set-up excluded; K is factorised at
its first use, so inside ``run`` for the strategies that solve with it),
iterations, ``converged``, largest angle error (degrees), the bare solve of
the paper map's K (``Result.timings_s["bare_solve"]`` of a ``paper``
simulation of the same mesh after one iteration: the host-independent
yardstick, time / bare solve), thick vertices, peak RSS of the fold (read
before that) and its growth over the RSS before the mesh is built (per thick
vertex).

Warm: the project's numba cache; one warm-up process first, then the runs of
one case interleaved over the strategies, RUNS rounds for the small cases,
one for Miura 20 × 20 and 50 × 50; medians. Cold: Miura 10 × 10 under the
default strategy with ``NUMBA_CACHE_DIR`` set to an empty folder
(everything compiled in-process). The share of the cores other processes
used is recorded before each run (``others_busy``).

Memory, fixed and marginal (stored under ``memory``): the growth above counts
what any first fold in a process pays once (numba's and LLVM's runtime, the
first call of each kernel), so per thick vertex it overstates what a bigger
sheet costs. A fresh process per size folds a small warm-up sheet
(WARMUP_CASE) with the default strategy first, then the case; reported: the
RSS before anything (``start_mb``), after the warm-up (``fixed_mb`` = its
growth) and the case's peak growth over the RSS after the warm-up, per thick
vertex (``marginal_kb_per_vertex``).

Run: ``python bench/time_to_solution.py`` (~15 min) or ``--quick``; writes
bench/results/time_to_solution.json and .png; ``--table`` prints the tables
of docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

import _meta

STRATEGIES = ("hybrid", "rigid", "lbfgs")
TOLERANCE, BUDGET, LBFGS_BUDGET = 1e-8, 10_000, 2_000
ACCURACY_DEG = 0.01
RUNS = 3
CASES = ("vertex", "waterbomb", "miura10", "miura20", "miura50")
ONE_RUN = ("miura20", "miura50")
WARMUP_CASE = "miura4"
MEMORY_CASES = ("miura10", "miura20", "miura50")
#: --quick: cases, rounds, L-BFGS budget, memory cases; no cold run
QUICK = {"cases": ("vertex", "miura10"), "runs": 1, "lbfgs_budget": 200,
         "memory": ("miura10",)}


def make_case(name: str):
    """(pattern, mesh, closed-form angles (C,), crease indices (C,)) of a case."""
    import accuracy
    import convergence
    from foldcore import thicken

    if name == "waterbomb":
        return convergence.waterbomb_scene()
    pattern, thickness, expected, creases = (accuracy.vertex(3.0, 1e-3) if name == "vertex"
                                             else accuracy.miura(int(name[len("miura"):])))
    return pattern, thicken(pattern, thickness), expected, creases


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: kB


def current_rss_mb() -> float:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


def probe(case: str, strategy: str, budget: int) -> dict:
    """One run in this process (see the module docstring); JSON-ready."""
    from foldcore import Simulation

    before = current_rss_mb()
    pattern, mesh, expected, creases = make_case(case)
    sim = Simulation(mesh, pattern, solver=strategy)
    start = time.perf_counter()
    result = sim.run(tolerance=TOLERANCE, max_iterations=budget)
    seconds = time.perf_counter() - start
    error = float(np.abs(result.fold_angles_deg[creases] - expected).max())
    peak = peak_rss_mb()  # the fold's: the yardstick below factorises K
    paper = Simulation(mesh, pattern, solver="paper")
    bare = paper.run(tolerance=0.0, max_iterations=1).timings_s["bare_solve"]
    return {"case": case, "strategy": strategy, "seconds": seconds,
            "iterations": int(result.iterations), "converged": bool(result.converged),
            "reason": result.reason, "error_deg": error, "accurate": bool(error <= ACCURACY_DEG),
            "bare_solve_s": bare, "thick_vertices": int(mesh.n_vertices),
            "peak_rss_mb": peak, "rss_growth_mb": peak - before,
            "kb_per_thick_vertex": (peak - before) * 1024.0 / mesh.n_vertices}


def memory_probe(case: str) -> dict:
    """Fixed and marginal memory of a default fold of ``case`` (module docstring)."""
    from foldcore import Simulation

    start = current_rss_mb()
    pattern, mesh, _, _ = make_case(WARMUP_CASE)
    Simulation(mesh, pattern).run(tolerance=TOLERANCE, max_iterations=BUDGET)
    del pattern, mesh
    warm = current_rss_mb()
    pattern, mesh, expected, creases = make_case(case)
    result = Simulation(mesh, pattern).run(tolerance=TOLERANCE, max_iterations=BUDGET)
    peak = peak_rss_mb()
    error = float(np.abs(result.fold_angles_deg[creases] - expected).max())
    return {"case": case, "warmup_case": WARMUP_CASE, "thick_vertices": int(mesh.n_vertices),
            "start_mb": start, "fixed_mb": warm - start, "peak_rss_mb": peak,
            "marginal_mb": peak - warm,
            "marginal_kb_per_vertex": (peak - warm) * 1024.0 / mesh.n_vertices,
            "iterations": int(result.iterations), "error_deg": error}


def child(*argv, env=None) -> dict:
    """The JSON line a fresh interpreter running this file with ``argv`` prints."""
    out = subprocess.run([sys.executable, __file__, *map(str, argv)], capture_output=True,
                         text=True, env=env, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def run_probe(case: str, strategy: str, budget: int, env=None) -> dict:
    """``probe`` in a fresh interpreter; adds the process wall time and the load."""
    busy = _meta.others_busy(1.0)
    start = time.perf_counter()
    row = child("--probe", case, strategy, budget, env=env)
    row.update(process_s=time.perf_counter() - start, others_busy=busy)
    print(f"  {case:9s} {strategy:6s} {row['seconds']:8.2f} s  its {row['iterations']:5d}  "
          f"err {row['error_deg']:.2g}°  {row['seconds'] / row['bare_solve_s']:9.0f} bare solves  "
          f"{row['kb_per_thick_vertex']:.2f} kB/vertex  (busy {busy:.2f})", flush=True)
    return row


def summarise(rows: list) -> list:
    """Median-time row per (case, strategy), with every run's seconds."""
    out = []
    for case in CASES:
        for strategy in STRATEGIES:
            runs = [r for r in rows if r["case"] == case and r["strategy"] == strategy]
            if runs:
                row = _meta.median_run(runs)
                row["bare_solves"] = row["seconds"] / row["bare_solve_s"]
                out.append(row)
    return out


def plot(data: dict, path) -> None:
    plt = _meta.pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    miura = [c for c in CASES if c.startswith("miura")]
    for strategy, style in zip(STRATEGIES, ("C4o-", "C3s--", "C2^:")):
        rows = [r for c in miura for r in data["warm"] if r["case"] == c
                and r["strategy"] == strategy]
        n = [r["thick_vertices"] for r in rows]
        left.loglog(n, [r["seconds"] for r in rows], style, label=strategy)
        right.loglog(n, [r["bare_solves"] for r in rows], style, label=strategy)
        for r in rows:
            if not r["accurate"]:
                left.annotate(f"{r['error_deg']:.2g}°", (r["thick_vertices"], r["seconds"]),
                              fontsize=7)
    left.set_xlabel("thick vertices (Miura n × n)")
    left.set_ylabel("wall time to the fold, s (warm)")
    right.set_xlabel("thick vertices")
    right.set_ylabel("wall time / bare solve of K")
    left.legend()
    left.set_title("time to a converged fold (labels: error if > 0.01°)", fontsize=9)
    right.set_title("host-independent: in bare solves", fontsize=9)
    _meta.save(fig, path, dpi=120)


def table(data: dict) -> str:
    """Per case and strategy: time (s), iterations, error; hybrid's bare solves, memory."""
    rows = []
    for case in CASES:
        hybrid = next((r for r in data["warm"] if r["case"] == case
                       and r["strategy"] == "hybrid"), None)
        if hybrid is None:
            continue
        cells = [case]
        for strategy in STRATEGIES:
            r = next((r for r in data["warm"] if r["case"] == case
                      and r["strategy"] == strategy), None)
            if r is None:
                cells.append("–")
                continue
            mark = "" if r["accurate"] else f", {r['error_deg']:.2g}° off"
            if r["converged"] and not r["accurate"]:
                mark += " yet “converged”"
            elif not r["converged"]:
                mark += f", not converged ({r.get('reason', 'budget')})"
            cells.append(f"{r['seconds']:.3g} s, {r['iterations']} its{mark}")
        cells += [f"{hybrid['thick_vertices']:,}", f"{hybrid['bare_solves']:,.0f}",
                  f"{hybrid['kb_per_thick_vertex']:.2f}"]
        rows.append(cells)
    return _meta.markdown_table(["case", *STRATEGIES, "thick vertices", "hybrid / bare solve",
                                 "kB / thick vertex (hybrid)"], rows)


def cold_line(data: dict) -> str:
    """The cold-cache run, when measured."""
    c = data.get("cold")
    return "" if c is None else (f"cold numba cache ({c['case']}, {c['strategy']}, everything "
                                 f"compiled in the process): {c['seconds']:.3g} s, "
                                 f"{c['iterations']} iterations")


def memory_table(data: dict) -> str:
    """Fixed MB, marginal MB and kB per thick vertex of the memory probes."""
    return _meta.markdown_table(
        ["case", "thick vertices", "fixed (MB)", "marginal (MB)", "marginal kB / thick vertex",
         "peak RSS (MB)"],
        [[r["case"], f"{r['thick_vertices']:,}", f"{r['fixed_mb']:.0f}",
          f"{r['marginal_mb']:.1f}", f"{r['marginal_kb_per_vertex']:.2f}",
          f"{r['peak_rss_mb']:.0f}"] for r in data.get("memory", {}).get("rows", [])])


def main() -> None:
    args = _meta.parser(__doc__).parse_args()
    if _meta.stored("time_to_solution", args, lambda data: "\n\n".join(
            [table(data), cold_line(data), memory_table(data)]), plot):
        return
    q = QUICK if args.quick else {"cases": CASES, "runs": RUNS, "lbfgs_budget": LBFGS_BUDGET,
                                  "memory": MEMORY_CASES}
    record = _meta.Record("time_to_solution", args, tolerance=TOLERANCE, budget=BUDGET,
                          lbfgs_budget=q["lbfgs_budget"], accuracy_deg=ACCURACY_DEG,
                          runs=q["runs"], runs_one=list(ONE_RUN), warmup_processes=1)
    child("--probe", q["cases"][0], "hybrid", BUDGET)  # warm-up: page cache, .pyc
    rows = []
    for case in q["cases"]:
        print(case, flush=True)
        for _ in range(1 if case in ONE_RUN else q["runs"]):
            for strategy in STRATEGIES:
                budget = q["lbfgs_budget"] if strategy == "lbfgs" else BUDGET
                rows.append(run_probe(case, strategy, budget))
    data = {"warm": summarise(rows), "runs": rows}
    if not args.quick:
        print("cold cache", flush=True)
        with tempfile.TemporaryDirectory() as cache:
            data["cold"] = run_probe("miura10", "hybrid", BUDGET,
                                     env={**os.environ, "NUMBA_CACHE_DIR": cache})
    print("memory", flush=True)
    data["memory"] = {"rows": [child("--memory-probe", case) for case in q["memory"]]}
    record.write(data, plot)
    print("\n\n".join([table(data), cold_line(data), memory_table(data)]))


if __name__ == "__main__":
    if sys.argv[1:2] == ["--probe"]:
        print(json.dumps(probe(sys.argv[2], sys.argv[3], int(sys.argv[4]))))
    elif sys.argv[1:2] == ["--memory-probe"]:
        print(json.dumps(memory_probe(sys.argv[2])))
    else:
        main()
