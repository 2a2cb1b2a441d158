"""The slender share of a ruled surface: how steeply the §4.3 rows can cross its generators."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ruledmesh.analysis.asymptotic import (
    SLENDER_ELONGATION,
    crossing_angles,
    least_elongation,
    slender_share,
)
from ruledmesh.analysis.faces import quad_diagonal_crossing
from ruledmesh.pq import pq_mesh


def _angle(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Acute angle between line directions, degrees."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1),
                                 np.abs(np.einsum("...i,...i->...", u, v))))


def _circle(q: np.ndarray) -> np.ndarray:
    return np.stack([np.cos(q), np.sin(q), np.zeros_like(q)], axis=-1)


def test_hyperbolic_paraboloid_lines_cross_at_the_other_family():
    # z = x y: the generators x = const have direction (0, 1, x), the other family's line
    # through (x, y) has (1, 0, y); the hop line is that line exactly.
    x = np.linspace(-1.0, 2.0, 13)
    a = np.stack([x, 0 * x, 0 * x], 1)
    b = np.stack([x, 1 + 0 * x, x], 1)
    t = np.linspace(0.0, 1.0, 7)
    angles, weights = crossing_angles(a, b, t)
    X, Y = np.meshgrid(x[1:-1], t, indexing="ij")
    g = np.stack([0 * X, 1 + 0 * X, X], -1)
    h = np.stack([1 + 0 * Y, 0 * Y, Y], -1)
    assert np.allclose(angles, _angle(g, h), atol=1e-10, rtol=0)
    assert weights.shape == angles.shape and (weights > 0).all()


def test_hyperboloid_lines_cross_at_the_other_regulus():
    # Circles of radius 1 at z = 0 and z = h, the top turned by phi: the line of the other
    # regulus through (1 - t) e(th) + t e(th + phi) starts at e(th + 2 beta), where
    # (1 - t) + t exp(i phi) = rho exp(i beta), and ends at e(th + 2 beta - phi) + h z.
    phi, h = np.radians(110.0), 0.8
    th = np.linspace(0.0, np.pi, 25)
    a, b = _circle(th), _circle(th + phi) + [0.0, 0.0, h]
    t = np.linspace(0.0, 1.0, 9)
    angles, _ = crossing_angles(a, b, t)
    beta = np.angle((1 - t) + t * np.exp(1j * phi))
    psi = th[1:-1, None] + 2 * beta[None, :]
    other = _circle(psi - phi) + [0.0, 0.0, h] - _circle(psi)
    assert np.allclose(angles, _angle(other, (b - a)[1:-1, None, :]), atol=1e-9, rtol=0)


def test_developable_and_helicoid():
    th = np.linspace(0.0, 2.0, 21)
    cylinder = _circle(th), _circle(th) + [0.0, 0.0, 3.0]
    assert slender_share(*cylinder) == 1.0
    assert (crossing_angles(*cylinder)[0] == 0.0).all()
    # A right helicoid's second asymptotic lines are helices, at right angles to the rulings.
    a = np.stack([0 * th, 0 * th, 0.7 * th], 1)
    b = np.stack([2 * np.cos(th), 2 * np.sin(th), 0.7 * th], 1)
    t = np.linspace(0.05, 1.0, 11)
    assert np.allclose(crossing_angles(a, b, t)[0], 90.0, atol=1e-6)
    assert slender_share(a, b) == 0.0


def test_the_bar_and_elongation():
    assert least_elongation(np.array([90.0]))[0] == pytest.approx(1.0)
    assert least_elongation(np.array([0.0]))[0] == np.inf
    bar = np.degrees(np.arcsin(1.0 / SLENDER_ELONGATION))
    assert least_elongation(np.array([bar]))[0] == pytest.approx(SLENDER_ELONGATION)
    x = np.linspace(0.0, 1.0, 5)
    with pytest.raises(ValueError, match="elongation"):
        slender_share(np.stack([x, 0 * x, 0 * x], 1), np.stack([x, 1 + 0 * x, x], 1), 1.0)
    with pytest.raises(ValueError, match="m >= 3"):
        crossing_angles(np.zeros((2, 3)), np.ones((2, 3)))


def _lines(draw_seed: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(draw_seed)
    s = np.linspace(0.0, 1.0, m)
    c1 = np.stack([6 * s, rng.uniform(-1, 1) * np.sin(3 * s), 0.3 * rng.uniform(-1, 1) * s ** 2], 1)
    c2 = np.stack([6 * s + rng.uniform(-0.5, 0.5), 1.5 * np.cos(2 * s) + rng.uniform(-1, 1) * s,
                   3 + rng.uniform(-1, 1) * np.sin(4 * s)], 1)
    return c1, c2


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31), scale=st.floats(1e-3, 1e4), angle=st.floats(0, 6.28))
def test_angles_do_not_depend_on_placement_or_orientation(seed, scale, angle):
    a, b = _lines(seed, 12)
    angles, weights = crossing_angles(a, b)
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])
    move = np.array([1e3, -2e2, 5e1])

    def f(p):
        return scale * p @ R.T + move

    moved, moved_w = crossing_angles(f(a), f(b))
    assert np.allclose(moved, angles, atol=1e-6)
    assert np.allclose(moved_w, weights * scale ** 2, rtol=1e-6, atol=0)
    # The generators in the other order, and each one reversed: the same angles.
    assert np.allclose(crossing_angles(a[::-1], b[::-1])[0], angles[::-1], atol=1e-9)
    assert np.allclose(crossing_angles(b, a)[0], angles[:, ::-1], atol=1e-9)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31))
def test_exact_faces_cross_at_the_measured_angle(seed):
    """A face of the §4.3 mesh centred on a generator has its diagonals crossing at the
    angle measured there: the bound holds for the faces the mesher makes."""
    a, b = _lines(seed, 14)
    mesh = pq_mesh(a, b, rows=10, trim=False)
    quads = np.flatnonzero(mesh.valences == 4)
    corners = mesh.face_indices[mesh.face_offsets[quads][:, None] + np.arange(4)]
    gen = np.asarray(mesh.vertex_data["generator"])[corners]
    tv = np.asarray(mesh.vertex_data["t"])[corners]
    # §4.3 faces: corners on generators i-1, i, i+1, i in order (either orientation).
    centred = (gen[:, 1] == gen[:, 3]) & (gen[:, 0] == gen[:, 1] - 1) & (gen[:, 2] == gen[:, 1] + 1)
    assert centred.sum() > 10
    P = mesh.vertices[corners[centred]]
    _, u, _ = quad_diagonal_crossing(P)
    i = gen[centred, 1]
    tc = tv[centred, 1] + u * (tv[centred, 3] - tv[centred, 1])   # the crossing on g_i
    expected = np.array([crossing_angles(a[k - 1:k + 2], b[k - 1:k + 2], np.array([x]))[0][0, 0]
                         for k, x in zip(i.tolist(), tc.tolist())])
    measured = _angle(P[:, 2] - P[:, 0], P[:, 3] - P[:, 1])
    assert np.allclose(measured, expected, atol=1e-6)
    # ... and each is at least as elongated as the bound says.
    diam2 = np.max([np.linalg.norm(P[:, p] - P[:, q], axis=1) ** 2 for p in range(4) for q in range(p)],
                   axis=0)
    area = 0.5 * np.linalg.norm(np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 1]), axis=1)
    assert (diam2 / (2 * area) >= least_elongation(measured) * (1 - 1e-9)).all()
