"""Triangulated grid crease patterns as FOLD dicts, any size (tests and bench/reading.py).

``n × n`` vertices on a unit (or ``size``) lattice; each square split by its
/ diagonal; interior edges cycle M, V, F (M −30°, V +45°, F passive), the
border is B. Vertex ``(i, j)`` has id ``j·n + i``.
"""
import numpy as np

#: How :func:`grid_fold` can break a grid (for refusal tests and benchmarks).
FLAWS = ("cross", "twin_vertex", "z")


def grid_fold(n: int, size: float = 1.0, unit: str = "mm", faces: bool = True,
              flaw: str | None = None) -> dict:
    """The FOLD dict of an ``n × n``-vertex triangulated grid.

    Parameters
    ----------
    n : int
        Vertices per side (≥ 2); V = n², E = 3n² − 4n + 1, F = 2(n − 1)².
    size : float
        Lattice spacing, in ``unit``.
    unit : str
        ``frame_unit``.
    faces : bool
        Write ``faces_vertices`` (else the reader derives them).
    flaw : {"cross", "twin_vertex", "z"} or None
        ``cross``: a last edge, the other diagonal of the last square (crosses
        its diagonal); ``twin_vertex``: a last vertex on top of vertex 0 with
        edges to vertex 0's neighbours (they overlap its edges); ``z``: the last vertex lifted to z = 1.
    """
    vid = lambda i, j: j * n + i
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="xy")
    xy = np.stack([i.ravel(), j.ravel()], axis=1) * float(size)
    a, b = np.meshgrid(np.arange(n - 1), np.arange(n), indexing="xy")
    horizontal = np.stack([vid(a, b), vid(a + 1, b)], -1).reshape(-1, 2)
    h_border = ((b == 0) | (b == n - 1)).ravel()
    a, b = np.meshgrid(np.arange(n), np.arange(n - 1), indexing="xy")
    vertical = np.stack([vid(a, b), vid(a, b + 1)], -1).reshape(-1, 2)
    v_border = ((a == 0) | (a == n - 1)).ravel()
    a, b = (x.ravel() for x in np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="xy"))
    diagonal = np.stack([vid(a, b), vid(a + 1, b + 1)], -1)
    edges = np.concatenate([horizontal, vertical, diagonal])
    kinds = np.array(list("MVF"))[np.arange(len(edges)) % 3]
    kinds[np.concatenate([h_border, v_border, np.zeros(len(diagonal), bool)])] = "B"
    angles = np.where(kinds == "M", -30.0, np.where(kinds == "V", 45.0, np.nan))
    d = {"file_spec": 1.2, "file_creator": "tests/grids.py", "frame_unit": unit,
         "vertices_coords": xy.tolist(), "edges_vertices": edges.tolist(),
         "edges_assignment": kinds.tolist(),
         "edges_foldAngle": [None if np.isnan(x) else float(x) for x in angles]}
    if faces:
        lower = np.stack([vid(a, b), vid(a + 1, b), vid(a + 1, b + 1)], 1)
        upper = np.stack([vid(a, b), vid(a + 1, b + 1), vid(a, b + 1)], 1)
        d["faces_vertices"] = np.concatenate([lower, upper]).tolist()
    if flaw == "cross":
        d["edges_vertices"].append([vid(n - 1, n - 2), vid(n - 2, n - 1)])
        d["edges_assignment"].append("M")
        d["edges_foldAngle"].append(None)
    elif flaw == "twin_vertex":
        d["vertices_coords"].append(list(d["vertices_coords"][0]))
        d["edges_vertices"] += [[n * n, vid(1, 0)], [n * n, vid(0, 1)]]
        d["edges_assignment"] += ["B", "B"]
        d["edges_foldAngle"] += [None, None]
    elif flaw == "z":
        d["vertices_coords"][-1] = d["vertices_coords"][-1] + [1.0]
    elif flaw is not None:
        raise ValueError(f"unknown flaw {flaw!r} (one of {', '.join(FLAWS)})")
    return d
