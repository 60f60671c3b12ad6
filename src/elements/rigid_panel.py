"""Rigid panel: an n-sided prism whose target is its rest shape (paper §4).

Vertex order (n top vertices counter-clockwise seen from +z, then the n bottom
vertices in the same order)::

        3 ─────── 2          top    (z = +H/2): 0 … n-1
       /         /           bottom (z = -H/2): n … 2n-1, vertex n+i below i
      0 ─────── 1

The projection rotates the rest shape onto the current one (Kabsch, det = +1).
"""
from numba import njit, prange

from ._registry import ElementType
from .rotation import fit_rotated


@njit(cache=True)
def project(x, ids, rest, params, out, state):
    """Rotated rest shape of one panel; returns its residual Σ‖Cx − R·rest‖² (mm²).

    Parameters
    ----------
    x : (N, 3) current positions, mm
    ids : (m,) vertex ids
    rest : (m, 3) centred rest shape, mm
    params : (0,) unused
    out : (m, 3) written: the rotated target, mm
    state : (0,) unused
    """
    return fit_rotated(x, ids, rest, out)


@njit(parallel=True, cache=True)
def batch(x, indptr, indices, rest, params, out, energy, state):
    """Project every panel; ``energy[e]`` gets each residual (mm²)."""
    for e in prange(len(indptr) - 1):
        s, t = indptr[e], indptr[e + 1]
        energy[e] = project(x, indices[s:t], rest[s:t], params[e], out[s:t], state[e])


class RigidPanel(ElementType):
    """Panel that keeps its rest shape (rigid-origami panel)."""

    name = "rigid_panel"
    params = ()
    state = ()
    batch = batch
    project = project
