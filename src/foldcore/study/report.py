"""What a designer reads of a study: plots (PNG) and one self-contained HTML report.

:func:`write_plots` draws each figure of the table (:data:`PLOTTED`, and every
numeric column of the user's metric) against each swept parameter (a point
name with more than one value), one PNG each; :func:`write_report` writes one
HTML file holding a summary, those plots, a picture of each kept folded solid
(``result_fold``) linking to its ``foldcore view`` page, and the table.

The report loads nothing: its pictures are ``data:`` URIs and it has no script;
the view pages sit in a folder beside it (``OUT_files/``), linked by relative
names. Every value of the table reaches the page through :func:`html.escape`:
the values come from files and users, and none becomes markup. matplotlib
(Agg, no pyplot: no global state) and pyvista are imported only inside the
functions that draw.
"""
from __future__ import annotations

import base64
import html
import json
import math
import numbers
import os
import tempfile
from pathlib import Path
from urllib.parse import quote

from .sweep import FIGURES, TRAILING

#: Figures plotted against each swept parameter (with the metric's columns).
PLOTTED = ("miss_max_deg", "iterations", "wall_s", "largest_strain", "stack_height_mm")
#: Axis labels of the plotted figures, with their units.
LABELS = {"miss_max_deg": "largest miss of a driven crease (°)",
          "iterations": "iterations", "wall_s": "wall time of the point (s)",
          "largest_strain": "largest surface strain", "stack_height_mm": "stack height (mm)"}
#: Units of the options a study sweeps (``simulate``'s; mm and degrees).
OPTION_UNITS = {"thickness": "mm", "hinge-width": "mm", "fold-percent": "%",
                "elastic-cells": "mm", "branch-floor": "°", "ground": "mm",
                "sheet-size": "mm"}
#: Units read off a column name's ending (``span_mm``: mm).
SUFFIX_UNITS = {"_mm": "mm", "_deg": "°", "_s": "s"}
#: Most series (colours) in one plot; more values of the other parameters: one colour.
MAX_SERIES = 6
#: Suffixes ``--report`` writes.
REPORT_SUFFIXES = (".html", ".htm")
#: Size of a folded solid's picture in the report, pixels (width, height).
THUMBNAIL_PX = (240, 180)
#: Most kept points that get a picture and a view page (each page is about 1 MB).
MAX_SOLIDS = 100
#: Longest text of a value in a plot's labels, characters.
MAX_LABEL = 40


# ---------------------------------------------------------------- the table's columns
def point_names(frame) -> list[str]:
    """The point's names of a study table: its columns before the first figure (all
    columns but the trailing ones when it has no figure)."""
    columns = [str(c) for c in frame.columns]
    first = next((i for i, c in enumerate(columns) if c in FIGURES), None)
    if first is None:
        return [c for c in columns if c not in TRAILING]
    return columns[:first]


def swept(frame, names=None) -> list[str]:
    """The parameters of the table: point names with more than one distinct value."""
    names = point_names(frame) if names is None else [str(n) for n in names]
    return [n for n in names if n in frame.columns and len(_distinct(frame[n])) > 1]


def plotted(frame, names=None) -> list[str]:
    """The columns :func:`write_plots` draws: :data:`PLOTTED` present in the table,
    then every numeric column that is neither a point name, a figure nor a trailing
    column (the metric's)."""
    names = set(point_names(frame) if names is None else map(str, names))
    metric = [c for c in map(str, frame.columns)
              if c not in names and c not in FIGURES and c not in TRAILING
              and _numeric(frame[c])]
    return [c for c in PLOTTED if c in frame.columns] + metric


def failed(frame):
    """Boolean Series: the rows whose ``error`` is not empty."""
    import pandas as pd

    if "error" not in frame.columns:
        return pd.Series(False, index=frame.index)
    return frame["error"].map(_filled)


def label(name: str) -> str:
    """An axis label for a column or parameter, with its unit."""
    if name in LABELS:
        return LABELS[name]
    unit = OPTION_UNITS.get(name) or next((u for s, u in SUFFIX_UNITS.items()
                                           if name.endswith(s)), None)
    return _plain(f"{name} ({unit})" if unit else name)


def _missing(value) -> bool:
    """None, NaN, or pandas' NA / NaT (a failed point's figures)."""
    if value is None or type(value).__name__ in ("NAType", "NaTType"):
        return True
    return _real(value) and not isinstance(value, numbers.Integral) and math.isnan(value)


def _real(value) -> bool:
    """A real number (Python's or numpy's); bools are not."""
    return isinstance(value, numbers.Real) and type(value).__name__ not in ("bool", "bool_")


def _numeric(series) -> bool:
    """Whether every present value is a real number (bools are not) and one is finite."""
    values = [v for v in series.tolist() if not _missing(v)]
    return bool(values) and all(map(_real, values)) \
        and any(math.isfinite(float(v)) for v in values)


def _text(value) -> str:
    """A value as a designer reads it: numbers short (4 significant digits), lists as
    JSON, missing as empty."""
    if isinstance(value, (list, tuple)):
        return json.dumps(value, default=str)
    if _missing(value):
        return ""
    if _real(value) and not isinstance(value, numbers.Integral):
        return f"{float(value):.4g}"
    return str(value)


def _key(value) -> str:
    """A value's identity: as :func:`_text` but numbers at full precision (0.10001 and
    0.10002 are two values even where they read alike)."""
    if _real(value) and not _missing(value) and not isinstance(value, numbers.Integral):
        return repr(float(value))
    return _text(value)


def _distinct(series) -> dict[str, str]:
    """{key: text} of the series' distinct values, in order of first appearance."""
    return {_key(v): _text(v) for v in series.tolist()}


def _plain(text: str) -> str:
    """Text for a matplotlib label: ``$`` literal (no mathtext), at most MAX_LABEL chars."""
    text = text if len(text) <= MAX_LABEL else text[:MAX_LABEL - 1] + "…"
    return text.replace("$", r"\$")


# ---------------------------------------------------------------- plots
def write_plots(frame, folder, names=None) -> list[Path]:
    """One PNG per plotted figure against each swept parameter.

    Parameters
    ----------
    frame : pandas.DataFrame
        A study's table (:func:`foldcore.study.sweep`, or read back from its CSV).
    folder : path
        Where the PNGs go (``FIGURE-vs-PARAMETER.png``); made if missing.
    names : list of str, optional
        The point's names (default: the columns before the first figure).

    Returns
    -------
    list of Path
        The PNGs written: :func:`plotted` × :func:`swept` in that order, less the
        figures with no finite value (a table without swept parameter: none).

    Notes
    -----
    Numeric parameters are lines (markers only where a series has several points
    at one value), others grouped points. The other swept parameters' combinations
    are series (colours) when there are at most :data:`MAX_SERIES`; else the first
    such parameter with so few values; else one colour. Failed rows (``error``)
    are left out, their count in the title; hollow markers did not converge.
    Units (mm, °, s) are in the axis labels.
    """
    folder = Path(folder)
    params = swept(frame, names)
    bad = failed(frame)
    ok = frame[~bad.to_numpy(dtype=bool)]
    written, used = [], set()
    for column in plotted(frame, names):
        values = _floats(ok[column])
        if not params or not any(math.isfinite(v) for v in values):
            continue
        for param in params:
            others = [p for p in params if p != param]
            path = folder / _file_name(f"{column}-vs-{param}", used)
            folder.mkdir(parents=True, exist_ok=True)
            _plot(frame, ok, column, param, others, int(bad.sum()), path)
            written.append(path)
    return written


def _file_name(stem: str, used: set) -> str:
    """A safe, unique PNG name: characters other than letters, digits, ``.-_`` as ``_``."""
    safe = "".join(c if c.isascii() and (c.isalnum() or c in "._-") else "_"
                   for c in stem)[:120].lstrip(".") or "plot"
    name, k = f"{safe}.png", 1
    while name.lower() in used:
        k += 1
        name = f"{safe}-{k}.png"
    used.add(name.lower())
    return name


def _floats(series) -> list[float]:
    out = []
    for v in series.tolist():
        out.append(float(v) if _real(v) else math.nan)
    return out


def _plot(frame, ok, column, param, others, n_failed, path) -> None:
    """Draw ``column`` against ``param`` (one PNG at ``path``, atomically)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..files import atomic_path

    fig = Figure(figsize=(6.4, 4.4), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    numeric = _numeric(frame[param])
    categories = {} if numeric else _distinct(frame[param])
    place = {key: i for i, key in enumerate(categories)}
    by, keys = _series_keys(frame, others)
    hollow = False
    for k, key in enumerate(keys or [None]):
        rows = ok if key is None else ok[[_row_key(r) == key
                                          for r in ok[by].itertuples(index=False)]]
        x = _floats(rows[param]) if numeric else \
            [place[_key(v)] + _dodge(k, len(keys)) for v in rows[param].tolist()]
        done = _converged(rows)
        hollow |= not all(done)
        _draw(ax, x, _floats(rows[column]), done, f"C{k % 10}", numeric,
              None if key is None else _plain(", ".join(keys[key])))
    if not numeric:
        ax.set_xticks(range(len(categories)), [_plain(c) for c in categories.values()])
    ax.set_xlabel(label(param))
    ax.set_ylabel(label(column))
    ax.grid(True, alpha=0.3)
    notes = [f"{n_failed} failed point{'s' if n_failed != 1 else ''} left out"] \
        if n_failed else []
    notes += ["hollow: not converged"] if hollow else []
    ax.set_title(f"{label(column)} against {label(param)}"
                 + (f"\n({'; '.join(notes)})" if notes else ""), fontsize="medium")
    if keys and ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small", title_fontsize="small", title=_plain(", ".join(by)))
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, format="png")


def _series_keys(frame, others) -> tuple[list[str], dict]:
    """(names, {key: texts} of their value combinations): the series (colours) of a
    plot; ([], {}) for one colour."""
    if not others:
        return [], {}
    combos = _combinations(frame, others)
    if len(combos) <= MAX_SERIES:
        return others, combos
    few = [p for p in others if len(_distinct(frame[p])) <= MAX_SERIES]
    return (few[:1], _combinations(frame, few[:1])) if few else ([], {})


def _combinations(frame, names) -> dict:
    """{key tuple: text tuple} of the combinations of ``names`` in the table, in order."""
    return {_row_key(r): tuple(map(_text, r)) for r in frame[names].itertuples(index=False)}


def _row_key(row) -> tuple:
    return tuple(map(_key, row))


def _dodge(k: int, count: int) -> float:
    """Offset of series ``k`` of ``count`` within a category, so groups stay apart."""
    return 0.0 if count <= 1 else 0.5 * (k / (count - 1) - 0.5)


def _converged(rows) -> list[bool]:
    if "converged" not in rows.columns:
        return [True] * len(rows)
    return [bool(v) if not _missing(v) else False for v in rows["converged"].tolist()]


def _draw(ax, x, y, done, colour, numeric, name) -> None:
    """One series: a line through its points where x is numeric and each x appears
    once, else markers; filled where converged, hollow where not."""
    points = sorted((a, b, c) for a, b, c in zip(x, y, done)
                    if math.isfinite(a) and math.isfinite(b))
    if not points:  # (its colour stays its own: a series' colour is its place in the table)
        return
    xs, ys, cs = map(list, zip(*points))
    line = numeric and len(set(xs)) == len(xs)
    if line:
        ax.plot(xs, ys, "-", color=colour, alpha=0.8)
    for filled in (True, False):
        chosen = [(a, b) for a, b, c in zip(xs, ys, cs) if c == filled]
        if chosen:
            ax.plot(*zip(*chosen), "o", color=colour, markersize=6,
                    markerfacecolor=colour if filled else "white")
    ax.plot([], [], "o-" if line else "o", color=colour, label=name)  # the legend's entry


# ---------------------------------------------------------------- the report
def report_folder(path) -> Path:
    """The folder of a report's view pages: ``OUT_files`` beside ``OUT.html``."""
    path = Path(path)
    return path.with_name(path.stem + "_files")


def check_folders(folders: dict) -> None:
    """Refuse folders a command writes into that it could not make or write, before
    any work.

    Parameters
    ----------
    folders : dict {option name: path or None}
        e.g. ``{"--plots": "plots/"}``: each an existing writable folder or one that
        can be made in an existing writable folder; None entries are skipped.

    Raises
    ------
    OutputError
        Naming the option and the path as given.
    """
    from ..files import OutputError

    for option, path in folders.items():
        if path is None:
            continue
        where = f"{option} {os.fspath(path)}"
        target = Path(os.path.realpath(os.fspath(path) or "."))
        if target.exists() and not target.is_dir():
            raise OutputError(f"{where}: is a file, not a folder")
        folder = target if target.is_dir() else target.parent
        if not folder.is_dir():
            raise OutputError(f"{where}: cannot make it (no such folder: {folder})")
        if not os.access(folder, os.W_OK | os.X_OK):
            raise OutputError(f"{where}: cannot write there (folder not writable: {folder})")


def write_report(frame, path, *, pattern_label, plots=None, thumbnails=True) -> None:
    """Write one self-contained HTML report of a study's table.

    Parameters
    ----------
    frame : pandas.DataFrame
        A study's table (:func:`foldcore.study.sweep`).
    path : path
        The HTML file (written atomically).
    pattern_label : str
        What was folded (a file name or a generator's), for the title.
    plots : list of path, optional
        PNGs to show (e.g. :func:`write_plots`'s); None: drawn now in a temporary
        folder; an empty list: no plots.
    thumbnails : bool
        For each row with a kept result FOLD (``result_fold``; at most
        :data:`MAX_SOLIDS`), a picture of the folded solid (pyvista, offscreen,
        :data:`THUMBNAIL_PX`) linking to its ``foldcore view`` page, written in
        :func:`report_folder` as ``point-NNNN.html`` (NNNN: the row). Without
        pyvista, or when a render fails, the pages are still written and the
        report says why it shows no picture.

    Notes
    -----
    The page loads nothing (pictures are ``data:`` URIs) and runs no script;
    every value of the table is HTML-escaped.
    """
    from ..files import write_text

    path = Path(path)
    if plots is None:
        with tempfile.TemporaryDirectory(prefix="foldcore-plots-") as folder:
            figures = _images(write_plots(frame, folder))
    else:
        figures = _images(plots)
    solids, notes = _solids(frame, report_folder(path)) if thumbnails else ([], [])
    write_text(path, _page(frame, pattern_label, figures, solids, notes))


def _images(paths) -> list[tuple[str, str]]:
    """(name, base64 PNG) of each picture."""
    return [(Path(p).stem, base64.b64encode(Path(p).read_bytes()).decode("ascii"))
            for p in paths]


def _kept_rows(frame) -> list[tuple[int, str]]:
    """(row position, result FOLD path) of the rows with a kept result."""
    if "result_fold" not in frame.columns:
        return []
    return [(i, str(v)) for i, v in enumerate(frame["result_fold"].tolist()) if _filled(v)]


def _solids(frame, folder: Path) -> tuple[list[dict], list[str]]:
    """The kept points' view pages (written in ``folder``) and pictures, and the
    notes the report shows about them."""
    from ..errors import FoldcoreError
    from ..view import view_html
    from .task import error_text

    kept = _kept_rows(frame)
    notes = [f"Pictures and view pages of the first {MAX_SOLIDS} of {len(kept)} kept "
             "results."] if len(kept) > MAX_SOLIDS else []
    names = point_names(frame)
    solids, render = [], True
    for i, fold in kept[:MAX_SOLIDS]:
        row = frame.iloc[i]
        solid = {"row": i, "point": ", ".join(f"{n}={_text(row[n])}" for n in names),
                 "href": None, "png": None, "note": ""}
        page = folder / f"point-{i:04d}.html"
        try:
            folder.mkdir(exist_ok=True)
            view_html(fold, page)
            solid["href"] = f"{quote(folder.name)}/{quote(page.name)}"
        except (FoldcoreError, OSError) as exc:
            solid["note"] = f"no view page: {error_text(exc)}"
            solids.append(solid)
            continue
        if render:
            try:
                solid["png"] = _thumbnail(fold)
            except Exception as exc:  # an optional picture never loses the report
                render = False
                notes.append(f"No pictures of the folded solids: {error_text(exc)}. "
                             "The view pages are linked instead.")
        solids.append(solid)
    return solids, notes


def _thumbnail(fold: str) -> str:
    """A small offscreen picture of the result FOLD's solid, as base64 PNG."""
    from ..render import render_png, require_pyvista
    from ..result_file import read_result

    require_pyvista()
    res = read_result(fold)
    with tempfile.TemporaryDirectory(prefix="foldcore-thumb-") as folder:
        png = Path(folder) / "solid.png"
        render_png(res.pattern, res.mesh, res.positions, png, size=THUMBNAIL_PX,
                   legend=False, padding=0.06)
        return base64.b64encode(png.read_bytes()).decode("ascii")


STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; margin-top: 1.6em; }
.plots, .solids { display: flex; flex-wrap: wrap; gap: 12px; }
.plots img { width: 420px; max-width: 100%; border: 1px solid #ddd; }
.solid { width: 244px; font-size: 0.8em; }
.solid img { border: 1px solid #ddd; display: block; }
.note { color: #8a4b00; }
table { border-collapse: collapse; font-size: 0.8em; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: right; white-space: nowrap; }
th { background: #f2f2f2; position: sticky; top: 0; }
td.text { text-align: left; white-space: normal; min-width: 12em; max-width: 40em; }
tr.failed { background: #fde8e8; }
"""


def _page(frame, pattern_label, figures, solids, notes) -> str:
    """The report's HTML; every value from the table or the user escaped."""
    e = html.escape
    title = f"foldcore study: {pattern_label}"
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
             f"<title>{e(title)}</title><style>{STYLE}</style></head><body>",
             f"<h1>{e(title)}</h1>", f"<p>{e(summary_text(frame))}</p>",
             '<h2 id="plots">Figures against the swept parameters</h2>']
    if figures:
        parts.append('<div class="plots">' + "".join(
            f'<img alt="{e(name)}" src="data:image/png;base64,{data}">'
            for name, data in figures) + "</div>")
    else:
        parts.append("<p>No plot: the study sweeps no parameter, or no point folded.</p>")
    if solids or notes:
        parts.append('<h2 id="solids">Folded solids</h2>')
        parts += [f'<p class="note">{e(n)}</p>' for n in notes]
        parts.append('<div class="solids">' + "".join(map(_solid_html, solids)) + "</div>")
    parts += ['<h2 id="table">Table</h2>',
              "<p>Numbers to 4 significant digits (the table file has them in full); "
              "a point's number links to its view page where it has one.</p>",
              _table_html(frame, solids), "</body></html>"]
    return "\n".join(parts) + "\n"


def summary_text(frame) -> str:
    """One paragraph: points, converged, not converged, failed, workers, cached."""
    n = len(frame)
    bad = failed(frame).tolist()
    converged = sum(d for d, b in zip(_converged(frame), bad) if not b)
    cached = [not _missing(v) and bool(v) for v in _values(frame, "cached")]
    workers = {str(w) for w, c in zip(_values(frame, "worker"), cached)
               if not c and _filled(w)}
    metric_failed = sum(map(_filled, _values(frame, "metric_error")))
    return (f"{_plural(n, 'point')}: {converged} converged, "
            f"{n - sum(bad) - converged} did not converge, {sum(bad)} failed. "
            f"Folded on {_plural(len(workers), 'worker')}, {sum(cached)} from the cache. "
            f"Swept: {', '.join(swept(frame)) or 'nothing'}."
            + (f" The metric failed on {_plural(metric_failed, 'point')} (metric_error)."
               if metric_failed else ""))


def _values(frame, column: str) -> list:
    """The column's values (None for each row where the table has no such column)."""
    return frame[column].tolist() if column in frame.columns else [None] * len(frame)


def _filled(value) -> bool:
    """Present and not empty text."""
    return not _missing(value) and str(value) != ""


def _plural(count: int, word: str) -> str:
    return f"{count} {word}{'s' if count != 1 else ''}"


def _solid_html(solid: dict) -> str:
    e = html.escape
    caption = e(f"point {solid['row']}: {solid['point']}")
    if solid["png"] and solid["href"]:
        body = (f'<a href="{e(solid["href"])}"><img alt="{caption}" width="{THUMBNAIL_PX[0]}" '
                f'height="{THUMBNAIL_PX[1]}" src="data:image/png;base64,{solid["png"]}"></a>')
    elif solid["href"]:
        body = f'<a href="{e(solid["href"])}">view the folded solid</a>'
    else:
        body = f'<span class="note">{e(solid["note"])}</span>'
    return f'<div class="solid">{body}<div>{caption}</div></div>'


def _table_html(frame, solids) -> str:
    """The table: a row per point (failed rows tinted), its number linking to the
    point's view page where there is one."""
    e = html.escape
    links = {s["row"]: s["href"] for s in solids if s["href"]}
    columns = [str(c) for c in frame.columns]
    text = {"warnings", "error", "metric_error", "result_fold", "worker"}
    bad = failed(frame).tolist()
    out = ["<table><thead><tr><th>#</th>" + "".join(f"<th>{e(c)}</th>" for c in columns)
           + "</tr></thead><tbody>"]
    for i, values in enumerate(frame.itertuples(index=False)):
        number = f'<a href="{e(links[i])}">{i}</a>' if i in links else str(i)
        cells = "".join(f'<td class="text">{e(_text(v))}</td>' if c in text
                        else f"<td>{e(_text(v))}</td>" for c, v in zip(columns, values))
        tint = ' class="failed"' if bad[i] else ""
        out.append(f"<tr{tint}><td>{number}</td>{cells}</tr>")
    out.append("</tbody></table>")
    return "\n".join(out)
