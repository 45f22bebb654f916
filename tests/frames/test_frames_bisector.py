"""Klok's bisector-plane projection for polygons without tangents (``method="bisector"``;
Klok 1986, Zheng's thesis §2.3), see docs/references.md."""

import numpy as np
import pytest
from conftest import angle_between, orthonormality_error
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import spinal
from spinal.curves import Helix


def planar_polygon(rows=40, seed=1):
    rng = np.random.default_rng(seed)
    rot = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    xy = np.cumsum(rng.normal(size=(rows, 2)), axis=0)
    return np.c_[xy, np.zeros(rows)] @ rot.T, rot[:, 2]


def test_tangents_are_the_bisector_plane_normals():
    x, _ = planar_polygon()
    F = spinal.frames(x, method="bisector")
    d = np.diff(x, axis=0)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    s = d[:-1] + d[1:]
    np.testing.assert_allclose(F[1:-1, :, 2], s / np.linalg.norm(s, axis=1, keepdims=True),
                               atol=1e-15)
    np.testing.assert_allclose(F[[0, -1], :, 2], d[[0, -1]], atol=1e-15)
    # each bisector plane contains the angle bisector d̂_i − d̂_{i−1} (to the round-off of
    # normalising a short sum where the polygon almost turns back: measured 1.2e-14)
    np.testing.assert_allclose(np.einsum("ij,ij->i", F[1:-1, :, 2], d[1:] - d[:-1]), 0,
                               atol=5e-14)


@pytest.mark.parametrize("closed", [False, True])
def test_no_twist_on_a_planar_polygon(closed):
    """Projection along segments that lie in the plane keeps the plane normal: started on
    it, r stays the normal; started in the plane, r stays in it (no twist, exactly)."""
    x, normal = planar_polygon()
    F = spinal.frames(x, method="bisector", initial=normal, closed=closed)
    np.testing.assert_allclose(F[:, :, 0], np.broadcast_to(normal, (len(x), 3)), atol=1e-12)
    G = spinal.frames(x, method="bisector", initial=np.cross(normal, F[0][:, 2]))
    assert np.abs(G[:, :, 0] @ normal).max() < 1e-13
    if closed:  # the RMF of a planar loop closes by itself: no closing angle
        assert abs(spinal.closing_angle(x, method="bisector")) < 1e-12


def test_helix_polygon_second_order():
    """On a helix polygon (uniform in arc length, a = 1, b = 0.5, S = 20) against the exact
    RMF cos(τs) N − sin(τs) B: 2nd order at the interior vertices (2.4890e-4 at 1024
    segments; the error falls by 4 per halving). At the first vertex the plane is ⟂ the
    first segment, which is tilted from the tangent by κh/2 towards N, so the exact r₀ = N
    projected onto it is off by κh/2 (1st order, the largest error)."""
    a, b, S = 1.0, 0.5, 20.0
    helix = Helix(a, b)
    kappa = a / (a * a + b * b)
    inner = []
    for n in (128, 256, 512, 1024):
        u = np.linspace(0, S / np.hypot(a, b), n + 1)
        exact = helix.rmf(u)
        F = spinal.frames(helix.point(u), method="bisector", initial=exact[0][:, 0])
        err = angle_between(F[:, :, 0], exact[:, :, 0])
        inner.append(err[1:-1].max())
        assert abs(err[0] / (kappa * S / n / 2) - 1) < 2e-3, (n, err[0])
    inner = np.array(inner)
    ratios = inner[1:] / inner[:-1]
    assert np.all((ratios > 0.245) & (ratios < 0.255)), ratios
    assert abs(inner[-1] / 2.4890e-4 - 1) < 0.01, inner


def test_bisector_arguments_and_bundles():
    x, _ = planar_polygon()
    with pytest.raises(ValueError, match="tangents: not used by method='bisector'"):
        spinal.frames(x, np.ones_like(x), method="bisector")
    with pytest.raises(ValueError, match="method: 'bisector' is Klok's projection for polygons"):
        spinal.frames(Helix(), u=20, method="bisector")
    back = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [1.5, 0, 0], [1.5, 1, 0]])
    with pytest.raises(ValueError, match="points: the polygon turns back on itself at row 2"):
        spinal.frames(back, method="bisector")
    with pytest.raises(ValueError, match="reflection: 'tangents'"):
        spinal.frames(x, method="bisector", reflection="tangents")
    y = Helix().sample(30)
    both = spinal.frames([x, y], method="bisector")
    np.testing.assert_array_equal(both[: len(x)], spinal.frames(x, method="bisector"))
    np.testing.assert_array_equal(both[len(x):], spinal.frames(y, method="bisector"))


def test_rigid_motion_scale_and_reversal():
    from scipy.spatial.transform import Rotation

    from spinal.curves import TorusKnot

    x = TorusKnot().sample(400)
    R = Rotation.from_rotvec([0.7, -0.2, 1.9]).as_matrix()
    F = spinal.frames(x, method="bisector")  # default initial frame
    G = spinal.frames(3.5 * x @ R.T + [10.0, -4.0, 2.0], method="bisector")
    assert np.abs(R @ F - G).max() < 1e-11
    # the projection between two planes along a segment is the same both ways
    B = spinal.frames(x[::-1], method="bisector", initial=F[-1][:, 0])[::-1]
    assert np.abs(B[:, :, 0] - F[:, :, 0]).max() < 1e-12


@settings(max_examples=200, deadline=None)
@given(
    arrays(np.float64, st.tuples(st.integers(0, 12), st.integers(2, 4)),
           elements=st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                              st.sampled_from([0.0, 1.0, -1.0]))),
    st.booleans(),
)
def test_garbage_never_panics_or_returns_nan(a, closed):
    try:
        F = spinal.frames(a, method="bisector", closed=closed)
    except (ValueError, TypeError) as e:
        assert str(e).split(":")[0] in {"points", "tangents", "initial", "end"}
    else:
        assert np.all(np.isfinite(F))
        assert orthonormality_error(F) < 1e-9


def test_a_reference_vector_along_the_next_chord_stays_orthonormal():
    """A hairpin after a chord of 2⁻²⁴ (found by the fuzz test above): the reference vector
    arrives nearly along the next chord, and its projection onto the next normal plane is a
    difference of nearly equal vectors; the frames stay orthonormal to rounding."""
    a = np.full((8, 3), 2.0**-24)
    a[5, 0], a[6, 1] = 0.0, 1.0
    for method in ("bisector", "projection", "double_reflection", "rotation"):
        try:
            F = spinal.frames(a, method=method)
        except ValueError as e:  # projection: the chord lies in the next normal plane
            assert method == "projection" and str(e).startswith("points"), e
            continue
        assert orthonormality_error(F) < 1e-14, method
