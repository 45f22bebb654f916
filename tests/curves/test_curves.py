"""Analytic curves: exact derivatives checked by finite differences, shape facts, bad input."""

import numpy as np
import pytest

import spinal
from spinal.curves import Bezier, Helix, Polynomial, TorusKnot, Viviani

CURVES = [Helix(1.3, -0.4), TorusKnot(), TorusKnot(3, 5, 2.0, 0.7), Viviani(0.8),
          Bezier([[0, 0, 0], [1, 2, 0], [2, -1, 1], [3, 0, 2], [4, 1, 0]]),
          Polynomial([[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.5, 0.2, -0.1]])]


@pytest.mark.parametrize("curve", CURVES, ids=lambda c: type(c).__name__)
def test_derivatives_match_finite_differences(curve):
    u = np.linspace(*curve.domain, 13)[1:-1]
    h = 1e-4
    for k, f, g in [(1, curve.point, curve.d1), (2, curve.d1, curve.d2), (3, curve.d2, curve.d3)]:
        fd = (-f(u + 2 * h) + 8 * f(u + h) - 8 * f(u - h) + f(u - 2 * h)) / (12 * h)
        scale = np.abs(g(u)).max() + 1
        assert np.abs(fd - g(u)).max() < 1e-8 * scale, (type(curve).__name__, k)


def test_curve_facts():
    v = Viviani(0.8)
    u = v.parameters(50)
    np.testing.assert_allclose(np.linalg.norm(v.point(u), axis=1), 1.6, atol=1e-14)
    b = Bezier([[0, 0, 0], [1, 2, 0], [2, -1, 1], [3, 0, 2]])
    np.testing.assert_allclose(b.point([0.0, 1.0]), [[0, 0, 0], [3, 0, 2]], atol=1e-14)
    np.testing.assert_allclose(b.d1([0.0]), [[3, 6, 0]], atol=1e-13)  # 3 (P1 − P0)
    h = Helix(1.0, 0.5)
    np.testing.assert_allclose(h.curvature([0.3]), 0.8)
    np.testing.assert_allclose(h.torsion([0.3]), 0.4)
    k = TorusKnot()
    np.testing.assert_allclose(k.point([0.0]), k.point([2 * np.pi]), atol=1e-15)
    R = h.rmf(h.parameters(20))
    assert np.abs(np.einsum("nji,njk->nik", R, R) - np.eye(3)).max() < 1e-14


def test_curve_bad_input():
    with pytest.raises(ValueError, match="a: the helix radius must be positive"):
        Helix(-1.0)
    with pytest.raises(ValueError, match="R, r: radii must be positive"):
        TorusKnot(R=0)
    with pytest.raises(ValueError, match="control_points: expected shape"):
        Bezier([[0, 0], [1, 1]])
    with pytest.raises(ValueError, match="coefficients: contains non-finite"):
        Polynomial([[0, 0, 0], [np.nan, 1, 0]])
    with pytest.raises(ValueError, match="u: contains non-finite"):
        Helix().point([0.0, np.nan])
    with pytest.raises(ValueError, match="n: a sample count must be at least 2"):
        Helix().parameters(1)
    with pytest.raises(TypeError, match="u: expected an array of real numbers"):
        Helix().point("x")


def test_closing_angle_bad_input():
    with pytest.raises(ValueError, match="points: a closed curve needs at least 3 distinct"):
        spinal.closing_angle([[0.0, 0, 0], [1, 0, 0]])
    with pytest.raises(ValueError, match="method: unknown value"):
        spinal.closing_angle(TorusKnot().sample(50), method="x")
    x = TorusKnot().sample(50)
    x[3] = np.nan
    with pytest.raises(ValueError, match="points: non-finite value"):
        spinal.closing_angle(x)
