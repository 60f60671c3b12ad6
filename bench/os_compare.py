"""foldcore's thin sheet against Origami Simulator's own settled shapes, its whole library.

Reads the states ``bench/os_library.py`` recorded (tests/data/origami_simulator/:
Origami Simulator's node positions once settled at 30, 60 and 90 %, its mesh,
its stepping time) and, for every file and fold percent where Origami
Simulator settled (its state (b)):

* **model**: foldcore's thin sheet (``foldcore.sheet``) built on Origami
  Simulator's own mesh — its triangulated FOLD data: the same vertices,
  triangles, creases and facet diagonals — folded from flat to the default
  tolerance. Only the models and the solvers differ.
* **end to end**: the SVG as a user gives it, read by ``foldcore.io.read`` and
  folded as ``foldcore simulate FILE.svg`` folds it (no thickness: the thin
  sheet), its vertices matched to Origami Simulator's by position (both
  normalised to a unit bounding radius, within ``MATCH``, one to one). A file
  whose vertices the two readers do not agree on is reported as not matched.

Shape difference: the largest and the median |Δφ| over the M/V creases,
degrees, both sheets measured by Origami Simulator's own signed dihedral angle
(``os_library.fold_angles``). Time: foldcore's in-process fold (the median of
``RUNS`` runs, warm kernels) against Origami Simulator's stepping seconds to
(a) mean strain < 0.01 % and to (b) still, from the same states; and once per
file the whole ``foldcore simulate FILE.svg --fold-percent 90 -q`` process
(start-up included) against Origami Simulator's read time plus its (b) at 90 %.
Origami Simulator's times come from the run that recorded the states, so the
ratios are of two runs on the same machine, not interleaved. Folds where
Origami Simulator did not settle have no shape to compare with: foldcore's
fold of the file (its reader, one run) is timed alone.

Writes bench/results/os_compare.json and .png (foldcore's time against Origami
Simulator's, and the shape differences). Run: ``python bench/os_compare.py``
(a few minutes); ``--quick``: the files of ``os_library.QUICK_FILES``;
``--table`` prints the tables of docs/benchmarks.md.
"""
from __future__ import annotations

import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

import _meta
import origami_simulator as osim
import os_library as osl

MATCH = 1e-2   # vertices of the two readers this close (unit bounding radius) are one
RUNS = 3
CLI_PERCENT = 90
CLI_LIMIT_S = 120.0  # a whole CLI run stopped past this is recorded as None


def pattern_of_mesh(state: dict):
    """The CreasePattern of Origami Simulator's triangulated FOLD data: vertex i is its
    node i, in foldcore's plane (x, −z) of the SVG's units."""
    from foldcore.pattern import CreasePattern

    fold = state["fold"]
    xy = fold["vertices_coords"][:, [0, 2]] * [1.0, -1.0]
    edges = fold.get("edges_vertices", state["beams"])   # stored once when they are equal
    faces = fold.get("faces_vertices", state["faces"])
    return CreasePattern(xy, edges, fold["edges_assignment"], fold_angles=fold["edges_foldAngle"],
                         faces=[np.asarray(f) for f in faces], source=state["svg"])


def to_os_frame(positions: np.ndarray) -> np.ndarray:
    """foldcore's positions (x, −z, y) back in Origami Simulator's axes (x, y, z)."""
    return np.column_stack([positions[:, 0], positions[:, 2], -positions[:, 1]])


def normalised(xy: np.ndarray) -> np.ndarray:
    centre = 0.5 * (xy.min(axis=0) + xy.max(axis=0))
    return (xy - centre) / np.sqrt(np.max(np.sum((xy - centre) ** 2, axis=1)))


def match(pattern, state: dict, drawn=None):
    """((the pattern vertex of each node of foldcore's sheet, Origami Simulator's node
    of each), largest gap) or (None, gap): the sheet leaves out straight degree-2
    vertices as Origami Simulator does, so its nodes, not the pattern's vertices,
    are matched."""
    from scipy.spatial import cKDTree
    from foldcore.sheet import build_sheet

    theirs = normalised(state["fold"]["vertices_coords"][:, [0, 2]] * [1.0, -1.0])
    vertices = np.asarray(pattern.vertices, dtype=float)
    sheet = build_sheet(pattern, merge_straight=True, drawn=drawn)
    kept = sheet.vertex_ids
    mine = normalised(vertices)[kept]
    k = min(4, len(theirs))
    gaps, near = cKDTree(theirs).query(mine, k=k)
    gaps, near = gaps.reshape(len(mine), k), near.reshape(len(mine), k)
    # vertices at one point (the two sides of a cut): the one whose faces lie the same way
    fans = fan_directions(mine, sheet.triangles) @ fan_directions(theirs, state["faces"]).T \
        if k > 1 and (gaps[:, 1] - gaps[:, 0] < 1e-9).any() else None
    idx = near[:, 0].copy()
    for i in np.flatnonzero(gaps[:, 1] - gaps[:, 0] < 1e-9) if fans is not None else []:
        tied = near[i][gaps[i] - gaps[i, 0] < 1e-9]
        idx[i] = tied[np.argmax(fans[i, tied])]
    gap = float(gaps[:, 0].max())
    one_to_one = len(idx) == len(theirs) and len(np.unique(idx)) == len(idx)
    return ((kept, idx) if gap <= MATCH and one_to_one else None), gap


def fan_directions(points: np.ndarray, triangles) -> np.ndarray:
    """(N, 2) unit vector from each point towards the mean centroid of its triangles."""
    triangles = np.asarray(triangles, dtype=np.int64)
    centroid = points[triangles].mean(axis=1)
    total, count = np.zeros_like(points), np.zeros(len(points))
    for corner in range(3):
        np.add.at(total, triangles[:, corner], centroid)
        np.add.at(count, triangles[:, corner], 1.0)
    d = total / np.maximum(count, 1.0)[:, None] - points
    return d / np.maximum(np.linalg.norm(d, axis=1), 1e-300)[:, None]


def fold(pattern, percent: float, runs: int, drawing=None):
    """(SheetFold, median seconds) of ``runs`` folds of ``pattern`` from flat
    (``drawing``: the vertices as drawn of a pattern read from an SVG, built as
    ``simulate`` builds it)."""
    from foldcore.sheet import SheetSolver, build_sheet

    seconds, result = [], None
    for _ in range(runs):
        t0 = time.perf_counter()
        result = SheetSolver(build_sheet(pattern, merge_straight=drawing is not None,
                                         drawn=drawing), percent,
                             pattern_edges=pattern.n_edges).run()
        seconds.append(time.perf_counter() - t0)
    return result, _meta.median(seconds)


def difference(state, entry, positions) -> dict:
    """Largest and median |Δφ| (degrees) over the M/V creases, and their count."""
    theirs = osl.fold_angles(state, entry["positions_b"])
    mine = osl.fold_angles(state, positions)
    delta = np.abs((mine - theirs + 180.0) % 360.0 - 180.0)
    return {"max_deg": float(delta.max()) if len(delta) else 0.0,
            "median_deg": float(np.median(delta)) if len(delta) else 0.0,
            "creases": int(len(delta))}


def one_file(path: Path, svgs: Path, runs: int) -> dict:
    """Every comparison of one state file (module docstring)."""
    from foldcore.io import read_file

    state = osl.load_state(path)
    row = {"svg": state["svg"], "nodes": int(len(state.get("nodes", []))), "folds": []}
    if "error" in state:
        return {**row, "os_error": state["error"]}
    row["ties_through_lowest"], row["ties_otherwise"] = tied_quadrilaterals(state)
    svg = svgs / state["svg"]
    try:
        mesh_pattern = pattern_of_mesh(state)
    except Exception as exc:  # a mesh foldcore's pattern refuses (cut sheets)
        mesh_pattern, row["mesh_error"] = None, f"{type(exc).__name__}: {exc}"[:200]
    try:
        loaded = read_file(svg)
        user_pattern, drawn = loaded.pattern, loaded.drawing
        nodes, row["gap"] = match(user_pattern, state, drawn)
    except Exception as exc:  # the reader's refusal, said in one line
        user_pattern, drawn, nodes, row["read_error"] = None, None, None, str(exc)[len(str(svg)) + 2:][:200]
    row["matched"] = nodes is not None
    for entry in state["folds"]:
        if entry.get("positions_b") is None or not entry["settled"]:
            if user_pattern is not None:  # no shape to compare with: foldcore's time alone
                result, seconds = fold(user_pattern, entry["percent"], 1, drawing=drawn)
                row["folds"].append({"percent": entry["percent"], "unsettled_os": {
                    "reason": result.reason, "iterations": result.iterations,
                    "seconds": seconds}})
            continue
        out = {"percent": entry["percent"], "os_still_s": entry["b_seconds"],
               "os_strain_s": entry["a_seconds"]}
        if mesh_pattern is not None:
            result, seconds = fold(mesh_pattern, entry["percent"], runs)
            out["model"] = {**difference(state, entry, to_os_frame(result.positions)),
                            "reason": result.reason, "iterations": result.iterations,
                            "seconds": seconds}
        if nodes is not None:
            result, seconds = fold(user_pattern, entry["percent"], runs, drawing=drawn)
            kept, theirs = nodes
            positions = np.empty((len(theirs), 3))
            positions[theirs] = to_os_frame(result.positions[kept])
            out["end_to_end"] = {**difference(state, entry, positions),
                                 "reason": result.reason, "iterations": result.iterations,
                                 "seconds": seconds}
        row["folds"].append(out)
    if user_pattern is not None:
        row["cli_s"] = _meta.cli_seconds(["simulate", svg, "--fold-percent", CLI_PERCENT, "-q"],
                                         CLI_LIMIT_S, check=True)
        row["os_load_s"] = state.get("load_seconds")
    return row


def tied_quadrilaterals(state: dict) -> tuple[int, int]:
    """(cut through their lowest vertex id, cut otherwise): Origami Simulator's
    quadrilaterals whose diagonals tie (within ``foldcore.sheet.build.TIE``), from
    its faces before and after it cut them."""
    from foldcore.sheet.build import TIE

    raw = state.get("fold_raw", {})
    if "faces_vertices" not in raw:
        return 0, 0
    xy = raw["vertices_coords"][:, [0, 2]]
    cut = {tuple(sorted(t)) for t in np.asarray(state["faces"]).tolist()}
    through, other = 0, 0
    for face in raw["faces_vertices"]:
        if len(face) != 4:
            continue
        p = xy[face]
        d02, d13 = np.sum((p[0] - p[2]) ** 2), np.sum((p[1] - p[3]) ** 2)
        if abs(d02 - d13) > TIE * max(d02, d13):
            continue
        lowest = int(np.argmin(face))
        tri = sorted((face[lowest], face[(lowest + 1) % 4], face[(lowest + 2) % 4]))
        through += tuple(tri) in cut
        other += tuple(tri) not in cut
    return through, other


def totals(rows: list[dict]) -> dict:
    """The library in numbers: files read, matched, compared; shape differences and
    time ratios over every settled fold (medians, largest, counts)."""
    folds = [f for r in rows for f in r["folds"] if "unsettled_os" not in f]
    alone = [f["unsettled_os"] for r in rows for f in r["folds"] if "unsettled_os" in f]
    out = {"files": len(rows), "os_read": sum("os_error" not in r for r in rows),
           "foldcore_read": sum("read_error" not in r and "os_error" not in r for r in rows),
           "matched": sum(r.get("matched", False) for r in rows),
           "settled_folds": len(folds),
           "ties_through_lowest": sum(r.get("ties_through_lowest", 0) for r in rows),
           "ties_otherwise": sum(r.get("ties_otherwise", 0) for r in rows)}
    for kind in ("model", "end_to_end"):
        done = [f for f in folds if kind in f]
        if not done:
            continue
        worst = np.array([f[kind]["max_deg"] for f in done])
        ratio = np.array([f["os_still_s"] / f[kind]["seconds"] for f in done])
        out[kind] = {"folds": len(done), "median_max_deg": float(np.median(worst)),
                     "within_1deg": int(np.count_nonzero(worst <= 1.0)),
                     "converged": sum(f[kind]["reason"] == "converged" for f in done),
                     "median_speedup": float(np.median(ratio)),
                     "slower_than_os": int(np.count_nonzero(ratio < 1.0)),
                     "over_10s": int(sum(f[kind]["seconds"] > 10.0 for f in done)),
                     "largest_s": float(max(f[kind]["seconds"] for f in done))}
    cli = [(r["cli_s"], r["os_load_s"] + f["os_still_s"]) for r in rows
           for f in r["folds"] if r.get("cli_s") is not None and f["percent"] == CLI_PERCENT
           and r.get("os_load_s") is not None and "os_still_s" in f]
    if alone:
        out["unsettled_os"] = {"folds": len(alone),
                               "converged": sum(a["reason"] == "converged" for a in alone),
                               "median_s": _meta.median([a["seconds"] for a in alone]),
                               "over_10s": sum(a["seconds"] > 10.0 for a in alone),
                               "largest_s": max(a["seconds"] for a in alone)}
    out["cli_over_limit"] = sum("cli_s" in r and r["cli_s"] is None for r in rows)
    if cli:
        out["cli"] = {"files": len(cli), "median_s": _meta.median([c for c, _ in cli]),
                      "median_os_s": _meta.median([o for _, o in cli]),
                      "faster_than_os": sum(c < o for c, o in cli)}
    return out


def table(data: dict) -> str:
    """The summary table of docs/benchmarks.md."""
    t = data["totals"]
    lines = [f"{t['files']} SVGs; Origami Simulator read {t['os_read']}, foldcore "
             f"{t['foldcore_read']}, the two readers' vertices matched on {t['matched']}; "
             f"{t['settled_folds']} folds (file × percent) where Origami Simulator settled; "
             f"of its quadrilaterals with tied diagonals, {t['ties_through_lowest']} cut "
             f"through their lowest vertex id, {t['ties_otherwise']} otherwise.", ""]
    header = ["comparison", "folds", "median largest Δφ", "within 1°", "converged",
              "median speed-up vs OS", "slower than OS", "over 10 s (largest)"]
    body = []
    for kind, label in (("model", "model (OS's own mesh)"),
                        ("end_to_end", "end to end (foldcore's reader)")):
        if kind in t:
            k = t[kind]
            body.append([label, k["folds"], f"{_meta.sig(k['median_max_deg'])}°",
                         k["within_1deg"], k["converged"], f"{_meta.sig(k['median_speedup'])}×",
                         k["slower_than_os"], f"{k['over_10s']} ({_meta.sig(k['largest_s'])} s)"])
    lines.append(_meta.markdown_table(header, body))
    if "unsettled_os" in t:
        u = t["unsettled_os"]
        lines += ["", f"Folds where Origami Simulator did not settle within its limit "
                  f"(foldcore's reader, timed alone): {u['folds']}, {u['converged']} "
                  f"converged; median {_meta.sig(u['median_s'])} s, "
                  f"{u['over_10s']} over 10 s (largest {_meta.sig(u['largest_s'])} s)."]
    if "cli" in t:
        c = t["cli"]
        lines += ["", f"Whole `foldcore simulate FILE.svg --fold-percent {CLI_PERCENT}` "
                  f"process: median {_meta.sig(c['median_s'])} s over {c['files']} files "
                  f"against Origami Simulator's read + fold {_meta.sig(c['median_os_s'])} s; "
                  f"faster on {c['faster_than_os']} of {c['files']}; "
                  f"{t['cli_over_limit']} files past {CLI_LIMIT_S:g} s."]
    return "\n".join(lines)


def plot(data: dict, path: Path) -> None:
    plt = _meta.pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    for kind, colour in (("model", "tab:blue"), ("end_to_end", "tab:orange")):
        done = [f for r in data["rows"] for f in r["folds"] if kind in f]
        if not done:
            continue
        left.scatter([f["os_still_s"] for f in done], [f[kind]["seconds"] for f in done],
                     s=10, color=colour, label=kind.replace("_", " "))
        right.hist([max(f[kind]["max_deg"], 1e-6) for f in done],
                   bins=np.logspace(-6, 3, 28), alpha=0.6, color=colour,
                   label=kind.replace("_", " "))
    lo, hi = 1e-3, 1e2
    left.plot([lo, hi], [lo, hi], "k--", lw=0.8, label="equal time")
    left.set(xscale="log", yscale="log", xlabel="Origami Simulator to still (s)",
             ylabel="foldcore (s)", title="time per fold")
    right.set(xscale="log", xlabel="largest |Δφ| over M/V creases (°)", ylabel="folds",
              title="shape difference to Origami Simulator")
    for ax in (left, right):
        ax.legend()
    fig.tight_layout()
    _meta.save(fig, path)


def main() -> None:
    p = _meta.parser(__doc__)
    osim.add_source_argument(p)
    args = p.parse_args()
    if _meta.stored("os_compare", args, table, plot):
        return
    paths = sorted(osl.STATES.glob("*.json.gz"))
    if args.quick:
        wanted = {osl.state_name(f) for f in osl.QUICK_FILES}
        paths = [q for q in paths if q.name in wanted]
    record = _meta.Record("os_compare", args, runs=RUNS, match=MATCH,
                          others_busy_before=_meta.others_busy())
    warnings.simplefilter("ignore")  # the readers' and the runs' notes: the rows say it
    with tempfile.TemporaryDirectory() as tmp:
        commit = osim.extract(args.origami_simulator, Path(tmp))  # its page and assets
        fold(pattern_of_mesh(osl.load_state(paths[0])), 50.0, 1)  # kernels compiled/loaded
        rows = []
        for path in paths:
            rows.append(one_file(path, Path(tmp), 1 if args.quick else RUNS))
            print(path.name, [(f["percent"], {k: round(f[k]["max_deg"], 3) for k in
                                              ("model", "end_to_end") if k in f})
                              for f in rows[-1]["folds"]], flush=True)
    record.meta.update(origami_simulator_commit=commit, others_busy_after=_meta.others_busy())
    data = {"rows": rows, "totals": totals(rows)}
    record.write(data, plot)
    print(table(data))


if __name__ == "__main__":
    main()
