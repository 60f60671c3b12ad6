"""Inexact rigid-body steps: can an iterative solve of the step's normal equations
cost less than the exact factorisation it replaces?

Issue 17 asks for a rigid-body (Levenberg–Marquardt) step costing ≤ 10 bare
solves of the paper map's K at ≥ 20 × 20; ``bench/rigid_step.py`` shows that
an exact step's factorisation alone is 8.7 (20 × 20) and 18.2 (50 × 50) bare
solves at its floor. Only a step whose linear solve is inexact goes below
that. This benchmark measures the candidates on the step's own matrices.

**Matrices.** The ``rigid`` fold of the thin Miura 20 × 20 and 50 × 50 of
``bench/time_to_solution.py`` (H = 1e-3·a, W = 3H, one zig-zag crease
driven; tolerance 1e-8) is run with the coarse twin's damped normal matrices
JᵀJ + λD and right-hand sides −Jᵀr captured at steps ``CAPTURED`` (an early
pair and a late pair: the later of each is solved, the earlier gives the
stale factorisation). Each is solved by conjugate gradients (x₀ = 0) to the
relative residuals ``RTOLS`` with at most ``MAX_ITERATIONS`` iterations and
preconditioner

- ``stale``: CHOLMOD's factorisation of the previous step's matrix (no
  set-up: the step before paid for it);
- ``block_jacobi``: the inverses of the diagonal blocks of the unknowns'
  bodies (6 per panel, 3 per free vertex and strip rotation, 1 per angle);
- ``ilu_<drop>``: SciPy's incomplete LU (SuperLU ``spilu``, drop tolerance
  ``ILU_DROPS``, fill ≤ ``ILU_FILL`` × nnz) — an incomplete Cholesky stand-in,
  SciPy having none; used in CG as it is (the system is SPD, the ILU of it
  nearly symmetric);
- ``amg``: PyAMG's smoothed aggregation (``symmetry="symmetric"``, one V-cycle
  per application), when PyAMG is installed (``pip install pyamg``; a
  benchmark-only dependency).

Reported per matrix and method: set-up time, iterations, wall of the whole
solve (set-up included), that wall in bare solves, and the error of the
result against the exact solution in the matrix's energy norm
‖x − x*‖_A / ‖x*‖_A. Beside them, ``exact``: the numeric refactorisation
(symbolic analysis reused, as the library does) and one solve; the matrix's
condition number; and why the stale factor fails late in the run: the
relative change ‖A − A_prev‖/‖A‖ of the matrix since the step before and the
ends of the spectrum of A_prev⁻¹·A (all 1 for an unchanged matrix).

**Folds.** Matrix-level figures leave out what an inexact step does to the
Levenberg–Marquardt iteration; ``fold`` rows therefore also run the whole fold
with the step's solves replaced (the library is not changed: its
``_factor`` is wrapped in this process) by the ``stale`` CG with
Eisenstat–Walker forcing (choice 2: η_k = 0.9 (‖g_k‖/‖g_{k−1}‖)², safeguarded,
≤ η_max; Eisenstat & Walker, SIAM J. Sci. Comput. 17, 1996), at most
``FOLD_CG_MAX`` iterations, refactorising when that fails or when the last
solve needed more than ``REFACTOR_AFTER`` iterations; the convergence
verdict's own solves are kept at relative residual ``VERDICT_RTOL``. The
conditioning that defeats the preconditioners is the mechanism's (the
folding motion is the soft direction of JᵀJ); the rows with a damping floor
(the engine's ``LAMBDA_MIN`` raised in the probe's process) measure what
damping it away costs the fold.

A fresh process per case, warm numba cache, ``others_busy`` before each.
The folds run in ``FOLD_ROUNDS`` interleaved rounds (exact and inexact of a
case alternate; ratios are per round). Writes bench/results/inexact_step.json
and .png; ``--table`` prints the README's tables; ``--folds`` re-runs the folds
only, keeping the stored matrix rows. Run:
``.venv/bin/python bench/inexact_step.py`` (~12 min).
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
CASES = ("miura20", "miura50")
CAPTURED = (3, 4, 40, 41)  # twin steps whose matrices are kept: (stale, solved) pairs
SOLVED = ((3, 4), (40, 41))
RTOLS = (1e-3, 1e-6)
MAX_ITERATIONS = 300
SPECTRUM_ENDS = 6  # eigenvalues of stale⁻¹·A kept at each end
ILU_DROPS, ILU_FILL = (1e-4, 1e-6), 20.0
REPEATS = 5
TOLERANCE, BUDGET = 1e-8, 10_000
FOLD_CG_MAX, REFACTOR_AFTER, VERDICT_RTOL = 10, 6, 1e-10
FOLD_ROUNDS = 3  # interleaved rounds of the folds (the machine is shared)
# folds: (case, η_max or None for exact steps, damping floor or None for the library's)
FOLDS = (("miura20", None, None), ("miura20", 1e-1, None), ("miura20", 1e-3, None),
         ("miura50", None, None), ("miura50", 1e-3, None),
         ("miura20", None, 1e-10), ("miura20", 1e-3, 1e-10), ("miura20", None, 1e-8))


def median_seconds(call, repeats: int = REPEATS) -> float:
    """Median wall time of ``call()`` over ``repeats`` calls after one warm-up."""
    call()
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        call()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def conjugate_gradients(matvec, precondition, b, rtol: float, max_iterations: int):
    """(x, iterations, converged) of preconditioned CG on A x = b from x₀ = 0, stopped at
    ‖b − A x‖ ≤ rtol ‖b‖."""
    x = np.zeros_like(b)
    r = b.copy()
    limit = rtol * np.linalg.norm(b)
    z = precondition(r)
    p = z.copy()
    rz = r @ z
    for its in range(1, max_iterations + 1):
        q = matvec(p)
        alpha = rz / (p @ q)
        x += alpha * p
        r -= alpha * q
        if np.linalg.norm(r) <= limit:
            return x, its, True
        z = precondition(r)
        rz, rz_old = r @ z, rz
        p = z + (rz / rz_old) * p
    return x, max_iterations, False


def body_blocks(engine) -> tuple[np.ndarray, np.ndarray]:
    """(block of each unknown (n,), start column of each block) for the unknowns'
    bodies: 6 per moving panel, 3 per free vertex and per strip rotation, 1 per fold
    angle (the layout of the engine's step)."""
    n_panel = 6 * int((engine.panel_col >= 0).sum())
    phi_col, n = int(engine.phi_col), int(engine.n_unknowns)
    starts = np.concatenate([np.arange(0, n_panel, 6), np.arange(n_panel, phi_col, 3),
                             np.arange(phi_col, n)])
    sizes = np.diff(np.append(starts, n))
    return np.repeat(np.arange(len(starts)), sizes), starts


def block_jacobi(full, blocks):
    """Preconditioner applying the inverses of ``full``'s diagonal blocks (batched
    dense inverses per block size)."""
    import scipy.sparse as sp

    block_of, starts = blocks
    sizes = np.diff(np.append(starts, full.shape[0]))
    coo = full.tocoo()
    inside = block_of[coo.row] == block_of[coo.col]
    row, col, val = coo.row[inside], coo.col[inside], coo.data[inside]
    out_rows, out_cols, out_vals = [], [], []
    for size in np.unique(sizes):
        ids = np.flatnonzero(sizes == size)
        slot = np.full(len(starts), -1)
        slot[ids] = np.arange(len(ids))
        dense = np.zeros((len(ids), size, size))
        mine = sizes[block_of[row]] == size
        b = slot[block_of[row[mine]]]
        dense[b, row[mine] - starts[block_of[row[mine]]],
              col[mine] - starts[block_of[col[mine]]]] = val[mine]
        inverse = np.linalg.inv(dense)
        index = starts[ids][:, None] + np.arange(size)
        out_rows.append(np.repeat(index, size, axis=1).ravel())
        out_cols.append(np.tile(index, (1, size)).ravel())
        out_vals.append(inverse.ravel())
    inverse = sp.csr_matrix((np.concatenate(out_vals), (np.concatenate(out_rows),
                                                         np.concatenate(out_cols))),
                            shape=full.shape)
    return lambda r: inverse @ r


def preconditioners(full, lower_stale, blocks) -> dict:
    """{name: set-up() → apply(r)} of the candidates (module docstring)."""
    from scipy.sparse.linalg import spilu
    from sksparse.cholmod import cholesky

    stale = cholesky(lower_stale, mode="simplicial")
    methods = {"stale": lambda: stale, "block_jacobi": lambda: block_jacobi(full, blocks)}
    for drop in ILU_DROPS:
        methods[f"ilu_{drop:g}"] = lambda drop=drop: spilu(full.tocsc(), drop_tol=drop,
                                                          fill_factor=ILU_FILL).solve
    try:
        import pyamg
    except ImportError:
        return methods
    methods["amg"] = lambda: pyamg.smoothed_aggregation_solver(
        full.tocsr(), symmetry="symmetric").aspreconditioner(cycle="V")
    return methods


def extreme_eigenvalues(full, factor) -> dict:
    """Largest and smallest eigenvalue of the SPD ``full`` (Lanczos; the smallest by
    shift-invert with its exact ``factor``)."""
    from scipy.sparse.linalg import LinearOperator, eigsh

    n = full.shape[0]
    largest = eigsh(full, k=1, which="LA", return_eigenvectors=False, tol=1e-6)[0]
    inverse = LinearOperator((n, n), matvec=factor, dtype=float)
    smallest = 1.0 / eigsh(inverse, k=1, which="LA", return_eigenvectors=False, tol=1e-6)[0]
    return {"eig_max": float(largest), "eig_min": float(smallest),
            "condition": float(largest / smallest)}


def stale_spectrum(full, stale_full, stale_factor, factor) -> dict:
    """Why the previous step's factor fails as a preconditioner: the extreme
    eigenvalues of stale⁻¹·A (``SPECTRUM_ENDS`` at each end; all 1 where the matrix
    did not change, and CG's iterations grow with their spread once a few outliers
    are spent) beside the relative change of the matrix itself."""
    from scipy.sparse.linalg import LinearOperator, eigs, norm

    n = full.shape[0]
    forward = LinearOperator((n, n), matvec=lambda v: stale_factor(full @ v), dtype=float)
    backward = LinearOperator((n, n), matvec=lambda v: factor(stale_full @ v), dtype=float)
    largest = np.sort(eigs(forward, k=SPECTRUM_ENDS, which="LM", return_eigenvectors=False,
                           tol=1e-6).real)[::-1]
    smallest = np.sort(1.0 / eigs(backward, k=SPECTRUM_ENDS, which="LM",
                                  return_eigenvectors=False, tol=1e-6).real)
    change = norm(full - stale_full) / norm(stale_full)
    return {"stale_smallest": smallest.tolist(), "stale_largest": largest.tolist(),
            "relative_change": float(change)}


def solve_row(engine, stale_normal, normal, rhs, bare: float) -> dict:
    """Every method on one captured matrix (values ``normal`` on the engine's lower
    pattern; the previous step's ``stale_normal``) and right-hand side ``rhs``."""
    import scipy.sparse as sp
    from sksparse.cholmod import cholesky

    n = engine.n_unknowns
    shape = (n, n)
    lower = sp.csc_matrix((normal, engine.csc_indices, engine.csc_indptr), shape=shape)
    full = (lower + sp.tril(lower, -1).T).tocsr()
    exact_factor = cholesky(lower, mode="simplicial")
    x_star = exact_factor(rhs)
    a_norm = np.sqrt(x_star @ (full @ x_star))
    refactor = median_seconds(lambda: exact_factor.cholesky_inplace(lower))
    solve = median_seconds(lambda: exact_factor(rhs))
    out = {"exact": {"setup_s": refactor, "solve_s": refactor + solve,
                     "bare": (refactor + solve) / bare, **extreme_eigenvalues(full, exact_factor)}}
    stale_lower = sp.csc_matrix((stale_normal, engine.csc_indices, engine.csc_indptr),
                                shape=shape)
    stale_full = (stale_lower + sp.tril(stale_lower, -1).T).tocsr()
    out["exact"].update(stale_spectrum(full, stale_full,
                                       cholesky(stale_lower, mode="simplicial"), exact_factor))
    for name, setup in preconditioners(full, stale_lower, body_blocks(engine)).items():
        setup_s = 0.0 if name == "stale" else median_seconds(setup, 3)
        apply = setup()
        row = {"setup_s": setup_s}
        for rtol in RTOLS:
            x, its, converged = conjugate_gradients(full.dot, apply, rhs, rtol,
                                                    MAX_ITERATIONS)
            wall = setup_s + median_seconds(
                lambda: conjugate_gradients(full.dot, apply, rhs, rtol, MAX_ITERATIONS), 3)
            e = x - x_star
            row[f"{rtol:g}"] = {"iterations": its, "converged": converged, "solve_s": wall,
                                "bare": wall / bare,
                                "energy_error": float(np.sqrt(e @ (full @ e)) / a_norm)}
        out[name] = row
    return out


def probe(case: str) -> dict:
    """Matrices of ``case``'s rigid fold, every method on them (module docstring)."""
    sys.path.insert(0, str(HERE))
    from time_to_solution import make_case

    from foldcore.rigid_body import RigidBodySolver
    from foldcore.simulation import Simulation

    captured, calls = {}, {"n": 0}
    factor = RigidBodySolver._factor

    def capturing(engine, normal, grad):
        out = factor(engine, normal, grad)  # damps ``normal`` in place
        if engine is not mesh_engine:
            calls["n"] += 1
            if calls["n"] in CAPTURED:
                captured[calls["n"]] = (engine, normal.copy(), -grad, float(engine.lam))
        return out

    RigidBodySolver._factor = capturing
    pattern, mesh, expected, creases = make_case(case)
    sim = Simulation(mesh, pattern, solver="rigid")
    mesh_engine = sim.strategy.engine
    result = sim.run(tolerance=TOLERANCE, max_iterations=BUDGET)
    RigidBodySolver._factor = factor
    rng = np.random.default_rng(0)
    rhs = rng.standard_normal((mesh.n_vertices, 3))
    bare = median_seconds(lambda: sim.system.factor.solve(rhs), 20)
    matrices = []
    for stale_step, step in SOLVED:
        engine, normal, b, lam = captured[step]
        same_engine = captured[stale_step][0] is engine
        if not same_engine:
            raise RuntimeError(f"{case}: steps {stale_step} and {step} on different layouts")
        matrices.append({"step": step, "damping": lam,
                         "methods": solve_row(engine, captured[stale_step][1], normal, b, bare)})
    return {"case": case, "thick_vertices": int(mesh.n_vertices),
            "twin_unknowns": int(captured[SOLVED[0][1]][0].n_unknowns),
            "iterations": int(result.iterations), "bare_solve_s": bare, "matrices": matrices}


def fold_probe(case: str, eta_max: float | None, damping_floor: float | None) -> dict:
    """The rigid fold of ``case`` with exact steps (``eta_max`` None) or inexact ones
    (module docstring, **Folds**), the damping floored at ``damping_floor`` (None:
    the library's ``LAMBDA_MIN``)."""
    sys.path.insert(0, str(HERE))
    from time_to_solution import make_case

    from foldcore import rigid_body
    from foldcore.simulation import Simulation

    if damping_floor is not None:
        rigid_body.LAMBDA_MIN = damping_floor

    counts = InexactSteps(eta_max).install() if eta_max is not None else None
    pattern, mesh, expected, creases = make_case(case)
    sim = Simulation(mesh, pattern, solver="rigid")
    start = time.perf_counter()
    result = sim.run(tolerance=TOLERANCE, max_iterations=BUDGET)
    wall = time.perf_counter() - start
    row = {"case": case, "eta_max": eta_max, "damping_floor": rigid_body.LAMBDA_MIN,
           "iterations": int(result.iterations),
           "converged": bool(result.converged), "wall_s": wall,
           "error_deg": float(np.abs(result.fold_angles_deg[creases] - expected).max())}
    if counts is not None:
        row.update(counts.summary())
    return row


class InexactSteps:
    """Wraps the rigid-body engine's factorisation so its solves are CG with the last
    factorisation as preconditioner (the **Folds** of the module docstring)."""

    def __init__(self, eta_max: float):
        self.eta_max = eta_max
        self.refactors = self.failures = 0
        self.iterations: list[int] = []

    def install(self) -> "InexactSteps":
        from foldcore.rigid_body import RigidBodySolver

        factor = RigidBodySolver._factor
        inexact = self

        def lagged(engine, normal, grad):
            forcing = inexact.forcing(engine, float(np.linalg.norm(grad)))
            lag = getattr(engine, "_bench_lag", None)
            if lag is None or lag.data.shape != normal.shape or engine._normal_factor is None:
                out = factor(engine, normal, grad)  # damps in place, factorises
                lag = engine._bench_lag = _Lagged(engine, inexact, out, normal)
                inexact.refactors += 1
            else:
                saved = engine._normal_factor
                engine._normal_factor = _NoFactor()  # damping only: its factor is skipped
                factor(engine, normal, grad)
                engine._normal_factor = saved
                lag.update(normal)
            lag.rtol = forcing
            engine._normal_factor = lag
            return lag

        RigidBodySolver._factor = lagged
        for name in ("_simplified_correction", "_closer_within_rounding"):
            setattr(RigidBodySolver, name, _tightened(getattr(RigidBodySolver, name)))
        return self

    def forcing(self, engine, gradient_norm: float) -> float:
        """Eisenstat–Walker choice 2 (γ = 0.9, α = 2) on the gradient's norm."""
        previous, eta_previous = getattr(engine, "_bench_forcing", (None, self.eta_max))
        if not previous:
            eta = self.eta_max
        else:
            eta = 0.9 * (gradient_norm / previous) ** 2
            if 0.9 * eta_previous ** 2 > 0.1:
                eta = max(eta, 0.9 * eta_previous ** 2)
            eta = max(min(eta, self.eta_max), VERDICT_RTOL)
        engine._bench_forcing = (gradient_norm, eta)
        return eta

    def summary(self) -> dict:
        its = np.array(self.iterations)
        return {"refactors": self.refactors, "cg_failures": self.failures,
                "cg_solves": len(its),
                "cg_iterations_mean": float(np.abs(its).mean()) if len(its) else 0.0}


class _NoFactor:
    """Stands for the engine's factor while the wrapped ``_factor`` only damps."""

    def refactor(self, matrix) -> None:
        pass


class _Lagged:
    """The step's matrix with the factorisation of an earlier one: CG solves."""

    def __init__(self, engine, counts: InexactSteps, factor, normal):
        self.engine, self.counts, self.factor = engine, counts, factor
        self.rtol, self.tight, self.last = 1.0, False, 0
        self._set(normal)
        self.exact = True

    def _set(self, normal) -> None:
        import scipy.sparse as sp

        n = self.engine.n_unknowns
        self.data = normal.copy()
        self.lower = sp.csc_matrix((self.data, self.engine.csc_indices,
                                    self.engine.csc_indptr), shape=(n, n))
        self.upper = self.lower.T.tocsr()
        self.diagonal = self.data[self.engine.diag_slot]

    def update(self, normal) -> None:
        self._set(normal)
        self.exact = False
        if self.last > REFACTOR_AFTER:
            self.refactor()

    def refactor(self) -> None:
        self.factor.refactor(self.lower)
        self.exact, self.last = True, 0
        self.counts.refactors += 1

    def matvec(self, v):
        return self.lower @ v + self.upper @ v - self.diagonal * v

    def solve(self, b):
        if self.exact:
            return self.factor.solve(b)
        rtol = VERDICT_RTOL if self.tight else self.rtol
        x, its, converged = conjugate_gradients(self.matvec, self.factor.solve, b, rtol,
                                                FOLD_CG_MAX)
        self.last = max(self.last, its)
        self.counts.iterations.append(its if converged else -its)
        if converged:
            return x
        self.counts.failures += 1
        self.refactor()
        return self.factor.solve(b)


def _tightened(method):
    """``method`` with the engine's CG solves held at ``VERDICT_RTOL``."""
    def wrapper(engine, *args, **kwargs):
        lag = getattr(engine, "_bench_lag", None)
        if lag is None:
            return method(engine, *args, **kwargs)
        lag.tight = True
        try:
            return method(engine, *args, **kwargs)
        finally:
            lag.tight = False
    return wrapper


def run_child(args: list[str]) -> dict:
    """A probe in a fresh interpreter, with the load before it."""
    from scaling import others_busy

    busy = others_busy(1.0)
    out = subprocess.run([sys.executable, __file__, *args], capture_output=True, text=True,
                         check=True)
    row = json.loads(out.stdout.strip().splitlines()[-1])
    row["others_busy"] = busy
    return row


METHODS = ("stale", "block_jacobi", *(f"ilu_{d:g}" for d in ILU_DROPS), "amg")


def plot(data: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = data["rows"]
    fig, axes = plt.subplots(1, len(rows), figsize=(5.5 * len(rows), 4.2), squeeze=False)
    for ax, row in zip(axes[0], rows):
        for k, matrix in enumerate(row["matrices"]):
            m = matrix["methods"]
            ax.axhline(m["exact"]["bare"], color=f"C{k}", ls="--",
                       label=f"exact, step {matrix['step']}")
            for name, marker in zip(METHODS, "osDv^"):
                if name not in m:
                    continue
                xs = [m[name][f"{r:g}"]["energy_error"] for r in RTOLS]
                ys = [m[name][f"{r:g}"]["bare"] for r in RTOLS]
                ax.loglog(xs, ys, marker + "-", color=f"C{k}", mfc="none" if k else None,
                          label=f"{name}, step {matrix['step']}")
        ax.axhline(10, color="C2", ls=":", label="issue 17: a whole step ≤ 10")
        ax.set_xlabel("‖x − x*‖_A / ‖x*‖_A at relative residual 1e-3, 1e-6")
        ax.set_ylabel("one solve, bare solves of K (set-up included)")
        ax.set_title(f"{row['case']}: {row['twin_unknowns']:,} twin unknowns", fontsize=9)
        ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def table(path: Path = RESULTS / "inexact_step.json") -> str:
    """README tables: methods on the captured matrices, and the folds.

    A matrix cell is "CG iterations (✗: residual not met in MAX_ITERATIONS),
    whole solve in bare solves, energy-norm error"."""
    from _meta import markdown_table

    data = json.loads(path.read_text())
    matrices = [(row, matrix) for row in data["rows"] for matrix in row["matrices"]]
    header = ["method"] + [f"{row['case']} step {matrix['step']}" for row, matrix in matrices]
    cells = [["condition (damping λ)"] + [
        f"{m['methods']['exact']['condition']:.1e} ({m['damping']:.1e})" for _, m in matrices],
        ["change since the previous step, ‖ΔA‖/‖A‖"] + [
            f"{m['methods']['exact']['relative_change']:.1e}" for _, m in matrices],
        ["spectrum of stale⁻¹·A, extremes"] + [
            f"{m['methods']['exact']['stale_smallest'][0]:.1e} … "
            f"{m['methods']['exact']['stale_largest'][0]:.1e}" for _, m in matrices],
        [f"same, {SPECTRUM_ENDS}th from each end"] + [
            f"{m['methods']['exact']['stale_smallest'][-1]:.1e} … "
            f"{m['methods']['exact']['stale_largest'][-1]:.1e}" for _, m in matrices],
        ["exact (refactor + solve)"] + [f"{m['methods']['exact']['bare']:.1f}"
                                        for _, m in matrices]]
    for name in METHODS:
        for rtol in RTOLS:
            row_cells = [f"{name}, residual {rtol:g}"]
            for _, m in matrices:
                r = m["methods"].get(name, {}).get(f"{rtol:g}")
                row_cells.append("—" if r is None else
                                 f"{r['iterations']}{'' if r['converged'] else ' ✗'}, "
                                 f"{r['bare']:.1f}, {r['energy_error']:.0e}")
            cells.append(row_cells)
    out = markdown_table(header, cells)
    folds = markdown_table(
        ["case", "steps", "η max", "damping floor", "iterations",
         "wall (s), median (each round's ratio to exact)",
         "refactorisations", "CG solves (failed)", "max error (°)"],
        [[f["case"], "exact" if f["eta_max"] is None else "inexact",
          "—" if f["eta_max"] is None else f"{f['eta_max']:g}", f"{f['damping_floor']:.1e}",
          str(f["iterations"]) + ("" if f["converged"] else " (not converged)"),
          f"{f['wall_s']:.2f}" + ("" if f["eta_max"] is None else
                                  " (× " + ", ".join(f"{r:.2f}" for r in
                                                     f["ratios_to_exact"]) + ")"),
          str(f.get("refactors", f["iterations"])),
          "—" if f["eta_max"] is None else f"{f['cg_solves']} ({f['cg_failures']})",
          f"{f['error_deg']:.1e}"] for f in data["folds"]])
    return out + "\n\n" + folds


def fold_rounds() -> list[dict]:
    """The ``FOLDS`` rows, interleaved over ``FOLD_ROUNDS`` rounds (a row whose exact
    fold runs out of its budget once is not repeated): wall times per round, their
    median, and each round's ratio to the exact fold of the same case and floor."""
    runs: dict[tuple, list[dict]] = {key: [] for key in FOLDS}
    for round_ in range(FOLD_ROUNDS):
        for key in FOLDS:
            case, eta, floor = key
            exact = runs[(case, None, floor)]
            if round_ and exact and not exact[0]["converged"]:
                continue
            f = run_child(["--fold", case, "exact" if eta is None else str(eta),
                           "library" if floor is None else str(floor)])
            runs[key].append(f)
            print(f"  round {round_ + 1}: {case} fold η_max {eta}, damping floor "
                  f"{f['damping_floor']:.1e}: {f['iterations']} iterations, "
                  f"{f['wall_s']:.2f} s (busy {f['others_busy']:.2f})", flush=True)
    folds = []
    for (case, eta, floor), done in runs.items():
        exact = runs[(case, None, floor)]
        row = dict(done[0])
        row["walls_s"] = [f["wall_s"] for f in done]
        row["wall_s"] = statistics.median(row["walls_s"])
        row["others_busy"] = max(f["others_busy"] for f in done)
        row["ratios_to_exact"] = [f["wall_s"] / e["wall_s"] for f, e in zip(done, exact)]
        folds.append(row)
    return folds


def main(matrices: bool = True) -> None:
    """Run the probes and folds (``matrices`` False: the folds only, the stored
    matrix rows kept) and write the JSON, PNG and tables."""
    sys.path.insert(0, str(HERE))
    from _meta import machine_meta

    path = RESULTS / "inexact_step.json"
    rows = [] if matrices else json.loads(path.read_text())["rows"]
    for case in CASES if matrices else ():
        rows.append(run_child(["--probe", case]))
        print(f"  {case}: matrices done (busy {rows[-1]['others_busy']:.2f})", flush=True)
    folds = fold_rounds()
    data = {"meta": {**machine_meta(), "date": time.strftime("%Y-%m-%d"),
                     "tolerance": TOLERANCE, "captured": CAPTURED, "rtols": RTOLS,
                     "max_iterations": MAX_ITERATIONS, "ilu": [ILU_DROPS, ILU_FILL],
                     "folds": FOLDS, "fold_rounds": FOLD_ROUNDS, "fold_cg_max": FOLD_CG_MAX,
                     "refactor_after": REFACTOR_AFTER, "verdict_rtol": VERDICT_RTOL},
            "rows": rows, "folds": folds}
    RESULTS.mkdir(exist_ok=True)
    path.write_text(json.dumps(data, indent=1))
    plot(data, RESULTS / "inexact_step.png")
    print(table())


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--probe":
        print(json.dumps(probe(sys.argv[2])))
    elif len(sys.argv) > 4 and sys.argv[1] == "--fold":
        print(json.dumps(fold_probe(sys.argv[2],
                                    None if sys.argv[3] == "exact" else float(sys.argv[3]),
                                    None if sys.argv[4] == "library" else float(sys.argv[4]))))
    elif len(sys.argv) > 1 and sys.argv[1] == "--table":
        sys.path.insert(0, str(HERE))
        print(table())
    else:
        main(matrices="--folds" not in sys.argv)
