"""Origami Simulator's Miura folded flat: how far thickness lets it go (issue 17).

The layout of Origami Simulator's ``Tessellations/miura-ori.svg`` (12 × 13
facets, 182 vertices; its zig-zag lines run at about 84° to the straight ones):
Miura 12 × 13, a = b = 80 mm, γ = GAMMA, every crease driven to its zero-
thickness rigid-fold angle (:func:`foldcore.patterns.miura_fold_angles`) at
facet tilt θ, default strategy unless the row names another, tolerance 1e-9.
Folded at tilt 45° (every crease below 90°) and at tilt 90° (flat: zig-zag
creases at 180°, straight ones at 180° too).

Why the flat fold misses, and why the straight creases miss most: the flat
state is a singular point of the Miura's kinematics. At tilt θ = 90° − d the
zig-zag creases are 2d short of flat and the straight ones, from tan(ρ/2) = cos
γ·tan θ, 2d / cos γ short: at γ = 84° every degree the zig-zag creases miss
shows as 1 / cos γ = 9.6° on the straight ones (the ``ratio`` column: 9.3–13).
Origami Simulator's own sheet has zero thickness. Here, flat, every degree-4
vertex stacks its four panels in four layers, and the crease opposite its odd
crease (M/V unlike the other three) must wrap around the other three. Equal
hinges stack each pair of panels the same distance apart (an axis hinge pivots
about its inner surface at 180°, panels H apart; an arc hinge of width W puts
them 2W / π apart), so the loop around each vertex misses by two layers: the
sheet has no flat state, and the run ends at the binding equilibrium (nearly
scale-free: zig-zag misses 0.72° and 0.79° at H / a = 0.01 and 0.001, Eq. 7's W
/ H). The fix this points to is checked on the last rows: arc hinges whose
straight-crease widths grow by twice the zig-zag width per vertex along each
line (:func:`foldcore.patterns.miura_flat_widths`: every wrapping crease as
wide as the other three together) fold the same sheet exactly flat, and a
single such vertex (``vertex`` rows: the wrapping crease 3W, or all W) shows
the same at one vertex. The widths reach 23 W on a 12-facet line: a uniform
thick Miura has no flat state, and the widths that give one grow with the
sheet.

Per row: θ* (degrees), iterations, verdict, wall time (median of RUNS warm runs
after one warm-up, interleaved across rows), the largest miss on the straight
and on the zig-zag creases (degrees), their ratio and the energy left. Run:
``.venv/bin/python bench/os_miura.py`` (a few minutes); writes
bench/results/os_miura.json and .png (the flat fold's misses against the zig-
zag miss / cos γ line, and each case's time) and prints the README table;
``--plot`` redraws the PNG from the JSON."""
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
#: (label, H / a, W / H or None for Eq. 7's automatic width, tilt in degrees,
#: options): ``hinge`` model, ``graded`` widths (:func:`foldcore.patterns.miura_flat_widths`
#: from W), ``solver``, ``vertex`` (one Miura vertex, radius a, instead of the sheet:
#: "wrap" = its wrapping crease 3W, "equal" = all W)
CASES = [("auto W, H = 0.01a", 0.01, None, 45.0, {}),
         ("auto W, H = 0.01a", 0.01, None, 90.0, {}),
         ("auto W, H = 0.001a", 0.001, None, 90.0, {}),
         ("W = 5H, H = 0.01a", 0.01, 5.0, 90.0, {}),
         ("W = 10H, H = 0.01a", 0.01, 10.0, 90.0, {}),
         ("W = 30H, H = 0.001a", 0.001, 30.0, 90.0, {}),
         ("W = 100H, H = 0.001a", 0.001, 100.0, 90.0, {}),
         ("arc, auto W, H = 0.01a", 0.01, None, 90.0, {"hinge": "arc"}),
         ("arc, graded W, H = 0.01a", 0.01, None, 90.0, {"hinge": "arc", "graded": True}),
         ("arc, graded W, newton", 0.01, None, 90.0,
          {"hinge": "arc", "graded": True, "solver": "newton"}),
         ("vertex, arc, all W", 0.01, None, 90.0,
          {"hinge": "arc", "vertex": "equal", "solver": "newton"}),
         ("vertex, arc, wrapping 3W", 0.01, None, 90.0,
          {"hinge": "arc", "vertex": "wrap", "solver": "newton"})]


def build(h_over_a: float, w_over_h, tilt: float, options: dict):
    """(pattern, mesh, edge kinds) of one case: every crease driven to its rigid-fold angle."""
    from foldcore import patterns
    from foldcore.thickening import thicken

    thickness = h_over_a * A
    width = np.pi / 2 * thickness if w_over_h is None else w_over_h * thickness
    if "vertex" in options:
        pattern, kinds = vertex(width, options["vertex"] == "wrap")
    else:
        kinds = patterns.miura_edge_kinds(N, M)
        widths = (patterns.miura_flat_widths(N, M, width) if options.get("graded")
                  else np.where(kinds == "boundary", np.nan, width))
        pattern = patterns.miura(N, M, a=A, b=A, gamma=GAMMA).replace(
            widths=widths, fold_angles=patterns.miura_fold_angles(N, M, GAMMA, tilt))
    return pattern, thicken(pattern, thickness, hinge=options.get("hinge")), kinds


def vertex(width: float, wrap: bool):
    """(pattern, edge kinds) of one Miura vertex (sectors γ, 180° − γ, 180° − γ, γ;
    creases 1 and 3 straight) folded flat; ``wrap``: the crease opposite the odd
    one 3W wide, the rest W."""
    from foldcore import patterns

    sectors = [GAMMA, 180.0 - GAMMA, 180.0 - GAMMA, GAMMA]
    mv = patterns.degree4_assignments(sectors, "B")
    odd = [k for k in range(4) if mv.count(mv[k]) == 1][0]
    widths = [3.0 * width if wrap and k == (odd + 2) % 4 else width for k in range(4)]
    targets = [180.0 if a == "V" else -180.0 for a in mv]
    pattern = patterns.single_vertex(sectors, mv, targets, radius=A, widths=widths)
    kinds = np.array(["straight", "zigzag"] * 2 + ["boundary"] * (len(pattern.edges) - 4))
    return pattern, kinds


def fold_once(pattern, mesh, kinds, options: dict) -> dict:
    from foldcore.hinges import pivot_angle_deg
    from foldcore.simulation import Simulation

    start = time.perf_counter()
    result = Simulation(mesh, pattern, solver=options.get("solver", "hybrid")).run(
        tolerance=1e-9, max_iterations=BUDGET)
    seconds = time.perf_counter() - start
    miss = np.abs(result.fold_angles_deg - pattern.fold_angles)
    creases = kinds != "boundary"
    return {"seconds": seconds, "iterations": result.iterations,
            "converged": result.converged, "reason": result.reason,
            "energy": float(result.energy[-1]) if len(result.energy) else 0.0,
            "straight_miss_deg": float(np.nanmax(miss[kinds == "straight"])),
            "zigzag_miss_deg": float(np.nanmax(miss[kinds == "zigzag"])),
            "pivot_deg": float(np.min(pivot_angle_deg(mesh.hinge_width[creases],
                                                      mesh.thickness))),
            "thick_vertices": mesh.n_vertices}


def main() -> None:
    load = os.getloadavg()
    built = [build(h, w, tilt, options) for _, h, w, tilt, options in CASES]
    for (pattern, mesh, kinds), case in zip(built, CASES):  # warm-up: compile and cache
        fold_once(pattern, mesh, kinds, case[-1])
    runs = [[] for _ in CASES]
    for _ in range(RUNS):  # interleaved: one run of every case per round
        for k, (pattern, mesh, kinds) in enumerate(built):
            runs[k].append(fold_once(pattern, mesh, kinds, CASES[k][-1]))
            print(CASES[k][0], CASES[k][3], json.dumps(runs[k][-1]), flush=True)
    cases, rows = [], []
    for (label, h, w, tilt, options), got in zip(CASES, runs):
        last = got[-1]
        seconds = float(np.median([g["seconds"] for g in got]))
        cases.append({"label": label, "h_over_a": h, "w_over_h": w, "tilt_deg": tilt,
                      "options": options, "median_seconds": seconds, "runs": got})
        verdict = "converged" if last["converged"] else last["reason"]
        ratio = last["straight_miss_deg"] / last["zigzag_miss_deg"] if tilt == 90.0 else None
        rows.append([label, f"{tilt:g}", f"{last['pivot_deg']:.1f}", verdict,
                     str(last["iterations"]), f"{seconds:.2f}",
                     f"{last['straight_miss_deg']:.3g}", f"{last['zigzag_miss_deg']:.3g}",
                     "—" if ratio is None else f"{ratio:.1f}", f"{last['energy']:.2g}"])
    out = {"pattern": f"Miura {N} x {M}, a = b = {A} mm, gamma = {GAMMA}",
           "tolerance": 1e-9, "budget": BUDGET, "runs": RUNS, "cases": cases,
           "load_before": load, "load_after": os.getloadavg(), "machine": machine_meta()}
    results = ROOT / "bench" / "results" / "os_miura.json"
    results.write_text(json.dumps(out, indent=1))
    plot(out, results.with_suffix(".png"))
    print(markdown_table(["case", "tilt (°)", "θ* (°)", "verdict", "iterations", "s",
                          "straight miss (°)", "zig-zag miss (°)", "ratio", "E (mm⁵)"],
                         rows))


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
    line = np.geomspace(zigzag.min() / 2, zigzag.max() * 2, 20)
    left.plot(line, line / np.cos(np.radians(GAMMA)), "k--",
              label=f"zig-zag miss / cos γ (γ = {GAMMA:g}°)")
    for c, z, st in zip(flat, zigzag, straight):
        options = c.get("options", {})
        marker = "^" if "vertex" in options else ("s" if options.get("hinge") == "arc" else "o")
        verdict = "" if c["runs"][-1]["converged"] else f", {c['runs'][-1]['reason']}"
        left.plot(z, st, marker, label=f"{c['label']}{verdict}")
    left.axhline(0.5, color="tab:red", lw=0.8)
    left.text(line[0], 0.6, "target 0.5°", color="tab:red", fontsize=8)
    left.set(xscale="log", yscale="log", xlabel="zig-zag crease miss at flat (°)",
             ylabel="straight crease miss (°)",
             title="Flat: equal hinges bind, graded arc widths fold flat")
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
