"""A user-defined element type outside foldcore: ``bar``, a straight strut of fixed length.

A bar joins two mesh vertices and keeps their distance: its projection puts
the two vertices at ±L/2 along their current direction, about their
midpoint (the nearest shape of length L). Defining the :class:`Bar` class
registers the type (``elements.registered()`` then lists it with this
module as its origin); a mesh group of kind ``"bar"`` is then simulated like
any built-in element, without editing foldcore. See ``prop.py`` for a scene
and ``docs/elements.md`` for the contract.

Parameters (one row per bar): none — the length is the rest shape's.
Vertex order: 2 vertices. Units: mm.
"""
import math

import numpy as np
from numba import njit, prange

from elements import ElementType


@njit(cache=True)
def project(x, ids, rest, params, out, state):
    """Segment of the rest length along the current direction; returns Σ‖Cx − T‖² (mm²).

    Parameters
    ----------
    x : (N, 3) current positions, mm
    ids : (2,) vertex ids
    rest : (2, 3) centred rest segment, mm (its length is kept)
    params : (0,) unused
    out : (2, 3) written: the centred target segment, mm
    state : (0,) unused
    """
    half = math.sqrt(rest[0, 0] ** 2 + rest[0, 1] ** 2 + rest[0, 2] ** 2)
    d0 = x[ids[1], 0] - x[ids[0], 0]
    d1 = x[ids[1], 1] - x[ids[0], 1]
    d2 = x[ids[1], 2] - x[ids[0], 2]
    norm = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    if norm == 0.0:  # coincident ends: keep the rest direction
        d0, d1, d2, norm = rest[1, 0] - rest[0, 0], rest[1, 1] - rest[0, 1], \
            rest[1, 2] - rest[0, 2], 2.0 * half
    residual = 0.0
    for k in range(2):
        sign = -1.0 if k == 0 else 1.0
        out[k, 0] = sign * half * d0 / norm
        out[k, 1] = sign * half * d1 / norm
        out[k, 2] = sign * half * d2 / norm
        residual += (sign * 0.5 * d0 - out[k, 0]) ** 2 + (sign * 0.5 * d1 - out[k, 1]) ** 2 \
            + (sign * 0.5 * d2 - out[k, 2]) ** 2
    return residual


@njit(parallel=True, cache=True)
def batch(x, indptr, indices, rest, params, out, energy, state):
    """Project every bar; ``energy[e]`` its residual (mm²)."""
    for e in prange(len(indptr) - 1):
        s, t = indptr[e], indptr[e + 1]
        energy[e] = project(x, indices[s:t], rest[s:t], params[e], out[s:t], state[e])


class Bar(ElementType):
    """Straight strut between two vertices that keeps its length."""

    name = "bar"
    params = ()
    state = ()
    batch = batch
    project = project


def bar_group(ends, lengths, weights):
    """An ElementGroup of bars.

    Parameters
    ----------
    ends : (n, 2) int, the two mesh vertex ids of each bar
    lengths : (n,) float, mm, each bar's length
    weights : (n,) float, mm³, each bar's weight in the global solve (compare
        with the elements' volumes: a weight ≫ the hinges' makes the bar stiff)
    """
    from foldcore.mesh import ElementGroup

    ends = np.asarray(ends, dtype=np.int64).reshape(-1, 2)
    half = 0.5 * np.asarray(lengths, dtype=float).reshape(-1)
    rest = np.zeros((2 * len(ends), 3))
    rest[0::2, 0], rest[1::2, 0] = -half, half
    n = len(ends)
    return ElementGroup("bar", np.arange(0, 2 * n + 1, 2, dtype=np.int64), ends.ravel(),
                        rest, np.zeros((n, 0)), np.asarray(weights, float),
                        np.asarray(weights, float), np.full(n, -1, dtype=np.int64))
