"""FOLD's JSON layer: units, foldcore's keys, parsing bytes and checking values.

Shared by the crease-pattern reader (:mod:`.fold`), the writer
(:mod:`.fold_write`), the OBJ reader and the result-file reader
(:mod:`foldcore.result_file`): every check raises :class:`PatternError`
naming the file (``source``) and the offending item.
"""
from __future__ import annotations

import gc
import json
from contextlib import contextmanager
from functools import partial
from itertools import chain

import numpy as np

from ..errors import PatternError

#: Millimetres per ``frame_unit``.
UNIT_MM = {"unit": 1.0, "mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4,
           "pt": 25.4 / 72.0, "um": 1e-3, "nm": 1e-6}

WIDTH_KEY = "foldcore:edges_width"
MAX_ANGLE_KEY = "foldcore:edges_maxAngle"
THICKNESS_KEY = "foldcore:thickness"
TARGET_KEY = "foldcore:edges_targetAngle"
EDGE_STIFFNESS_KEY = "foldcore:edges_stiffness"
FACE_STIFFNESS_KEY = "foldcore:faces_stiffness"
CELLS_KEY = "foldcore:faces_cells"
POISSON_KEY = "foldcore:edges_poisson"
HINGE_KEY = "foldcore:edges_hinge"
MODEL_KEY = "foldcore:model"  # "sheet" in the result of a thin sheet (no thickness)
#: What a JSON array may be in a FOLD dict: a list, or a tuple from a Python caller.
ARRAY = (list, tuple)
#: Digits to "0" and "E" to "e", for :func:`_may_overflow`'s plain substring search.
_DIGITS_TO_ZERO = bytes.maketrans(b"123456789E", b"000000000e")


def parse_json(data: bytes, source: str):
    """The JSON value of a FOLD file's bytes (UTF-8, optional BOM); PatternError naming
    ``source`` for bad text, bad JSON, NaN/Infinity or a number beyond float64."""
    _check_density(data, source)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        fail(source, f"not UTF-8 text (bad byte at offset {exc.start})")
    # every float is checked by a Python hook only when one could overflow; the
    # parser's many lists are freed by reference counting, so the cyclic GC's
    # passes over them (half of a 10⁶-vertex file's parse) are paused meanwhile
    hook = {"parse_float": partial(_finite_float, source)} if _may_overflow(data) else {}
    try:
        with _gc_paused():
            return json.loads(text, parse_constant=partial(_bad_constant, source), **hook)
    except PatternError:
        raise
    except json.JSONDecodeError as exc:
        fail(source, f"not valid JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}")
    except (ValueError, RecursionError) as exc:
        fail(source, f"not valid JSON ({type(exc).__name__}: {exc})")


#: Files larger than this (bytes) must have at least ``BYTES_PER_CONTAINER`` bytes
#: per JSON array or object: each costs Python about 64 bytes, so ``[],`` repeated
#: would need 25 × the file's size to parse. A FOLD file's rows take 6 bytes
#: (``[1,2],``) and more (a 10⁶-vertex grid: 26); with that, a parse needs at most
#: about 15 × the file's size.
DENSE_FROM_BYTES = 1024 * 1024
BYTES_PER_CONTAINER = 6


def _check_density(data: bytes, source: str) -> None:
    """Refuse a large file packed with more JSON arrays and objects than any FOLD
    file has (counted on the bytes, before any is built)."""
    if len(data) <= DENSE_FROM_BYTES:
        return
    containers = data.count(b"[") + data.count(b"{")
    if containers * BYTES_PER_CONTAINER > len(data):
        fail(source, f"{containers} JSON arrays and objects in {len(data)} bytes, more than "
                     f"one per {BYTES_PER_CONTAINER} bytes: no FOLD file is that dense, and "
                     "reading it would take over 20 times its size in memory")


def _may_overflow(data: bytes) -> bool:
    """False only if no JSON number in ``data`` can overflow a float64.

    A float overflows only beyond 1.8e308, so it needs an exponent of three
    or more digits or a hundred digits in a row (≤ 99 digits × 10⁹⁹ is finite).
    """
    t = data.translate(_DIGITS_TO_ZERO)
    return any(p in t for p in (b"0" * 100, b"e000", b"e+000"))


@contextmanager
def _gc_paused():
    """Pause the cyclic garbage collector (if on) for the block."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _bad_constant(source: str, name: str):
    fail(source, f"not valid JSON: literal {name} (NaN/Infinity are not JSON; use null)")


def _finite_float(source: str, text: str) -> float:
    value = float(text)
    if not np.isfinite(value):
        fail(source, f"number {text} is out of range of a 64-bit float")
    return value


def number_table(rows, widths: tuple) -> np.ndarray | None:
    """``rows`` as an (n, k) float array if they are lists/tuples of one length k in
    ``widths`` holding only int/float (not bool); None otherwise (check row by row)."""
    if not rows or not set(map(type, rows)) <= {list, tuple}:
        return None
    lengths = set(map(len, rows))
    if len(lengths) != 1 or not lengths <= set(widths) \
            or not set(map(type, chain.from_iterable(rows))) <= {int, float}:
        return None
    try:
        return np.array(rows, dtype=np.float64)
    except (OverflowError, ValueError, TypeError):  # e.g. an int beyond float range
        return None


def int_table(rows, width: int) -> np.ndarray | None:
    """``rows`` as an (n, width) int64 array if they are lists/tuples of ``width`` ints
    (not bool); None otherwise (check row by row)."""
    if not rows or not set(map(type, rows)) <= {list, tuple} or set(map(len, rows)) != {width} \
            or not set(map(type, chain.from_iterable(rows))) <= {int}:
        return None
    try:
        return np.array(rows, dtype=np.int64)
    except OverflowError:
        return None


def has_class(classes, name: str) -> bool:
    """Whether a FOLD ``frame_classes`` value (a list of strings, or anything a file
    or a caller's dict holds) names ``name``; compared string by string, so an
    array or other object in the list is no match (``in`` would compare it
    element-wise)."""
    return isinstance(classes, ARRAY) and any(isinstance(c, str) and c == name
                                               for c in classes)


def fail(source: str, message: str):
    """Raise PatternError ``source: message``."""
    raise PatternError(f"{source}: {message}")


def short(value, limit: int = 60) -> str:
    """``value`` for an error message: JSON-like, at most ``limit`` characters."""
    try:
        text = json.dumps(value) if isinstance(value, (*ARRAY, dict, str, type(None))) \
            else repr(value)
    except (TypeError, ValueError, RecursionError):  # not JSON (a Python caller's object)
        try:
            text = repr(value)
        except RecursionError:
            text = f"<nested {type(value).__name__}>"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def required_list(d: dict, key: str, source: str) -> list:
    """``d[key]``, which must be present and a list."""
    if key not in d:
        fail(source, f"missing required key {key!r}")
    if not isinstance(d[key], ARRAY):
        fail(source, f"{key} must be a list, got {type(d[key]).__name__}")
    return d[key]


def check_length(raw, key: str, n: int, source: str, item: str = "edge"):
    """Refuse a per-item list ``raw`` (key ``key``) that is not a list of ``n`` entries."""
    if not isinstance(raw, ARRAY):
        fail(source, f"{key} must be a list, got {type(raw).__name__}")
    if len(raw) != n:
        fail(source, f"{key} has {len(raw)} entries for {n} {item}s "
                     f"({item}s_vertices); entry {min(len(raw), n)} is the first mismatch")


def number(x) -> float | None:
    """``x`` as a finite float, or None if it is not a finite JSON number."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return None
    try:
        value = float(x)
    except OverflowError:
        return None
    return value if np.isfinite(value) else None


def index(x, n: int) -> int | None:
    """``x`` as a vertex id in 0..n-1, or None."""
    value = number(x)
    if value is None or value != int(value) or not 0 <= value < n:
        return None
    return int(value)
