"""Check the verdict on random folds: every ``converged`` run is where a re-run stays.

For each of COUNT seeded random problems (``tests/random_folds.py``: degree-4
vertices with one or all creases driven, binding vertices of degree 5–6,
hinges, rows of panels, small Miura sheets; thickness / size 1e-4 … 3e-2) and
each strategy, fold at tolerance 1e-8 within BUDGET iterations; from every
converged result, run ``newton`` (300 iterations) and measure how far it moves
the vertices (after the best rigid alignment), in units of the run's limit
(tolerance × size). A converged run is *false* when that move exceeds 2 limits
and its fold angles change by more than 2 · limit / H (radians → degrees).

With ``--units`` every problem is also folded given in µm (pattern and
thickness × 1000) and the verdicts compared: a pair disagrees when one unit
converges and the other does not.

Run: ``python tools/verdict_check.py [--units] [COUNT] [SEED] [BUDGET]``
(defaults 300, 7, 2000; about 5 min on 2 cores, twice that with ``--units``);
writes tools/results/verdict_check.json (one record per run, with the
certificate's checks and time, and the counts per strategy with the
certificate's median cost) and prints them.
"""
from __future__ import annotations

import json
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

SOLVERS = ("paper", "anderson", "lbfgs", "rigid", "hybrid", "newton")
TOLERANCE = 1e-8


def aligned_move(a: np.ndarray, b: np.ndarray) -> float:
    """max |b − (R a + t)| (mm) after the best rigid alignment of a onto b (Kabsch)."""
    ca, cb = a.mean(0), b.mean(0)
    u, _, vt = np.linalg.svd((a - ca).T @ (b - cb))
    d = np.sign(np.linalg.det(u @ vt))
    r = u @ np.diag([1, 1, d]) @ vt
    return float(np.abs((a - ca) @ r + cb - b).max())


def check(problem, mesh, solver: str, budget: int, units: bool = False) -> dict:
    """One run and, if converged, newton's re-run from its result; with ``units``
    the verdict of the same problem given in µm too."""
    from foldcore import thicken
    from foldcore.simulation import Simulation

    sim = Simulation(mesh, problem.pattern, solver=solver)
    start = time.perf_counter()
    result = sim.run(tolerance=TOLERANCE, max_iterations=budget)
    certificate = sim.convergence.certificate
    record = {"problem": problem.name, "solver": solver, "reason": result.reason,
              "iterations": result.iterations, "seconds": time.perf_counter() - start,
              "certificate_checks": certificate.checks,
              "certificate_seconds": certificate.seconds,
              "line_seconds": certificate.line_seconds}
    if units:
        scaled = problem.scaled(1e3)
        um = Simulation(thicken(scaled.pattern, scaled.thickness), scaled.pattern,
                        solver=solver).run(tolerance=TOLERANCE, max_iterations=budget)
        record["um_reason"] = um.reason
    if result.converged:
        limit = TOLERANCE * sim.length_scale
        again = Simulation(mesh, problem.pattern, solver="newton", branch_floor_deg=0.0)
        again.set_positions(result.positions)
        rerun = again.run(tolerance=TOLERANCE, max_iterations=300)
        moved = aligned_move(result.positions, rerun.positions) / limit
        turned = float(np.nanmax(np.abs(rerun.fold_angles_deg - result.fold_angles_deg)))
        bound = float(np.degrees(2 * limit / problem.thickness))
        record.update(moved_limits=moved, turned_deg=turned, bound_deg=bound,
                      false=bool(moved > 2.0 and turned > bound))
    return record


def certificate_cost(records: list[dict]) -> dict:
    """Over the runs the certificate judged: its median time per run, s, and its
    share of the run's time, and the median time of its step 4 (E along the map's
    step and the last step), s."""
    checked = [r for r in records if r["certificate_checks"]]
    if not checked:
        return {"certified_runs": 0}
    return {"certified_runs": len(checked),
            "certificate_s_median": float(np.median([r["certificate_seconds"] for r in checked])),
            "certificate_share_median": float(np.median(
                [r["certificate_seconds"] / r["seconds"] for r in checked])),
            "line_s_median": float(np.median([r["line_seconds"] for r in checked]))}


def main() -> None:
    from foldcore import thicken
    from random_folds import problem_set

    arguments = sys.argv[1:]
    units = "--units" in arguments
    given = [int(a) for a in arguments if a != "--units"][:3]
    count, seed, budget = given + [300, 7, 2000][len(given):]
    records = []
    for problem in problem_set(count, seed):
        mesh = thicken(problem.pattern, problem.thickness)
        for solver in SOLVERS:
            records.append(check(problem, mesh, solver, budget, units))
    converged = Counter(r["solver"] for r in records if r["reason"] == "converged")
    false = Counter(r["solver"] for r in records if r.get("false"))
    differ = Counter(r["solver"] for r in records
                     if units and (r["reason"] == "converged") != (r["um_reason"] == "converged"))
    summary = {s: {"runs": count, "converged": converged[s], "false": false[s],
                   **({"unit_disagreements": differ[s]} if units else {}),
                   **certificate_cost([r for r in records if r["solver"] == s])}
               for s in SOLVERS}
    out = ROOT / "tools" / "results" / "verdict_check.json"
    out.write_text(json.dumps({"count": count, "seed": seed, "budget": budget,
                               "tolerance": TOLERANCE, "units": units, "summary": summary,
                               "runs": records}, indent=1))
    for s in SOLVERS:
        cost = summary[s]
        print(f"{s:9s} converged {converged[s]:4d}  false {false[s]:3d}"
              + (f"  unit disagreements {differ[s]:3d}" if units else "")
              + (f"  certificate median {1e3 * cost['certificate_s_median']:.1f} ms"
                 f" ({100 * cost['certificate_share_median']:.0f} % of the run),"
                 f" its lines {1e3 * cost['line_s_median']:.1f} ms"
                 if cost["certified_runs"] else ""))


if __name__ == "__main__":
    main()
