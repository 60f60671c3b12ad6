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
        seconds, result = _meta.timed(lambda: sim.run(tolerance=1e-8, max_iterations=2_000))
        out["on" if contact else "off"] = {
            "fold_angles_deg": [round(float(a), 4) for a in result.fold_angles_deg[:2]],
            "iterations": int(result.iterations), "reason": result.reason,
            "seconds": seconds, "worst_overlap_share": worst_overlap(mesh, result.positions)}
    return out


def overhead(sizes, runs: int) -> list:
    from foldcore import patterns
    from foldcore.simulation import Simulation
    from foldcore.strategies.rigid import RigidOptions
    from foldcore.thickening import thicken

    rows = []
    for n in sizes:
        pattern = patterns.miura_one_crease(n, n, tilt=45.0)
        mesh = thicken(pattern, H)

        def fold(contact):
            sim = Simulation(mesh, pattern, solver="rigid", contact=contact,
                             options=RigidOptions(coarse_start=False))
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


def table(data: dict) -> str:
    letter_rows = []
    for key, row in data["letter"].items():
        a, b = row["fold_angles_deg"]
        letter_rows.append([f"contact {key}", f"{a:.4g}°", f"{b:.4g}°", row["iterations"],
                            f"{row['seconds']:.2f}", _meta.sig(row["worst_overlap_share"], 2)])
    miura_rows = [[row["n"], row["iterations"], _meta.sig(row["off_s"]), _meta.sig(row["on_s"]),
                   f"{row['ratio']:.2f}", row["identical"]] for row in data["overhead"]]
    return "\n\n".join([
        _meta.markdown_table(["letter fold", "crease 1", "crease 2", "steps", "s",
                              "worst overlap"], letter_rows),
        _meta.markdown_table(["Miura n × n", "steps", "off (s)", "on (s)", "on / off",
                              "identical"], miura_rows)])


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
    record = _meta.Record(NAME, args, thickness_mm=H, sizes=list(sizes), runs=runs)
    data = {"letter": letter(), "overhead": overhead(sizes, runs)}
    record.write(data, plot)
    print(table(data))


if __name__ == "__main__":
    main()
