"""The points of a study: option values by name, from a grid, a CSV file or a list.

A point is a dict {name: value}. Names are ``foldcore simulate``'s long flags
without the dashes (``thickness``, ``hinge-width``, ``fold-percent``, … :data:`OPTIONS`;
``_`` is read as ``-``), and, for a built-in pattern generator
(:mod:`foldcore.study.source`), that generator's keyword parameters. Values are
in the command line's units (mm, degrees). A point is checked whole before any
fold: unknown names and values an option refuses fail here, naming the point.
"""
from __future__ import annotations

import csv
import itertools
import json
import math

from ..errors import FoldcoreError
from ..options import FLAGS, Solving

#: Option groups a study may set, and the ``simulate`` fields it may not (lists,
#: outputs: a study writes its own).
_GROUPS = ("thickening", "solving", "reading")
_NOT_SWEPT = ("solving.obstacles", "reading.hinges")


def _option_table() -> tuple[dict, dict]:
    """({study name: (group, field)}, {switch name: (group, field, value when on)}) from
    the command line's flags (one table of names)."""
    import ast

    options, switches = {}, {}
    for name, flag in FLAGS.items():
        group, _, field = name.partition(".")
        if group not in _GROUPS or name in _NOT_SWEPT or not flag.startswith("--"):
            continue
        if "=" in field:  # a flag without a value: field=value when given
            field, _, value = field.partition("=")
            switches[flag[2:]] = (group, field, ast.literal_eval(value))
        else:
            options[flag[2:]] = (group, field)
    return options, switches


#: {name: (option group, field)} of every ``simulate`` option a study can set, and
#: {name: (group, field, value)} of its switches (``mv-passive=true``: the field is
#: set to the value, as the flag does; false: the default).
OPTIONS, SWITCHES = _option_table()
#: The option whose points run as one continuation path (:func:`paths`).
FOLD_PERCENT = "fold-percent"
#: Most points one study may hold (a grid's product is checked before it is made).
MAX_POINTS = 100_000


class StudyError(FoldcoreError, ValueError):
    """A study's points, names or values are not what it accepts; the message names
    the point or the ``--set`` it came from."""


def canonical(name: str) -> str:
    """A point's name as the study writes it: ``hinge_width`` → ``hinge-width``."""
    return str(name).strip().replace("_", "-")


def parse_value(text: str):
    """A value as written on the command line or in a CSV cell: a number (int if it
    reads as one), ``true``/``false``, a JSON list (``[135, 90, 45, 90]``), or the text."""
    text = text.strip()
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    for kind in (int, float):
        try:
            value = kind(text)
        except ValueError:
            continue
        return value
    if text.startswith("["):
        try:
            return json.loads(text)
        except json.JSONDecodeError:
            raise StudyError(f"{text!r}: not a JSON list") from None
    return text


def split_values(text: str) -> list[str]:
    """``V1,V2,…`` split at the commas outside brackets (a list value stays whole)."""
    out, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        depth += (ch == "[") - (ch == "]")
        if ch == "," and depth == 0:
            out.append(text[start:i])
            start = i + 1
    out.append(text[start:])
    return [v for v in (s.strip() for s in out) if v]


def parse_set(spec: str) -> tuple[str, list]:
    """``NAME=V1,V2,…`` (a ``--set``) → (name, [values])."""
    name, eq, values = spec.partition("=")
    if not eq or not name.strip():
        raise StudyError(f"--set {spec!r}: expected NAME=V1,V2,… (e.g. thickness=0.1,0.2)")
    parsed = [parse_value(v) for v in split_values(values)]
    if not parsed:
        raise StudyError(f"--set {spec!r}: no value after {name.strip()}=")
    return canonical(name), parsed


def grid(values: dict) -> list[dict]:
    """Every combination of ``values`` ({name: [v, …]}), the last name varying fastest."""
    names = [canonical(n) for n in values]
    if len(set(names)) < len(names):
        raise StudyError(f"a name is set twice: {', '.join(names)}")
    lists = [list(v) if isinstance(v, (list, tuple)) else [v] for v in values.values()]
    count = math.prod(len(v) for v in lists)
    if count > MAX_POINTS:
        raise StudyError(f"the grid has {count} points, more than {MAX_POINTS}")
    return [dict(zip(names, combo)) for combo in itertools.product(*lists)]


def read_points(path) -> list[dict]:
    """The points of a CSV file: a header of names, a row per point (empty cell: the
    option's default)."""
    import os

    name = os.fspath(path)
    with open(name, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    if not rows or not any(h.strip() for h in rows[0]):
        raise StudyError(f"{name}: no header line of option names")
    header = [canonical(h) for h in rows[0]]
    points = []
    for line, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise StudyError(f"{name}: line {line}: {len(row)} cells, the header has "
                             f"{len(header)}")
        points.append({h: parse_value(c) for h, c in zip(header, row) if c.strip()})
    if not points:
        raise StudyError(f"{name}: no point (only a header)")
    if len(points) > MAX_POINTS:
        raise StudyError(f"{name}: {len(points)} points, more than {MAX_POINTS}")
    return points


def option_groups(point: dict) -> dict:
    """The point's options as ``simulate``'s groups ({"thickening": {...}, ...}); names
    that are not options (a generator's parameters) are left out."""
    groups = {g: {} for g in _GROUPS}
    for name, value in point.items():
        if name in OPTIONS:
            group, field = OPTIONS[name]
            groups[group][field] = value
        elif name in SWITCHES and value is True:
            group, field, on = SWITCHES[name]
            groups[group][field] = on
    return groups


def check(points: list[dict], parameters=()) -> list[dict]:
    """The points with canonical names, each checked: every name an option or one
    of ``parameters`` (the generator's), every option value accepted by its group."""
    from ..io import Reading
    from ..options import OptionError, Solving, Thickening, as_group

    classes = {"thickening": Thickening, "solving": Solving, "reading": Reading}
    out = []
    for i, raw in enumerate(points):
        point = {canonical(k): v for k, v in raw.items()}
        unknown = sorted(set(point) - set(OPTIONS) - set(SWITCHES) - set(parameters))
        if unknown:
            known = sorted(OPTIONS) + sorted(SWITCHES) + sorted(parameters)
            raise StudyError(f"point {i}: unknown name {unknown[0]!r} (options and "
                             f"parameters: {', '.join(known)})")
        bad = [n for n in set(point) & set(SWITCHES) if not isinstance(point[n], bool)]
        if bad:
            raise StudyError(f"point {i} ({describe(point)}): {bad[0]} is true or false, "
                             f"got {point[bad[0]]!r}")
        for group, values in option_groups(point).items():
            try:
                as_group(classes[group], values, group)
            except OptionError as exc:
                raise StudyError(f"point {i} ({describe(point)}): {in_names(str(exc))}") \
                    from None
        out.append(point)
    return out


def in_names(text: str) -> str:
    """A library message with ``group.field`` replaced by the study's name for it."""
    for name, (group, field, value) in SWITCHES.items():
        text = text.replace(f"{group}.{field}={value!r}", f"{name}=true")
    for name, (group, field) in sorted(OPTIONS.items(), key=lambda kv: -len(kv[1][1])):
        text = text.replace(f"{group}.{field}", name)
    return text


def describe(point: dict) -> str:
    """``name=value, …`` of a point, for messages."""
    return ", ".join(f"{k}={v}" for k, v in point.items())


def paths(points: list[dict]) -> list[list[int]]:
    """Indices of ``points`` grouped into continuation paths: points equal but for
    their fold percent, in the order of |fold percent| (one point per path where
    nothing else is equal). Paths are listed in the order of their first point."""
    groups: dict = {}
    for i, point in enumerate(points):
        key = json.dumps({k: v for k, v in point.items() if k != FOLD_PERCENT},
                         sort_keys=True, default=str)
        groups.setdefault(key, []).append(i)
    return [sorted(ids, key=lambda i: abs(fold_percent(points[i])))
            for ids in groups.values()]


def fold_percent(point: dict) -> float:
    """The point's fold percent: its own, or ``simulate``'s default."""
    return point.get(FOLD_PERCENT, Solving.fold_percent)
