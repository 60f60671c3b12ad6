"""Screen an SVG file before it is read: its size, its XML, its depth and its count of
elements, each within a bound no crease pattern meets.

The XML is parsed once with defusedxml (entity declarations, external entities and
DTD tricks refused) and written back without its comments, processing instructions
and document type: the SVG reader (svgelements) then sees only elements and their
attributes, in time linear in the file's size. The bounds sit far above Origami
Simulator's library (84 patterns: at most 0.7 MB, 5 011 elements, nested 7
deep): a file past them is refused in one line before any work. The defused
parse itself (:func:`hardened_xml`) serves ORIPA's ``.opx`` reader too.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

from ..errors import PatternError
from .fold import read_bytes

#: Largest SVG file read, bytes (32 MiB).
MAX_SVG_BYTES = 32 * 1024 * 1024
#: Deepest nesting of elements (svgelements recurses per level).
MAX_DEPTH = 100
#: Most elements in one file.
MAX_ELEMENTS = 200_000

SVG_NAMESPACE = "http://www.w3.org/2000/svg"


def screened_svg(path) -> bytes:
    """The file at ``path`` as screened XML bytes (elements and attributes only).

    Raises
    ------
    PatternError
        Larger than :data:`MAX_SVG_BYTES`, not well-formed XML, entities or a DTD
        that declares them, a root element other than ``<svg>``, nesting deeper
        than :data:`MAX_DEPTH` or more than :data:`MAX_ELEMENTS` elements; the
        message names the file (and the line where the parser stopped).
    """
    source = str(path)
    root = hardened_xml(read_bytes(path, MAX_SVG_BYTES), source, forbid_dtd=False,
                        needs="an SVG crease pattern needs no entities")
    if _local_name(root.tag) != "svg":
        raise PatternError(f"{source}: the root element is <{_local_name(root.tag)}>, "
                           "not <svg>")
    _check_tree(root, source)
    return ET.tostring(root, encoding="utf-8")  # names as written (ASCII would
    #                                               turn À in a name into &#192;)


def hardened_xml(data: bytes, source: str, forbid_dtd: bool, needs: str):
    """The root element of ``data`` parsed with defusedxml: entity declarations and
    external references refused, and a DTD too with ``forbid_dtd``; PatternError
    naming ``source`` otherwise (``needs``: what the file's kind does without)."""
    import defusedxml
    from defusedxml.ElementTree import XMLParser

    parser = XMLParser(forbid_dtd=forbid_dtd, forbid_entities=True, forbid_external=True)
    try:
        parser.feed(data)
        return parser.close()
    except ET.ParseError as exc:
        raise PatternError(f"{source}: not well-formed XML ({exc})") from None
    except defusedxml.DefusedXmlException as exc:
        raise PatternError(f"{source}: refused XML construct ({exc}); {needs}") from None


def _check_tree(root, source: str) -> None:
    """Depth and element count within :data:`MAX_DEPTH` and :data:`MAX_ELEMENTS`
    (an iterative walk: the tree may be deeper than Python's recursion)."""
    count, stack = 0, [(root, 1)]
    while stack:
        element, depth = stack.pop()
        count += 1
        if depth > MAX_DEPTH:
            raise PatternError(f"{source}: elements nested more than {MAX_DEPTH} deep "
                               f"(<{_local_name(element.tag)}> at depth {depth})")
        if count > MAX_ELEMENTS:
            raise PatternError(f"{source}: more than {MAX_ELEMENTS} elements")
        stack.extend((child, depth + 1) for child in element)


def _local_name(tag) -> str:
    """The element's name without its namespace ({ns}svg → svg)."""
    return str(tag).rsplit("}", 1)[-1]
