"""CHOLMOD fill-reducing orderings on the scaling scene's K: why ``linsolve`` switches to nesdis.

Scene: the Miura-ori of ``bench/scaling.py`` (same builder) at n × n for n in
SIZES, K + the anchor pin as ``Simulation`` factors it. For each CHOLMOD
``ordering_method`` in ORDERINGS (simplicial mode, as ``linsolve.Factor``):
``analyze`` seconds, ``cholesky_inplace`` (numeric) seconds, nnz(L), and the
median of SOLVES solves of a random (N, 3) column-major rhs (seconds). The
factorisations run one after another in one process; the machine is shared,
so compare within a size. ``linsolve.NESTED_DISSECTION_FROM`` is chosen from
these figures (see its module docstring).

Run: ``.venv/bin/python bench/ordering.py [--sizes 20 50 100 200]`` (~2 min);
writes bench/results/ordering.json.
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _meta import machine_meta  # noqa: E402
from scaling import setup_once  # noqa: E402

RESULTS = Path(__file__).parent / "results"
SIZES = (20, 50, 100, 200)
ORDERINGS = ("default", "metis", "nesdis")
SOLVES = 15


def measure(n: int) -> dict:
    from sksparse.cholmod import analyze

    _, mesh, _, sim = setup_once(n)
    matrix = sim.system._with_pins()
    del sim
    rhs = np.asfortranarray(np.random.default_rng(0).normal(size=(matrix.shape[0], 3)))
    row = {"n": n, "rows": int(matrix.shape[0]), "orderings": {}}
    for method in ORDERINGS:
        t0 = time.perf_counter()
        factor = analyze(matrix, mode="simplicial", ordering_method=method)
        t1 = time.perf_counter()
        factor.cholesky_inplace(matrix)
        t2 = time.perf_counter()
        solves = []
        for _ in range(SOLVES):
            s0 = time.perf_counter()
            factor(rhs)
            solves.append(time.perf_counter() - s0)
        row["orderings"][method] = {"analyze_s": t1 - t0, "numeric_s": t2 - t1,
                                    "nnz_L": int(factor.L().nnz),
                                    "solve_s": statistics.median(solves)}
        del factor
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    args = parser.parse_args()
    import scipy.sparse.linalg  # noqa: F401  (scipy's BLAS loaded before the guard scans)

    import foldcore.simulation  # noqa: F401
    from foldcore.threads import blas_on_one_thread

    rows = []
    with blas_on_one_thread(refresh=True):
        for n in args.sizes:
            row = measure(n)
            for method, r in row["orderings"].items():
                print(f"n={n:4d} {method:8s} nnz(L) {r['nnz_L']:11d} analyze "
                      f"{r['analyze_s']:8.3f} s numeric {r['numeric_s']:8.3f} s solve "
                      f"{1e3 * r['solve_s']:9.2f} ms", flush=True)
            rows.append(row)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "ordering.json").write_text(json.dumps(
        {"meta": machine_meta(), "solves": SOLVES, "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
