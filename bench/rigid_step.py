"""One rigid-body step in bare solves: where its time goes, and the floor of an exact step.

Issue 17 asks for a rigid-body (Levenberg–Marquardt) step costing ≤ 10 bare
solves of the paper map's K at ≥ 20 × 20. This benchmark folds the thin Miura
cases of ``bench/time_to_solution.py`` (10 × 10, 20 × 20, 50 × 50; H = 1e-3·a,
W = 3H, one zig-zag crease driven) with the ``rigid`` strategy, which steps
the mesh's coarse twin (``foldcore.coarse``), and splits the time of the
twin's steps, per step:

- ``factor``: CHOLMOD's numeric refactorisation of the damped normal matrix
  (symbolic analysis reused);
- ``solves``: its two triangular solves (velocity, geodesic acceleration);
- ``linearise``: Jacobian, residuals and the normal matrix's assembly;
- ``other``: trial states, their energies, the finite-difference probe.

and measures two floors on the step's matrix, taken at the run's third step:

- ``schur_factor``: the numeric factorisation of its Schur complement on the
  panels' unknowns (6 per panel: the issue's condensation, the per-crease
  unknowns eliminated exactly), median of ``REPEATS``, the faster of CHOLMOD's
  simplicial and supernodal modes (AMD ordering);
- ``bare_solve``: one solve with the paper map's factorised K of the mesh
  (the unit), median of ``REPEATS``.

Every time is also given in bare solves (``*_bare``). A fresh process per
size, warm numba cache; ``others_busy`` records the share of the cores other
processes used before each run. Timers wrap the engine's methods in the
probe's process (the library is not changed); they add ≲ 1 µs per call.

Writes bench/results/rigid_step.json and .png; ``--table`` prints the
README's table from the JSON. Run: ``.venv/bin/python bench/rigid_step.py``
(~1 min).
"""
from __future__ import annotations

import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
CASES = ("miura10", "miura20", "miura50")
REPEATS = 7
CAPTURE_STEP = 3  # the step whose matrix the floors are measured on
TOLERANCE, BUDGET = 1e-8, 10_000


class StepTimers:
    """Wall time per engine method of the twin's steps (wraps the class's methods;
    calls of the mesh's own engine, ``mesh_engine``, are not counted)."""

    PARTS = {"factor": "_factor", "linearise": "_linearise"}

    def __init__(self):
        from foldcore.rigid_body import RigidBodySolver

        self.seconds = {"step": 0.0, "factor": 0.0, "linearise": 0.0, "solve_time": 0.0}
        self.steps, self.mesh_engine, self.captured = 0, None, None
        self._wrap(RigidBodySolver)

    def _wrap(self, cls) -> None:
        timers = self
        step, factor, linearise = cls.step, cls._factor, cls._linearise

        def timed_step(engine):
            t, solve0 = time.perf_counter(), engine.solve_time
            out = step(engine)
            if engine is not timers.mesh_engine:
                timers.seconds["step"] += time.perf_counter() - t
                timers.seconds["solve_time"] += engine.solve_time - solve0
                timers.steps += 1
            return out

        def timed_factor(engine, normal, grad):
            t = time.perf_counter()
            out = factor(engine, normal, grad)
            if engine is not timers.mesh_engine:
                timers.seconds["factor"] += time.perf_counter() - t
                if timers.steps + 1 == CAPTURE_STEP:
                    timers.captured = (engine, normal.copy())
            return out

        def timed_linearise(engine, state):
            t = time.perf_counter()
            out = linearise(engine, state)
            if engine is not timers.mesh_engine:
                timers.seconds["linearise"] += time.perf_counter() - t
            return out

        cls.step, cls._factor, cls._linearise = timed_step, timed_factor, timed_linearise


def median_seconds(call, repeats: int = REPEATS) -> float:
    """Median wall time of ``call()`` over ``repeats`` calls, after one warm-up call."""
    call()
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        call()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def panel_schur(engine, normal: np.ndarray):
    """(Schur complement on the panel unknowns (lower, CSC), its size, the number and
    the largest size of the eliminated blocks) of the engine's damped normal
    matrix with values ``normal`` on its lower pattern. The panel unknowns are
    the engine's first columns; the rest (strip vertices, strip rotations, fold
    angles) couple within one crease each."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components
    from sksparse.cholmod import cholesky

    n = engine.n_unknowns
    low = sp.csc_matrix((normal, engine.csc_indices, engine.csc_indptr), shape=(n, n))
    full = (low + sp.tril(low, -1).T).tocsc()
    n_panel = int(engine.free_col[0]) if len(engine.free) else int(engine.rot_col)
    eliminated = full[n_panel:, n_panel:].tocsc()
    blocks, labels = connected_components(eliminated, directed=False)
    coupling = full[:n_panel, n_panel:]
    inner = cholesky(eliminated, mode="simplicial")
    schur = full[:n_panel, :n_panel] - coupling @ inner.solve_A(coupling.T.tocsc())
    schur = sp.tril(0.5 * (schur + schur.T)).tocsc()
    return schur, n_panel, int(blocks), int(np.bincount(labels).max())


def factor_seconds(matrix) -> dict:
    """Median numeric refactorisation time (s) of a lower-stored SPD ``matrix`` by
    CHOLMOD's simplicial and supernodal modes (AMD ordering), with nnz(L)."""
    from sksparse.cholmod import cholesky

    out = {}
    for mode in ("simplicial", "supernodal"):
        factor = cholesky(matrix, mode=mode, ordering_method="amd")
        out[mode] = median_seconds(lambda: factor.cholesky_inplace(matrix))
        out[f"{mode}_nnz_L"] = int(factor.L().nnz)
    return out


def probe(case: str) -> dict:
    """The ``rigid`` fold of ``case`` with the twin's steps timed (module docstring)."""
    import scipy.sparse as sp

    sys.path.insert(0, str(HERE))
    from time_to_solution import make_case

    from foldcore.simulation import Simulation

    timers = StepTimers()
    pattern, mesh, expected, creases = make_case(case)
    sim = Simulation(mesh, pattern, solver="rigid")
    timers.mesh_engine = sim.strategy.engine
    start = time.perf_counter()
    result = sim.run(tolerance=TOLERANCE, max_iterations=BUDGET)
    wall = time.perf_counter() - start
    error = float(np.abs(result.fold_angles_deg[creases] - expected).max())
    engine, normal = timers.captured
    n = engine.n_unknowns
    full_matrix = sp.csc_matrix((normal, engine.csc_indices, engine.csc_indptr), shape=(n, n))
    schur, n_panel, blocks, block_max = panel_schur(engine, normal)
    floors = {"full": factor_seconds(full_matrix), "schur": factor_seconds(schur)}
    rhs = np.random.default_rng(0).standard_normal((mesh.n_vertices, 3))
    bare = median_seconds(lambda: sim.system.factor.solve(rhs), 20)
    s = timers.seconds
    steps = timers.steps
    per_step = {"step": s["step"] / steps, "factor": s["factor"] / steps,
                "solves": (s["solve_time"] - s["factor"]) / steps,
                "linearise": s["linearise"] / steps}
    per_step["other"] = per_step["step"] - per_step["factor"] - per_step["solves"] \
        - per_step["linearise"]
    per_step["schur_factor"] = min(floors["schur"]["simplicial"], floors["schur"]["supernodal"])
    row = {"case": case, "thick_vertices": int(mesh.n_vertices), "iterations":
           int(result.iterations), "twin_steps": steps, "wall_s": wall, "error_deg": error,
           "twin_unknowns": n, "panel_unknowns": n_panel, "eliminated_blocks": blocks,
           "eliminated_block_max": block_max, "schur_nnz_lower": int(schur.nnz),
           "refactor_modes": floors, "bare_solve_s": bare,
           "per_step_s": per_step,
           "per_step_bare": {k: v / bare for k, v in per_step.items()}}
    return row


def run_probe(case: str) -> dict:
    """``probe`` in a fresh interpreter, with the load before it."""
    from scaling import others_busy

    busy = others_busy(1.0)
    out = subprocess.run([sys.executable, __file__, "--probe", case],
                         capture_output=True, text=True, check=True)
    row = json.loads(out.stdout.strip().splitlines()[-1])
    row["others_busy"] = busy
    b = row["per_step_bare"]
    print(f"  {case:8s} {row['twin_steps']:3d} twin steps  step {b['step']:.1f}  factor "
          f"{b['factor']:.1f}  solves {b['solves']:.1f}  linearise {b['linearise']:.1f}  other "
          f"{b['other']:.1f}  schur factor {b['schur_factor']:.1f} bare solves "
          f"({row['bare_solve_s'] * 1e3:.2f} ms; busy {busy:.2f})", flush=True)
    return row


PARTS = ("factor", "solves", "linearise", "other")


def plot(data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = data["rows"]
    n = [r["thick_vertices"] for r in rows]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    bottom = np.zeros(len(rows))
    labels = [f"{r['case']}\n{r['thick_vertices']:,} v" for r in rows]
    for part, colour in zip(PARTS, ("C3", "C1", "C0", "C7")):
        values = np.array([r["per_step_bare"][part] for r in rows])
        left.bar(labels, values, bottom=bottom, color=colour, label=part)
        bottom += values
    left.plot(labels, [r["per_step_bare"]["schur_factor"] for r in rows], "k^--",
              label="floor: Schur complement's factorisation (6 / panel)")
    left.axhline(10, color="C2", ls=":", label="issue 17 target (10)")
    left.set_ylim(0, 1.6 * bottom.max())
    left.set_ylabel("per rigid step, in bare solves of K")
    left.legend(fontsize=7)
    left.set_title("a rigid step of the coarse twin, split", fontsize=9)
    for part, style in (("step", "ko-"), ("factor", "C3s-"), ("schur_factor", "k^--")):
        right.loglog(n, [r["per_step_s"][part] * 1e3 for r in rows], style, label=part)
    right.loglog(n, [r["bare_solve_s"] * 1e3 for r in rows], "C2v:", label="bare solve of K")
    right.set_xlabel("thick vertices")
    right.set_ylabel("ms")
    right.legend(fontsize=7)
    right.set_title("absolute (this host)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def table(path: Path = RESULTS / "rigid_step.json") -> str:
    """README table: per size, the step's parts and the floor in bare solves."""
    from _meta import markdown_table

    rows = json.loads(path.read_text())["rows"]
    return markdown_table(
        ["case", "thick vertices", "twin unknowns (panel)", "twin steps", "bare solve (ms)",
         "step", "factor", "solves", "linearise", "other", "Schur factor (floor)"],
        [[r["case"], f"{r['thick_vertices']:,}",
          f"{r['twin_unknowns']:,} ({r['panel_unknowns']:,})", str(r["twin_steps"]),
          f"{r['bare_solve_s'] * 1e3:.2f}",
          *(f"{r['per_step_bare'][k]:.1f}" for k in ("step", *PARTS, "schur_factor"))]
         for r in rows])


def main() -> None:
    sys.path.insert(0, str(HERE))
    from _meta import machine_meta

    rows = [run_probe(case) for case in CASES]
    data = {"meta": {**machine_meta(), "date": time.strftime("%Y-%m-%d"),
                     "tolerance": TOLERANCE, "repeats": REPEATS, "capture_step": CAPTURE_STEP},
            "rows": rows}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "rigid_step.json").write_text(json.dumps(data, indent=1))
    plot(data, RESULTS / "rigid_step.png")
    print(table())


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--probe":
        print(json.dumps(probe(sys.argv[2])))
    elif len(sys.argv) > 1 and sys.argv[1] == "--table":
        sys.path.insert(0, str(HERE))
        print(table())
    else:
        main()
