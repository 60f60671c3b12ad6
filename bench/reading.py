"""Reading at scale (issue 18 item 5): read time and peak memory of large inputs.

Inputs (``tests/grids.py``): triangulated n × n-vertex grids, unit lattice in
mm, interior creases cycling M/V/F, border B, ``faces_vertices`` given, as
FOLD files (V = n² for n in SIZES: 10³…10⁶ vertices) in three cases —
``valid``; ``cross``: one more edge at the end crossing the last square's
diagonal; ``twin_vertex``: one more vertex on top of vertex 0 with two edges
overlapping its edges — and the valid grid as OBJ + hinge file
(``write_obj``/``write_hinges``), read with ``read_mesh``.

Each run is a fresh interpreter, so ``rss_mb``, its peak resident memory
(``VmHWM`` of /proc/self/status, MiB: the JSON objects, NumPy arrays and
GEOS geometries alike; ``ru_maxrss`` would keep the parent's across exec),
is that read's alone; ``rss_baseline_mb`` is the peak
after ``import foldcore.io`` and before the read. ``seconds`` is the wall time of
``read_fold`` / ``read_mesh`` inside the child (file read included,
interpreter start and imports not). Per size and case: one warm-up run
(discarded: page cache, .pyc), then RUNS runs; the median is reported.

``--before SRC`` also times another source tree (e.g. the main checkout's
``src``, the code before this change), interleaved run by run with this
one so load changes hit both: RUNS runs while its reads are fast, then
one without warm-up once a size took more than 10 s; at 10⁶ vertices only
the valid and crossing FOLD grids (the old reads take minutes each; see
``reference_plan``). The machine is shared:
``others_busy`` is the share of all cores other processes used during the
run (from /proc/stat, this child's CPU time subtracted).

Run: ``.venv/bin/python bench/reading.py [--before ../main/src]``
(~25 min with --before). Writes bench/results/reading.json and .png;
``--plot`` redraws the PNG from the JSON; ``--inputs DIR`` keeps the
generated files there (and reuses them: generating takes minutes).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = Path(__file__).parent / "results"
SIZES = (32, 100, 317, 1000)
FOLD_CASES = ("valid", "cross", "twin_vertex")
RUNS = 3
#: A reference ("before") read slower than SLOW_S / 6 at one size runs once at the next.
SLOW_S = 60.0
#: At this many vertices and more the reference runs only on these inputs.
BEFORE_ONLY_ABOVE = 10**6
BEFORE_BIG = {("fold", "valid"), ("fold", "cross")}
CHILD_TIMEOUT_S = 1800

PROBE = """
import json, sys, time, warnings
warnings.simplefilter("ignore")
import foldcore
import foldcore.io as fio
from foldcore.errors import PatternError


def peak_mb():  # this process image's own high-water mark (ru_maxrss keeps the parent's)
    with open("/proc/self/status") as fh:
        return next(int(l.split()[1]) for l in fh if l.startswith("VmHWM")) / 1024


kind, path = sys.argv[1], sys.argv[2]
rss0 = peak_mb()
t = time.perf_counter()
try:
    p = fio.read_fold(path) if kind == "fold" else fio.read_mesh(path)
    outcome = f"read: {p.n_vertices} vertices, {p.n_edges} edges, {len(p.faces)} faces"
except PatternError as exc:
    outcome = "refused: " + str(exc).split(": ", 1)[1]
seconds = time.perf_counter() - t
print(json.dumps({"seconds": seconds, "outcome": outcome, "rss_baseline_mb": rss0,
                  "rss_mb": peak_mb(), "file": foldcore.__file__}))
"""


def write_inputs(folder: Path, sizes) -> list[dict]:
    """Every input file; rows of (format, case, n, vertices, path, bytes)."""
    sys.path.insert(0, str(ROOT / "tests"))
    from grids import grid_fold

    from foldcore.io import write_hinges, write_obj
    from foldcore.io.fold import pattern_from_fold_dict

    inputs = []
    for n in sizes:
        for case in FOLD_CASES:
            path = folder / f"grid{n}_{case}.fold"
            if not path.exists():
                path.write_text(json.dumps(grid_fold(n, flaw=None if case == "valid" else case)))
            inputs.append({"format": "fold", "case": case, "n": n, "path": str(path)})
        path = folder / f"grid{n}.obj"
        if not path.with_suffix(".hinges").exists():
            pattern = pattern_from_fold_dict(grid_fold(n), "grid")
            write_obj(path, pattern)
            write_hinges(path.with_suffix(".hinges"), pattern)
            del pattern
        inputs.append({"format": "obj", "case": "valid", "n": n, "path": str(path)})
    for row in inputs:
        row["vertices"] = row["n"] ** 2
        row["bytes"] = os.path.getsize(row["path"])
        if row["format"] == "obj":
            row["bytes"] += os.path.getsize(Path(row["path"]).with_suffix(".hinges"))
    return inputs


def run_child(src: Path, kind: str, path: str) -> dict:
    sys.path.insert(0, str(Path(__file__).parent))
    from scaling import busy_seconds

    env = dict(os.environ, PYTHONPATH=str(src))
    start, busy0 = time.perf_counter(), busy_seconds()
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run([sys.executable, "-c", PROBE, kind, path], capture_output=True,
                          text=True, env=env, timeout=CHILD_TIMEOUT_S, check=True)
    wall = time.perf_counter() - start
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    own = cpu1.ru_utime + cpu1.ru_stime - cpu0.ru_utime - cpu0.ru_stime
    row = json.loads(proc.stdout.strip().splitlines()[-1])
    assert row["file"].startswith(str(src)), (row["file"], src)
    row["others_busy"] = max(0.0, (busy_seconds() - busy0 - own) / (wall * os.cpu_count()))
    return row


def summary(runs: list[dict]) -> dict:
    return {"seconds": statistics.median(r["seconds"] for r in runs),
            "rss_mb": statistics.median(r["rss_mb"] for r in runs),
            "rss_baseline_mb": statistics.median(r["rss_baseline_mb"] for r in runs),
            "others_busy": statistics.median(r["others_busy"] for r in runs),
            "outcome": runs[0]["outcome"], "runs": len(runs),
            "seconds_runs": [r["seconds"] for r in runs],
            "rss_mb_runs": [r["rss_mb"] for r in runs]}


def measure(row: dict, trees: dict, once: set) -> dict:
    """Warm-up + RUNS interleaved runs of each source tree on one input; the trees
    named in ``once`` run once, without warm-up."""
    runs = {name: [] for name in trees}
    for name, src in trees.items():
        if name not in once:
            run_child(src, row["format"], row["path"])  # warm-up, discarded
    for i in range(RUNS):
        for name, src in trees.items():
            if not (i and name in once):
                runs[name].append(run_child(src, row["format"], row["path"]))
    return {name: summary(r) for name, r in runs.items()}


def reference_plan(row: dict, trees: dict, previous: dict | None) -> tuple[dict, set]:
    """The trees to run on ``row`` and those to run once: the reference tree once
    after its previous size took more than SLOW_S / 6, and at 10⁶ vertices only
    on the valid and crossing FOLD grids (its reads take minutes there)."""
    if "before" not in trees:
        return trees, set()
    if row["vertices"] >= BEFORE_ONLY_ABOVE and (row["format"], row["case"]) not in BEFORE_BIG:
        return {"after": trees["after"]}, set()
    slow = previous is not None and previous.get("before", {}).get("seconds", 0) > SLOW_S / 6
    return trees, {"before"} if slow else set()


def plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(11, 4.2))
    styles = {"valid": "o-", "cross": "s--", "twin_vertex": "^:"}
    for fmt in ("fold", "obj"):
        for case, style in styles.items():
            for name, color in (("after", "C0" if fmt == "fold" else "C2"), ("before", "C3")):
                pts = [(r["vertices"], r[name]) for r in rows
                       if r["format"] == fmt and r["case"] == case and name in r]
                if not pts:
                    continue
                x = [p[0] for p in pts]
                label = f"{fmt} {case} ({'now' if name == 'after' else 'before'})"
                kw = {"color": color if fmt == "fold" or name == "after" else "C1",
                      "label": label}
                ax_t.loglog(x, [p[1]["seconds"] for p in pts], style, **kw)
                ax_m.loglog(x, [p[1]["rss_mb"] for p in pts], style, **kw)
    for ax, what in ((ax_t, "read time, s (median)"), (ax_m, "peak RSS of the process, MB")):
        ax.set_xlabel("vertices")
        ax.set_ylabel(what)
        ax.grid(True, which="both", alpha=0.3)
    ax_t.axhline(2, color="grey", lw=0.8)
    ax_t.axhline(20, color="grey", lw=0.8)
    ax_m.legend(fontsize=7)
    fig.suptitle("Reading triangulated grids (bench/reading.py)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--before", type=Path, help="another source tree to time alongside")
    parser.add_argument("--plot", action="store_true", help="redraw reading.png from the JSON")
    parser.add_argument("--inputs", type=Path, help="keep (and reuse) the input files here")
    parser.add_argument("--sizes", type=int, nargs="+", default=SIZES,
                        help="grid sides n (V = n²); default %(default)s")
    args = parser.parse_args()
    if args.plot:
        plot(json.loads((RESULTS / "reading.json").read_text())["rows"], RESULTS / "reading.png")
        return
    sys.path.insert(0, str(Path(__file__).parent))
    from _meta import machine_meta

    trees = {"after": ROOT / "src"}
    if args.before is not None:
        trees["before"] = args.before.resolve()
    rows, previous = [], {}
    with tempfile.TemporaryDirectory(prefix="foldcore-reading-") as tmp:
        folder = args.inputs or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        for row in write_inputs(folder, args.sizes):
            key = (row["format"], row["case"])
            result = measure(row, *reference_plan(row, trees, previous.get(key)))
            previous[key] = result
            rows.append({k: v for k, v in row.items() if k != "path"} | result)
            if "before" in result:
                rows[-1]["same_outcome"] = result["before"]["outcome"] == \
                    result["after"]["outcome"]
            print(f"{row['format']} {row['case']:11s} V={row['vertices']:>8d}: " + ", ".join(
                f"{name} {r['seconds']:.2f} s {r['rss_mb']:.0f} MB (busy {r['others_busy']:.2f})"
                for name, r in result.items()) + f" — {result['after']['outcome']}", flush=True)
    data = {"meta": {**machine_meta(), "runs": RUNS, "slow_s": SLOW_S, "sizes_n": list(args.sizes),
                     "before": str(args.before) if args.before else None,
                     "input": "tests/grids.py grid_fold(n), unit lattice, mm, faces given",
                     "units": {"seconds": "s", "rss_mb": "MiB (VmHWM)"}},
            "rows": rows}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "reading.json").write_text(json.dumps(data, indent=1))
    plot(rows, RESULTS / "reading.png")


if __name__ == "__main__":
    main()
