"""Reading at scale: read time and peak memory of large inputs; and a folder of SVGs.

Inputs (``tests/grids.py``): triangulated n × n-vertex grids, unit lattice in
mm, interior creases cycling M/V/F, border B, ``faces_vertices`` given, as
FOLD files (V = n² for n in SIZES: 10³…10⁶ vertices) in three cases —
``valid``; ``cross``: one more edge at the end crossing the last square's
diagonal; ``twin_vertex``: one more vertex on top of vertex 0 with two edges
overlapping its edges — and the valid grid as OBJ + hinge file (written
with ``foldcore.io.write_obj`` / ``write_hinges``). Every input is read with
:func:`foldcore.read`.

Each run is a fresh interpreter, so ``rss_mb``, its peak resident memory
(``VmHWM`` of /proc/self/status, MiB: the JSON objects, NumPy arrays and
GEOS geometries alike), is that read's alone. ``rss_imports_mb`` is the peak
after ``import foldcore`` and its readers; ``rss_baseline_mb`` the peak
after first reads of a 3 × 3 grid in the same format and of a 3 × 3 FOLD grid
with a twin vertex (refused), which load what a read loads on first use
(SciPy's sparse graphs, shapely, GEOS's overlap test: ~32 MB, whatever the
file). ``ratio`` is the read's memory above that baseline per byte of
input (``(rss_mb − rss_baseline_mb)`` MiB / ``bytes`` MiB; OBJ: mesh and
hinge file). ``seconds`` is the wall time of ``foldcore.read`` inside the
child (file read included, interpreter start, imports and the first read
not). Per size and case: one warm-up run (discarded: page cache, .pyc), then
RUNS runs; the median is reported.

``--before SRC`` also times another source tree (e.g. the main checkout's
``src``, the code before a change), interleaved run by run with this one so
load changes hit both: RUNS runs while its reads are fast, one without
warm-up once a size took more than SLOW_S / 6, and at 10⁶ vertices only on
the valid and crossing FOLD grids unless ``--cases`` names the inputs
(e.g. ``--sizes 1000 --cases valid twin_vertex``). ``others_busy`` is the
share of all cores other processes used during each run.

``--svgs DIR`` reads instead every SVG under DIR (or the ``assets/`` of a
bare git directory, e.g. Origami Simulator's) in this process, after one
warm-up read, and sorts each into read (vertices, edges, seconds) or
refused, grouped by the kind of its one-line message, or crashed (any other
exception: the reader's bug); each file read is thickened too at
``THICK_MM`` (``foldcore.thicken``'s defaults): built, built with hinges
narrowed to fit small faces, or refused by the first words of its message;
writes bench/results/reading_svgs.json.

Run: ``python bench/reading.py [--before ../main/src]`` (~25 min with
--before) or ``--quick``; writes bench/results/reading.json and .png;
``--inputs DIR`` keeps the generated files there (and reuses them:
generating takes minutes); ``--table`` prints the table of
docs/benchmarks.md from the JSON.
"""
from __future__ import annotations

import collections
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import _meta

SIZES = (32, 100, 317, 1000)
QUICK_SIZES, QUICK_RUNS = (10, 32), 2
FOLD_CASES = ("valid", "cross", "twin_vertex")
RUNS = 3
#: A reference ("before") read slower than SLOW_S / 6 at one size runs once at the next.
SLOW_S = 60.0
#: At this many vertices and more the reference runs only on BEFORE_BIG (unless --cases).
BEFORE_ONLY_ABOVE = 10**6
BEFORE_BIG = {("fold", "valid"), ("fold", "cross")}
CHILD_TIMEOUT_S = 1800
#: kinds of SVG refusal, by a phrase of the message
KINDS = (("curved", "curved"), ("overlap", "overlap with different"),
         ("not connected", "not connected"), ("boundary/faces", "boundary"),
         ("boundary/faces", "both sides"), ("dangling", "dangling"),
         ("not an SVG", "not a readable SVG"))

PROBE = """
import json, sys, time, warnings
warnings.simplefilter("ignore")
import foldcore
read = foldcore.read  # imports the readers


def peak_mb():  # this process image's own high-water mark (ru_maxrss keeps the parent's)
    with open("/proc/self/status") as fh:
        return next(int(l.split()[1]) for l in fh if l.startswith("VmHWM")) / 1024


path, firsts = sys.argv[1], sys.argv[2:]
rss_imports = peak_mb()
for first in firsts:  # 3 x 3 grids: what a read loads on first use
    try:
        read(first)
    except foldcore.PatternError:
        pass
rss0 = peak_mb()
t = time.perf_counter()
try:
    p = read(path)
    outcome = f"read: {p.n_vertices} vertices, {p.n_edges} edges, {len(p.faces)} faces"
except foldcore.PatternError as exc:
    outcome = "refused: " + str(exc).split(": ", 1)[1]
seconds = time.perf_counter() - t
print(json.dumps({"seconds": seconds, "outcome": outcome, "rss_imports_mb": rss_imports,
                  "rss_baseline_mb": rss0, "rss_mb": peak_mb(), "file": foldcore.__file__}))
"""


def write_inputs(folder: Path, sizes, cases) -> list[dict]:
    """Every input file; rows of (format, case, n, vertices, path, bytes)."""
    sys.path.insert(0, str(_meta.ROOT / "tests"))
    from grids import grid_fold

    import foldcore
    from foldcore.io import write_hinges, write_obj

    first = {"fold": folder / "first.fold", "obj": folder / "first.obj",
             "twin": folder / "first_twin_vertex.fold"}  # the first reads of each child
    if not first["obj"].with_suffix(".hinges").exists():
        first["fold"].write_text(json.dumps(grid_fold(3)))
        first["twin"].write_text(json.dumps(grid_fold(3, flaw="twin_vertex")))
        write_obj(first["obj"], foldcore.read(first["fold"]))
        write_hinges(first["obj"].with_suffix(".hinges"), foldcore.read(first["fold"]))
    inputs = []
    for n in sizes:
        for case in FOLD_CASES:
            path = folder / f"grid{n}_{case}.fold"
            if not path.exists() and (case in cases or case == "valid" and "obj" in cases):
                path.write_text(json.dumps(grid_fold(n, flaw=None if case == "valid" else case)))
            if case in cases:
                inputs.append({"format": "fold", "case": case, "n": n, "path": str(path)})
        path = folder / f"grid{n}.obj"
        if "obj" in cases:
            if not path.with_suffix(".hinges").exists():
                pattern = foldcore.read(folder / f"grid{n}_valid.fold")
                write_obj(path, pattern)
                write_hinges(path.with_suffix(".hinges"), pattern)
                del pattern
            inputs.append({"format": "obj", "case": "valid", "n": n, "path": str(path)})
    for row in inputs:
        row["first"] = [str(first[row["format"]]), str(first["twin"])]
        row["vertices"] = row["n"] ** 2
        row["bytes"] = os.path.getsize(row["path"])
        if row["format"] == "obj":
            row["bytes"] += os.path.getsize(Path(row["path"]).with_suffix(".hinges"))
    return inputs


def run_child(src: Path, path: str, first: list) -> dict:
    """One read of ``path`` by the tree ``src`` in a fresh interpreter, after reads of
    the files ``first`` (module docstring), with the load."""
    env = dict(os.environ, PYTHONPATH=str(src))
    start, busy0 = time.perf_counter(), _meta.busy_seconds()
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.run([sys.executable, "-c", PROBE, path, *first], capture_output=True,
                          text=True, env=env, timeout=CHILD_TIMEOUT_S, check=True)
    wall = time.perf_counter() - start
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    own = cpu1.ru_utime + cpu1.ru_stime - cpu0.ru_utime - cpu0.ru_stime
    row = json.loads(proc.stdout.strip().splitlines()[-1])
    assert row["file"].startswith(str(src)), (row["file"], src)
    row["others_busy"] = max(0.0, (_meta.busy_seconds() - busy0 - own) / (wall * os.cpu_count()))
    return row


def summary(runs: list[dict]) -> dict:
    return {"seconds": _meta.median(r["seconds"] for r in runs),
            "rss_mb": _meta.median(r["rss_mb"] for r in runs),
            "rss_imports_mb": _meta.median(r["rss_imports_mb"] for r in runs),
            "rss_baseline_mb": _meta.median(r["rss_baseline_mb"] for r in runs),
            "others_busy": _meta.median(r["others_busy"] for r in runs),
            "outcome": runs[0]["outcome"], "runs": len(runs),
            "seconds_runs": [r["seconds"] for r in runs],
            "rss_mb_runs": [r["rss_mb"] for r in runs]}


def measure(row: dict, trees: dict, once: set, runs: int) -> dict:
    """Warm-up + ``runs`` interleaved runs of each source tree on one input; the trees
    named in ``once`` run once, without warm-up."""
    done = {name: [] for name in trees}
    for name, src in trees.items():
        if name not in once:
            run_child(src, row["path"], row["first"])  # warm-up, discarded
    for i in range(runs):
        for name, src in trees.items():
            if not (i and name in once):
                done[name].append(run_child(src, row["path"], row["first"]))
    return {name: summary(r) for name, r in done.items()}


def reference_plan(row: dict, trees: dict, previous: dict | None,
                   chosen: bool) -> tuple[dict, set]:
    """The trees to run on ``row`` and those to run once: the reference tree once after
    its previous size took more than SLOW_S / 6, and at 10⁶ vertices only on the valid
    and crossing FOLD grids (its reads take minutes there) unless the cases were
    ``chosen`` on the command line."""
    if "before" not in trees:
        return trees, set()
    if (not chosen and row["vertices"] >= BEFORE_ONLY_ABOVE
            and (row["format"], row["case"]) not in BEFORE_BIG):
        return {"after": trees["after"]}, set()
    slow = previous is not None and previous.get("before", {}).get("seconds", 0) > SLOW_S / 6
    return trees, {"before"} if slow else set()


def grids(args, trees: dict) -> list:
    """Every grid input measured (module docstring)."""
    sizes = args.sizes or (QUICK_SIZES if args.quick else SIZES)
    cases = args.cases or (*FOLD_CASES, "obj")
    rows, previous = [], {}
    with tempfile.TemporaryDirectory(prefix="foldcore-reading-") as tmp:
        folder = args.inputs or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        for row in write_inputs(folder, sizes, cases):
            key = (row["format"], row["case"])
            plan = reference_plan(row, trees, previous.get(key), bool(args.cases))
            result = measure(row, *plan, QUICK_RUNS if args.quick else RUNS)
            previous[key] = result
            rows.append({k: v for k, v in row.items() if k not in ("path", "first")}
                        | result)
            for r in result.values():
                r["ratio"] = ratio(r, row["bytes"])
            if "before" in result:
                rows[-1]["same_outcome"] = result["before"]["outcome"] == \
                    result["after"]["outcome"]
            print(f"{row['format']} {row['case']:11s} V={row['vertices']:>8d}: " + ", ".join(
                f"{name} {r['seconds']:.2f} s {r['rss_mb']:.0f} MB (busy {r['others_busy']:.2f})"
                for name, r in result.items()) + f" — {result['after']['outcome']}", flush=True)
    return rows


def svg_files(source: Path, into: Path) -> list[Path]:
    """The SVGs under ``source``, a folder or a bare git directory (its ``assets/``
    extracted into ``into``)."""
    if (source / "HEAD").exists() and (source / "objects").is_dir():
        git = ["git", "--git-dir", str(source)]
        names = subprocess.run([*git, "ls-tree", "-r", "--name-only", "HEAD", "assets"],
                               capture_output=True, text=True, check=True).stdout.split("\n")
        archive = subprocess.run([*git, "archive", "HEAD", *[n for n in names
                                                             if n.endswith(".svg")]],
                                 capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
        source = into
    return sorted(source.rglob("*.svg"))


#: Thickness (mm) at which ``--svgs`` thickens each file read.
THICK_MM = 1.0


def thick_outcome(pattern) -> str:
    """``built``, ``built, narrowed`` or the start of the refusal of ``pattern``
    thickened at :data:`THICK_MM`."""
    import foldcore

    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        try:
            foldcore.thicken(pattern, THICK_MM)
        except foldcore.FoldcoreError as exc:
            words = re.sub(r"\d+(\.\d+)?", "N", str(exc).split(": ", 1)[-1])
            return "refused: " + re.sub(r"\(.*", "", words).split(";")[0].strip()[:60]
    return "built, narrowed" if any("narrowed" in str(w.message) for w in said) else "built"


def read_svg(path: Path) -> dict:
    """One SVG read in this process: read, refused (by kind) or crashed; seconds; and
    what thickening it does (:func:`thick_outcome`)."""
    import foldcore

    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            p = foldcore.read(path)
            entry = {"read": True, "vertices": int(p.n_vertices), "edges": int(p.n_edges)}
        except foldcore.FoldcoreError as exc:
            message = str(exc).split(": ", 1)[-1]
            entry = {"read": False, "kind": next((k for k, needle in KINDS
                                                  if needle in message), "other"),
                     "message": message}
        except Exception as exc:  # noqa: BLE001  (a crash is the reader's bug: counted)
            entry = {"read": False, "kind": "crash", "message": repr(exc)}
    entry["seconds"] = time.perf_counter() - start
    if entry["read"]:
        entry["thick"] = thick_outcome(p)
    return entry


def svgs(args) -> None:
    """``--svgs``: every SVG of a folder through the reader (module docstring)."""
    record = _meta.Record("reading_svgs", args, source=str(args.svgs))
    with tempfile.TemporaryDirectory() as tmp:
        files = svg_files(args.svgs, Path(tmp))
        if files:
            read_svg(files[0])  # warm-up: imports, shapely
        each = [{"file": str(p.relative_to(p.parents[1])).replace("/", "__"), **read_svg(p)}
                for p in files]
    counts = collections.Counter("read" if e["read"] else "refused: " + e["kind"]
                                 for e in each)
    thick = collections.Counter(e["thick"] for e in each if e["read"])
    record.write({"files": len(each), "counts": dict(counts), "thick_mm": THICK_MM,
                  "thick_counts": dict(thick), "each": each})
    print(json.dumps({"read": dict(counts), f"thickened at {THICK_MM:g} mm": dict(thick)},
                     indent=1))


def plot(data: dict, path: Path) -> None:
    plt = _meta.pyplot()
    rows = data["rows"]
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
    ax_m.legend(fontsize=7)
    fig.suptitle("Reading triangulated grids (bench/reading.py)")
    _meta.save(fig, path)


def ratio(result: dict, size: int) -> float:
    """A read's peak memory above its baseline per byte of input (module docstring)."""
    return (result["rss_mb"] - result["rss_baseline_mb"]) * 2 ** 20 / size


def table(data: dict) -> str:
    """Per input: vertices, file size, read seconds, peak RSS and its ratio to the file
    size (and the reference tree's), outcome."""
    before = any("before" in r for r in data["rows"])
    rows = []
    for r in data["rows"]:
        a = r["after"]
        cells = [f"{r['format'].upper()} {r['case'].replace('_', ' ')}", f"{r['vertices']:,}",
                 _meta.sig(r["bytes"] / 2 ** 20), _meta.sig(a["seconds"]), f"{a['rss_mb']:.0f}",
                 f"{ratio(a, r['bytes']):.1f}"]
        if before:
            b = r.get("before")
            cells += ["—", "—", "—"] if b is None else [
                _meta.sig(b["seconds"]) + (" (1 run)" if b["runs"] == 1 else ""),
                f"{b['rss_mb']:.0f}", f"{ratio(b, r['bytes']):.1f}"]
        rows.append(cells + [a["outcome"].split(":")[0]])
    header = ["input", "vertices", "file (MiB)", "read (s)", "peak RSS (MiB)",
              "above baseline ÷ file"]
    header += ["before: read (s)", "before: peak RSS (MiB)", "before: ÷ file"] if before else []
    return _meta.markdown_table(header + ["outcome"], rows)


def svgs_table(data: dict) -> str:
    """Files read, refused by kind, and crashed, of ``--svgs``."""
    counts = dict(data["counts"])
    crashed = counts.pop("refused: crash", 0)
    rows = sorted(counts.items(), key=lambda kv: (kv[0] != "read", -kv[1]))
    table = _meta.markdown_table(["outcome", "files"],
                                 [[k, str(v)] for k, v in rows + [("crashed", crashed)]])
    thick = sorted(data.get("thick_counts", {}).items(), key=lambda kv: -kv[1])
    if thick:
        table += "\n\n" + _meta.markdown_table(
            [f"thickened at {data['thick_mm']:g} mm", "files"], [[k, str(v)] for k, v in thick])
    return table


def main() -> None:
    parser = _meta.parser(__doc__)
    parser.add_argument("--before", type=Path, help="another source tree to time alongside")
    parser.add_argument("--inputs", type=Path, help="keep (and reuse) the input files here")
    parser.add_argument("--sizes", type=int, nargs="+", help="grid sides n (V = n²)")
    parser.add_argument("--cases", nargs="+", choices=(*FOLD_CASES, "obj"),
                        help="only these inputs (obj: the valid grid as OBJ + hinges)")
    parser.add_argument("--svgs", type=Path, help="read every SVG of this folder instead")
    args = parser.parse_args()
    if args.svgs is not None:
        svgs(args)
        return
    if _meta.stored("reading", args, table, plot):
        if args.table and (args.out or _meta.RESULTS).joinpath("reading_svgs.json").exists():
            print("\n" + svgs_table(_meta.load_json("reading_svgs", args)))
        return
    trees = {"after": _meta.ROOT / "src"}
    if args.before is not None:
        trees["before"] = args.before.resolve()
    record = _meta.Record("reading", args, runs=QUICK_RUNS if args.quick else RUNS,
                          slow_s=SLOW_S, before=str(args.before) if args.before else None,
                          input="tests/grids.py grid_fold(n), unit lattice, mm, faces given",
                          units={"seconds": "s", "rss_mb": "MiB (VmHWM)",
                                 "ratio": "(rss_mb - rss_baseline_mb) MiB / input MiB"})
    rows = grids(args, trees)
    record.meta["sizes_n"] = sorted({r["n"] for r in rows})
    record.write({"rows": rows}, plot)
    print(table({"rows": rows}))


if __name__ == "__main__":
    main()
