"""A thin sheet with and without contact, on Origami Simulator's files whose facets meet.

What it measures: Origami Simulator's model lets facets pass through each
other; ``--contact on`` keeps a thin sheet's triangles apart
(:mod:`foldcore.contact.sheet`). Per file and fold percent, both folds from
flat (in-process, ``SheetSolver.run``, interleaved rounds, median time; the
files of ``ONLY`` once):
verdict, Newton steps, seconds, whether the folded triangles cross (ipctk's
edge–triangle test, faces sharing a vertex excluded), the largest crease
angle, and with contact the pairs within d̂, the smallest gap (mm) and the
barrier's stiffening. Files: ``Tessellations/miura-ori.svg`` (its targets ask
some creases for more than 180° at 90 %) and the two files of Origami
Simulator's ``needsCollisions`` folder.

Writes bench/results/sheet_contact.json and .png. Run: ``python
bench/sheet_contact.py [--origami-simulator PATH]`` (about twelve minutes);
``--quick``: the Miura only, one run; ``--table`` prints the table of
docs/benchmarks.md.
"""
from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

import numpy as np

import _meta
import origami_simulator as osim

FILES = ["Tessellations/miura-ori.svg", "needsCollisions/byu solar driven.svg",
         "needsCollisions/rose.svg"]
PERCENTS = [30, 60, 90]
RUNS = 3
#: Files timed once, at these percents: the rose runs out its 500 Newton steps
#: either way, and with contact each of its folds takes minutes (its barrier pins
#: pairs at gaps of 1e-9 of the radius, where each collision check costs more).
ONLY = {"needsCollisions/rose.svg": PERCENTS}


def crossing(sheet, positions) -> bool:
    """Whether two triangles of the folded sheet that share no vertex cross."""
    import ipctk

    faces = np.ascontiguousarray(sheet.triangles, dtype=np.int32)
    mesh = ipctk.CollisionMesh(np.asfortranarray(sheet.flat), ipctk.edges(faces), faces)
    return bool(ipctk.has_intersections(mesh, np.asfortranarray(sheet.from_mm(positions))))


def one_fold(sheet, pattern, percent, contact):
    """(seconds, row) of one fold from flat."""
    from foldcore.sheet import SheetSolver

    seconds, result = _meta.timed(lambda: SheetSolver(
        sheet, percent, pattern_edges=pattern.n_edges, contact=contact).run())
    return {"seconds": seconds, "reason": result.reason, "iterations": result.iterations,
            "crossing": crossing(sheet, result.positions),
            "largest_angle_deg": float(np.nanmax(np.abs(result.fold_angles_deg))),
            "contact": result.contact}


def warm_up(svg: Path) -> None:
    """Kernels compiled or loaded and ipctk imported: one fold each way, not timed."""
    from foldcore.io import read_file
    from foldcore.sheet import build_sheet

    loaded = read_file(svg)
    sheet = build_sheet(loaded.pattern, merge_straight=True, drawn=loaded.drawing)
    for contact in (False, True):
        one_fold(sheet, loaded.pattern, PERCENTS[0], contact)


def one_file(svg: Path, name: str, runs: int) -> dict:
    """Every fold of one file, contact off and on in interleaved rounds."""
    from foldcore.io import read_file
    from foldcore.sheet import build_sheet

    loaded = read_file(svg)
    sheet = build_sheet(loaded.pattern, merge_straight=True, drawn=loaded.drawing)
    row = {"svg": name, "triangles": int(len(sheet.triangles)), "folds": []}
    for percent in ONLY.get(name, PERCENTS):
        cases = {key: (lambda c=contact: one_fold(sheet, loaded.pattern, percent, c))
                 for key, contact in (("off", False), ("on", True))}
        done = _meta.interleaved(cases, runs, warmup=0)
        row["folds"].append({"percent": percent,
                             **{k: _meta.median_run(v) for k, v in done.items()}})
        print(name, percent, {k: (round(v["seconds"], 2), v["reason"], v["crossing"])
                              for k, v in row["folds"][-1].items() if k != "percent"},
              flush=True)
    return row


def table(data: dict) -> str:
    rows = []
    for r in data["rows"]:
        for f in r["folds"]:
            off, on = f["off"], f["on"]
            c = on["contact"] or {}
            gap = c.get("smallest_gap_mm")
            rows.append([f"{r['svg']} ({r['triangles']})", f["percent"],
                         f"{off['reason']}, {off['iterations']}, {_meta.sig(off['seconds'])} s",
                         "yes" if off["crossing"] else "no",
                         f"{off['largest_angle_deg']:.2f}°",
                         f"{on['reason']}, {on['iterations']}, {_meta.sig(on['seconds'])} s",
                         "yes" if on["crossing"] else "no",
                         f"{on['largest_angle_deg']:.2f}°", c.get("active_pairs", "—"),
                         "—" if gap is None else _meta.sig(gap),
                         f"{c.get('stiffness', 1):g}"])
    return _meta.markdown_table(
        ["file (triangles)", "fold %", "off: verdict, steps, time", "off: crosses",
         "off: largest angle", "on: verdict, steps, time", "on: crosses",
         "on: largest angle", "pairs within d̂", "smallest gap (mm)", "κ / start"], rows)


def plot(data: dict, path: Path) -> None:
    plt = _meta.pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    labels, off, on = [], [], []
    for r in data["rows"]:
        for f in r["folds"]:
            labels.append(f"{Path(r['svg']).stem[:10]} {f['percent']}%")
            off.append(f["off"]["seconds"])
            on.append(f["on"]["seconds"])
    x = np.arange(len(labels))
    ax.bar(x - 0.2, off, 0.4, label="contact off (Origami Simulator's model)")
    ax.bar(x + 0.2, on, 0.4, label="--contact on")
    ax.set_xticks(x, labels, rotation=45, ha="right")
    ax.set_yscale("log")
    ax.set_ylabel("fold from flat, s (median)")
    ax.legend()
    _meta.save(fig, path)


def main() -> None:
    p = _meta.parser(__doc__)
    osim.add_source_argument(p)
    args = p.parse_args()
    if _meta.stored("sheet_contact", args, table, plot):
        return
    files = FILES[:1] if args.quick else FILES
    record = _meta.Record("sheet_contact", args, runs=1 if args.quick else RUNS,
                          others_busy_before=_meta.others_busy())
    warnings.simplefilter("ignore")  # the readers' notes: the rows say what matters
    with tempfile.TemporaryDirectory() as tmp:
        commit = osim.extract(args.origami_simulator, Path(tmp))
        warm_up(Path(tmp) / "assets" / FILES[0])
        rows = [one_file(Path(tmp) / "assets" / name, name,
                         1 if args.quick or name in ONLY else RUNS) for name in files]
    record.meta.update(origami_simulator_commit=commit, others_busy_after=_meta.others_busy())
    data = {"rows": rows}
    record.write(data, plot)
    print(table(data))


if __name__ == "__main__":
    main()
