"""Read ORIPA's own ``.opx`` files: its lines as Java's ``XMLEncoder`` writes them.

ORIPA saves an ``oripa.DataSet`` whose ``lines`` property is an array of
``oripa.OriLineProxy`` objects, each with the properties ``type`` (int),
``x0``, ``y0``, ``x1``, ``y1`` (double). ``XMLEncoder`` leaves out a property
at its default, so a missing one is 0. The types and everything after are the
``.cp`` format's (:mod:`.cp`): 1 border, 2 mountain, 3 valley (folding to
∓180° × the fold percent), 0 and 4 auxiliary (left out, said once); one file
unit is 1 mm; the lines are noded as a ``.cp`` file's. Each line is named by
its index in the array (``line 12``) in messages.

The XML is parsed with defusedxml (no entities, no DTD, no external file);
the root must be ``<java>`` holding an ``oripa.DataSet``. Files over
:data:`foldcore.io.MAX_FILE_BYTES` or with more than :data:`.cp.MAX_LINES`
lines are refused.
"""
from __future__ import annotations

import os

from ..errors import PatternError
from ..pattern import CreasePattern
from .conventions import Reading
from .cp import checked_line, pattern_of_typed_lines, typed_lines

#: The properties of a line, each with the XML element its value is written in.
PROPERTIES = {"type": "int", "x0": "double", "y0": "double", "x1": "double", "y1": "double"}


def read_opx(path, reading: Reading | None = None) -> CreasePattern:
    """Read an ORIPA ``.opx`` crease pattern (module docstring); lengths mm, angles degrees.

    Raises
    ------
    PatternError
        Not ORIPA's XML, a line with a malformed or out-of-range value (named by
        its index), no crease, or a malformed pattern (named as
        :class:`CreasePattern` names it).
    """
    source = os.fspath(path)
    objects = _line_objects(_root(source), source)
    return pattern_of_typed_lines(typed_lines(_parsed(objects, source), source), source,
                                  reading)


def _root(source: str):
    """The parsed ``<java>`` root element of the file."""
    from .fold import read_bytes
    from .svg_screen import hardened_xml

    root = hardened_xml(read_bytes(source), source, forbid_dtd=True,
                        needs="an ORIPA file needs no entities or DTD")
    if root.tag != "java":
        raise PatternError(f"{source}: the root element is <{root.tag}>, not <java> "
                           "(ORIPA's .opx is Java's XMLEncoder output)")
    return root


def _line_objects(root, source: str):
    """The ``(index, oripa.OriLineProxy element)`` pairs of the data set's lines."""
    data = root.find("object[@class='oripa.DataSet']")
    if data is None:
        raise PatternError(f"{source}: no oripa.DataSet object: not an ORIPA crease pattern")
    array = data.find("void[@property='lines']/array")
    if array is None:
        raise PatternError(f"{source}: the oripa.DataSet has no lines")
    out = []
    for position, item in enumerate(array.findall("void")):
        line = item.find("object[@class='oripa.OriLineProxy']")
        if line is None:
            raise PatternError(f"{source}: line {position}: not an oripa.OriLineProxy")
        out.append((item.get("index", str(position)), line))
    return out


def _parsed(objects, source: str):
    """(TYPES entry, (2, 2) segment, name) of each line, lazily (its count is bounded
    by :func:`.cp.typed_lines` as it goes)."""
    for index, line in objects:
        where = f"{source}: line {index}"
        values = {name: 0.0 for name in PROPERTIES}
        for prop in line.findall("void"):
            name = prop.get("property")
            if name not in PROPERTIES:
                continue
            values[name] = _value(prop, PROPERTIES[name], f"{where}: {name}")
        yield checked_line(int(values["type"]), [values[k] for k in ("x0", "y0", "x1", "y1")],
                           where) + (f"line {index}",)


def _value(prop, kind: str, where: str) -> float:
    """The number a ``<void property=…>`` holds in its ``<int>`` or ``<double>``."""
    element = prop.find(kind)
    text = element.text if element is not None else None
    try:  # (a coordinate's range is checked with the line's)
        return int(text) if kind == "int" else float(text)
    except (TypeError, ValueError):
        raise PatternError(f"{where}: expected <{kind}>NUMBER</{kind}>") from None
