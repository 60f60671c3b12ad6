"""Setup and per-iteration cost vs mesh size: Miura-ori n × n, paper solver (issue 7 item 1).

Scene: ``patterns.miura(n, n, a=10, b=10, gamma=60)`` (mm, degrees), every
crease actuated (demo style) to its zero-thickness rigid-fold angle at facet
tilt 30° (zig-zag 60°, straight 32.2°, signed by M/V), thickened with
H = 1 mm (0.1 of the 10 mm panel edge), hinge width W = 2 mm, k = 4
sub-strips per crease. n ∈ SIZES, grown until one size takes more than
STOP_AFTER_S of wall time in total (or fails).

Each size runs in its own fresh subprocess (``--child n``), so the peak
resident memory (``resource.getrusage(...).ru_maxrss``, which covers
CHOLMOD's allocations, unlike tracemalloc) is that size's alone. In it:

* warm-up: a 2 × 2 Miura through the whole pipeline and a few iterations
  (numba kernels loaded from the cache, imports done); ``rss_baseline_mb`` is
  the peak RSS at that point;
* setup, SETUP_RUNS repeats, median of each part (seconds): ``pattern``
  (``patterns.miura``), ``actuate`` (``pattern.replace(fold_angles=...)``,
  re-validates), ``thicken``, ``assembly`` (``system.element_matrix``),
  ``slots`` (``system.vertex_slots``, the gather's CSR), ``symbolic``
  (``sksparse.cholmod.analyze``, simplicial, the ordering
  ``linsolve.cholmod_ordering`` picks) and
  ``numeric`` (``Factor.cholesky_inplace``) on K + the anchor pin,
  ``factor`` (one ``linsolve.Factor(...)`` construction, both at once) and
  ``simulation`` (the whole ``Simulation(mesh, pattern)`` construction,
  which assembles and factors again); ``total`` = pattern + actuate +
  thicken + simulation;
* iterations, after WARM_ITERATIONS warm-up steps, ITERATIONS rounds, each
  round timing (interleaved, so load changes on the shared machine hit all
  alike) one ``sim.step()`` (``step``), the same iteration done by its pieces
  — ``projection`` (every group's ``_GroupRun.project``: the numba element
  kernels), ``gather`` (``System.rhs`` into the column-major rhs + the anchor
  pin term), ``solve`` (``system.factor.solve`` of that (N, 3) rhs), ``take``
  (``system.take_solution``: the C-ordered positions and the largest move in
  one pass) — and a ``bare_solve`` (the CHOLMOD forward/back solve of an
  (N, 3) column-major rhs, CHOLMOD's own layout, on the same factor); then ``projection_1thread`` / ``gather_1thread``: the same two
  kernels again on one numba thread (``Simulation`` uses numba's default,
  2 here, above its SERIAL_BELOW_SLOTS element-vertex slots); medians per
  iteration, s. ``step_vs_bare_solve`` is the ratio of the two medians
  measured in the same process, ``projection_speedup_2_threads`` the
  1-thread / default-thread projection ratio.
* memory: peak RSS (MB) after setup and at the end; ``mb_per_vertex`` =
  (peak − baseline) / thick-mesh vertices. nnz(K) and nnz(L) are read after
  the peak was recorded (L() makes a copy).

The whole child runs with BLAS on one thread, as ``Simulation.step`` does
(``foldcore.threads``: OpenBLAS's spinning threads otherwise take a core from
numba's projection).

The machine is shared: before each size the parent waits (up to
QUIET_WAIT_S) until other jobs use < QUIET_BELOW of the cores, and records
``others_busy_during`` (share of all cores used by other processes while the
size ran, from /proc/stat minus the child's own CPU time). numba's parallel
loops (projection, gather) wait for their slowest thread, so a busy machine
inflates them most, small sizes above all; ``per_iteration_min_s`` (fastest
round) is kept beside the medians as the least-disturbed figure.

Exponents: log-log least squares of time vs thick-mesh vertices over the
sizes with n ≥ 10. Writes bench/results/scaling.json and .png.

Run: ``.venv/bin/python bench/scaling.py`` (all sizes: ~25 min and 8 GB at
400×400 on the 2-core machine) or ``--sizes 5 10 20`` (subset); ``--child n``
prints one size's JSON; ``--replot`` redraws the PNG from the JSON.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).parent / "results"
SIZES = (5, 10, 20, 50, 100, 150, 200, 300, 400)
STOP_AFTER_S = 600.0       # stop growing once one size took longer than this (wall, total)
CHILD_TIMEOUT_S = 1800.0
EDGE, GAMMA, TILT = 10.0, 60.0, 30.0     # mm, degrees, degrees
THICKNESS, WIDTH, SUBDIVISIONS = 1.0, 2.0, 4
SETUP_RUNS = 3
SETUP_BUDGET_S = 90.0      # fewer setup repeats once this much setup time was spent
WARM_ITERATIONS = 3
ITERATIONS = 30            # rounds (step + pieces + bare solve); at least MIN_ITERATIONS
MIN_ITERATIONS = 20
ITERATION_BUDGET_S = 120.0
FIT_FROM_N = 10
QUIET_BELOW, QUIET_WAIT_S = 0.25, 300.0  # before each size, wait for other jobs to calm down
SETUP_PARTS = ("pattern", "actuate", "thicken", "assembly", "slots", "symbolic", "numeric",
               "factor", "simulation", "total")
ITERATION_PARTS = ("step", "projection", "gather", "solve", "take", "bare_solve",
                   "projection_1thread", "gather_1thread")


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: KiB


# ------------------------------------------------------------------ child
def miura_actuated(n: int):
    """(pattern generation seconds, actuation seconds, actuated pattern)."""
    from foldcore import patterns

    t0 = time.perf_counter()
    pattern = patterns.miura(n, n, a=EDGE, b=EDGE, gamma=GAMMA)
    t1 = time.perf_counter()
    pattern = pattern.replace(fold_angles=patterns.miura_fold_angles(n, n, GAMMA, TILT))
    return t1 - t0, time.perf_counter() - t1, pattern


def setup_once(n: int):
    """One timed setup; returns (seconds per part, mesh, pattern, simulation)."""
    import scipy.sparse as sp
    from sksparse.cholmod import analyze

    from foldcore import thicken
    from foldcore.linsolve import Factor, cholmod_ordering
    from foldcore.simulation import Simulation
    from foldcore.system import element_matrix, vertex_slots

    t = {}
    t["pattern"], t["actuate"], pattern = miura_actuated(n)
    t0 = time.perf_counter()
    mesh = thicken(pattern, THICKNESS, hinge_width=WIDTH, subdivisions=SUBDIVISIONS)
    t["thicken"] = time.perf_counter() - t0
    groups = [g for g in mesh.groups.values() if len(g)]
    weights = [np.array(g.weights, dtype=float) for g in groups]
    n_vertices = mesh.n_vertices
    t0 = time.perf_counter()
    matrix = element_matrix(groups, weights, n_vertices)
    t["assembly"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    vertex_slots(np.concatenate([g.indices for g in groups]), n_vertices)
    t["slots"] = time.perf_counter() - t0
    pins = np.zeros(n_vertices)
    pins[0] = matrix.diagonal().mean()  # the anchor Simulation adds without position targets
    pinned = (matrix + sp.diags(pins)).tocsc()
    t0 = time.perf_counter()
    factor = analyze(pinned, mode="simplicial", ordering_method=cholmod_ordering(n_vertices))
    t1 = time.perf_counter()
    factor.cholesky_inplace(pinned)
    t2 = time.perf_counter()
    t["symbolic"], t["numeric"] = t1 - t0, t2 - t1
    del factor
    t0 = time.perf_counter()
    factor = Factor(pinned, "cholmod")
    t["factor"] = time.perf_counter() - t0
    del factor, matrix, pinned
    t0 = time.perf_counter()
    sim = Simulation(mesh, pattern, solver="paper")
    t["simulation"] = time.perf_counter() - t0
    t["total"] = t["pattern"] + t["actuate"] + t["thicken"] + t["simulation"]
    return t, mesh, pattern, sim


def project_and_gather(sim, x, rhs) -> tuple[float, float]:
    """The paper iteration's local step at ``x`` by its pieces: every group's
    projection (numba element kernels), then the gather into ``rhs`` with the
    anchor pin term. Returns (projection, gather) seconds."""
    t0 = time.perf_counter()
    for run, w in zip(sim._runs, sim.system.weights):
        run.project(x, sim._targets, w)
    t1 = time.perf_counter()
    sim.system.rhs(sim._targets, rhs)
    sim._add_pin_terms(rhs, x)
    return t1 - t0, time.perf_counter() - t1


def solve_and_take(sim, rhs, x):
    """The paper iteration's global step: K⁻¹ ``rhs``, then the C-ordered copy and
    the largest move from ``x`` (``system.take_solution``). Returns (new
    positions, solve seconds, take seconds)."""
    from foldcore.system import take_solution

    t0 = time.perf_counter()
    solution = sim.system.factor.solve(rhs)
    t1 = time.perf_counter()
    new_x = np.empty_like(x)
    take_solution(solution, x, new_x)
    return new_x, t1 - t0, time.perf_counter() - t1


def one_round(sim) -> dict:
    """Time one step, one iteration by its pieces and one bare solve (seconds).

    Then the projection and gather once more on one numba thread (same x), to
    show what the second thread buys at this size. Called with BLAS held to
    one thread, as ``Simulation.step`` runs (``foldcore.threads``).
    """
    import numba

    t = {}
    t0 = time.perf_counter()
    sim.step()
    t["step"] = time.perf_counter() - t0
    # the paper iteration by pieces (what Simulation._paper_iteration does)
    numba.set_num_threads(sim.threads)
    x = sim.x
    t["projection"], t["gather"] = project_and_gather(sim, x, sim._rhs)
    new_x, t["solve"], t["take"] = solve_and_take(sim, sim._rhs, x)
    sim.x = new_x
    bare_rhs = np.asfortranarray(new_x)  # CHOLMOD's own layout, as the iteration's rhs
    t0 = time.perf_counter()
    sim.system.factor.solve(bare_rhs)
    t["bare_solve"] = time.perf_counter() - t0
    numba.set_num_threads(1)
    t0 = time.perf_counter()
    for run, w in zip(sim._runs, sim.system.weights):
        run.project(new_x, sim._targets, w)
    t1 = time.perf_counter()
    sim.system.rhs(sim._targets, sim._rhs)
    t["projection_1thread"], t["gather_1thread"] = t1 - t0, time.perf_counter() - t1
    numba.set_num_threads(sim.threads)
    return t


def child(n: int) -> dict:
    import scipy.sparse.linalg  # noqa: F401  (loads scipy's BLAS before the guard scans)

    import foldcore.simulation  # noqa: F401
    from foldcore.threads import blas_on_one_thread

    with blas_on_one_thread(refresh=True):
        return _child(n)


def _child(n: int) -> dict:
    start = time.perf_counter()
    load_start = os.getloadavg()[0]
    # warm-up: imports, numba cache loads, first factorisation, shapely
    _, mesh, pattern, sim = setup_once(2)
    for _ in range(WARM_ITERATIONS):
        one_round(sim)
    del mesh, pattern, sim
    baseline = peak_rss_mb()

    runs, sim, spent = [], None, 0.0
    while len(runs) < SETUP_RUNS and (not runs or spent < SETUP_BUDGET_S):
        sim = mesh = pattern = None  # free the previous repeat before the next peak
        t, mesh, pattern, sim = setup_once(n)
        runs.append(t)
        spent += sum(v for k, v in t.items() if k not in ("total",))
    setup = {k: statistics.median(r[k] for r in runs) for k in SETUP_PARTS}
    after_setup = peak_rss_mb()

    for _ in range(WARM_ITERATIONS):
        one_round(sim)
    rounds, t_iter = [], time.perf_counter()
    while len(rounds) < ITERATIONS and (len(rounds) < MIN_ITERATIONS
                                        or time.perf_counter() - t_iter < ITERATION_BUDGET_S):
        rounds.append(one_round(sim))
    per_iteration = {k: statistics.median(r[k] for r in rounds) for k in ITERATION_PARTS}
    per_iteration_min = {k: min(r[k] for r in rounds) for k in ITERATION_PARTS}
    peak = peak_rss_mb()

    n_vertices = mesh.n_vertices
    lower = sim.system.factor._factor.L()  # after the peak reading: L() copies the factor
    row = {
        "n": n,
        "pattern_vertices": int(pattern.n_vertices),
        "pattern_edges": int(pattern.n_edges),
        "thick_vertices": int(n_vertices),
        "elements": {k: len(g) for k, g in mesh.groups.items()},
        "nnz_K": int(sim.system.matrix.nnz),
        "nnz_L": int(lower.nnz),
        "setup_s": setup,
        "setup_runs": runs,
        "per_iteration_s": per_iteration,
        "per_iteration_min_s": per_iteration_min,
        "iterations_timed": len(rounds),
        "numba_threads_used": int(sim.threads),
        "projection_speedup_2_threads": (per_iteration["projection_1thread"]
                                         / per_iteration["projection"]),
        "step_vs_bare_solve": per_iteration["step"] / per_iteration["bare_solve"],
        "pieces_vs_bare_solve": (per_iteration["projection"] + per_iteration["gather"]
                                 + per_iteration["solve"] + per_iteration["take"])
        / per_iteration["bare_solve"],
        "rss_baseline_mb": baseline,
        "rss_after_setup_mb": after_setup,
        "peak_rss_mb": peak,
        "mb_per_vertex": (peak - baseline) / n_vertices,
        "kb_per_vertex": 1024.0 * (peak - baseline) / n_vertices,
        "child_seconds": time.perf_counter() - start,
        "load_average_1min": [load_start, os.getloadavg()[0]],  # at start, at end (shared machine)
    }
    return row


# ----------------------------------------------------------------- parent
def busy_seconds() -> float:
    """CPU seconds spent busy by the whole machine since boot (/proc/stat, all cores)."""
    with open("/proc/stat") as fh:
        fields = [float(v) for v in fh.readline().split()[1:]]
    idle = fields[3] + fields[4]  # idle + iowait
    return (sum(fields[:8]) - idle) / os.sysconf("SC_CLK_TCK")


def others_busy(seconds: float = 2.0) -> float:
    """Fraction of all cores busy over ``seconds`` while this script sleeps."""
    b0, t0 = busy_seconds(), time.perf_counter()
    time.sleep(seconds)
    return (busy_seconds() - b0) / ((time.perf_counter() - t0) * os.cpu_count())


def wait_for_quiet() -> float:
    """Wait (up to QUIET_WAIT_S) until other jobs use < QUIET_BELOW of the cores."""
    deadline = time.perf_counter() + QUIET_WAIT_S
    busy = others_busy()
    while busy > QUIET_BELOW and time.perf_counter() < deadline:
        busy = others_busy(5.0)
    return busy


def run_child(n: int) -> dict | None:
    quiet = wait_for_quiet()
    start = time.perf_counter()
    busy0 = busy_seconds()
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        proc = subprocess.run([sys.executable, __file__, "--child", str(n)], capture_output=True,
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
    # share of the cores used by other jobs while this size ran (0: machine to ourselves)
    row["others_busy_during"] = max(0.0, (busy_seconds() - busy0 - own)
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
    out = {"setup_" + k: fit(rows, lambda r, k=k: r["setup_s"][k]) for k in SETUP_PARTS}
    out.update({"per_iteration_" + k: fit(rows, lambda r, k=k: r["per_iteration_s"][k])
                for k in ITERATION_PARTS})
    out.update({"per_iteration_min_" + k: fit(rows, lambda r, k=k: r["per_iteration_min_s"][k])
                for k in ITERATION_PARTS})
    out["peak_rss_above_baseline"] = fit(rows, lambda r: r["peak_rss_mb"] - r["rss_baseline_mb"])
    return out


def plot(rows, fits, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    verts = np.array([r["thick_vertices"] for r in rows])
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5))
    styles = {"pattern": "C0o-", "actuate": "C1v-", "thicken": "C2s-", "assembly": "C3^-",
              "symbolic": "C4D-", "numeric": "C5<-", "simulation": "C6>-", "total": "k*-"}
    for part, style in styles.items():
        e = fits["setup_" + part]["exponent"]
        left.loglog(verts, [r["setup_s"][part] for r in rows], style, ms=4,
                    label=f"{part} (∝ N^{e:.2f})" if e is not None else part)
    left.set_title("setup parts (median of repeats)")
    left.set_ylabel("seconds")
    styles = {"step": "k*-", "projection": "C0o-", "gather": "C1s-", "solve": "C3^-",
              "take": "C2v-", "bare_solve": "C3^--", "projection_1thread": "C0o:"}
    for part, style in styles.items():
        e = fits["per_iteration_" + part]["exponent"]
        right.loglog(verts, [r["per_iteration_s"][part] for r in rows], style, ms=4,
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
        ax.legend(fontsize=8)
    fig.suptitle(f"Miura n×n, a = b = {EDGE:g} mm, H = {THICKNESS:g} mm, W = {WIDTH:g} mm, "
                 f"k = {SUBDIVISIONS}, all creases actuated; exponents over n ≥ {FIT_FROM_N}",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(sizes) -> None:
    sys.path.insert(0, str(Path(__file__).parent))
    from _meta import machine_meta

    rows = []
    for n in sizes:
        row = run_child(n)
        if row is None:
            break
        rows.append(row)
        s, it = row["setup_s"], row["per_iteration_s"]
        print(f"n={n:4d} N={row['thick_vertices']:8d} setup {s['total']:8.3f} s "
              f"(thicken {s['thicken']:.3f}, sim {s['simulation']:.3f}) "
              f"step {it['step'] * 1e3:9.3f} ms bare {it['bare_solve'] * 1e3:8.3f} ms "
              f"×{row['step_vs_bare_solve']:.2f} peak {row['peak_rss_mb']:.0f} MB "
              f"wall {row['wall_s']:.0f} s others busy {row['others_busy_during']:.0%}",
              flush=True)
        if row["wall_s"] > STOP_AFTER_S:
            print(f"n={n} took {row['wall_s']:.0f} s > {STOP_AFTER_S:.0f} s: stop growing",
                  flush=True)
            break
    fits = exponents(rows)
    meta = {**machine_meta(), "load_average_at_end": os.getloadavg(),
            "scene": {"pattern": "miura", "a_mm": EDGE, "b_mm": EDGE, "gamma_deg": GAMMA,
                      "actuated": "all creases, rigid-fold angles at facet tilt 30°",
                      "thickness_mm": THICKNESS, "hinge_width_mm": WIDTH,
                      "subdivisions": SUBDIVISIONS, "solver": "paper"},
            "setup_runs": SETUP_RUNS, "iterations": ITERATIONS,
            "warm_iterations": WARM_ITERATIONS, "fit_from_n": FIT_FROM_N,
            "stop_after_s": STOP_AFTER_S, "quiet_below": QUIET_BELOW,
            "quiet_wait_s": QUIET_WAIT_S, "sizes_requested": list(sizes),
            "units": {"time": "s", "memory": "MB (2^20 bytes), ru_maxrss"}}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "scaling.json").write_text(json.dumps({"meta": meta, "exponents": fits,
                                                      "rows": rows}, indent=1))
    plot(rows, fits, RESULTS / "scaling.png")
    for k, v in fits.items():
        if v["exponent"] is not None:
            print(f"{k:32s} N^{v['exponent']:.2f}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", type=int, help="measure one size, print its JSON row")
    parser.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    parser.add_argument("--replot", action="store_true",
                        help="redraw scaling.png from the committed scaling.json")
    args = parser.parse_args()
    if args.child is not None:
        print(json.dumps(child(args.child)), flush=True)
    elif args.replot:
        data = json.loads((RESULTS / "scaling.json").read_text())
        plot(data["rows"], data["exponents"], RESULTS / "scaling.png")
    else:
        main(args.sizes)
