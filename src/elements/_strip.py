"""Shared numba helpers of the 8-vertex strip elements (bending and stretch hinges).

Vertex order (see :mod:`elements.bending_hinge`): top 0-1-2-3, bottom 4-7 below
them; 0→1 and 3→2 (4→5, 7→6) run across the width at crease ends a and b.
"""
import math

from numba import njit


@njit(cache=True)
def distance(x, i, j):
    """‖x[i] − x[j]‖ (mm)."""
    return math.sqrt((x[i, 0] - x[j, 0]) ** 2 + (x[i, 1] - x[j, 1]) ** 2
                     + (x[i, 2] - x[j, 2]) ** 2)


@njit(cache=True)
def strip_widths(x, ids):
    """(top, bottom) width of a strip, each the mean of its two width edges (mm)."""
    top = 0.5 * (distance(x, ids[0], ids[1]) + distance(x, ids[3], ids[2]))
    bottom = 0.5 * (distance(x, ids[4], ids[5]) + distance(x, ids[7], ids[6]))
    return top, bottom
