"""tube/sweep with given tangents and a chosen tangent rule: they reach the frames."""

import numpy as np
import pytest

import spinal


def _spine(n=20):
    u = np.linspace(0, 3, n)
    return np.c_[np.cos(u), np.sin(u), 0.3 * u**2]


def test_tangent_rule_reaches_the_frames():
    x = _spine()
    for rule in ("five_point_bounded", "five_point", "five_point_uniform", "circle"):
        t = spinal.estimate_tangents(x, method=rule)
        ref = spinal.tube(x, 0.1, 8, frames=spinal.frames(x, t))
        m = spinal.tube(x, 0.1, 8, tangent_rule=rule)
        np.testing.assert_allclose(m.vertices, ref.vertices, atol=1e-14)
        # the first ring lies in the normal plane of the chosen end tangent
        np.testing.assert_allclose((m.vertices[:8] - x[0]) @ t[0], 0, atol=1e-14)
    # the default is the bounded rule, and equals the tube of the default frames
    np.testing.assert_array_equal(
        spinal.tube(x, 0.1, 8).vertices, spinal.tube(x, 0.1, 8, frames=spinal.frames(x)).vertices
    )


def test_given_tangents_reach_the_frames_and_bundles():
    x = _spine()
    u = np.linspace(0, 3, 20)
    t = np.c_[-np.sin(u), np.cos(u), 0.6 * u] * 3.0  # exact directions, not unit
    m = spinal.sweep(x, [[0, 0], [1, 0], [0, 1]], tangents=t)
    ref = spinal.sweep(x, [[0, 0], [1, 0], [0, 1]], frames=spinal.frames(x, t))
    np.testing.assert_allclose(m.vertices, ref.vertices, atol=1e-14)
    tu = t / np.linalg.norm(t, axis=1, keepdims=True)
    np.testing.assert_allclose((m.vertices[3:6] - x[1]) @ tu[1], 0, atol=1e-13)
    # a bundle of two spines with tangents and with a rule
    xx = np.r_[x, x + [3, 0, 0]]
    b = spinal.tube(xx, 0.1, 6, tangents=np.r_[t, t], lengths=[20, 20])
    one = spinal.tube(x, 0.1, 6, tangents=t)
    np.testing.assert_allclose(b.vertices[: len(one.vertices)], one.vertices, atol=1e-14)
    c = spinal.tube(xx, 0.1, 6, tangent_rule="circle", lengths=[20, 20])
    one = spinal.tube(x, 0.1, 6, tangent_rule="circle")
    np.testing.assert_allclose(c.vertices[: len(one.vertices)], one.vertices, atol=1e-14)
    # a closed loop with its tangents
    a = np.linspace(0, 2 * np.pi, 40)[:-1]
    loop = np.c_[np.cos(a), np.sin(a), 0.2 * np.sin(3 * a)]
    tl = np.c_[-np.sin(a), np.cos(a), 0.6 * np.cos(3 * a)]
    m = spinal.tube(loop, 0.05, 6, closed=True, tangents=tl)
    ref = spinal.tube(loop, 0.05, 6, closed=True, frames=spinal.frames(loop, tl, closed=True))
    np.testing.assert_allclose(m.vertices, ref.vertices, atol=1e-14)


def test_bad_tangent_inputs_are_named():
    x = _spine()
    t = spinal.estimate_tangents(x)
    with pytest.raises(ValueError, match=r"tangents: expected shape \(20, 3\)"):
        spinal.tube(x, tangents=t[:-1])
    with pytest.raises(ValueError, match="tangents: expected an array of shape"):
        spinal.tube(x, tangents=t[:, :2])
    z = t.copy()
    z[4] = 0
    with pytest.raises(ValueError, match="tangents: .*row 4"):
        spinal.sweep(x, [[0, 0], [1, 0], [0, 1]], tangents=z)
    with pytest.raises(ValueError, match="tangents: .*row 7"):
        spinal.tube(x, tangents=np.where(np.arange(20)[:, None] == 7, np.nan, t))
    with pytest.raises(ValueError, match="tangent_rule: unknown value 'x'"):
        spinal.tube(x, tangent_rule="x")
    with pytest.raises(TypeError, match="tangents: not used with frames="):
        spinal.tube(x, frames=spinal.frames(x), tangents=t)
    with pytest.raises(TypeError, match="tangent_rule: not used with frames="):
        spinal.tube(x, frames=spinal.frames(x), tangent_rule="circle")
    with pytest.raises(TypeError, match="tangent_rule: not used with tangents="):
        spinal.tube(x, tangents=t, tangent_rule="circle")
