"""Public crease patterns folded as a new user would (issue 19, item 8).

Every pattern of ``tests/data/real/`` (sources and licences: its SOURCES.md)
through :func:`foldcore.job.fold` — the command line's path — at fold percents
30, 60 and 90, sheet scaled to SHEET mm (``sheet_size``; most files are unit
squares), thickness H, the default strategy, tolerance 1e-8, at most BUDGET
iterations. Per run: the verdict and reason, iterations, wall time, the driven
creases' miss (max, median, degrees), how many M/V creases ended on the wrong
side (achieved sign against the assignment by more than 1°) and the warnings
said (RunWarning: binding, nothing driven). A file refused is listed with its
one-line message. One run per case (a table of behaviour, not a timing
benchmark; times are single runs on a shared machine, load recorded).

Run: ``.venv/bin/python bench/real_patterns.py`` (a few minutes). Writes
bench/results/real_patterns.json and prints the README table.

``--elastic``: the files whose rigid panels bind, again with elastic panels
(``elastic_cells`` = CELL mm: every face in rings of cells, the command line's
``--elastic-cells``), at most ELASTIC_BUDGET iterations (the default
``hybrid``: the rigid-panel twin from rest, then ``newton``); writes
bench/results/real_patterns_elastic.json.
"""
from __future__ import annotations

import json
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _meta import machine_meta, markdown_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT / "tests" / "data" / "real"
SHEET = 100.0  # mm, the larger extent of every sheet
H = 0.5  # mm, thickness
BUDGET = 3000
PERCENTS = (30, 60, 90)
SKIP = {"BoxPleatPyramid.fold": "2 704 vertices: minutes per fold (issue 17)"}
CELL = 10.0  # mm, elastic cells (--elastic)
ELASTIC_BUDGET = 40_000
#: files folded again with elastic panels: those that bind with rigid ones, without
#: the two largest (hypar, miura-ori: minutes per elastic fold)
ELASTIC = ("bird-base-3d.fold", "crane.fold", "resch-tess.fold", "mapfold.svg",
           "simpleVertex.svg", "singlesquaretwist.svg", "squareBase.svg",
           "waterbombBase.svg")


def wrong_side(pattern, angles) -> int:
    """M/V creases whose achieved angle has the other sign, by more than 1°."""
    kinds = pattern.assignments
    a = np.nan_to_num(angles)
    return int(np.count_nonzero((kinds == "M") & (a > 1.0) | (kinds == "V") & (a < -1.0)))


def run_one(path: Path, percent: float, elastic_cells=None, budget=BUDGET) -> dict:
    from foldcore.errors import FoldcoreError
    from foldcore.job import fold
    from foldcore.outputs import actuation_entries

    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            done = fold(path, thickness=H, sheet_size=SHEET, fold_percent=percent,
                        max_iterations=budget, elastic_cells=elastic_cells)
        except FoldcoreError as exc:
            return {"refused": str(exc).replace(str(path), path.name)}
    seconds = time.perf_counter() - start
    act = actuation_entries(done.result, done.pattern)
    return {"converged": done.result.converged, "reason": done.result.reason,
            "iterations": done.result.iterations, "seconds": seconds,
            "driven": len(act["creases"]), "miss_max_deg": act["largest_miss_deg"],
            "miss_median_deg": act["median_miss_deg"],
            "wrong_side": wrong_side(done.pattern, done.result.fold_angles_deg),
            "warnings": sorted({w.category.__name__ for w in caught})}


def main(elastic: bool = False) -> None:
    load = os.getloadavg()
    rows, cases = [], []
    for path in sorted(CORPUS.glob("*.fold")) + sorted(CORPUS.glob("*.svg")):
        if path.name in SKIP or (elastic and path.name not in ELASTIC):
            if not elastic:
                cases.append({"file": path.name, "skipped": SKIP[path.name]})
            continue
        for percent in PERCENTS:
            extra = dict(elastic_cells=CELL, budget=ELASTIC_BUDGET) if elastic else {}
            case = {"file": path.name, "fold_percent": percent,
                    **run_one(path, percent, **extra)}
            cases.append(case)
            print(json.dumps(case), flush=True)
            if "refused" in case:
                break
    for c in cases:
        if "skipped" in c:
            rows.append([c["file"], "—", "skipped: " + c["skipped"], "", "", "", ""])
        elif "refused" in c:
            rows.append([c["file"], "—", "refused: " + c["refused"].split(": ", 1)[-1][:90],
                         "", "", "", ""])
        else:
            verdict = "converged" if c["converged"] else c["reason"]
            if "RunWarning" in c["warnings"]:
                verdict += " (warned)"
            rows.append([c["file"], c["fold_percent"], verdict, c["iterations"],
                         f"{c['seconds']:.2f}",
                         f"{c['miss_max_deg']:.3g} / {c['miss_median_deg']:.3g}",
                         c["wrong_side"]])
    out = {"sheet_mm": SHEET, "thickness_mm": H, "cases": cases,
           "budget": ELASTIC_BUDGET if elastic else BUDGET,
           "elastic_cells_mm": CELL if elastic else None,
           "load_before": load, "load_after": os.getloadavg(), "machine": machine_meta()}
    name = "real_patterns_elastic.json" if elastic else "real_patterns.json"
    (ROOT / "bench" / "results" / name).write_text(json.dumps(out, indent=1))
    rows = [[str(cell) for cell in row] for row in rows]
    print(markdown_table(["file", "fold %", "verdict", "iterations", "s",
                          "miss max / median (°)", "wrong side"], rows))


if __name__ == "__main__":
    main(elastic="--elastic" in sys.argv[1:])
