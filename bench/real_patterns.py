"""Public crease patterns folded as a new user would.

Every pattern of ``tests/data/real/`` (sources and licences: its SOURCES.md)
through :func:`foldcore.simulate` — the command line's path — at fold
percents 30, 60 and 90, sheet scaled to SHEET mm (``sheet_size``; most files
are unit squares), thickness H, the default strategy, tolerance 1e-8, at most
BUDGET iterations. Per case: the verdict and reason, iterations, wall time
(median of RUNS runs after one warm-up fold), the driven creases' miss
(achieved against ``Result.target_angles_deg``: max and median, degrees), how
many M/V creases ended on the wrong side (achieved sign against the
assignment by more than 1°) and the warnings said (RunWarning: binding,
nothing driven). A file refused is listed with its one-line message. A table
of behaviour first: the times are of a shared machine, its load recorded.

``--elastic``: the files whose rigid panels bind, again with elastic panels
(``elastic_cells`` = CELL mm: every face in rings of cells, the command line's
``--elastic-cells``), at most ELASTIC_BUDGET iterations; writes
bench/results/real_patterns_elastic.json.

Run: ``python bench/real_patterns.py [--elastic]`` (a few minutes) or
``--quick``; writes bench/results/real_patterns.json and .png; ``--table`` prints the
table of docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import time
import warnings

import numpy as np

import _meta

CORPUS = _meta.ROOT / "tests" / "data" / "real"
SHEET = 100.0  # mm, the larger extent of every sheet
H = 0.5  # mm, thickness
BUDGET = 3000
RUNS = 3
PERCENTS = (30, 60, 90)
SKIP = {"BoxPleatPyramid.fold": "2 704 vertices: minutes per fold"}
CELL = 10.0  # mm, elastic cells (--elastic)
ELASTIC_BUDGET = 40_000
#: files folded again with elastic panels: those that bind with rigid ones, without
#: the two largest (hypar, miura-ori: minutes per elastic fold)
ELASTIC = ("bird-base-3d.fold", "crane.fold", "resch-tess.fold", "mapfold.svg",
           "simpleVertex.svg", "singlesquaretwist.svg", "squareBase.svg",
           "waterbombBase.svg")
#: --quick: these files at 30 % only, one run
QUICK_FILES = ("diagonal-cp.fold", "kite.fold", "squareBase.svg")


def wrong_side(assignments, angles) -> int:
    """M/V creases whose achieved angle (degrees) has the other sign, by more than 1°."""
    a = np.nan_to_num(angles)
    return int(np.count_nonzero((assignments == "M") & (a > 1.0)
                                | (assignments == "V") & (a < -1.0)))


def simulate(path, percent: float, elastic_cells, budget: int):
    """:func:`foldcore.simulate` of ``path`` with this benchmark's settings."""
    import foldcore

    return foldcore.simulate(path, reading={"size": SHEET},
                             thickening={"thickness": H, "elastic_cells": elastic_cells},
                             solving={"fold_percent": percent, "max_iterations": budget})


def run_one(path, percent: float, elastic_cells=None, budget=BUDGET) -> dict:
    """One fold of ``path`` through :func:`foldcore.simulate` (module docstring)."""
    import foldcore

    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = simulate(path, percent, elastic_cells, budget)
        except foldcore.FoldcoreError as exc:
            return {"refused": str(exc).replace(str(path), path.name), "seconds": 0.0}
        seconds = time.perf_counter() - start
        assignments = foldcore.read(path).assignments
    targets = result.target_angles_deg
    driven = np.flatnonzero(np.isfinite(targets))
    miss = np.abs((result.fold_angles_deg[driven] - targets[driven] + 180.0) % 360.0 - 180.0)
    return {"converged": bool(result.converged), "reason": result.reason,
            "iterations": int(result.iterations), "seconds": seconds, "driven": int(len(driven)),
            "miss_max_deg": float(miss.max()) if len(miss) else 0.0,
            "miss_median_deg": float(np.median(miss)) if len(miss) else 0.0,
            "wrong_side": wrong_side(assignments, result.fold_angles_deg),
            "warnings": sorted({w.category.__name__ for w in caught})}


def cases(elastic: bool, quick: bool, runs: int) -> list:
    """Every file and fold percent: the median-time run of each, or why not folded."""
    out = []
    extra = dict(elastic_cells=CELL, budget=ELASTIC_BUDGET) if elastic else {}
    files = sorted(CORPUS.glob("*.fold")) + sorted(CORPUS.glob("*.svg"))
    for path in files:
        if quick and path.name not in (ELASTIC[-2:] if elastic else QUICK_FILES):
            continue
        if path.name in SKIP or (elastic and path.name not in ELASTIC):
            if not elastic:
                out.append({"file": path.name, "skipped": SKIP[path.name]})
            continue
        for percent in PERCENTS[:1] if quick else PERCENTS:
            got = _meta.repeat(lambda: run_one(path, percent, **extra), runs, warmup=0)
            case = {"file": path.name, "fold_percent": percent, **_meta.median_run(got)}
            out.append(case)
            print(f"{path.name} {percent} %: " + ("refused" if "refused" in case else
                  f"{case['reason']}, {case['iterations']} its, {case['seconds']:.2f} s, "
                  f"miss {case['miss_max_deg']:.3g}°"), flush=True)
            if "refused" in case:
                break
    return out


def short(message: str, limit: int = 80) -> str:
    """``message`` cut at a word before ``limit`` characters, with an ellipsis."""
    return message if len(message) <= limit else message[:limit].rsplit(" ", 1)[0] + " …"


def table(data: dict) -> str:
    rows = []
    for c in data["cases"]:
        if "skipped" in c:
            rows.append([c["file"], "—", "skipped: " + c["skipped"].split(" (")[0],
                         "", "", "", ""])
        elif "refused" in c:
            rows.append([c["file"], "—", "refused: " + short(c["refused"].split(": ", 1)[-1]),
                         "", "", "", ""])
        else:
            verdict = "converged" if c["converged"] else c["reason"]
            if "RunWarning" in c["warnings"]:
                verdict += " (warned)"
            rows.append([c["file"], c["fold_percent"], verdict, c["iterations"],
                         f"{c['seconds']:.2f}",
                         f"{c['miss_max_deg']:.3g} / {c['miss_median_deg']:.3g}",
                         c["wrong_side"]])
    return _meta.markdown_table(["file", "fold %", "verdict", "iterations", "s",
                                 "miss max / median (°)", "wrong side"], rows)


def plot(data: dict, path) -> None:
    """Per file: the largest miss of the driven creases at each fold percent (left) and
    the wall time (right); refused and skipped files are left out."""
    plt = _meta.pyplot()
    folded = [c for c in data["cases"] if "converged" in c]
    files = list(dict.fromkeys(c["file"] for c in folded))
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 0.35 * len(files) + 1.8),
                                      sharey=True)
    for k, percent in enumerate(PERCENTS):
        rows = [c for c in folded if c["fold_percent"] == percent]
        y = [files.index(c["file"]) + 0.2 * (k - 1) for c in rows]
        left.semilogx([max(c["miss_max_deg"], 1e-9) for c in rows], y, "o", color=f"C{k}",
                      ms=4, label=f"{percent} %")
        right.barh(y, [c["seconds"] for c in rows], 0.2, color=f"C{k}")
    left.set_yticks(range(len(files)), files, fontsize=7)
    left.invert_yaxis()
    left.axvline(1.0, color="grey", lw=0.5)
    left.set_xlabel("largest miss of a driven crease, ° (grey: 1°, the warning's)")
    right.set_xlabel("wall seconds (median)")
    left.legend(fontsize=7)
    fig.suptitle(f"tests/data/real/, sheet {SHEET:g} mm, H = {H:g} mm, default strategy"
                 + (f", elastic cells {CELL:g} mm" if data.get("elastic_cells_mm")
                    or data.get("meta", {}).get("elastic_cells_mm")
                    else ""), fontsize=9)
    _meta.save(fig, path)


def main() -> None:
    p = _meta.parser(__doc__)
    p.add_argument("--elastic", action="store_true", help="elastic panels (module docstring)")
    args = p.parse_args()
    name = "real_patterns_elastic" if args.elastic else "real_patterns"
    if _meta.stored(name, args, table, plot):
        return
    runs = 1 if args.quick else RUNS
    run_one(CORPUS / "diagonal-cp.fold", 30)  # warm-up: numba cache, readers
    record = _meta.Record(name, args, sheet_mm=SHEET, thickness_mm=H, runs=runs,
                          budget=ELASTIC_BUDGET if args.elastic else BUDGET,
                          elastic_cells_mm=CELL if args.elastic else None)
    data = {"cases": cases(args.elastic, args.quick, runs)}
    record.write(data, plot)
    print(table(data))


if __name__ == "__main__":
    main()
