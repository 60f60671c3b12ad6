"""Origami Simulator's Miura folded flat: how far thickness lets it go (issue 17).

The layout of Origami Simulator's ``Tessellations/miura-ori.svg`` (12 × 13
facets, 182 vertices; its zig-zag lines run at about 84° to the straight
ones): Miura 12 × 13, a = b = 80 mm, γ = GAMMA, every crease driven to its
zero-thickness rigid-fold angle (:func:`foldcore.patterns.miura_fold_angles`)
at facet tilt θ, default strategy, tolerance 1e-9. Folded at tilt 45° (every
crease below 90°) and at tilt 90° (flat: zig-zag creases at 180°, straight
ones at 180° too).

Why the flat fold misses, and why the straight creases miss most: the flat
state is a singular point of the Miura's kinematics. At tilt θ = 90° − d the
zig-zag creases are 2d short of flat and the straight ones, from
tan(ρ/2) = cos γ·tan θ, 2d / cos γ short: at γ = 84° every degree the
zig-zag creases miss shows as 1 / cos γ = 9.6° on the straight ones (the
``ratio`` column: 9.3–13). Origami Simulator's own sheet has zero thickness;
here the thick hinges stop the zig-zag creases 0.7–4° short of flat: an axis
hinge of width W turns its panels about the crease's mid-line only up to
θ* = 2·atan(W/H) (:func:`foldcore.hinges.pivot_angle_deg`), then about their
inner edges, which moves the hinge axes off the creases. The zig-zag miss
does not fall with H/a at Eq. 7's automatic width (W/H = π/2 at every H:
θ* = 115°), nor steadily with W/H. Straight creases within 0.5° of flat would
need the zig-zag ones within 0.05°, a tilt within 0.026° of 90°.

Per row: θ* (degrees), iterations, verdict, wall time (median of RUNS warm
runs after one warm-up, interleaved across rows), the largest miss on the
straight and on the zig-zag creases (degrees) and their ratio. Run:
``.venv/bin/python bench/os_miura.py`` (a few minutes); writes
bench/results/os_miura.json and .png (the flat fold's misses against the
zig-zag miss / cos γ line, and each case's time) and prints the README table;
``--plot`` redraws the PNG from the JSON.
"""
from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _meta import machine_meta, markdown_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
N, M, A, GAMMA = 12, 13, 80.0, 84.0  # facets, mm, degrees
RUNS = 3
BUDGET = 5_000
#: (label, H / a, W / H or None for Eq. 7's automatic width, tilt in degrees)
CASES = [("auto W, H = 0.01a", 0.01, None, 45.0),
         ("auto W, H = 0.01a", 0.01, None, 90.0),
         ("auto W, H = 0.001a", 0.001, None, 90.0),
         ("W = 5H, H = 0.01a", 0.01, 5.0, 90.0),
         ("W = 10H, H = 0.01a", 0.01, 10.0, 90.0),
         ("W = 30H, H = 0.001a", 0.001, 30.0, 90.0),
         ("W = 100H, H = 0.001a", 0.001, 100.0, 90.0)]


def build(h_over_a: float, w_over_h, tilt: float):
    """(pattern, mesh) of one case: every crease driven to its rigid-fold angle."""
    from foldcore import patterns
    from foldcore.thickening import thicken

    thickness = h_over_a * A
    width = np.nan if w_over_h is None else w_over_h * thickness
    pattern = patterns.miura(N, M, a=A, b=A, gamma=GAMMA, width=width).replace(
        fold_angles=patterns.miura_fold_angles(N, M, GAMMA, tilt))
    return pattern, thicken(pattern, thickness)


def fold_once(pattern, mesh) -> dict:
    from foldcore import patterns
    from foldcore.hinges import pivot_angle_deg
    from foldcore.simulation import Simulation

    start = time.perf_counter()
    result = Simulation(mesh, pattern).run(tolerance=1e-9, max_iterations=BUDGET)
    seconds = time.perf_counter() - start
    kinds = patterns.miura_edge_kinds(N, M)
    miss = np.abs(result.fold_angles_deg - pattern.fold_angles)
    creases = kinds != "boundary"
    return {"seconds": seconds, "iterations": result.iterations,
            "converged": result.converged, "reason": result.reason,
            "straight_miss_deg": float(np.nanmax(miss[kinds == "straight"])),
            "zigzag_miss_deg": float(np.nanmax(miss[kinds == "zigzag"])),
            "pivot_deg": float(np.min(pivot_angle_deg(mesh.hinge_width[creases],
                                                      mesh.thickness))),
            "thick_vertices": mesh.n_vertices}


def main() -> None:
    load = os.getloadavg()
    built = [build(h, w, tilt) for _, h, w, tilt in CASES]
    for pattern, mesh in built:  # warm-up: compile and cache every kernel first
        fold_once(pattern, mesh)
    runs = [[] for _ in CASES]
    for _ in range(RUNS):  # interleaved: one run of every case per round
        for k, (pattern, mesh) in enumerate(built):
            runs[k].append(fold_once(pattern, mesh))
            print(CASES[k][0], CASES[k][3], json.dumps(runs[k][-1]), flush=True)
    cases, rows = [], []
    for (label, h, w, tilt), got in zip(CASES, runs):
        last = got[-1]
        seconds = float(np.median([g["seconds"] for g in got]))
        cases.append({"label": label, "h_over_a": h, "w_over_h": w, "tilt_deg": tilt,
                      "median_seconds": seconds, "runs": got})
        verdict = "converged" if last["converged"] else last["reason"]
        ratio = last["straight_miss_deg"] / last["zigzag_miss_deg"] if tilt == 90.0 else None
        rows.append([label, f"{tilt:g}", f"{last['pivot_deg']:.1f}", verdict,
                     str(last["iterations"]), f"{seconds:.2f}",
                     f"{last['straight_miss_deg']:.3g}", f"{last['zigzag_miss_deg']:.3g}",
                     "—" if ratio is None else f"{ratio:.1f}"])
    out = {"pattern": f"Miura {N} x {M}, a = b = {A} mm, gamma = {GAMMA}",
           "tolerance": 1e-9, "budget": BUDGET, "runs": RUNS, "cases": cases,
           "load_before": load, "load_after": os.getloadavg(), "machine": machine_meta()}
    results = ROOT / "bench" / "results" / "os_miura.json"
    results.write_text(json.dumps(out, indent=1))
    plot(out, results.with_suffix(".png"))
    print(markdown_table(["case", "tilt (°)", "θ* (°)", "verdict", "iterations", "s",
                          "straight miss (°)", "zig-zag miss (°)", "ratio"], rows))


def plot(out: dict, path: Path) -> None:
    """Flat-fold misses: straight against zig-zag (with the singularity's 1 / cos γ
    line), and the time of every case."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    flat = [c for c in out["cases"] if c["tilt_deg"] == 90.0]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    zigzag = np.array([c["runs"][-1]["zigzag_miss_deg"] for c in flat])
    straight = np.array([c["runs"][-1]["straight_miss_deg"] for c in flat])
    line = np.linspace(0.0, zigzag.max() * 1.1, 20)
    left.plot(line, line / np.cos(np.radians(GAMMA)), "k--",
              label=f"zig-zag miss / cos γ (γ = {GAMMA:g}°)")
    for c, z, st in zip(flat, zigzag, straight):
        left.plot(z, st, "o", label=f"{c['label']} (θ* = {c['runs'][-1]['pivot_deg']:.0f}°)")
    left.axhline(0.5, color="tab:red", lw=0.8)
    left.text(0.02, 0.7, "target 0.5°", color="tab:red", fontsize=8)
    left.set(xlabel="zig-zag crease miss at flat (°)", ylabel="straight crease miss (°)",
             title="Flat fold: the straight creases amplify the zig-zag miss")
    left.legend(fontsize=7)
    labels = [f"{c['label']}\ntilt {c['tilt_deg']:g}°" for c in out["cases"]]
    right.barh(range(len(labels)), [c["median_seconds"] for c in out["cases"]])
    right.axvline(0.5, color="tab:red", lw=0.8)
    right.set_yticks(range(len(labels)), labels, fontsize=7)
    right.set(xlabel="wall time to converged (s, median)", title="Time (target 0.5 s)")
    fig.suptitle(f"{out['pattern']}, every crease driven; {out['machine']['machine']}, "
                 f"load {out['load_before'][0]:.1f}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    if "--plot" in sys.argv[1:]:
        results = ROOT / "bench" / "results" / "os_miura.json"
        plot(json.loads(results.read_text()), results.with_suffix(".png"))
    else:
        main()
