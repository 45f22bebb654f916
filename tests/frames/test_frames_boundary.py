"""Closed curves and prescribed end frames (Wang et al. §6.3): twist linear in arc length."""

import numpy as np
import pytest
from conftest import orthonormality_error

import spinal
from spinal.curves import Curve, TorusKnot


def signed(a, b, t):
    return np.arctan2(np.einsum("ij,ij->i", np.cross(a, b), t), np.einsum("ij,ij->i", a, b))


class Cinquefoil(Curve):
    """Zheng's Eq. 7.9 with a = √2: a (2, 5) torus knot over [0, 10π]."""

    closed = True
    domain = (0.0, 10 * np.pi)

    def _eval(self, u, k):
        w = 2 / 5  # 2/(2a²+1)
        c, s = np.cos(u), np.sin(u)
        g = [2 - np.cos(w * u), w * np.sin(w * u), w**2 * np.cos(w * u)]
        if k == 0:
            return np.stack([c * g[0], s * g[0], -np.sin(w * u)], 1)
        if k == 1:
            return np.stack([-s * g[0] + c * g[1], c * g[0] + s * g[1], -w * np.cos(w * u)], 1)
        return np.stack([-c * g[0] - 2 * s * g[1] + c * g[2],
                         -s * g[0] + 2 * c * g[1] + s * g[2], w**2 * np.sin(w * u)], 1)


class Trefoil(Curve):
    """Zheng's Eq. 7.10 over [0, 2π]."""

    closed = True
    domain = (0.0, 2 * np.pi)
    # coefficients of cos t, sin t, cos 2t, sin 2t, cos 3t, sin 3t per axis
    C = ((41, -18, -83, -83, -11, 27), (36, 27, -113, 30, 11, -27), (0, 45, -30, 113, -11, 27))

    def _eval(self, u, k):
        cols = []
        for axis in range(3):
            v = np.zeros_like(u)
            for j, f in enumerate((1, 1, 2, 2, 3, 3)):
                base = f * u + (np.pi / 2 if j % 2 else 0.0)  # sin x = cos(x − π/2)
                v = v + self.C[axis][j] * f**k * np.cos(base - np.pi * (j % 2) + k * np.pi / 2)
            cols.append(v)
        return np.stack(cols, 1)


@pytest.mark.parametrize("curve, exact", [(TorusKnot(), -2.875711998),
                                          (Cinquefoil(), -1.407701989),
                                          (Trefoil(), 1.368871103)])
def test_published_closing_angles(curve, exact):
    """Closing angles of the closed curves of Zheng's thesis (eq. 6.1, 7.9, 7.10; the thesis
    prints no values: these were computed independently with DR at 2^15 samples), ±1e-8."""
    assert abs(spinal.closing_angle(curve, u=4097) - exact) < 1e-8
    x = curve.sample(4097)
    assert abs(spinal.closing_angle(x) - exact) < 1e-8  # estimated periodic tangents


def test_closed_frames_meet_at_seam_and_twist_is_linear_in_arc_length():
    k = TorusKnot()
    x = k.sample(1001)  # repeats the first point
    F = spinal.frames(x, closed=True)
    assert F.shape == (1001, 3, 3) and orthonormality_error(F) < 1e-12
    np.testing.assert_array_equal(F[-1], F[0])
    # frames of the unique points only: the same frames, one fewer row
    G = spinal.frames(x[:-1], closed=True)
    np.testing.assert_allclose(G, F[:-1], atol=1e-14)
    # carrying the last frame across the closing segment and adding that segment's share of
    # the twist lands on the first frame: no seam
    R = spinal.frames(np.r_[x[-2:-1], x[:1], x[1:2]], np.r_[F[-2:-1, :, 2], F[:2, :, 2]],
                      initial=F[-2][:, 0])
    seg = np.linalg.norm(np.diff(x, axis=0), axis=1)
    step = signed(R[1:2, :, 0], F[0:1, :, 0], F[0:1, :, 2])[0]
    assert abs(step - spinal.closing_angle(x) * seg[-1] / seg.sum()) < 1e-12
    # the correction relative to the open RMF is α s / L with α the closing angle
    H = spinal.frames(x, initial=F[0][:, 0])  # open RMF with the same start
    alpha = signed(H[:, :, 0], F[:, :, 0], F[:, :, 2])
    s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))]
    a = spinal.closing_angle(x)
    np.testing.assert_allclose(alpha, a * s / s[-1], atol=1e-12)


@pytest.mark.parametrize("turns", [-1, 1, 2])
def test_closed_extra_turns(turns):
    k = TorusKnot()
    x = k.sample(801)
    F0 = spinal.frames(x, closed=True)
    F = spinal.frames(x, closed=True, turns=turns, initial=F0[0][:, 0])
    s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))]
    d = np.unwrap(signed(F0[:, :, 0], F[:, :, 0], F[:, :, 2]))
    np.testing.assert_allclose(d, 2 * np.pi * turns * s / s[-1], atol=1e-11)
    assert np.abs(F[-1] - F[0]).max() < 1e-12


@pytest.mark.parametrize("method", ["double_reflection", "rotation", "projection"])
def test_end_condition_met_exactly(method):
    k = TorusKnot()
    u = np.linspace(0.2, 3.0, 300)
    x = k.point(u)
    t = k.tangent(u)
    target = np.cross(t[-1], [0.0, 0.0, 1.0])  # any vector ⟂ t
    target /= np.linalg.norm(target)
    F = spinal.frames(x, t, method=method, end=target)
    np.testing.assert_allclose(F[-1][:, 0], target, atol=1e-12)
    # a non-unit, non-perpendicular vector is projected; a whole frame works too
    G = spinal.frames(x, t, method=method, end=3 * target + 2 * t[-1])
    np.testing.assert_allclose(G, F, atol=1e-12)
    H = spinal.frames(x, t, method=method, end=F[-1])
    np.testing.assert_allclose(H, F, atol=1e-12)
    # the start is untouched, and the twist relative to the RMF is linear in arc length
    R = spinal.frames(x, t, method=method, initial=F[0][:, 0])
    np.testing.assert_allclose(R[0], F[0], atol=1e-15)
    alpha = signed(R[:, :, 0], F[:, :, 0], t)
    s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))]
    np.testing.assert_allclose(alpha, alpha[-1] * s / s[-1], atol=1e-12)
    assert abs(alpha[-1]) <= np.pi


def test_end_condition_on_analytic_curve_uses_arc_length():
    k = TorusKnot()
    u = np.linspace(0.0, 2.0, 201)
    F = spinal.frames(k, u=u, end=[0.0, 0.0, 1.0], method="rk4")
    t = k.tangent(u)
    target = np.array([0.0, 0, 1]) - t[-1, 2] * t[-1]
    np.testing.assert_allclose(F[-1][:, 0], target / np.linalg.norm(target), atol=1e-12)


def test_closing_angle_is_total_torsion():
    """The closing angle is +∮τ ds (mod 2π): total torsion of the classic trefoil from
    spectral derivatives (independent of the frame code)."""
    n = 4096
    u = np.linspace(0, 2 * np.pi, n, endpoint=False)
    x = np.c_[np.sin(u) + 2 * np.sin(2 * u), np.cos(u) - 2 * np.cos(2 * u), -np.sin(3 * u)]
    k = 1j * np.fft.fftfreq(n, 1 / n)[:, None]
    d1, d2, d3 = (np.real(np.fft.ifft(np.fft.fft(x, axis=0) * k**m, axis=0)) for m in (1, 2, 3))
    c = np.cross(d1, d2)
    tau = np.einsum("ij,ij->i", c, d3) / np.einsum("ij,ij->i", c, c)
    total = np.sum(tau * np.linalg.norm(d1, axis=1)) * 2 * np.pi / n
    wrapped = (total + np.pi) % (2 * np.pi) - np.pi
    assert abs(wrapped) > 1.0  # far from 0 and from ±π: the sign is tested
    assert abs(spinal.closing_angle(x) - wrapped) < 1e-9
