"""Contact: what it does to a fold that needs it, and what it costs where nothing touches.

* ``letter``: three panels 6 | 10 | 6 mm in a row (10 mm deep), H = 1 mm, both
  creases valleys driven to 180°, ``rigid``, tolerance 1e-8: fold angles,
  steps, seconds and the worst overlap of two panels' convex hulls (manifold3d,
  as a share of the smaller panel's volume), contact off and on.
* ``overhead``: a thick Miura n × n (H = 1 mm, ``miura_one_crease`` at tilt
  45°, ``rigid`` with the coarse start off: the same steps both ways) where
  no two panels ever come near: seconds of the run with contact off and on,
  interleaved, median of RUNS after a warm-up, and whether the positions are
  bit-identical.

The 1-minute load average is recorded before and after. Run:
``python bench/contact.py`` (~1 min); writes bench/results/contact.json and
.png; ``--table`` prints the tables of docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import json
import os
import platform
import sys
import time
from itertools import combinations
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
OUT = ROOT / "bench" / "results" / "contact.json"
SIZES = (10, 20, 30)
RUNS = 3
H = 1.0


def letter_pattern():
    from foldcore.pattern import CreasePattern

    xs = [0.0, 6.0, 16.0, 22.0]
    v = [(x, 0.0) for x in xs] + [(x, 10.0) for x in xs]
    e = [(1, 5), (2, 6), (0, 1), (1, 2), (2, 3), (4, 5), (5, 6), (6, 7), (0, 4), (3, 7)]
    return CreasePattern(np.array(v), np.array(e), np.array(["V", "V"] + ["B"] * 8),
                         source="letter")


def worst_overlap(mesh, positions) -> float:
    import manifold3d

    g = mesh.groups[mesh.panel_group]
    hulls = [manifold3d.Manifold.hull_points(np.ascontiguousarray(
        positions[g.indices[g.slots(p)]])) for p in range(len(g))]
    return max([(a ^ b).volume() / min(a.volume(), b.volume())
                for a, b in combinations(hulls, 2)] + [0.0])


def letter() -> dict:
    from foldcore.simulation import Simulation
    from foldcore.thickening import thicken

    pattern = letter_pattern()
    mesh = thicken(pattern, H)
    out = {}
    for contact in (False, True):
        sim = Simulation(mesh, pattern, solver="rigid", contact=contact)
        sim.set_fold_angles({0: 180.0, 1: 180.0})
        t0 = time.perf_counter()
        result = sim.run(tolerance=1e-8, max_iterations=2_000)
        out["on" if contact else "off"] = {
            "fold_angles_deg": [round(float(a), 4) for a in result.fold_angles_deg[:2]],
            "iterations": int(result.iterations), "reason": result.reason,
            "seconds": time.perf_counter() - t0,
            "worst_overlap_share": worst_overlap(mesh, result.positions)}
    return out


def overhead() -> list:
    from foldcore import patterns
    from foldcore.simulation import Simulation
    from foldcore.strategies.rigid import RigidOptions
    from foldcore.thickening import thicken

    rows = []
    for n in SIZES:
        pattern = patterns.miura_one_crease(n, n, tilt=45.0)
        mesh = thicken(pattern, H)
        times, last = {False: [], True: []}, {}
        for run in range(RUNS + 1):  # the first round warms up
            for contact in (False, True):
                sim = Simulation(mesh, pattern, solver="rigid", contact=contact,
                                 options=RigidOptions(coarse_start=False))
                t0 = time.perf_counter()
                last[contact] = sim.run(tolerance=1e-8, max_iterations=2_000)
                if run:
                    times[contact].append(time.perf_counter() - t0)
        off, on = (float(np.median(times[c])) for c in (False, True))
        rows.append({"n": n, "iterations": int(last[False].iterations),
                     "off_s": off, "on_s": on, "ratio": on / off,
                     "identical": bool(np.array_equal(last[False].positions,
                                                      last[True].positions))})
        print(rows[-1], flush=True)
    return rows


def table(data: dict) -> str:
    lines = ["| letter fold | crease 1 | crease 2 | steps | s | worst overlap |",
             "|---|---|---|---|---|---|"]
    for key, row in data["letter"].items():
        a, b = row["fold_angles_deg"]
        lines.append(f"| contact {key} | {a:.4g}° | {b:.4g}° | {row['iterations']} | "
                     f"{row['seconds']:.2f} | {row['worst_overlap_share']:.2g} |")
    lines += ["", "| Miura n × n | steps | off (s) | on (s) | on / off | identical |",
              "|---|---|---|---|---|---|"]
    for row in data["overhead"]:
        lines.append(f"| {row['n']} | {row['iterations']} | {row['off_s']:.3g} | "
                     f"{row['on_s']:.3g} | {row['ratio']:.2f} | {row['identical']} |")
    return "\n".join(lines)


def plot(data: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = data["overhead"]
    fig, ax = plt.subplots(figsize=(5, 3.5))
    n = [r["n"] for r in rows]
    ax.plot(n, [r["off_s"] for r in rows], "o-", label="contact off")
    ax.plot(n, [r["on_s"] for r in rows], "s-", label="contact on (nothing near)")
    ax.set_xlabel("Miura n × n")
    ax.set_ylabel("run time, s (median)")
    ax.set_yscale("log")
    ax.legend()
    fig.tight_layout()
    fig.savefig(OUT.with_suffix(".png"), dpi=120)


def main() -> None:
    if "--table" in sys.argv:
        print(table(json.loads(OUT.read_text())))
        return
    load_before = os.getloadavg()[0]
    data = {"letter": letter(), "overhead": overhead(),
            "machine": {"python": platform.python_version(), "cpus": os.cpu_count(),
                        "load_before": load_before, "load_after": os.getloadavg()[0]}}
    OUT.write_text(json.dumps(data, indent=1) + "\n")
    plot(data)
    print(table(data))


if __name__ == "__main__":
    main()
