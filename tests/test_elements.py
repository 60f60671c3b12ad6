"""Contract tests over every registered element type (scikit-fem / STUMPY style).

Every type in ``elements.available()`` must have a spec in ``SPECS`` (how to
pose its rest, live and random parameters) and a NumPy twin in
``tests/naive.py``; a type without them fails here on purpose.

States come in two kinds: ``mesh`` (a thickened pattern, shared vertices,
perturbed) and ``soup`` (every element on its own vertices, randomly bent,
rotated and moved, random parameters: wrong-side M/V estimates and angles
beyond ``max_angle`` included). Tolerances are relative to element size.
Units: mm, radians.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import Callable

import numba
import numpy as np
import pytest

import elements
import naive
from elements import _registry
from foldcore import patterns
from foldcore.system import gather, vertex_slots
from foldcore.thickening import thicken

# the user-defined type of examples/plugin_bar is registered by importing it, as a
# user's code would; the contracts below then cover it like a built-in type
sys.path.insert(0, str(Path(__file__).parent.parent / "examples" / "plugin_bar"))
import bar as plugin_bar  # noqa: E402

W, H, TARGET, SIGN, MAX_ANGLE, FLOOR, MODEL, STRIPS, SERIES = range(9)
EQ8, ARC, AXIS = naive.EQ8, naive.ARC, naive.AXIS
TYPES = elements.available()
KINDS = ("mesh", "soup")
RTOL = 1e-12


# ------------------------------------------------------------------ scenes
@functools.lru_cache(maxsize=None)
def scenes() -> dict:
    """Small realistic thick meshes: actuated / passive V, M, U; axis, arc and Eq. 8."""
    sh = patterns.single_hinge
    return {
        "hinge_act_arc": thicken(sh(angle=90.0, width=4.0), 1.0, subdivisions=4, hinge="arc"),
        "hinge_act_axis": thicken(sh(angle=150.0, width=1.5), 1.0, subdivisions=4),
        "hinge_act_M_eq8": thicken(sh(angle=-60.0, assignment="M", width=3.0), 1.0,
                                   subdivisions=3, hinge="eq8"),
        "hinge_V_arc": thicken(sh(assignment="V", width=2.0, max_angle=120.0), 0.5,
                               subdivisions=2, hinge="arc"),
        "hinge_M_eq8": thicken(sh(assignment="M", width=2.0), 0.5, subdivisions=2,
                               hinge="eq8"),
        "hinge_U_axis": thicken(sh(assignment="U", width=2.0), 0.5, subdivisions=3),
        "hinge_U_eq8": thicken(sh(assignment="U", width=2.0), 0.5, subdivisions=3,
                               hinge="eq8"),
        "degree4_axis": thicken(patterns.degree4_vertex(rho1=40.0), 2.0),
        "degree4_B_eq8": thicken(patterns.degree4_vertex(mode="B", rho1=-30.0), 2.0,
                                 hinge="eq8"),
        "hinge_stretch": thicken(sh(width=2.0), 1.0, stretch={0: 0.3}),
        "hinge_with_bars": _with_bars(thicken(sh(angle=90.0, width=4.0), 1.0,
                                              subdivisions=2)),
    }


def _with_bars(mesh):
    """The mesh plus bars between every 7th pair of vertices (plugin type ``bar``)."""
    ends = np.column_stack([np.arange(0, mesh.n_vertices - 7, 7),
                            np.arange(7, mesh.n_vertices, 7)])
    rest = mesh.rest_positions
    lengths = np.linalg.norm(rest[ends[:, 1]] - rest[ends[:, 0]], axis=1)
    group = plugin_bar.bar_group(ends, lengths, np.ones(len(ends)))
    return dataclasses.replace(mesh, groups={**mesh.groups, "bar": group})


# ------------------------------------------------------------- type specs
def _same(p, rng=None):
    return p.copy()


def _rest_shape(rest, params, rng):
    return rest.copy()


def _hinge_rest(p, rng=None):
    """Actuated strips → target 0; passive strips keep NaN with floor 0."""
    p = p.copy()
    p[~np.isnan(p[:, TARGET]), TARGET] = 0.0
    p[:, FLOOR] = 0.0
    return p


def _hinge_live(p, rng=None):
    p = p.copy()
    p[:, FLOOR] = 0.02
    return p


def _hinge_random(p, rng):
    p, n = p.copy(), len(p)
    p[:, SIGN] = rng.choice([-1.0, 0.0, 1.0], n)
    p[:, MAX_ANGLE] = rng.uniform(0.1, 1.5, n)
    p[:, FLOOR] = rng.uniform(0.0, 0.08, n)
    p[:, MODEL] = rng.integers(0, 3, n)
    p[:, TARGET] = np.where(rng.random(n) < 0.3, rng.uniform(-1.5, 1.5, n), np.nan)
    # soup strips stand alone: a passive one is its own series (k = 1); an actuated
    # one's crease bends k × its target whatever its neighbours
    p[:, STRIPS] = np.where(np.isnan(p[:, TARGET]), 1, rng.integers(1, 9, n))
    p[:, SERIES] = 0
    # a constant-length arc turns its inner face inside out past 2W/H (its radius
    # W/φ < H/2): keep arc strips inside the range their shape exists in
    arc = p[:, MODEL] == ARC
    reach = 0.95 * 2.0 * p[:, W] / p[:, H]
    p[arc, MAX_ANGLE] = np.minimum(p[arc, MAX_ANGLE], reach[arc])
    p[arc, TARGET] = np.clip(p[arc, TARGET], -reach[arc], reach[arc])
    # an Eq. 8 trapezoid's inner face has negative width past 2·atan(W/H)
    eq8 = p[:, MODEL] == EQ8
    reach = 0.95 * 2.0 * np.arctan(p[:, W] / p[:, H])
    p[eq8, MAX_ANGLE] = np.minimum(p[eq8, MAX_ANGLE], reach[eq8])
    p[eq8, TARGET] = np.clip(p[eq8, TARGET], -reach[eq8], reach[eq8])
    return p


def _hinge_bent(rest, params, rng):
    return naive.bent_target(rest, params[W], rng.uniform(-2.6, 2.6), int(params[MODEL]),
                             params[H], int(params[STRIPS]))


def _stretch_rest(p, rng=None):
    """Passive strips estimate λ = 1 at rest: the rest shape is their fixed point."""
    p = p.copy()
    p[:, 2] = np.nan
    return p


def _stretch_live(p, rng=None):
    p = p.copy()
    p[:, 2] = 1.15
    return p


def _stretch_random(p, rng):
    p, n = p.copy(), len(p)
    p[:, 2] = np.where(rng.random(n) < 0.5, rng.uniform(0.7, 1.5, n), np.nan)
    p[:, 3] = rng.uniform(-0.5, 0.5, n)
    return p


def _stretch_shape(rest, params, rng):
    ratio = rng.uniform(0.7, 1.5)
    return rest * np.array([ratio, 1.0, ratio ** -params[3]])


@dataclass(frozen=True)
class Spec:
    rest_params: Callable     # params under which the rest shape is a fixed point
    live_params: Callable     # params for perturbed mesh states
    random_params: Callable   # (params, rng) → random valid params
    random_shape: Callable    # (rest (m,3), params (p,), rng) → local shape to perturb


SPECS = {
    "rigid_panel": Spec(_same, _same, _same, _rest_shape),
    "bending_hinge": Spec(_hinge_rest, _hinge_live, _hinge_random, _hinge_bent),
    "stretch_hinge": Spec(_stretch_rest, _stretch_live, _stretch_random, _stretch_shape),
    "bar": Spec(_same, _same, _same, _rest_shape),
}


def spec(name) -> Spec:
    if name not in SPECS or name not in naive.NAIVE:
        pytest.fail(f"element type {name!r} has no contract spec in tests/test_elements.py "
                    "(SPECS) or no NumPy twin in tests/naive.py (NAIVE): add both")
    return SPECS[name]


def groups_of(name) -> list:
    found = [(s, m, m.groups[name]) for s, m in scenes().items()
             if name in m.groups and len(m.groups[name])]
    if not found:
        pytest.fail(f"no test scene builds a group of element type {name!r}")
    return found


# ---------------------------------------------------------------- helpers
def random_rotation(rng) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def run(name, x, g, params):
    """Call the registered batch loop; returns (out, energy, state)."""
    etype = elements.get(name)
    n = len(g.indptr) - 1
    out = np.zeros((len(g.indices), 3))
    energy = np.zeros(n)
    state = np.zeros((n, len(etype.state)))
    etype.batch(np.ascontiguousarray(x, dtype=np.float64), g.indptr, g.indices, g.rest,
                np.ascontiguousarray(params, dtype=np.float64), out, energy, state)
    return out, energy, state


def sizes(g):
    """Per-element diameter of the rest shape (mm), and the same per slot."""
    ptr = g.indptr
    d = np.array([2 * np.linalg.norm(g.rest[ptr[e]:ptr[e + 1]], axis=1).max()
                  for e in range(len(ptr) - 1)])
    return d, np.repeat(d, np.diff(ptr))[:, None]


def centroids(x, g):
    return np.array([x[g.indices[g.indptr[e]:g.indptr[e + 1]]].mean(axis=0)
                     for e in range(len(g.indptr) - 1)])


def soup(name, groups, rng, min_elements=300):
    """Independent copies of the groups' elements: random shapes, poses, params."""
    sp = spec(name)
    rest, params, counts = [], [], []
    while len(counts) < min_elements:
        for g in groups:
            for e in range(len(g)):
                rest.append(g.rest[g.slots(e)])
                counts.append(len(rest[-1]))
                params.append(sp.random_params(g.params[e:e + 1], rng)[0])
    indptr = np.zeros(len(counts) + 1, dtype=np.int64)
    np.cumsum(counts, out=indptr[1:])
    x = []
    for r, p in zip(rest, params):
        scale = 2 * np.linalg.norm(r, axis=1).max()
        local = sp.random_shape(r, p, rng) + rng.normal(0, 0.02 * scale, r.shape)
        x.append(local @ random_rotation(rng).T + rng.uniform(-100, 100, 3))
    g = SimpleNamespace(indptr=indptr, indices=np.arange(indptr[-1], dtype=np.int64),
                        rest=np.ascontiguousarray(np.vstack(rest)))
    return np.vstack(x), g, np.array(params).reshape(len(counts), -1)


def states(name, kind, seed=0):
    """[(label, x, group_like, params)] of one type, for one kind of state."""
    rng = np.random.default_rng(seed)
    found = groups_of(name)
    if kind == "soup":
        x, g, p = soup(name, [g for _, _, g in found], rng)
        return [("soup", x, g, p)]
    out = []
    for label, mesh, g in found:
        x = mesh.rest_positions + rng.normal(0, 0.05 * mesh.thickness, (mesh.n_vertices, 3))
        out.append((label, x, g, spec(name).live_params(g.params)))
    return out


def assert_energy_close(e1, e0, m, size, factor=1.0):
    tol = factor * (RTOL * size * np.sqrt(m * np.maximum(e0, 0)) + 1e-24 * m * size ** 2)
    assert np.all(np.abs(e1 - e0) <= tol), np.max(np.abs(e1 - e0) / tol)


# -------------------------------------------------------------- contracts
@pytest.mark.parametrize("name", TYPES)
def test_rest_shape_is_a_fixed_point(name):
    for label, mesh, g in groups_of(name):
        x = mesh.rest_positions
        out, energy, _ = run(name, x, g, spec(name).rest_params(g.params))
        size, slot_size = sizes(g)
        centred = x[g.indices] - np.repeat(centroids(x, g), np.diff(g.indptr), axis=0)
        assert np.all(np.abs(out - centred) <= RTOL * slot_size), label
        assert np.all(energy <= 1e-24 * np.diff(g.indptr) * size ** 2), label


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", TYPES)
def test_rigid_motion_invariance(name, kind):
    rng = np.random.default_rng(1)
    for label, x, g, params in states(name, kind):
        q, b = random_rotation(rng), rng.uniform(-50, 50, 3)
        out, energy, state = run(name, x, g, params)
        out2, energy2, state2 = run(name, x @ q.T + b, g, params)
        size, slot_size = sizes(g)
        assert np.all(np.abs(out2 - out @ q.T) <= RTOL * slot_size), label
        assert np.all(np.abs(energy2 - energy) <= 1e-10 * energy + 1e-24 * size ** 2), label
        np.testing.assert_allclose(state2, state, rtol=0, atol=1e-10, err_msg=label)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", TYPES)
def test_projection_is_idempotent(name, kind):
    for label, x, g, params in states(name, kind):
        out, _, state = run(name, x, g, params)
        counts = np.diff(g.indptr)
        x2 = np.repeat(centroids(x, g), counts, axis=0) + out
        soup_g = SimpleNamespace(indptr=g.indptr, indices=np.arange(len(x2), dtype=np.int64),
                                 rest=g.rest)
        out2, energy2, state2 = run(name, x2, soup_g, params)
        size, slot_size = sizes(g)
        assert np.all(np.abs(out2 - out) <= RTOL * slot_size), label
        assert np.all(energy2 <= 1e-22 * counts * size ** 2), label
        np.testing.assert_allclose(state2, state, rtol=0, atol=1e-10, err_msg=label)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", TYPES)
def test_kernel_equals_numpy_twin(name, kind):
    spec(name)
    for seed in range(3):
        for label, x, g, params in states(name, kind, seed):
            out, energy, state = run(name, x, g, params)
            out_n, energy_n, state_n = naive.project_group(name, x, g, params)
            size, slot_size = sizes(g)
            assert np.all(np.abs(out - out_n) <= RTOL * slot_size), label
            assert_energy_close(energy, energy_n, np.diff(g.indptr), size)
            np.testing.assert_allclose(state, state_n, rtol=0, atol=1e-12, err_msg=label)


PREPARED = [n for n in TYPES if elements.get(n).prepared_batch is not None]


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", PREPARED)
def test_prepared_batch_gives_what_batch_gives_to_the_last_bit(name, kind):
    """The engine projects through prepare + prepared_batch: it must not change a bit."""
    etype = elements.get(name)
    for seed in range(2):
        for label, x, g, params in states(name, kind, seed):
            params = np.ascontiguousarray(params, dtype=np.float64)
            x = np.ascontiguousarray(x, dtype=np.float64)
            shapes = np.full_like(g.rest, np.nan)  # rows prepare leaves alone stay unread
            etype.prepare(g.indptr, g.rest, params, shapes)
            n = len(g.indptr) - 1
            out, energy = np.zeros((len(g.indices), 3)), np.zeros(n)
            state = np.zeros((n, len(etype.state)))
            etype.prepared_batch(x, g.indptr, g.indices, g.rest, shapes, params, out,
                                 energy, state)
            expected = run(name, x, g, params)
            for got, want in zip((out, energy, state), expected):
                np.testing.assert_array_equal(got, want, err_msg=label)


def test_prepare_without_prepared_batch_is_refused(saved_registry):
    with pytest.raises(TypeError, match="both"):
        class HalfPrepared(elements.ElementType):
            name = "test_half_prepared"
            prepare = staticmethod(lambda *a: None)


def test_twin_states_cover_the_clamps():
    """The soup really holds wrong-side M/V estimates and angles beyond max_angle."""
    x, g, p = soup("bending_hinge", [g for _, _, g in groups_of("bending_hinge")],
                   np.random.default_rng(0))
    passive = np.isnan(p[:, TARGET])
    est = np.array([naive.estimate_angle(x[g.indices[g.indptr[e]:g.indptr[e + 1]]],
                                         p[e, MODEL] != EQ8) for e in range(len(p))])
    wrong_side = passive & (p[:, SIGN] * est < 0)
    too_far = passive & (np.abs(est) > p[:, MAX_ANGLE])
    assert len(p) >= 300 and wrong_side.sum() >= 20 and too_far.sum() >= 20


# ----------------------------------------------------------------- threads
@pytest.fixture
def thread_counts():
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has fewer than 2 threads")
    before = numba.get_num_threads()
    yield (1, 2)
    numba.set_num_threads(before)


def _with_threads(n, fn, *args):
    numba.set_num_threads(n)
    return fn(*args)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("name", TYPES)
def test_batch_identical_with_1_and_2_threads(name, kind, thread_counts):
    for label, x, g, params in states(name, kind):
        one, two = (_with_threads(n, run, name, x, g, params) for n in thread_counts)
        _, slot_size = sizes(g)
        assert np.all(np.abs(one[0] - two[0]) <= RTOL * slot_size), label
        np.testing.assert_allclose(one[1], two[1], rtol=RTOL, atol=0, err_msg=label)
        np.testing.assert_allclose(one[2], two[2], rtol=0, atol=RTOL, err_msg=label)


@pytest.mark.parametrize("scene", list(scenes()))
def test_gather_identical_with_1_and_2_threads(scene, thread_counts):
    mesh = scenes()[scene]
    rng = np.random.default_rng(2)
    groups = list(mesh.groups.values())
    indices = np.concatenate([g.indices for g in groups])
    v_indptr, v_slots = vertex_slots(indices, mesh.n_vertices)
    weights = rng.uniform(0.5, 2.0, len(indices))
    targets = rng.normal(size=(len(indices), 3))
    rhs = [np.zeros((mesh.n_vertices, 3)) for _ in thread_counts]
    for n, r in zip(thread_counts, rhs):
        _with_threads(n, gather, v_indptr, v_slots, weights, targets, r)
    np.testing.assert_allclose(rhs[0], rhs[1], rtol=RTOL, atol=0)
    expected = np.zeros((mesh.n_vertices, 3))
    np.add.at(expected, indices, weights[:, None] * targets)
    np.testing.assert_allclose(rhs[0], expected, rtol=1e-12, atol=1e-12)


# ----------------------------------------------------------- hinge physics
def _strip(width=1.0, height=0.8, length=5.0):
    """Rest (8, 3) of one sub-strip in its local frame, kernel vertex order."""
    x, y, z = width / 2, height / 2, length / 2
    top = [(-x, y, -z), (x, y, -z), (x, y, z), (-x, y, z)]
    return np.array(top + [(a, -y, c) for a, _, c in top])


def _project_strip(rest, phi, model, x=None, passive=False, strips=1, height=0.8):
    params = np.array([[1.0, height, np.nan if passive else phi, 0.0, math.pi, 0.0,
                        float(model), float(strips), 0.0]])
    g = SimpleNamespace(indptr=np.array([0, 8], dtype=np.int64),
                        indices=np.arange(8, dtype=np.int64), rest=rest)
    return run("bending_hinge", rest if x is None else x, g, params)


def _d(p, i, j):
    return np.linalg.norm(p[i] - p[j])


@pytest.mark.parametrize("phi", [-2.0, -0.7, 0.3, 1.0, 2.5])
def test_exact_arc_target_is_a_circular_bend(phi):
    rest = _strip()
    width, height = 1.0, 0.8
    out, _, state = _project_strip(rest, phi, ARC)
    radius = width / phi
    assert state[0, 0] == phi
    for i, j in ((0, 1), (3, 2)):
        assert _d(out, i, j) == pytest.approx(2 * (radius - height / 2) * math.sin(phi / 2),
                                              rel=1e-12)
    for i, j in ((4, 5), (7, 6)):
        assert _d(out, i, j) == pytest.approx(2 * (radius + height / 2) * math.sin(phi / 2),
                                              rel=1e-12)
    for top in range(4):  # end faces have length H and point at the arc's centre
        assert _d(out, top, top + 4) == pytest.approx(height, rel=1e-12)
    centres = [out[t] + (out[t] - out[t + 4]) / height * (radius - height / 2)
               for t in range(4)]
    assert np.allclose(centres[0], centres[1], rtol=0, atol=1e-12 * abs(radius))
    assert np.allclose(centres[3], centres[2], rtol=0, atol=1e-12 * abs(radius))
    # its own estimate (asin) returns φ, so a passive arc strip is a fixed point
    assert naive.estimate_angle(out, True) == pytest.approx(phi, abs=1e-12)
    assert _project_strip(rest, 0.0, ARC, x=out, passive=True)[2][0, 0] == pytest.approx(
        phi, abs=1e-12)


@pytest.mark.parametrize("phi", [-1.7, -0.7, 0.3, 1.0, 1.5])
def test_eq8_target_is_inverted_by_eq9(phi):
    """Within one strip's limit 2·atan(W/H) (1.79 rad here) the top face stays positive."""
    rest = _strip()
    height = 0.8
    out, _, _ = _project_strip(rest, phi, EQ8)
    w_top, w_bot, _ = naive.strip_measures(out)
    assert w_bot - w_top == pytest.approx(2 * height * math.tan(phi / 2), abs=1e-12)
    assert naive.estimate_angle(out, False) == pytest.approx(phi, abs=1e-12)
    kernel_phi = _project_strip(rest, 0.0, EQ8, x=out, passive=True)[2][0, 0]
    assert kernel_phi == pytest.approx(phi, abs=1e-12)


def _end_face_frame(face):
    """(origin, across-thickness unit vector) of an end face's 4 vertices in the
    cross-section plane (x, y): the neutral-axis point and the face direction."""
    mid = face.mean(axis=0)
    up = face[:2].mean(axis=0) - face[2:].mean(axis=0)  # top pair minus bottom pair
    return mid[:2], up[:2] / np.linalg.norm(up[:2])


@pytest.mark.parametrize("strips", [1, 2, 4])
@pytest.mark.parametrize("theta", [-2.2, -1.0, 0.4, 1.2, 2.0])
def test_axis_hinge_turns_the_end_faces_about_the_crease_mid_line(theta, strips):
    """k axis sub-strips, each bent θ/k, chained end face to end face: the crease's
    last face is its first turned by θ about the crease's mid-line (the defining
    property, checked on the kernel's own targets). θ below θ* = 2·atan(W/H):
    W = k·1 = 1…4 mm, H = 0.2 mm."""
    height, width = 0.2, 1.0
    rest = _strip(width=width, height=height)
    phi = theta / strips
    out, _, _ = _project_strip(rest, phi, AXIS, strips=strips, height=height)
    left, right = [0, 3, 4, 7], [1, 2, 5, 6]
    o_l, u_l = _end_face_frame(out[left])
    o_r, _ = _end_face_frame(out[right])
    tilt = math.atan2(-u_l[0], u_l[1])  # the target's left face: up = R(tilt)·ŷ

    def rotation(a):
        return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])

    # chain the k strips from the crease's first face, x = −W/2 turned by −θ/2
    turn = -theta / 2
    origin = rotation(turn) @ np.array([-strips * width / 2, 0.0])
    for _ in range(strips):
        origin = origin + rotation(turn - tilt) @ (o_r - o_l)
        turn += phi
    # rigid origami: the last face is x = W/2 of the flat strip turned by θ/2 about 0
    expected = strips * width / 2 * np.array([math.cos(theta / 2), math.sin(theta / 2)])
    np.testing.assert_allclose(origin, expected, atol=1e-12)
    # and the estimate inverts it (passive axis strips are fixed points)
    assert _project_strip(rest, 0.0, AXIS, x=out, passive=True, strips=strips,
                          height=height)[2][0, 0] == pytest.approx(phi, abs=1e-12)


@pytest.mark.parametrize("phi", [1.9, 2.5, -3.0])
def test_axis_hinge_past_its_pivot_angle_keeps_a_zero_inner_radius(phi):
    """Past θ* = 2·atan(W/H) (W = 1, H = 0.8: 1.79 rad) the neutral axis stays at
    H|φ|/2: the inner face has zero length (radius 0), the end faces length H."""
    rest = _strip()
    out, _, _ = _project_strip(rest, phi, AXIS)
    inner = (0, 1) if phi > 0 else (4, 5)
    assert _d(out, *inner) == pytest.approx(0.0, abs=1e-12)
    assert _d(out, 0, 4) == pytest.approx(0.8, rel=1e-12)


@pytest.mark.parametrize("phi", [1.0, -1.0])
@pytest.mark.parametrize("length, kept", [(0.96, 0.96), (1.2, 1.0), (0.8, None)])
def test_slack_strip_keeps_its_own_length_between_its_bounds(phi, length, kept):
    """A slack strip (W = 1, H = 0.8, φ = ±1 rad) bent on an arc of length ℓ is
    projected onto the arc of ℓ kept between the axis hinge's length
    (0.5/tan 0.5 = 0.915) and W = 1: inside, the strip is its own target (residual
    at rounding); outside, the target's neutral chord is the bound's,
    2(ℓ/φ)·sin(φ/2), to rounding."""
    from elements.bending_hinge import SLACK, arc_shape, axis_length, neutral_chord

    rest = _strip()
    bent = np.empty_like(rest)
    arc_shape(rest, 1.0, phi, length, bent)
    out, energy, _ = _project_strip(rest, phi, SLACK, x=bent)
    kept = axis_length(1.0, 0.8, phi, phi) if kept is None else kept
    chord = 2 * kept / abs(phi) * math.sin(abs(phi) / 2)
    assert neutral_chord(out, np.arange(8)) == pytest.approx(chord, rel=1e-12)
    if length == kept:
        assert energy[0] < 1e-24


def test_pivot_blend_is_one_constant_on_both_sides_of_the_layering():
    """elements cannot import foldcore, foldcore.hinges must not import numba: the
    rounding band of the axis hinge's switch is written twice and kept equal here."""
    from elements.bending_hinge import PIVOT_BLEND as kernel_band
    from foldcore.hinges import PIVOT_BLEND as model_band

    assert kernel_band == model_band


def test_bend_is_continuous_at_zero():
    rest = _strip()
    for model in (EQ8, ARC, AXIS, 3.0):  # 3: slack
        out, energy, _ = _project_strip(rest, 1e-13, model, strips=4)
        assert np.allclose(out, rest, rtol=0, atol=1e-12) and energy[0] < 1e-24


# ---------------------------------------------------------------- registry
@pytest.mark.parametrize("name", TYPES)
def test_registered_type_has_metadata(name):
    etype = elements.get(name)
    assert etype.name == name and name in elements.registered()
    assert isinstance(etype.params, tuple) and all(isinstance(p, str) for p in etype.params)
    assert isinstance(etype.state, tuple) and callable(etype.batch)


def test_unknown_type_lists_available():
    with pytest.raises(KeyError, match="available: .*rigid_panel"):
        elements.get("nope")


@pytest.fixture
def saved_registry():
    elements.get("rigid_panel")
    saved = dict(_registry._REGISTRY)
    yield
    _registry._REGISTRY.clear()
    _registry._REGISTRY.update(saved)


def test_name_collision_warns(saved_registry):
    original = elements.get("rigid_panel")
    with pytest.warns(RuntimeWarning, match="rigid_panel"):
        class Impostor(elements.ElementType):
            name = "rigid_panel"
    assert elements.get("rigid_panel") is Impostor
    with warnings.catch_warnings():
        warnings.simplefilter("error")

        class Fresh(elements.ElementType):
            name = "test_fresh_type"
    assert elements.get("test_fresh_type") is Fresh and original is not Impostor


def test_registry_left_untouched():
    assert elements.get("rigid_panel").__module__ == "elements.rigid_panel"
    assert "test_fresh_type" not in elements.registered()


def random_covariance(rng, sigma, inverted):
    """Q·diag(sigma)·Vᵀ with random orthogonal Q, V; det < 0 iff ``inverted``."""
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    v, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if (np.linalg.det(q @ v.T) > 0) == inverted:
        v[:, 2] = -v[:, 2]
    return q @ np.diag(sigma) @ v.T


def assert_best_rotation(r, a, atol):
    """r is a proper rotation reaching the optimum tr(Rᵀ a) = σ₁ + σ₂ ± σ₃, and
    equals the Kabsch rotation within ``atol`` where that one is unique (atol
    given from the problem's sensitivity; None: several rotations are optimal)."""
    s = np.linalg.svd(a, compute_uv=False)
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-13)
    assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-12)
    optimum = s[0] + s[1] + np.sign(np.linalg.det(a)) * s[2]
    assert np.trace(r.T @ a) == pytest.approx(optimum, abs=1e-13 * s[0])
    if atol is not None:
        np.testing.assert_allclose(r, naive.kabsch_of(a), atol=atol)


@pytest.mark.parametrize("cond", [1.0, 1e3, 1e6])
@pytest.mark.parametrize("inverted", [False, True])
def test_polar_rotation_is_the_best_rotation(cond, inverted):
    """The allocation-free Newton polar factor (det > 0) and its Jacobi fallback
    (inverted A) give the Kabsch rotation U·diag(1,1,det(UVᵀ))·Vᵀ.

    The proper rotation's sensitivity is ‖A‖/(σ₂ + σ₃) for det > 0 (≤ cond
    here) and ‖A‖/(σ₂ − σ₃) for an inverted A, so the allowed gap is 10·ε
    times that; with σ₂ = σ₃ (cond = 1, inverted) every rotation about one
    axis is optimal and only the optimum is checked.
    """
    from elements.rotation import polar_rotation

    rng = np.random.default_rng(int(cond) + inverted)
    eps = np.finfo(float).eps
    for _ in range(300):
        sigma = np.array([1.0, rng.uniform(1.0 / cond, 1.0), 1.0 / cond])
        a = random_covariance(rng, sigma, inverted) * 10.0 ** rng.uniform(-6, 6)
        gap = sigma[1] - sigma[2] if inverted else sigma[1] + sigma[2]
        r = np.array(polar_rotation(*a.ravel())).reshape(3, 3)
        assert_best_rotation(r, a, 10 * eps / gap if gap > 1e-6 else None)


@pytest.mark.parametrize("rank", [0, 1, 2, 3])
@pytest.mark.parametrize("inverted", [False, True])
def test_jacobi_rotation_is_the_best_rotation(rank, inverted):
    """The rare path (inverted or nearly singular A) called directly: Horn's
    quaternion from a Jacobi eigen-decomposition reaches the optimum for every
    rank, inverted or not, and is the Kabsch rotation where that is unique
    (sensitivity ‖A‖/(σ₂ ∓ σ₃) ≤ 4 here: allowed gap 40·ε)."""
    from elements.rotation import jacobi_rotation

    rng = np.random.default_rng(10 * rank + inverted)
    eps = np.finfo(float).eps
    for _ in range(300):
        sigma = np.array([1.0, rng.uniform(0.5, 1.0), rng.uniform(0.0, 0.25)])
        sigma[rank:] = 0.0
        a = random_covariance(rng, sigma, inverted) * 10.0 ** rng.uniform(-6, 6)
        r = np.array(jacobi_rotation(*a.ravel())).reshape(3, 3)
        assert np.isfinite(r).all()
        assert_best_rotation(r, a, 40 * eps if rank >= 2 else None)


@pytest.mark.parametrize("cond", [1.0, 1e3, 1e6])
@pytest.mark.parametrize("inverted", [False, True])
def test_fitted_rotation_matches_the_svd_kabsch_rotation(cond, inverted):
    """The quaternion fit (+ polishing, or its polar/SVD fallbacks) equals the
    Kabsch rotation U·diag(1, 1, det(UVᵀ))·Vᵀ to the problem's conditioning.

    The proper rotation's sensitivity is ‖A‖/(σ₂ ± σ₃) (+ for det > 0, − for an
    inverted A), kept ≤ 2·cond here (σ₃ = 1/(2 cond) ≤ σ₂/2), so the allowed gap
    is 20·cond·ε. ``upper``
    is any bound ≥ Horn's largest eigenvalue: drawn 1e-12…1 above it.
    """
    from elements.rotation import fitted_rotation

    rng = np.random.default_rng(int(cond) + inverted)
    eps = np.finfo(float).eps
    for _ in range(300):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        v, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        sigma = np.array([1.0, rng.uniform(1.0 / cond, 1.0), 0.5 / cond])
        if np.linalg.det(q @ v.T) > 0 if inverted else np.linalg.det(q @ v.T) < 0:
            v[:, 2] = -v[:, 2]
        a = q @ np.diag(sigma) @ v.T * 10.0 ** rng.uniform(-6, 6)
        s = np.linalg.svd(a, compute_uv=False)
        lam = s[0] + s[1] + np.sign(np.linalg.det(a)) * s[2]
        upper = lam * (1.0 + 10.0 ** rng.uniform(-12, 0))
        r = np.array(fitted_rotation(*a.ravel(), upper)).reshape(3, 3)
        np.testing.assert_allclose(r, naive.kabsch_of(a), atol=20 * cond * eps)
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-14)
        assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("rank", [0, 1, 2])
def test_fitted_rotation_of_degenerate_covariances_is_a_rotation(rank):
    """Coincident (rank 0), collinear (1) or coplanar-with-a-zero-singular-value (2)
    covariances have a non-unique best rotation: any proper rotation reaching
    the optimum tr(Rᵀ A) = σ₁ + σ₂ + σ₃ will do, and no NaN may come out."""
    from elements.rotation import fitted_rotation

    rng = np.random.default_rng(rank)
    for _ in range(100):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        v, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        sigma = np.array([1.0, 0.5, 0.0])[:3] * (np.arange(3) < rank)
        a = q @ np.diag(sigma) @ v.T
        upper = sigma.sum() + 1.0
        r = np.array(fitted_rotation(*a.ravel(), upper)).reshape(3, 3)
        assert np.isfinite(r).all()
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-12)
        assert np.trace(r.T @ a) == pytest.approx(sigma.sum(), abs=1e-12)


@pytest.mark.parametrize("n", [1, 7, 1000])
def test_take_solution_copies_to_c_order_and_returns_the_largest_move(n):
    """The paper iteration's last pass: C-ordered copy of the (column-major) solve
    result and max |new − old| in one go; a non-finite value must surface as NaN
    (the run stops on it) and not be lost in the maximum."""
    from foldcore.system import take_solution

    rng = np.random.default_rng(n)
    previous = rng.normal(size=(n, 3))
    solution = np.asfortranarray(previous + rng.normal(scale=1e-3, size=(n, 3)))
    out = np.empty((n, 3))
    moved = take_solution(solution, previous, out)
    np.testing.assert_array_equal(out, solution)
    assert moved == np.abs(solution - previous).max()
    solution[n // 2, 1] = np.nan
    assert np.isnan(take_solution(solution, previous, out))
    solution[n // 2, 1] = np.inf
    assert np.isnan(take_solution(solution, previous, out))


@pytest.mark.parametrize("scale", [1e-12, 1e-8, 1.0, 1e6])
def test_fit_rotated_is_scale_free_between_the_current_shape_and_its_target(scale):
    """A current shape much smaller (or larger) than its target — a collapsed
    element, or one far from its rest size — still gets the Kabsch rotation:
    the root search must not start so far above λ that it stops before it."""
    from elements.rotation import fit_rotated

    rng = np.random.default_rng(int(-np.log10(scale)) + 20)
    for _ in range(200):
        target = rng.normal(size=(8, 3))
        target -= target.mean(axis=0)
        rot, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        rot *= np.sign(np.linalg.det(rot))
        x = scale * (target @ rot.T + 0.05 * rng.normal(size=(8, 3))) + 3.0 * scale
        out = np.empty_like(target)
        fit_rotated(x, np.arange(8), target, out)
        centred = x - x.mean(axis=0)
        expected = target @ naive.kabsch_of(centred.T @ target).T
        np.testing.assert_allclose(out, expected, atol=1e-11 * np.abs(target).max())
