"""Time folds of two source trees in interleaved child processes (a refactor's cost).

Each round runs one child per tree, in alternating order; a child folds each
case with each strategy once to warm up, then ``--runs`` times, timing
``Simulation.run`` alone (the benchmarks' cases: bench/accuracy.py,
bench/convergence.py). Prints per case the median time of each tree, the
ratio after / before round by round (median, range), iterations and the miss
from the closed form, and the load average of each round.

    git worktree add /tmp/before <commit>
    python tools/interleave.py --before /tmp/before/src --after src \\
        --cases vertex,waterbomb,miura10,miura20 --strategies hybrid,rigid --rounds 4
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "bench"


def child(src: str, cases: list, strategies: list, runs: int) -> None:
    """Fold every case in this process with the tree at ``src``; prints JSON rows."""
    sys.path[:0] = [src, str(BENCH)]
    import numpy as np

    import accuracy
    import convergence
    from foldcore import Simulation, thicken

    rows = []
    for case in cases:
        if case == "waterbomb":
            pattern, mesh, expected, creases = convergence.waterbomb_scene()
        else:
            pattern, h, expected, creases = (accuracy.vertex(3.0, 1e-3) if case == "vertex"
                                             else accuracy.miura(int(case[len("miura"):])))
            mesh = thicken(pattern, h)
        for strategy in strategies:
            times = []
            for run in range(runs + 1):  # the first warms up
                sim = Simulation(mesh, pattern, solver=strategy)
                start = time.perf_counter()
                result = sim.run(tolerance=1e-8, max_iterations=10_000)
                if run:
                    times.append(time.perf_counter() - start)
            miss = float(np.abs(result.fold_angles_deg[creases] - expected).max())
            rows.append({"case": case, "strategy": strategy, "seconds": statistics.median(times),
                         "iterations": int(result.iterations), "miss_deg": miss})
    print(json.dumps(rows))


def compare(args) -> dict:
    trees = {"before": str(Path(args.before).resolve()), "after": str(Path(args.after).resolve())}
    rows = {name: [] for name in trees}
    loads = [os.getloadavg()[0]]
    for rnd in range(args.rounds):
        for name in ("before", "after") if rnd % 2 == 0 else ("after", "before"):
            proc = subprocess.run([sys.executable, __file__, "--child", trees[name],
                                   "--cases", args.cases, "--strategies", args.strategies,
                                   "--runs", str(args.runs)], capture_output=True, text=True,
                                  env={**os.environ, "PYTHONPATH": trees[name]}, check=True)
            rows[name].append(json.loads(proc.stdout.splitlines()[-1]))
            loads.append(os.getloadavg()[0])
    return {"rows": rows, "loads": loads}


def report(data: dict) -> None:
    before, after = data["rows"]["before"], data["rows"]["after"]
    print("load average per child:", " ".join(f"{x:.2f}" for x in data["loads"]))
    for i, row in enumerate(before[0]):
        b = [r[i]["seconds"] for r in before]
        a = [r[i]["seconds"] for r in after]
        ratios = [x / y for x, y in zip(a, b)]
        print(f"{row['case']:10s} {row['strategy']:7s} before {statistics.median(b):.4g} s "
              f"after {statistics.median(a):.4g} s  after/before {statistics.median(ratios):.3f} "
              f"[{min(ratios):.3f}, {max(ratios):.3f}]  iterations {row['iterations']} / "
              f"{after[0][i]['iterations']}  miss {row['miss_deg']:.1e} / "
              f"{after[0][i]['miss_deg']:.1e} deg")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before")
    parser.add_argument("--after")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--cases", default="vertex,waterbomb,miura10,miura20")
    parser.add_argument("--strategies", default="hybrid,rigid")
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    if args.child:
        child(args.child, args.cases.split(","), args.strategies.split(","), args.runs)
        return 0
    if not (args.before and args.after):
        parser.error("give --before SRC and --after SRC")
    report(compare(args))
    return 0


if __name__ == "__main__":
    sys.exit(main())
