"""Time to a converged fold, per strategy and size, beside the bare solve (issue 17).

What a user waits for: wall time and iterations from the thick mesh to a fold
that meets the accuracy issue's tolerance (largest angle error ≤ 0.01° against
the closed form), and the peak memory of the process.

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
flat). Reported: wall time of ``run`` (setup excluded; K is factorised at
its first use, so inside ``run`` for the strategies that solve with it —
lbfgs, and hybrid's finish where it hands over — and never for a rigid-body
fold), iterations, ``converged``, largest angle error (degrees), the paper
map's bare solve of K (N × 3 right-hand side, median of 20, the
host-independent yardstick: time / bare solve), thick vertices, peak RSS of
the fold (read before the bare solves, which factorise K where the run did
not) and its growth over the RSS before the mesh is built (per thick vertex).

Warm: the project's numba cache (the README's set-up fills it); runs of one
size interleaved over strategies, ``RUNS`` rounds for the small cases, one for
Miura 20 × 20 and 50 × 50. Cold: Miura 10 × 10 under the default strategy with
``NUMBA_CACHE_DIR`` set to an empty folder (everything compiled in-process).
The machine is shared: the share of the cores other processes used is
recorded before each run (``others_busy``).

Memory, fixed and marginal (``--memory``; stored under ``memory``): the
growth above counts what any first fold in a process pays once (numba's and
LLVM's runtime, the first call of each kernel: ≈ 0.1 GB whatever the size),
so per thick vertex it overstates what a bigger sheet costs. A fresh process
per size folds a small warm-up sheet (``WARMUP_CASE``) with the default
strategy first, then the case; reported: the RSS before anything (``start``),
after the warm-up (``fixed_mb`` = its growth) and the case's peak growth over
the RSS after the warm-up, per thick vertex (``marginal_kb_per_vertex``).

Writes bench/results/time_to_solution.json and .png; ``--table`` prints the
README's table from the JSON (and the memory table when measured); ``--rerun
lbfgs`` runs only the strategies named (comma-separated) again and replaces
their rows; ``--memory`` runs the memory probes and stores them.

Run: ``.venv/bin/python bench/time_to_solution.py`` (~15 min).
"""
from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
STRATEGIES = ("hybrid", "rigid", "lbfgs")
TOLERANCE, BUDGET, LBFGS_BUDGET = 1e-8, 10_000, 2_000
ACCURACY_DEG = 0.01
RUNS = 3
CASES = ("vertex", "waterbomb", "miura10", "miura20", "miura50")
ONE_RUN = ("miura20", "miura50")
BARE_SOLVES = 20
WARMUP_CASE = "miura4"
MEMORY_CASES = ("miura10", "miura20", "miura50")


def make_case(name: str):
    """(pattern, mesh, closed-form angles (C,), crease indices (C,)) of a case."""
    sys.path.insert(0, str(HERE))
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


def probe(case: str, strategy: str) -> dict:
    """One run in this process (see the module docstring); JSON-ready."""
    from foldcore.simulation import Simulation

    before = current_rss_mb()
    pattern, mesh, expected, creases = make_case(case)
    sim = Simulation(mesh, pattern, solver=strategy)
    budget = LBFGS_BUDGET if strategy == "lbfgs" else BUDGET
    start = time.perf_counter()
    result = sim.run(tolerance=TOLERANCE, max_iterations=budget)
    seconds = time.perf_counter() - start
    error = float(np.abs(result.fold_angles_deg[creases] - expected).max())
    peak = peak_rss_mb()  # the fold's: the bare solves below may factorise K first
    rhs = np.random.default_rng(0).standard_normal((mesh.n_vertices, 3))
    sim.system.factor.solve(rhs)
    solves = []
    for _ in range(BARE_SOLVES):
        t = time.perf_counter()
        sim.system.factor.solve(rhs)
        solves.append(time.perf_counter() - t)
    return {"case": case, "strategy": strategy, "seconds": seconds,
            "iterations": int(result.iterations), "converged": bool(result.converged),
            "reason": result.reason, "error_deg": error, "accurate": bool(error <= ACCURACY_DEG),
            "bare_solve_s": statistics.median(solves), "thick_vertices": int(mesh.n_vertices),
            "peak_rss_mb": peak, "rss_growth_mb": peak - before,
            "kb_per_thick_vertex": (peak - before) * 1024.0 / mesh.n_vertices}


def memory_probe(case: str) -> dict:
    """Fixed and marginal memory of a hybrid fold of ``case`` (module docstring)."""
    from foldcore.simulation import Simulation

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


def memory() -> None:
    """Run ``memory_probe`` per size in fresh processes; store under ``memory``."""
    from _meta import machine_meta

    rows = []
    for case in MEMORY_CASES:
        out = subprocess.run([sys.executable, __file__, "--memory-probe", case],
                             capture_output=True, text=True, check=True)
        row = json.loads(out.stdout.strip().splitlines()[-1])
        print(f"  {case:9s} fixed {row['fixed_mb']:.1f} MB  marginal {row['marginal_mb']:.1f} MB"
              f" = {row['marginal_kb_per_vertex']:.2f} kB/vertex  peak {row['peak_rss_mb']:.0f} MB",
              flush=True)
        rows.append(row)
    path = RESULTS / "time_to_solution.json"
    data = json.loads(path.read_text())
    data["memory"] = {"meta": {**machine_meta(), "date": time.strftime("%Y-%m-%d")},
                      "rows": rows}
    path.write_text(json.dumps(data, indent=1))
    print(memory_table())


def memory_table(path: Path = RESULTS / "time_to_solution.json") -> str:
    """README table of the memory probes: fixed MB, marginal MB and kB per thick vertex."""
    from _meta import markdown_table

    data = json.loads(path.read_text())
    if "memory" not in data:
        return ""
    return markdown_table(
        ["case", "thick vertices", "fixed (MB)", "marginal (MB)", "marginal kB / thick vertex",
         "peak RSS (MB)"],
        [[r["case"], f"{r['thick_vertices']:,}", f"{r['fixed_mb']:.0f}",
          f"{r['marginal_mb']:.1f}", f"{r['marginal_kb_per_vertex']:.2f}",
          f"{r['peak_rss_mb']:.0f}"] for r in data["memory"]["rows"]])


def run_probe(case: str, strategy: str, env=None) -> dict:
    """``probe`` in a fresh interpreter; adds the process wall time and the load."""
    from scaling import others_busy

    busy = others_busy(1.0)
    start = time.perf_counter()
    out = subprocess.run([sys.executable, __file__, "--probe", case, strategy],
                         capture_output=True, text=True, env=env, check=True)
    row = json.loads(out.stdout.strip().splitlines()[-1])
    row.update(process_s=time.perf_counter() - start, others_busy=busy)
    print(f"  {case:9s} {strategy:6s} {row['seconds']:8.2f} s  its {row['iterations']:5d}  "
          f"err {row['error_deg']:.2g}°  {row['seconds'] / row['bare_solve_s']:9.0f} bare solves  "
          f"{row['kb_per_thick_vertex']:.2f} kB/vertex  (busy {busy:.2f})", flush=True)
    return row


def summarise(rows: list) -> list:
    """Median-time row per (case, strategy), with every run's seconds."""
    from _meta import median_run

    out = []
    for case in CASES:
        for strategy in STRATEGIES:
            runs = [r for r in rows if r["case"] == case and r["strategy"] == strategy]
            if not runs:
                continue
            row = median_run(runs)
            row["bare_solves"] = row["seconds"] / row["bare_solve_s"]
            out.append(row)
    return out


def cold_run() -> dict:
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        return run_probe("miura10", "hybrid", env)


def plot(data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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
    left.set_xlabel("thick vertices (Miura 10, 20, 50)")
    left.set_ylabel("wall time to the fold, s (warm)")
    right.set_xlabel("thick vertices")
    right.set_ylabel("wall time / bare solve of K")
    left.legend()
    left.set_title("time to a converged fold (labels: error if > 0.01°)", fontsize=9)
    right.set_title("host-independent: in bare solves", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def table(path: Path = RESULTS / "time_to_solution.json") -> str:
    """README table: per case and strategy, time (s), iterations, error, bare solves."""
    from _meta import markdown_table

    data = json.loads(path.read_text())
    rows = []
    for case in CASES:
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
        r = next(r for r in data["warm"] if r["case"] == case and r["strategy"] == "hybrid")
        cells += [f"{r['thick_vertices']:,}", f"{r['bare_solves']:,.0f}",
                  f"{r['kb_per_thick_vertex']:.2f}"]
        rows.append(cells)
    return markdown_table(["case", *STRATEGIES, "thick vertices", "hybrid / bare solve",
                           "kB / thick vertex (hybrid)"], rows)


def rerun(strategies: list) -> None:
    """Run only ``strategies`` again (same cases and rounds) and replace their rows in
    the stored JSON; the rerun's date and machine are recorded under ``meta.reruns``
    (the other strategies' rows keep their own run's)."""
    from _meta import machine_meta

    path = RESULTS / "time_to_solution.json"
    data = json.loads(path.read_text())
    rows = [r for r in data["runs"] if r["strategy"] not in strategies]
    for case in CASES:
        print(case, flush=True)
        for _ in range(1 if case in ONE_RUN else RUNS):
            for strategy in strategies:
                rows.append(run_probe(case, strategy))
    data["meta"].setdefault("reruns", []).append(
        {**machine_meta(), "date": time.strftime("%Y-%m-%d"), "strategies": strategies})
    data.update(warm=summarise(rows), runs=rows)
    path.write_text(json.dumps(data, indent=1))
    plot(data, RESULTS / "time_to_solution.png")
    print(table())


def main() -> None:
    sys.path.insert(0, str(HERE))
    from _meta import machine_meta

    rows = []
    for case in CASES:
        print(case, flush=True)
        for _ in range(1 if case in ONE_RUN else RUNS):
            for strategy in STRATEGIES:
                rows.append(run_probe(case, strategy))
    print("cold cache", flush=True)
    cold = cold_run()
    data = {"meta": {**machine_meta(), "date": time.strftime("%Y-%m-%d"),
                     "tolerance": TOLERANCE, "budget": BUDGET, "lbfgs_budget": LBFGS_BUDGET,
                     "accuracy_deg": ACCURACY_DEG},
            "warm": summarise(rows), "runs": rows, "cold": cold}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "time_to_solution.json").write_text(json.dumps(data, indent=1))
    plot(data, RESULTS / "time_to_solution.png")
    print(table())


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--probe":
        print(json.dumps(probe(sys.argv[2], sys.argv[3])))
    elif len(sys.argv) > 1 and sys.argv[1] == "--memory-probe":
        print(json.dumps(memory_probe(sys.argv[2])))
    elif len(sys.argv) > 1 and sys.argv[1] == "--memory":
        sys.path.insert(0, str(HERE))
        memory()
    elif len(sys.argv) > 1 and sys.argv[1] == "--table":
        sys.path.insert(0, str(HERE))
        print(table())
        print(memory_table())
    elif len(sys.argv) > 2 and sys.argv[1] == "--rerun":
        sys.path.insert(0, str(HERE))
        rerun(sys.argv[2].split(","))
    else:
        main()
