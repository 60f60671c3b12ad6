"""A crease pattern split along its cuts (``C`` edges: kirigami, Origami Simulator's
green lines), and the slits a split leaves.

A cut is drawn as one edge with a face on each side. Splitting gives each side
its own boundary edge and each vertex along the cut one copy per side: around
a vertex, the face corners linked across edges that are neither cuts nor
boundary form one fan, and each fan keeps a vertex of its own (the first fan the
original id, the others new ids after the pattern's vertices, vertex by vertex).
A cut's end inside the sheet stays one vertex, as its faces still go round it.
The cut edge keeps the side whose face is on its left; the other side is a new
edge after the pattern's edges. Both are ``B``. A cut whose two ends both stay
one vertex (a single segment between vertices with no other cut) cannot open:
its sides would be one edge twice, so it stays one edge, a free hinge (``U``),
which is how Origami Simulator folds it (two boundary edges on the same two
vertices, a bar between two triangles with no crease spring). This is Origami
Simulator's ``splitCuts``, done on face corners instead of by walking each
vertex's edges.

A split leaves coincident vertices and edges: the two sides of a slit.
:func:`welded_ids` tells them apart from vertices drawn twice by mistake.
Units: mm.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .planar import loop_starts, next_in_loop


@dataclass(frozen=True)
class Split:
    """A pattern split along its cuts.

    Attributes
    ----------
    vertices : (V', 2) float, mm: the pattern's vertices, then the copies
    edges : (E', 2) int: the pattern's edges (renumbered ends), then each cut's
        second side
    flat : (N,) int: the face loops' corners, renumbered (lengths unchanged)
    copied_from : (V' − V,) int: the pattern vertex each copy was made from
    second_side_of : (E' − E,) int: the cut each new edge is the second side of
    shut : (E,) bool: the cuts that cannot open (module docstring)
    """

    vertices: np.ndarray
    edges: np.ndarray
    flat: np.ndarray
    copied_from: np.ndarray
    second_side_of: np.ndarray
    shut: np.ndarray


def split_along_cuts(vertices: np.ndarray, edges: np.ndarray, flat: np.ndarray,
                     lengths: np.ndarray, slots: np.ndarray, cut: np.ndarray) -> Split:
    """The :class:`Split` of a pattern along the edges where ``cut`` is True.

    Parameters
    ----------
    vertices : (V, 2) float, mm
    edges : (E, 2) int
    flat, lengths : the face loops (counter-clockwise), concatenated, and their lengths
    slots : (N,) int, the edge along each corner's side, + E on the edge's right
        (:attr:`foldcore.pattern.CreasePattern.side_slots`); every cut has both sides
    cut : (E,) bool
    """
    side_end = next_in_loop(loop_starts(lengths), lengths)
    left_corner, right_corner = _side_corners(slots, len(edges))
    linked = (left_corner >= 0) & (right_corner >= 0) & ~cut
    # across a linked edge u → v: the left face's corner at u with the right face's
    # corner at u (where the right side v → u ends), and likewise at v
    left, right = left_corner[linked], right_corner[linked]
    a = np.concatenate([left, side_end[left]])            # at u, at v
    b = np.concatenate([side_end[right], right])          # at u, at v
    fan = _components(len(flat), a, b)
    new_id, copied_from = _fan_ids(flat, fan, len(vertices))
    corner_id = new_id[fan]
    out_edges = np.empty_like(edges)
    has_left = left_corner >= 0
    k = np.where(has_left, left_corner, right_corner)
    ends = np.stack([corner_id[k], corner_id[side_end[k]]], axis=1)
    out_edges[:] = np.where(has_left[:, None], ends, ends[:, ::-1])
    cuts = np.flatnonzero(cut)
    r = right_corner[cuts]
    second = np.stack([corner_id[side_end[r]], corner_id[r]], axis=1)
    same = (second == out_edges[cuts]).all(axis=1)
    shut = np.zeros(len(edges), dtype=bool)
    shut[cuts[same]] = True
    return Split(np.concatenate([vertices, vertices[copied_from]]),
                 np.concatenate([out_edges, second[~same]]), corner_id, copied_from,
                 cuts[~same], shut)


def _side_corners(slots: np.ndarray, n_edges: int):
    """Per edge, the corner where its left side (u → v) starts and where its right side
    (v → u) starts (−1 where there is no such side)."""
    left, right = np.full(n_edges, -1, dtype=np.int64), np.full(n_edges, -1, dtype=np.int64)
    on_left = slots < n_edges
    left[slots[on_left]] = np.flatnonzero(on_left)
    right[slots[~on_left] - n_edges] = np.flatnonzero(~on_left)
    return left, right


def _components(n: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n,) component label of each of ``n`` nodes linked pairwise by ``a``–``b``."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def _fan_ids(flat: np.ndarray, fan: np.ndarray, n_vertices: int):
    """(new id of each fan label, vertex each copy came from): a vertex's first fan
    (in corner order) keeps its id, its other fans get new ids, vertex by vertex."""
    labels, first = np.unique(fan, return_index=True)
    vertex = flat[first]
    order = np.lexsort((first, vertex))        # fans vertex by vertex, first corner first
    v_sorted = vertex[order]
    is_first = np.concatenate([[True], v_sorted[1:] != v_sorted[:-1]])
    ids = np.empty(len(order), dtype=np.int64)
    ids[is_first] = v_sorted[is_first]
    extra = np.flatnonzero(~is_first)
    ids[extra] = n_vertices + np.arange(len(extra))
    new_id = np.empty(int(labels.max()) + 1 if len(labels) else 0, dtype=np.int64)
    new_id[labels[order]] = ids
    return new_id, v_sorted[extra]


def cut_note(split: Split) -> str:
    """The line that says what a split did (cuts opened, vertices copied, cuts shut)."""
    opened, copies, shut = len(split.second_side_of), len(split.copied_from), int(split.shut.sum())
    said = []
    if opened:
        said.append(f"{opened} cut edge{'s' if opened != 1 else ''} ('C'): the sheet is split "
                    f"along {'them' if opened != 1 else 'it'}, each side a boundary edge "
                    f"({copies} vertex cop{'ies' if copies != 1 else 'y'} along the cuts)")
    if shut:
        said.append(f"{shut} cut edge{'s' if shut != 1 else ''} ('C') of one segment between "
                    "vertices no other cut reaches cannot open: a free hinge (U) each, as "
                    "Origami Simulator folds them")
    return "; ".join(said)


def welded_ids(vertices: np.ndarray):
    """(V,) int, for each vertex the smallest id at exactly the same point, or None
    when no two vertices coincide (the common case, found with one sort)."""
    order = np.lexsort((vertices[:, 1], vertices[:, 0]))
    ordered = vertices[order]
    same = (ordered[1:] == ordered[:-1]).all(axis=1)
    if not same.any():
        return None
    group = np.concatenate([[0], np.cumsum(~same)])  # runs of one point, in sorted order
    smallest = np.full(group[-1] + 1, len(vertices), dtype=np.int64)
    np.minimum.at(smallest, group, order)
    out = np.empty(len(vertices), dtype=np.int64)
    out[order] = smallest[group]
    return out
