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
* ``overhead_default``: the same Miuras (the three smallest sizes) with the
  library's defaults but contact (``hybrid``, whose rigid phase starts on the
  coarse twin, which contact turns off).
* ``flat``: a thick Miura n × m with the graded widths meant to fold it
  exactly flat (``miura_flat_widths``, arc hinges, H = 0.2 mm, γ = 84°), every
  crease driven to ±180° by ``newton`` from the flat sheet: many panels end
  stacked face to face, the case where contact has the most pairs to hold.
  Contact off and on, interleaved, median of RUNS: iterations, seconds, the
  largest miss from flat, the pairs within d̂ at the end, the smallest gap
  and the worst overlap of two panels' hulls, joined (a crease between
  them) and not, and the pairs of parts contact keeps apart (panels, hinge
  strips) whose surfaces cross (``ContactModel.overlapping``).

Run: ``python bench/contact.py`` (about 4 min; ``--quick``: sizes 6 and 10,
one run); writes bench/results/contact.json and .png with the machine and its
load (``bench/_meta.py``); ``--table`` prints the tables of docs/benchmarks.md
from the JSON.
"""
from __future__ import annotations

import sys
from itertools import combinations
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _meta  # noqa: E402

NAME = "contact"
SIZES = (10, 20, 30, 40, 50)
QUICK_SIZES = (6, 10)
FLAT_SIZES = ((4, 2), (6, 4), (8, 6))
QUICK_FLAT_SIZES = ((4, 2),)
FLAT_H, FLAT_GAMMA = 0.2, 84.0  # mm, degrees
RUNS = 3
H = 1.0


def letter_pattern():
    from foldcore import patterns

    return patterns.panel_row([6.0, 10.0, 6.0])


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
        seconds, result = _meta.timed(lambda: sim.run(tolerance=1e-8, max_iterations=2_000))
        out["on" if contact else "off"] = {
            "fold_angles_deg": [round(float(a), 4) for a in result.fold_angles_deg[:2]],
            "iterations": int(result.iterations), "reason": result.reason,
            "seconds": seconds, "worst_overlap_share": worst_overlap(mesh, result.positions)}
    return out


def overhead(sizes, runs: int, strategy: str = "rigid") -> list:
    from foldcore import patterns
    from foldcore.simulation import Simulation
    from foldcore.strategies.rigid import RigidOptions
    from foldcore.thickening import thicken

    rows = []
    for n in sizes:
        pattern = patterns.miura_one_crease(n, n, tilt=45.0)
        mesh = thicken(pattern, H)

        def fold(contact):
            if strategy == "rigid":
                sim = Simulation(mesh, pattern, solver="rigid", contact=contact,
                                 options=RigidOptions(coarse_start=False))
            else:  # the library's defaults but contact
                sim = Simulation(mesh, pattern, contact=contact)
            return _meta.timed(lambda: sim.run(tolerance=1e-8, max_iterations=2_000))

        done = _meta.interleaved({c: (lambda c=c: fold(c)) for c in (False, True)}, runs)
        off, on = (_meta.median([t for t, _ in done[c]]) for c in (False, True))
        last = {c: done[c][-1][1] for c in (False, True)}
        rows.append({"n": n, "iterations": int(last[False].iterations),
                     "off_s": off, "on_s": on, "ratio": on / off,
                     "identical": bool(np.array_equal(last[False].positions,
                                                      last[True].positions))})
        print(rows[-1], flush=True)
    return rows


def flat(sizes, runs: int) -> list:
    from foldcore import patterns
    from foldcore.contact import ContactModel
    from foldcore.contact.solids import PartSolids
    from foldcore.simulation import Simulation
    from foldcore.thickening import thicken

    rows = []
    for n, m in sizes:
        angles = patterns.miura_fold_angles(n, m, FLAT_GAMMA, 90.0)
        pattern = patterns.miura(n, m, a=20.0, b=20.0, gamma=FLAT_GAMMA).replace(
            fold_angles=angles, widths=patterns.miura_flat_widths(n, m, np.pi / 2 * FLAT_H))
        mesh = thicken(pattern, FLAT_H, hinge="arc")
        driven = np.isfinite(angles)

        def fold(contact):
            sim = Simulation(mesh, pattern, solver="newton", contact=contact)
            return _meta.timed(lambda: sim.run(tolerance=1e-8, max_iterations=2_000))

        done = _meta.interleaved({c: (lambda c=c: fold(c)) for c in (False, True)}, runs)
        joined = {tuple(p) for p in PartSolids(mesh, pattern).joined_pairs.tolist()}
        parts = ContactModel(mesh, pattern, 1.0)
        row = {"n": n, "m": m, "panels": len(pattern.faces)}
        for c in (False, True):
            result = done[c][-1][1]
            unjoined, joined_worst = overlaps(mesh, result.positions, joined)
            row["on" if c else "off"] = {
                "iterations": int(result.iterations), "reason": result.reason,
                "seconds": _meta.median([t for t, _ in done[c]]),
                "largest_miss_deg": float(np.abs(result.fold_angles_deg[driven]
                                                 - angles[driven]).max()),
                "active_pairs": len(result.contact["active_pairs"]) if c else None,
                "smallest_gap_mm": result.contact["smallest_gap_mm"] if c else None,
                "worst_unjoined_overlap": unjoined, "worst_joined_overlap": joined_worst,
                "crossing_parts": len(parts.overlapping(result.positions))}
        rows.append(row)
        print(rows[-1], flush=True)
    return rows


def overlaps(mesh, positions, joined: set) -> tuple[float, float]:
    """Worst overlap of two panels' hulls (share of the smaller) over the pairs no
    crease joins and over those one does (``joined``: panel-slot pairs a < b)."""
    import manifold3d

    g = mesh.groups[mesh.panel_group]
    hulls = [manifold3d.Manifold.hull_points(np.ascontiguousarray(
        positions[g.indices[g.slots(p)]])) for p in range(len(g))]
    worst = {False: 0.0, True: 0.0}
    for a, b in combinations(range(len(hulls)), 2):
        share = (hulls[a] ^ hulls[b]).volume() / min(hulls[a].volume(), hulls[b].volume())
        key = (a, b) in joined
        worst[key] = max(worst[key], share)
    return worst[False], worst[True]


def table(data: dict) -> str:
    letter_rows = []
    for key, row in data["letter"].items():
        a, b = row["fold_angles_deg"]
        letter_rows.append([f"contact {key}", f"{a:.4g}°", f"{b:.4g}°", row["iterations"],
                            f"{row['seconds']:.2f}", _meta.sig(row["worst_overlap_share"], 2)])
    tables = [_meta.markdown_table(["letter fold", "crease 1", "crease 2", "steps", "s",
                                    "worst overlap"], letter_rows)]
    for key, title in (("overhead", "Miura n × n, rigid"),
                       ("overhead_default", "Miura n × n, defaults")):
        rows = [[row["n"], row["iterations"], _meta.sig(row["off_s"]), _meta.sig(row["on_s"]),
                 f"{row['ratio']:.2f}", row["identical"]] for row in data.get(key, [])]
        if rows:
            tables.append(_meta.markdown_table([title, "steps", "off (s)", "on (s)", "on / off",
                                                "identical"], rows))
    flat_rows = [[f"{r['n']} × {r['m']}", key, r[key]["iterations"], r[key]["reason"],
                  f"{r[key]['seconds']:.2f}", _meta.sig(r[key]["largest_miss_deg"], 2),
                  r[key]["active_pairs"] if r[key]["active_pairs"] is not None else "",
                  _meta.sig(r[key]["worst_unjoined_overlap"], 2),
                  _meta.sig(r[key]["worst_joined_overlap"], 2),
                  r[key].get("crossing_parts", "")]
                 for r in data.get("flat", []) for key in ("off", "on")]
    if flat_rows:
        tables.append(_meta.markdown_table(
            ["graded Miura flat", "contact", "steps", "verdict", "s", "miss (°)",
             "pairs within d̂", "overlap, unjoined", "overlap, joined",
             "parts crossing"], flat_rows))
    return "\n\n".join(tables)


def plot(data: dict, path: Path) -> None:
    plt = _meta.pyplot()
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
    fig.savefig(path, dpi=120)


def main() -> None:
    args = _meta.parser(__doc__).parse_args()
    if _meta.stored(NAME, args, table=table, plot=plot):
        return
    sizes, runs = (QUICK_SIZES, 1) if args.quick else (SIZES, RUNS)
    flat_sizes = QUICK_FLAT_SIZES if args.quick else FLAT_SIZES
    record = _meta.Record(NAME, args, thickness_mm=H, sizes=list(sizes), runs=runs)
    data = {"letter": letter(), "overhead": overhead(sizes, runs),
            "overhead_default": overhead(sizes[:3], runs, strategy="default"),
            "flat": flat(flat_sizes, runs)}
    record.write(data, plot)
    print(table(data))


if __name__ == "__main__":
    main()
