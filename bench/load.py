"""Steady under load (issue 17, item 4): a step's time with the cores shared.

Per case, the time of single strategy steps (``Simulation.step``; warm numba
cache, STEPS timed after WARMUP), measured quiet and with COMPETITORS
CPU-bound processes (``while True: pass``) sharing the machine's cores; the
rounds alternate quiet / loaded ROUNDS times, so a change of the machine's
own load hits both. Reported per case and condition: median and 95th
percentile step time, and loaded / quiet ratios. With every core taken by a
competitor, a step that computes should cost about (competitors + 1) / cores
of its quiet time; one that waits on spinning or yielding threads (numba's
parallel loops, OpenBLAS's threads) can cost far more — the issue measured
40–80 ms instead of 0.2 ms for a paper step of a Miura 4 × 4, and 26–182 ms
instead of ≈ 1 ms for an L-BFGS step of a Miura 10 × 10 with ``threads=1``.
Target: no case ≥ 10× its quiet median.

Cases: ``paper`` Miura 4 × 4 (serial by size), ``lbfgs`` Miura 10 × 10 with
``threads=1`` and with the default (2) threads, ``paper`` Miura 20 × 20
(2 threads). Run: ``.venv/bin/python bench/load.py`` (~3 min). Writes
bench/results/load.json and .png.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _meta import machine_meta  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
WARMUP, STEPS, ROUNDS = 20, 150, 3
COMPETITORS = os.cpu_count() or 2
CASES = {"paper, Miura 4x4": ("paper", 4, None), "lbfgs, Miura 10x10, threads=1":
         ("lbfgs", 10, 1), "lbfgs, Miura 10x10, default threads": ("lbfgs", 10, None),
         "paper, Miura 20x20, default threads": ("paper", 20, None)}


def simulation(solver: str, n: int, threads):
    from foldcore import Simulation, patterns, thicken

    pattern = patterns.miura_one_crease(n, n, a=20.0, b=20.0, width=0.6)
    mesh = thicken(pattern, 0.2)
    sim = Simulation(mesh, pattern, solver=solver, threads=threads)
    sim.run(tolerance=1e-12, max_iterations=WARMUP)  # compile, settle the first steps
    return sim


def step_times(sim) -> list:
    out = []
    for _ in range(STEPS):
        start = time.perf_counter()
        sim.step()
        out.append(time.perf_counter() - start)
    return out


def competitors() -> list:
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"])
            for _ in range(COMPETITORS)]


def main() -> None:
    sims = {name: simulation(*case) for name, case in CASES.items()}
    times = {name: {"quiet": [], "loaded": []} for name in CASES}
    load = [os.getloadavg()]
    for _ in range(ROUNDS):
        for condition in ("quiet", "loaded"):
            busy = competitors() if condition == "loaded" else []
            try:
                time.sleep(0.5 if busy else 0.0)  # let the competitors take the cores
                for name, sim in sims.items():
                    times[name][condition] += step_times(sim)
            finally:
                for p in busy:
                    p.kill()
                    p.wait()
            load.append(os.getloadavg())
    rows = {}
    for name, t in times.items():
        q, b = np.array(t["quiet"]), np.array(t["loaded"])
        rows[name] = {"threads": sims[name].threads,
                      "quiet_median_ms": 1e3 * float(np.median(q)),
                      "quiet_p95_ms": 1e3 * float(np.percentile(q, 95)),
                      "loaded_median_ms": 1e3 * float(np.median(b)),
                      "loaded_p95_ms": 1e3 * float(np.percentile(b, 95)),
                      "quiet_max_ms": 1e3 * float(q.max()),
                      "loaded_max_ms": 1e3 * float(b.max()),
                      "loaded_p99_ms": 1e3 * float(np.percentile(b, 99)),
                      "median_ratio": float(np.median(b) / np.median(q)),
                      "p95_ratio": float(np.percentile(b, 95) / np.median(q)),
                      "p99_ratio": float(np.percentile(b, 99) / np.median(q)),
                      "max_ratio": float(b.max() / np.median(q))}
        print(f"{name:40s} threads {rows[name]['threads']}  quiet {rows[name]['quiet_median_ms']:.3f}"
              f" ms (p95 {rows[name]['quiet_p95_ms']:.3f})  loaded {rows[name]['loaded_median_ms']:.3f}"
              f" ms (p95 {rows[name]['loaded_p95_ms']:.3f})  ratio {rows[name]['median_ratio']:.2f}"
              f" / p95 {rows[name]['p95_ratio']:.2f} / p99 {rows[name]['p99_ratio']:.1f}"
              f" / max {rows[name]['max_ratio']:.0f}", flush=True)
    out = {"cases": rows, "steps_per_round": STEPS, "rounds": ROUNDS,
           "competitors": COMPETITORS, "load": load, "machine": machine_meta()}
    results = ROOT / "bench" / "results"
    (results / "load.json").write_text(json.dumps(out, indent=1))
    plot(rows, results / "load.png")


def plot(rows: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(rows)
    x = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(8, 4))
    for i, (key, label) in enumerate((("median_ratio", "median"), ("p95_ratio", "95th pct"))):
        ax.bar(x + (i - 0.5) * 0.35, [rows[n][key] for n in names], 0.35, label=label)
    ax.axhline(10, color="red", lw=1, ls="--", label="target: < 10×")
    ax.set_xticks(x, [n.replace(", ", "\n") for n in names], fontsize=8)
    ax.set_ylabel("loaded / quiet median step time")
    ax.set_yscale("log")
    ax.legend()
    ax.set_title(f"step time with {COMPETITORS} CPU-bound competitors")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


if __name__ == "__main__":
    main()
