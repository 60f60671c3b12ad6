"""Steady under load: a step's time with the cores shared.

Per case, the time of single strategy steps (``Simulation.step``; warm numba
cache, STEPS timed after WARMUP), measured quiet and with COMPETITORS
CPU-bound processes (``while True: pass``) sharing the machine's cores; the
rounds alternate quiet / loaded ROUNDS times, so a change of the machine's
own load hits both. Reported per case and condition: median, 95th and 99th
percentile and largest step time, and their ratios to the quiet median. With
every core taken by a competitor, a step that computes should cost about (competitors + 1) / cores
of its quiet time; one that waits on spinning or yielding threads (numba's
parallel loops, OpenBLAS's threads) can cost far more (measured before the
wait policy below was set: 40–80 ms instead of 0.2 ms for a paper step of a
Miura 4 × 4). Target: no case ≥ 10× its quiet median.

Cases: ``paper`` Miura 4 × 4 (serial by size), ``lbfgs`` Miura 10 × 10 with
``threads=1`` and with the default (2) threads, ``paper`` Miura 20 × 20
(2 threads). Beside each, a control: a serial pure-Python loop (no numba,
no BLAS, no threads) calibrated to that case's quiet median step time and
timed in the same rounds. Its loaded / quiet ratios are what the operating
system's scheduler alone does to a task of that length when more processes
are runnable than there are cores — the floor any step of that length
reaches, whatever its thread layer.

The whole measurement runs in child processes, alternating REPEATS times
between OpenMP wait policies (POLICIES): ``PASSIVE``, which ``import
foldcore`` sets unless the user set the variable, and GNU OpenMP's default
(threads spin before they sleep), so the gain of the setting is measured in
one run. Each policy's times are merged over its children. Each child warms
every simulation up (WARMUP iterations) before it times anything.

Run: ``python bench/load.py`` (~1.5 min) or ``--quick``; writes
bench/results/load.json and .png; ``--table`` prints the table of
docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from functools import partial
from pathlib import Path

import numpy as np

import _meta

WARMUP, STEPS, ROUNDS, REPEATS = 20, 150, 3, 2
QUICK_STEPS, QUICK_ROUNDS, QUICK_REPEATS = 20, 1, 1
# OpenMP wait policies compared, each in its own child processes (libgomp
# reads the variable once, when it loads): foldcore's default, and GNU
# OpenMP's own (threads spin ~300 000 polls before they sleep)
POLICIES = {"passive (foldcore's default)": "PASSIVE", "GNU OpenMP's default": "default"}
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


def run_times(work, runs: int) -> list:
    """Wall times (s) of ``runs`` calls of ``work()``, one by one."""
    out = []
    for _ in range(runs):
        start = time.perf_counter()
        work()
        out.append(time.perf_counter() - start)
    return out


def serial_work(count: int) -> int:
    """A pure-Python loop: one thread, no numba, no BLAS; ``count`` sets its length."""
    total = 0
    for i in range(count):
        total += i * i
    return total


def calibrated_count(target_s: float) -> int:
    """Loop count of ``serial_work`` whose median time (quiet) is ``target_s`` seconds."""
    count = 1000
    for _ in range(3):
        times = run_times(partial(serial_work, count), 31)
        count = max(1, int(round(count * target_s / float(np.median(times)))))
    return count


def competitors() -> list:
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"])
            for _ in range(COMPETITORS)]


def measure(steps: int, rounds: int) -> dict:
    """Raw step and control times (s) per case and condition, ``rounds`` alternating
    quiet / loaded rounds of ``steps`` steps in this process; and the load averages
    between them."""
    sims = {name: simulation(*case) for name, case in CASES.items()}
    counts = {name: calibrated_count(float(np.median(run_times(sim.step, steps))))
              for name, sim in sims.items()}
    controls = {f"control for {name}": count for name, count in counts.items()}
    times = {name: {"quiet": [], "loaded": []} for name in (*CASES, *controls)}
    load = [os.getloadavg()]
    for _ in range(rounds):
        for condition in ("quiet", "loaded"):
            busy = competitors() if condition == "loaded" else []
            try:
                time.sleep(0.5 if busy else 0.0)  # let the competitors take the cores
                for name, sim in sims.items():
                    times[name][condition] += run_times(sim.step, steps)
                    control = f"control for {name}"
                    work = partial(serial_work, controls[control])
                    times[control][condition] += run_times(work, steps)
            finally:
                for p in busy:
                    p.kill()
                    p.wait()
            load.append(os.getloadavg())
    return {"times": times, "load": load, "loop_counts": controls}


def child(policy: str, out: Path, steps: int, rounds: int) -> None:
    """One measurement with OpenMP's wait policy ``policy`` ("default": GNU
    OpenMP's own, i.e. unset after ``import foldcore`` set it and before
    anything loaded libgomp)."""
    import foldcore  # noqa: F401  (sets OMP_WAIT_POLICY unless the user did)

    if policy == "default":
        os.environ.pop("OMP_WAIT_POLICY", None)
    else:
        os.environ["OMP_WAIT_POLICY"] = policy
    out.write_text(json.dumps(measure(steps, rounds)))


def summary(t: dict) -> dict:
    """Medians, percentiles (ms) and loaded / quiet ratios of one case's times."""
    q, b = np.array(t["quiet"]), np.array(t["loaded"])
    return {"quiet_median_ms": 1e3 * float(np.median(q)),
            "quiet_p95_ms": 1e3 * float(np.percentile(q, 95)),
            "loaded_median_ms": 1e3 * float(np.median(b)),
            "loaded_p95_ms": 1e3 * float(np.percentile(b, 95)),
            "quiet_max_ms": 1e3 * float(q.max()),
            "loaded_max_ms": 1e3 * float(b.max()),
            "loaded_p99_ms": 1e3 * float(np.percentile(b, 99)),
            "median_ratio": float(np.median(b) / np.median(q)),
            "p95_ratio": float(np.percentile(b, 95) / np.median(q)),
            "p99_ratio": float(np.percentile(b, 99) / np.median(q)),
            "max_ratio": float(b.max() / np.median(q)),
            "steps": {"quiet": int(q.size), "loaded": int(b.size)}}


def children(steps: int, rounds: int, repeats: int) -> tuple[dict, dict]:
    """Alternate child processes over POLICIES ``repeats`` times; each policy's times
    merged, and its load averages and loop counts."""
    merged = {policy: {} for policy in POLICIES}
    meta = {policy: {"load": [], "loop_counts": []} for policy in POLICIES}
    with tempfile.TemporaryDirectory() as tmp:
        scratch = Path(tmp) / "load-child.json"
        for _ in range(repeats):
            for policy, value in POLICIES.items():
                subprocess.run([sys.executable, __file__, "--child", value, str(scratch),
                                str(steps), str(rounds)], check=True)
                run = json.loads(scratch.read_text())
                for name, t in run["times"].items():
                    slot = merged[policy].setdefault(name, {"quiet": [], "loaded": []})
                    slot["quiet"] += t["quiet"]
                    slot["loaded"] += t["loaded"]
                meta[policy]["load"] += run["load"]
                meta[policy]["loop_counts"].append(run["loop_counts"])
    return merged, meta


def main() -> None:
    args = _meta.parser(__doc__).parse_args()
    if _meta.stored("load", args, table, lambda data, path: plot(data["policies"], path)):
        return
    steps, rounds, repeats = ((QUICK_STEPS, QUICK_ROUNDS, QUICK_REPEATS) if args.quick
                              else (STEPS, ROUNDS, REPEATS))
    record = _meta.Record("load", args, steps_per_round=steps, rounds_per_child=rounds,
                          children_per_policy=repeats, competitors=COMPETITORS,
                          warmup_iterations=WARMUP)
    merged, meta = children(steps, rounds, repeats)
    out = {"policies": {}}
    for policy, times in merged.items():
        threads = {f"control for {n}": 1 for n in CASES}
        threads.update({n: case[2] or "default" for n, case in CASES.items()})
        rows = {name: {"threads": threads[name], **summary(t)} for name, t in times.items()}
        out["policies"][policy] = {"OMP_WAIT_POLICY": POLICIES[policy], "cases": rows,
                                   "load": meta[policy]["load"],
                                   "loop_counts": meta[policy]["loop_counts"]}
    record.write(out, lambda data, path: plot(data["policies"], path))
    print(table(out))


def table(data: dict) -> str:
    """Per wait policy and case: quiet median (ms), loaded / quiet at the median, 95th
    and 99th percentile, and the serial control's 99th."""
    rows = []
    for policy, entry in data["policies"].items():
        cases = entry["cases"]
        for name, r in cases.items():
            if name.startswith("control for "):
                continue
            control = cases[f"control for {name}"]
            rows.append([policy, name, f"{r['quiet_median_ms']:.3g}",
                         f"{r['median_ratio']:.2f}", f"{r['p95_ratio']:.1f}",
                         f"{r['p99_ratio']:.1f}", f"{control['p99_ratio']:.1f}"])
    return _meta.markdown_table(["OpenMP wait policy", "case", "quiet median (ms)",
                                 "loaded / quiet: median", "95th pct", "99th pct",
                                 "serial control, 99th"], rows)


def plot(policies: dict, path: Path) -> None:
    """Per wait policy (one panel each) and case, loaded / quiet ratios of the step
    (solid) and of its serial control (hatched)."""
    plt = _meta.pyplot()

    stats = (("median_ratio", "median"), ("p95_ratio", "95th pct"),
             ("p99_ratio", "99th pct"), ("max_ratio", "max"))
    width = 0.1
    fig, axes = plt.subplots(1, len(policies), figsize=(14, 4.8), sharey=True)
    for ax, (policy, entry) in zip(np.atleast_1d(axes), policies.items()):
        rows = entry["cases"]
        cases = [n for n in rows if not n.startswith("control for ")]
        x = np.arange(len(cases))
        for i, (key, label) in enumerate(stats):
            colour = f"C{i}"
            offset = (2 * i - 3.5) * width
            ax.bar(x + offset, [rows[n][key] for n in cases], width, color=colour,
                   label=f"{label}, step")
            ax.bar(x + offset + width, [rows[f"control for {n}"][key] for n in cases], width,
                   color="white", edgecolor=colour, hatch="///",
                   label=f"{label}, serial Python control")
        ax.axhline(10, color="red", lw=1, ls="--", label="target: < 10×")
        ax.set_xticks(x, [n.replace(", ", "\n") for n in cases], fontsize=8)
        ax.set_yscale("log")
        ax.set_title(f"OpenMP wait policy: {policy}", fontsize=10)
    np.atleast_1d(axes)[0].set_ylabel("loaded / quiet median time")
    np.atleast_1d(axes)[0].legend(fontsize=7, ncol=2)
    fig.suptitle(f"step time with {COMPETITORS} CPU-bound competitors, beside a serial"
                 " loop of the same quiet length")
    _meta.save(fig, path, dpi=100)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        child(sys.argv[2], Path(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]))
    else:
        main()
