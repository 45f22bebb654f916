"""Bad input gets a clear TypeError/ValueError naming the argument; never NaN, never a panic."""

import numpy as np
import pytest

import spinal
from spinal.curves import Helix, TorusKnot

GOOD = TorusKnot().sample(40)


@pytest.mark.parametrize(
    "points, exc, match",
    [
        (np.zeros((5, 2)), ValueError, r"points: expected an array of shape \(n, 3\)"),
        (np.zeros(3), ValueError, r"points: expected an array of shape \(n, 3\)"),
        (np.zeros((2, 3, 1)), ValueError, r"points: expected"),
        ([[0, 0, 0], [1, 2]], ValueError, "points: cannot be read as an array"),
        (np.array([["a", "b", "c"]] * 3), TypeError, "points: expected an array of real numbers"),
        (np.zeros((4, 3), complex), TypeError, "complex"),
        ("abc", TypeError, "points"),
        (np.array([[0.0, 0, 0]]), ValueError, "points: need at least 2 samples, got 1"),
        (np.zeros((0, 3)), ValueError, "points: need at least 2 samples, got 0"),
    ],
)
def test_bad_points(points, exc, match):
    with pytest.raises(exc, match=match):
        spinal.frames(points)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite(bad):
    x = GOOD.copy()
    x[7, 1] = bad
    with pytest.raises(ValueError, match="points: non-finite value .* at row 7"):
        spinal.frames(x)
    t = np.ones_like(GOOD)
    t[3, 2] = bad
    with pytest.raises(ValueError, match="tangents: non-finite value .* at row 3"):
        spinal.frames(GOOD, t)


def test_repeated_points_and_zero_tangents():
    # a repeated point is merged: its row gets the frame (tangent) of the row it repeats,
    # the others those of the curve without it
    x = np.insert(GOOD, 12, GOOD[11], axis=0)
    rows = np.r_[np.arange(12), 11, np.arange(12, len(GOOD))]
    for method in ("double_reflection", "rotation", "projection", "frenet"):
        np.testing.assert_array_equal(spinal.frames(x, method=method),
                                      spinal.frames(GOOD, method=method)[rows])
    np.testing.assert_array_equal(spinal.estimate_tangents(x),
                                  spinal.estimate_tangents(GOOD)[rows])
    # given tangents are cut alike
    tg = spinal.estimate_tangents(GOOD)
    np.testing.assert_array_equal(spinal.frames(x, tg[rows]), spinal.frames(GOOD, tg)[rows])
    # two distinct points of which one repeats: too few
    with pytest.raises(ValueError, match="points: an open curve needs at least 2 distinct"):
        spinal.frames(np.zeros((3, 3)))
    t = TorusKnot().tangent(np.linspace(0, 1, 40))
    t[5] = 0
    with pytest.raises(ValueError, match="tangents: zero-length .* row 5"):
        spinal.frames(GOOD, t)
    with pytest.raises(ValueError, match=r"tangents: shape \(39, 3\) does not match"):
        spinal.frames(GOOD, t[:-1])


def test_cusp_and_reversal():
    # a path that goes out and comes back along itself: framed (the apex tangent normal to
    # the chord, the limit of near reversals' bisectors); twice in a row leaves a segment
    # with no tangent along it: refused
    x = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 0, 0], [0, 0, 0]])
    assert spinal.frames(x)[2, 0, 2] == 0
    with pytest.raises(ValueError, match="points: the segment from row 1 to row 2"):
        spinal.frames(x[1:][[0, 1, 0, 1]])
    # tangents reversed between two samples (an exact reversal): refused for every method
    t = np.array([[1.0, 0, 0]] * 5)
    t[3] = [-1.0, 0, 0]
    y = np.c_[np.arange(5.0), np.zeros(5), np.zeros(5)]
    for method in ("double_reflection", "rotation", "projection"):
        with pytest.raises(ValueError, match="points: the segment from row 2 to row 3 runs against"):
            spinal.frames(y, t, method=method)
    # the S-arc of TOG §4.4 (v2 = 0): chord ⟂ both tangents
    with pytest.raises(ValueError, match="runs against"):
        spinal.frames([[0.0, 0, 0], [1, 0, 0]], [[0.0, 1, 0], [0, 1, 0]])


def test_bad_options():
    with pytest.raises(ValueError, match="method: unknown value 'dr'"):
        spinal.frames(GOOD, method="dr")
    with pytest.raises(TypeError, match="method: expected a string"):
        spinal.frames(GOOD, method=3)
    with pytest.raises(ValueError, match="method: 'rk4'.*analytic curve"):
        spinal.frames(GOOD, method="rk4")
    with pytest.raises(ValueError, match="method: 'rk4_phi'.*analytic curve"):
        spinal.frames(GOOD, method="rk4_phi")
    with pytest.raises(TypeError, match="closed: expected True or False"):
        spinal.frames(GOOD, closed=1)
    with pytest.raises(ValueError, match="turns: expected a whole or half number"):
        spinal.frames(GOOD, closed=True, turns=1.25)
    with pytest.raises(TypeError, match="turns: expected a whole or half number"):
        spinal.frames(GOOD, closed=True, turns="1")
    with pytest.raises(ValueError, match="end: cannot be combined with closed=True"):
        spinal.frames(GOOD, closed=True, end=[1.0, 0, 0])
    with pytest.raises(ValueError, match="initial: is not used by method='frenet'"):
        spinal.frames(GOOD, method="frenet", initial=[1.0, 0, 0])
    with pytest.raises(ValueError, match="reflection: 'tangents'.*double_reflection"):
        spinal.frames(GOOD, TorusKnot().d1(np.linspace(0, 1, 40)), method="rotation",
                      reflection="tangents")
    with pytest.raises(TypeError, match="points: required"):
        spinal.frames(None)
    with pytest.raises(TypeError, match="u: only used with an analytic curve"):
        spinal.frames(GOOD, u=10)
    with pytest.raises(TypeError, match="lengths, offsets: pass one of them"):
        spinal.frames(GOOD, lengths=[40], offsets=[0, 40])
    with pytest.raises(ValueError, match="closed curve needs at least 3 distinct points"):
        spinal.frames([[0.0, 0, 0], [1, 0, 0]], closed=True)


def test_bad_initial_and_end():
    t0 = spinal.frames(GOOD)[0][:, 2]
    with pytest.raises(ValueError, match="initial: the vector is zero or parallel to the tangent"):
        spinal.frames(GOOD, initial=t0)
    with pytest.raises(ValueError, match="initial: the vector is zero"):
        spinal.frames(GOOD, initial=[0.0, 0, 0])
    with pytest.raises(ValueError, match=r"initial: expected shape \(3,\) or \(3, 3\)"):
        spinal.frames(GOOD, initial=[1.0, 0])
    with pytest.raises(ValueError, match="initial: contains a non-finite value"):
        spinal.frames(GOOD, initial=[np.nan, 0, 1])
    with pytest.raises(ValueError, match="initial: is not a rotation matrix"):
        spinal.frames(GOOD, initial=2 * np.eye(3))
    with pytest.raises(ValueError, match="initial: is not a rotation matrix"):
        spinal.frames(GOOD, initial=np.diag([1.0, 1, -1]))
    with pytest.raises(ValueError, match="initial: its third column"):
        spinal.frames(GOOD, initial=np.eye(3))
    t1 = spinal.frames(GOOD)[-1][:, 2]
    with pytest.raises(ValueError, match="end: the vector is zero or parallel to the tangent at row 39"):
        spinal.frames(GOOD, end=-t1)


def test_analytic_curve_errors():
    h = Helix()
    with pytest.raises(TypeError, match="u: required with an analytic curve"):
        spinal.frames(h)
    with pytest.raises(ValueError, match="u: parameter values must increase strictly"):
        spinal.frames(h, u=[0.0, 1.0, 1.0, 2.0])
    with pytest.raises(ValueError, match="u: closed=True on an analytic curve needs"):
        spinal.frames(h, u=np.linspace(0, 1, 10), closed=True)
    with pytest.raises(TypeError, match="tangents: not accepted with an analytic curve"):
        spinal.frames(h, np.ones((10, 3)), u=10)
    # a curve with a singular point (x' = 0 at u = 0): (u², u³, 0)
    from spinal.curves import Polynomial

    cusp = Polynomial([[0, 0, 0], [0, 0, 0], [1, 0, 0], [0, 1, 0]], domain=(-1, 1))
    with pytest.raises(ValueError, match="derivative vanishes at u = 0"):
        spinal.frames(cusp, u=np.linspace(-1, 1, 11), method="rk4")
    with pytest.raises(ValueError, match="derivative vanishes at u = 0"):
        spinal.frames(cusp, u=np.linspace(-1, 1, 11), method="rk4_phi")


def test_tangent_estimation_errors():
    with pytest.raises(ValueError, match="method: unknown value"):
        spinal.estimate_tangents(GOOD, method="spline")
    with pytest.raises(ValueError, match="points: need at least 2 points"):
        spinal.estimate_tangents(GOOD[:1])
    t = spinal.estimate_tangents(GOOD, closed=True)
    assert t.shape == GOOD.shape and np.all(np.isfinite(t))
    np.testing.assert_array_equal(t[-1], t[0])


def test_five_point_tangents_do_not_swing_round_at_a_kink():
    """A straight run, a 35° kink and very uneven chords (found by the sweep property test):
    the interpolating quartic's end tangent points backwards (t·chord = −0.23); the guard
    falls back to the circle estimate, which follows the chords."""
    x = np.array([[4.93422374, 18.71165806, -8.53999907],
                  [3.7953209, 19.4846463, -9.04887575],
                  [3.68386077, 19.56029574, -9.09867759],
                  [3.65097633, 19.62439471, -9.09746686],
                  [3.34808006, 20.21480587, -9.08631497]])
    t = spinal.estimate_tangents(x)
    c = np.diff(x, axis=0)
    c /= np.linalg.norm(c, axis=1)[:, None]
    assert np.einsum("ij,ij->i", t[:-1], c).min() > 0.5
    assert np.einsum("ij,ij->i", t[1:], c).min() > 0.5
    np.testing.assert_allclose(t[0], spinal.estimate_tangents(x, method="circle")[0], atol=1e-15)
