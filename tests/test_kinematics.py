"""Zero-thickness closed forms of :mod:`foldcore.kinematics` against its closure oracle."""
import numpy as np
import pytest

from foldcore import kinematics as k

SECTOR_SETS = [(135.0, 90.0), (60.0, 100.0), (80.0, 50.0)]  # (α, β) degrees
RHO1 = np.linspace(0.01, np.pi - 0.01, 25)


def test_rotation_is_right_handed_and_valley_positive():
    r = k.rotation([1.0, 0.0], np.pi / 2)
    assert np.allclose(r @ [0.0, 1.0, 0.0], [0.0, 0.0, 1.0])
    assert np.allclose(r @ r.T, np.eye(3)) and np.isclose(np.linalg.det(r), 1.0)


def test_pehrson_mode_a_reference_state_closes():
    d = k.degree4_directions(np.radians(135), np.radians(90))
    assert np.allclose(np.degrees(np.arctan2(d[:, 1], d[:, 0])) % 360, [0, 135, 225, 270])
    rho = np.radians([90.0, 45.0, 90.0, -45.0])
    assert k.closure_residual(d, rho) < 1e-12
    assert k.closure_residual(d[:, :2], rho) < 1e-12  # 2D directions accepted
    assert k.closure_residual(d, np.radians([90.0, 45.0, -90.0, 45.0])) > 0.1


def test_closure_is_mirror_symmetric():
    """Reversed product order = mirrored state: the order alone cannot fix signs."""
    d = k.degree4_directions(np.radians(60), np.radians(100))
    rho = k.degree4_mode_a(np.radians(60), np.radians(100), 1.0)
    assert k.closure_residual(d[::-1], rho[::-1]) < 1e-9
    assert k.closure_residual(d, -rho) < 1e-9


@pytest.mark.parametrize("mode", ["A", "B"])
@pytest.mark.parametrize("alpha,beta", SECTOR_SETS)
def test_degree4_modes_close(mode, alpha, beta):
    a, b = np.radians(alpha), np.radians(beta)
    fn = k.degree4_mode_a if mode == "A" else k.degree4_mode_b
    d = k.degree4_directions(a, b)
    states = fn(a, b, RHO1)
    assert states.shape == (len(RHO1), 4)
    for rho in np.concatenate([states, -states]):
        assert k.closure_residual(d, rho) < 1e-9


@pytest.mark.parametrize("mode", ["A", "B"])
def test_degree4_flat_folded_at_pi(mode):
    rho = k.degree4_deg(135, 90, 180.0, mode)
    assert np.allclose(np.abs(rho), 180.0)


def test_pehrson_ratios():
    t = np.tan(np.radians(20.0) / 2)
    rho_a = k.degree4_mode_a(np.radians(135), np.radians(90), np.radians(20.0))
    rho_b = k.degree4_mode_b(np.radians(135), np.radians(90), np.radians(20.0))
    assert np.isclose(np.tan(rho_a[1] / 2) / t, np.sqrt(2) - 1)
    assert np.isclose(np.tan(rho_b[1] / 2) / t, np.sqrt(2) + 1)
    assert np.allclose(k.degree4_deg(135, 90, 90.0, "A"), [90, 45, 90, -45])


@pytest.mark.parametrize("rho1,rho2", [(30, 12.66647), (60, 26.89895), (120, 71.31426),
                                       (150, 114.20343), (170, 156.14698)])
def test_pehrson_mode_a_table(rho1, rho2):
    assert abs(k.degree4_deg(135, 90, rho1, "A")[1] - rho2) < 1e-4


@pytest.mark.parametrize("gamma", [30.0, 60.0, 75.0])
@pytest.mark.parametrize("theta", [5.0, 30.0, 60.0, 85.0])
def test_miura_relations_close_as_mode_b(gamma, theta):
    """Straight crease = crease 1 (between the two γ sectors), zig-zag = 2 and 4."""
    z, s = k.miura_angles(np.radians(gamma), np.radians(theta))
    assert np.isclose(z, 2 * np.radians(theta))
    g = np.radians(gamma)
    rho = np.array([s, -z, -s, -z])  # mode B with α = γ < β: crease 1 is the odd one
    assert k.closure_residual(k.degree4_directions(g, np.pi - g), rho) < 1e-9
    mode_b = k.degree4_mode_b(g, np.pi - g, s)
    assert np.allclose(mode_b, rho, atol=1e-12)


def test_miura_cell_limits():
    h, s, length, v = k.miura_cell(20.0, 10.0, np.radians(60), 0.0)
    assert np.isclose(h, 0) and np.isclose(length, 20.0) and np.isclose(v, 5.0)
    assert np.isclose(s, 10.0 * np.sin(np.radians(60)))
    assert np.allclose(k.miura_angles_deg(60.0, 30.0),
                       np.degrees(k.miura_angles(np.radians(60), np.radians(30))))


@pytest.mark.parametrize("minor,major", [(5, 18.622), (10, 37.019), (20, 72.330),
                                         (30, 104.666)])
def test_waterbomb_table(minor, major):
    assert abs(k.waterbomb_major_deg(6, minor) - major) < 1e-3
    assert abs(k.waterbomb_minor_deg(6, major) - minor) < 1e-3


@pytest.mark.parametrize("n_creases", [6, 8, 12])
def test_waterbomb_branches_close(n_creases):
    phi = 2 * np.pi * np.arange(n_creases) / n_creases
    d = np.column_stack([np.cos(phi), np.sin(phi)])
    is_m = np.arange(n_creases) % 2 == 0
    for major in np.radians([1.0, 30.0, 90.0, 150.0, 179.0]):
        minor = k.waterbomb_minor(n_creases, major)
        assert 0 < minor < major
        m_major = np.where(is_m, -major, minor)
        v_major = np.where(is_m, -minor, major)
        assert k.closure_residual(d, m_major) < 1e-9
        assert k.closure_residual(d, v_major) < 1e-9


def test_waterbomb_limits():
    # branch end: major 180°, minor π − 2π/n with n = n_creases / 2
    assert np.isclose(k.waterbomb_minor_deg(6, 180.0), 60.0)
    assert np.isclose(k.waterbomb_minor_deg(8, 180.0), 90.0)
    assert np.isclose(k.waterbomb_major_deg(6, 60.0), 180.0)
    assert np.allclose(k.waterbomb_minor_deg(4, [10.0, 90.0]), 0.0, atol=1e-6)  # 4 creases: a line
    ratio = k.waterbomb_major_deg(6, 1e-4) / 1e-4
    assert abs(ratio - (2 + np.sqrt(3))) < 1e-3
    with pytest.raises(ValueError):
        k.waterbomb_minor(5, 1.0)


def test_solve_vertex_recovers_mode_a():
    a, b = np.radians(135), np.radians(90)
    d = k.degree4_directions(a, b)
    exact = k.degree4_mode_a(a, b, np.radians(60))
    guess = np.sign(exact) * 0.5
    rho = k.solve_vertex(d, {0: exact[0]}, guess)
    assert k.closure_residual(d, rho) < 1e-9
    assert np.allclose(rho, exact, atol=1e-7)


def test_solve_vertex_degree6_waterbomb():
    phi = np.pi / 3 * np.arange(6)
    d = np.column_stack([np.cos(phi), np.sin(phi)])
    major = np.radians(80.0)
    guess = np.array([-1, 0.3, -1, 0.3, -1, 0.3])
    rho = k.solve_vertex(d, {0: -major, 2: -major, 4: -major}, guess)
    assert k.closure_residual(d, rho) < 1e-9
    assert np.allclose(rho[1::2], k.waterbomb_minor(6, major), atol=1e-7)
