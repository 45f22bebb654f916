"""Property tests over random curves and random bad input."""

import numpy as np
from conftest import orthonormality_error
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import spinal

METHODS = ["double_reflection", "rotation", "projection", "frenet"]


@st.composite
def smooth_curves(draw):
    """Random walks whose direction turns by at most ~60° per step, random step lengths."""
    n = draw(st.integers(2, 80))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    pts = [rng.normal(size=3) * 10]
    for _ in range(n - 1):
        kick = rng.normal(size=3) * draw(st.sampled_from([0.0, 0.05, 0.3]))
        d = d + kick
        d /= np.linalg.norm(d)
        pts.append(pts[-1] + d * rng.uniform(0.01, 2.0))
    return np.array(pts)


@settings(max_examples=150, deadline=None)
@given(smooth_curves(), st.sampled_from(METHODS))
def test_random_curves_give_rotations(x, method):
    F = spinal.frames(x, method=method)
    assert F.shape == (len(x), 3, 3)
    assert np.all(np.isfinite(F))
    assert orthonormality_error(F) < 1e-12
    assert np.abs(np.linalg.det(F) - 1).max() < 1e-12
    np.testing.assert_allclose(F[:, :, 2], spinal.estimate_tangents(x), atol=1e-13)


@settings(max_examples=100, deadline=None)
@given(smooth_curves())
def test_random_curves_reversal_and_closure(x):
    t = spinal.estimate_tangents(x)
    F = spinal.frames(x, t)
    G = spinal.frames(x[::-1], -t[::-1], initial=F[-1][:, 0])[::-1]
    assert np.abs(G[:, :, 0] - F[:, :, 0]).max() < 1e-11  # (t and s change sign)
    if len(x) >= 3:
        end = np.cross(t[-1], [0.3, 0.4, 0.5]) + 1e-3 * np.array([1.0, 0, 0])
        try:
            E = spinal.frames(x, t, end=end)
        except ValueError as e:  # only if `end` happens to be (nearly) parallel to t
            assert "parallel" in str(e)
        else:
            p = end - end.dot(t[-1]) * t[-1]
            np.testing.assert_allclose(E[-1][:, 0], p / np.linalg.norm(p), atol=1e-11)


@settings(max_examples=200, deadline=None)
@given(
    arrays(np.float64, st.tuples(st.integers(0, 12), st.integers(2, 4)),
           elements=st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                              st.sampled_from([0.0, 1.0, -1.0]))),
    st.sampled_from(METHODS),
    st.booleans(),
)
def test_garbage_never_panics_or_returns_nan(a, method, closed):
    before = a.copy()
    try:
        F = spinal.frames(a, method=method, closed=closed)
    except (ValueError, TypeError) as e:
        assert str(e).split(":")[0] in {"points", "tangents", "initial", "end"}
    else:
        assert np.all(np.isfinite(F))
        assert orthonormality_error(F) < 1e-9
    np.testing.assert_array_equal(a, before)
