"""Checks of ``thicken``'s arguments: thickness, stiffness factors, stretch hinges and
elastic faces (their kinds and cell counts)."""
from __future__ import annotations

import numpy as np

from ..errors import MeshError
from ..limits import MAX_MESH_VERTICES
from .geometry import edge_of

__all__ = ["cell_count", "check_stiffness", "check_thickness", "mesh_vertices", "plate_counts",
           "resolve_stretch", "split_elastic", "strip_segments"]


def check_thickness(pattern, thickness) -> None:
    """Refuse a thickness (mm) that is not a positive number."""
    if not (np.isfinite(thickness) and thickness > 0):
        raise MeshError(f"{pattern.source}: thickness must be a positive number of mm, "
                        f"got {thickness}")


def check_stiffness(pattern, stiffness) -> None:
    """Stiffness factors: known keys, right lengths, positive and finite."""
    counts = {"panel": (len(pattern.faces), "face"), "hinge": (pattern.n_edges, "edge")}
    for key, value in dict(stiffness or {}).items():
        if key not in counts:
            raise MeshError(f"{pattern.source}: stiffness key {key!r} is not 'panel' or 'hinge'")
        n, item = counts[key]
        factors = np.asarray(value, dtype=float)
        if factors.ndim and factors.shape != (n,):
            raise MeshError(f"{pattern.source}: stiffness[{key!r}] needs one factor per {item} "
                            f"({n}) or one for all, got shape {factors.shape}")
        bad = np.flatnonzero(~(np.atleast_1d(factors) > 0) | ~np.isfinite(np.atleast_1d(factors)))
        if len(bad):
            where = f" ({item} {bad[0]})" if factors.ndim else ""
            raise MeshError(f"{pattern.source}: stiffness[{key!r}]{where} must be a positive "
                            f"finite factor, got {np.atleast_1d(factors)[bad[0]]!r}")


def resolve_stretch(pattern, stretch) -> dict:
    """{crease edge id: ν} of the stretch hinges, validated."""
    out = {}
    for e, nu in dict(stretch or {}).items():
        e = int(e)
        if not 0 <= e < pattern.n_edges or pattern.assignments[e] == "B":
            raise MeshError(f"{pattern.source}: stretch hinge: edge {e} is not a crease")
        if np.isfinite(pattern.fold_angles[e]):
            raise MeshError(f"{pattern.source}: edge {e} has a fold-angle target but is a "
                            "stretch hinge (actuated by its stretch ratio, not an angle)")
        if not (np.isfinite(nu) and -1.0 <= nu <= 0.5):
            raise MeshError(f"{pattern.source}: stretch hinge on edge {e}: Poisson ratio "
                            f"must be in [-1, 0.5], got {nu!r}")
        out[e] = float(nu)
    return out


def split_elastic(pattern, elastic) -> tuple[dict, dict, dict]:
    """Elastic faces as ({face: n or "auto"} bars, {face: (n1, n2)} plates,
    {face: n or "auto"} facets cut into rings — ``("rings", n)``, or a count on a
    face that is not a quadrilateral); ``"plates"``: every quadrilateral face a
    plate with "auto" counts; ``"facets"``: every face rings with "auto" counts."""
    if isinstance(elastic, str):
        if elastic == "plates":
            return {}, {f: ("auto", "auto") for f, face in enumerate(pattern.faces)
                        if len(face) == 4}, {}
        if elastic == "facets":
            return {}, {}, {f: "auto" for f in range(len(pattern.faces))}
        raise MeshError(f"{pattern.source}: elastic must be a dict {{face: cells}}, "
                        f"'plates' or 'facets', got {elastic!r}")
    bars, plates, facets = {}, {}, {}
    for f, n in dict(elastic or {}).items():
        f = int(f)
        if not 0 <= f < len(pattern.faces):
            raise MeshError(f"{pattern.source}: elastic panel: face {f} does not exist")
        if isinstance(n, (tuple, list)) and len(n) == 2 and n[0] == "rings":
            facets[f] = n[1]
        elif isinstance(n, (tuple, list)):
            if len(n) != 2:
                raise MeshError(f"{pattern.source}: elastic plate on face {f}: give two cell "
                                f"counts (n1, n2) or ('rings', n), got {n!r}")
            plates[f] = tuple(n)
        elif len(pattern.faces[f]) != 4:
            facets[f] = n
        else:
            bars[f] = n
    return bars, plates, facets


def cell_count(n, length: float, cell_size, where: str, bad: str) -> int:
    """A cell count: ``n`` checked, or for ``"auto"`` ⌈length / cell_size⌉ (mm / mm);
    ``where`` and ``bad`` make the refusal's message."""
    if isinstance(n, str) and n == "auto":
        if not (cell_size is not None and np.isfinite(cell_size) and cell_size > 0):
            raise MeshError(f"{where}: 'auto' needs a positive cell_size in mm, "
                            f"got {cell_size!r}")
        cells = float(length) / float(cell_size)  # (inf, not a NumPy warning, if too many)
        if not cells <= MAX_MESH_VERTICES:  # (an int of it may not even exist)
            raise MeshError(f"{where}: {length:g} mm in cells of {cell_size:g} mm would be "
                            f"{cells:.3g} cells, more than the {MAX_MESH_VERTICES:.3g} "
                            "vertices a thick mesh may have; use larger cells")
        n = max(1, int(np.ceil(cells - 1e-9)))
    if isinstance(n, str) or int(n) != n or n < 1:
        raise MeshError(f"{where}: {bad}")
    return int(n)


def plate_counts(pattern, plates, corners, cell_size) -> dict:
    """{face: (n1, n2)} validated, "auto" entries from ``cell_size`` (mm): n1 cells
    along the face's sides 0 and 2 (its first and third, in pattern order), n2
    along sides 1 and 3; ``corners``: each face's inset corners (m, 2), mm."""
    out = {}
    for f, counts in plates.items():
        if len(pattern.faces[f]) != 4:
            raise MeshError(f"{pattern.source}: elastic plate on face {f}: only "
                            f"quadrilateral faces can be gridded, got {len(pattern.faces[f])} "
                            "sides")
        c = np.asarray(corners[f])
        side = np.linalg.norm(np.roll(c, -1, axis=0) - c, axis=1)
        where = f"{pattern.source}: elastic plate on face {f}"
        out[f] = tuple(
            cell_count(n, length, cell_size, where,
                       f"cell counts must be positive integers or 'auto', got {counts!r}")
            for n, length in zip(counts, (max(side[0], side[2]), max(side[1], side[3]))))
    return out


def strip_segments(pattern, plates, stretch, bars) -> np.ndarray:
    """(E,) int: prisms along each crease's strip (1; a plate's cell count along its
    crease sides, so the strip conforms with the cells; 0 for boundary edges).
    A bar (1D cells) cannot share a split crease: refused, naming both faces."""
    segments = np.where(pattern.assignments == "B", 0, 1).astype(np.int64)
    owner = {}
    for f, counts in plates.items():
        face = pattern.faces[f]
        for side in range(4):
            e = edge_of(pattern, face[side], face[(side + 1) % 4])
            if pattern.assignments[e] == "B":
                continue
            if e in stretch:
                raise MeshError(f"{pattern.source}: elastic plate on face {f}: its side edge "
                                f"{e} is a stretch hinge (one strip, cannot follow the cells)")
            n = counts[side % 2]
            if e in owner and segments[e] != n:
                raise MeshError(f"{pattern.source}: elastic plates on faces {owner[e]} and {f} "
                                f"put {segments[e]} and {n} cells along their shared edge {e}")
            segments[e], owner[e] = n, f
            other = [g for g in pattern.edge_faces[e] if g != f]
            if n > 1 and other and int(other[0]) in bars:
                raise MeshError(f"{pattern.source}: elastic bar on face {int(other[0])} shares "
                                f"edge {e} with the plate on face {f}, whose {n} cells split "
                                "the strip; make both plates")
    return segments


def mesh_vertices(pattern, ks, segments, corners, kinds, cell_size) -> tuple[float, float]:
    """Estimates of the thick mesh's vertex count and of those inside elastic cells,
    before its strips and cells are built: twice its footprint points — the panels' inset ``corners``; for each
    crease, k − 1 inner lines of ``segments`` + 1 points (``ks``: sub-strips) and
    its two sides, whose ends are mostly panel corners; and the cells of the
    elastic faces ``kinds`` (bars, plates with resolved counts, facets; "auto"
    counts from ``cell_size``, mm). 1.07 … 1.42 × the count built on a hinge, a
    Miura and a waterbomb, rigid and with elastic bars, plates and facets (a
    Miura 400 × 400: 6.8 million for 5.75)."""
    bars, plates, facets = kinds
    crease = pattern.assignments != "B"
    along = np.asarray(segments, dtype=float) + 1.0
    rigid = float(sum(len(c) for c in corners))
    rigid += float(((np.asarray(ks, dtype=float) - 1.0) * along + 2.0 * (along - 1.0))[
        crease].sum())
    points = 0.0
    sides = pattern.edge_faces[crease]
    inserted = np.bincount(sides[sides >= 0], weights=np.repeat(along[crease] - 1.0, 2)[
        sides.ravel() >= 0], minlength=len(pattern.faces))  # strip points in a panel's loop
    for f, n in bars.items():
        c = np.asarray(corners[f])
        length = float(np.linalg.norm(np.roll(c, -1, axis=0) - c, axis=1).max())
        points += 2.0 * cell_count(n, length, cell_size, f"{pattern.source}: elastic panel on "
                                   f"face {f}", f"the number of cells must be a positive "
                                   f"integer or 'auto', got {n!r}")
    points += sum((n1 + 1.0) * (n2 + 1.0) for n1, n2 in plates.values())
    for f, n in facets.items():
        c = np.asarray(corners[f])
        reach = float(np.linalg.norm(c - c.mean(axis=0), axis=1).max())
        rings = cell_count(n, reach, cell_size, f"{pattern.source}: elastic facet on face {f}",
                           f"the number of rings must be a positive integer or 'auto', got {n!r}")
        points += (len(c) + inserted[f]) * rings + 1.0
    return 2.0 * (rigid + points), 2.0 * points
