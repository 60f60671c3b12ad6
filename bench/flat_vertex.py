"""Pehrson's thick vertex folded flat: which hinge model stacks it, at what cost.

The vertex of the paper's d4v scene (sectors 135/90/45/90°, R 76.2 mm,
H = 3.175 mm, mode A, widths 16/4/8/4 mm from its wrapping crease on,
k = 4 sub-strips) with every crease driven from the flat sheet to ±180°, for
each hinge model and the strategies that take it (slack under `hybrid` also
with contact on), tolerance 1e-10:

* accuracy: the largest miss of a crease from 180° (°); the panels' layers
  (mid-planes along the normal of the panel left of crease 1 closer than H/2
  are one layer), the
  smallest distance between consecutive layers (mm, ≥ H: no two panels
  interpenetrate) and the stack height (mm), as the d4v scene measures them;
  the worst overlap of two panels' convex hulls as a share of the smaller
  panel (manifold3d, as ``bench/contact.py`` measures it);
* cost: iterations and wall seconds (median of RUNS after a warm-up, the
  cases interleaved round by round).

Run: ``python bench/flat_vertex.py`` (about a minute); writes
bench/results/flat_vertex.json and .png; ``--table`` prints the table of
docs/benchmarks.md.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _meta  # noqa: E402
from contact import worst_overlap  # noqa: E402

NAME = "flat_vertex"
H = 3.175  # mm
SUBDIVISIONS = 4
TOLERANCE = 1e-10
BUDGET = 2_000
RUNS = 3
CASES = (("axis", "hybrid", False), ("arc", "hybrid", False), ("slack", "hybrid", False),
         ("slack", "newton", False), ("slack", "hybrid", True))


def fold_flat(hinge: str, solver: str, contact: bool) -> dict:
    """One run from the flat sheet to every crease at ±180°; its measures."""
    from foldcore import patterns
    from foldcore.simulation import Simulation
    from foldcore.thickening import thicken

    pattern = patterns.degree4_vertex(mode="A")
    targets = np.where(pattern.assignments[:4] == "M", -180.0, 180.0)
    mesh = thicken(pattern, H, subdivisions=SUBDIVISIONS, hinge=hinge)
    sim = Simulation(mesh, pattern, solver=solver, contact=contact)
    sim.set_fold_angles({i: float(t) for i, t in enumerate(targets)})
    seconds, result = _meta.timed(lambda: sim.run(tolerance=TOLERANCE, max_iterations=BUDGET))
    return {"seconds": seconds, "iterations": int(result.iterations), "reason": result.reason,
            "fold_angles_deg": [round(float(a), 6) for a in result.fold_angles_deg[:4]],
            "largest_miss_deg": float(np.abs(result.fold_angles_deg[:4] - targets).max()),
            **stack(mesh, pattern, result.positions)}


def stack(mesh, pattern, positions) -> dict:
    """Layers, smallest gap between consecutive layers' mid-planes and stack height
    (mm) as the d4v scene measures them, and the worst hull overlap share (the
    contact benchmark's)."""
    from foldcore.scenes.d4v import stack as scene_stack

    measured = scene_stack(mesh, pattern, positions)
    return {"layers": measured["layers"], "smallest_gap_mm": measured["smallest_layer_gap_mm"],
            "stack_height_mm": measured["stack_height_mm"],
            "worst_overlap_share": worst_overlap(mesh, positions)}


def table(data: dict) -> str:
    rows = []
    for row in data["rows"]:
        rows.append([row["hinge"], row["solver"], "on" if row.get("contact") else "off",
                     _meta.sig(row["largest_miss_deg"], 2),
                     row["layers"], f"{row['smallest_gap_mm']:.3f}",
                     f"{row['stack_height_mm']:.2f}",
                     _meta.sig(row["worst_overlap_share"], 2),
                     row["iterations"], f"{row['seconds']:.3f}", row["reason"]])
    return _meta.markdown_table(
        ["hinge", "solver", "contact", "largest miss (°)", "layers", "smallest gap (mm)",
         "stack (mm)", "worst overlap", "iterations", "s", "verdict"], rows)


def plot(data: dict, path: Path) -> None:
    plt = _meta.pyplot()
    fig, ax = plt.subplots(figsize=(5.5, 3.5))
    for row in data["rows"]:
        ax.scatter(row["seconds"], max(row["largest_miss_deg"], 1e-12), s=40,
                   label=f"{row['hinge']} / {row['solver']}"
                   + (" / contact" if row.get("contact") else ""))
    ax.set_xlabel("run time, s (median)")
    ax.set_ylabel("largest miss from 180°, degrees")
    ax.set_yscale("log")
    ax.set_title(f"Pehrson's vertex folded flat (H = {H} mm)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    args = _meta.parser(__doc__).parse_args()
    if _meta.stored(NAME, args, table=table, plot=plot):
        return
    runs = 1 if args.quick else RUNS
    record = _meta.Record(NAME, args, tolerance=TOLERANCE, thickness_mm=H,
                          subdivisions=SUBDIVISIONS, runs=runs)
    cases = {case: (lambda case=case: fold_flat(*case)) for case in CASES}
    results = _meta.interleaved(cases, runs)
    rows = [{"hinge": hinge, "solver": solver, "contact": contact,
             **_meta.median_run(results[hinge, solver, contact])}
            for hinge, solver, contact in CASES]
    data = {"rows": rows}
    record.write(data, plot)
    print(table(data))


if __name__ == "__main__":
    main()
