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
    """Random walks: straight runs or turns (usually small, occasionally over 90°) with
    random step lengths (ratios up to 200)."""
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
    try:
        F = spinal.frames(x, method=method)
    except ValueError as e:
        # the documented refusal of the projection method: a chord lying in (or behind) the
        # next normal plane, which a sharp kink next to a short chord produces
        assert method == "projection" and "needs each chord to cross" in str(e)
        c = np.diff(x, axis=0)
        t = spinal.estimate_tangents(x)
        assert (np.einsum("ij,ij->i", c, t[1:]) <= 1e-9 * np.linalg.norm(c, axis=1)).any()
        return
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


@st.composite
def profiles(draw):
    """Polygons star-shaped about the origin (3–12 vertices, counter-clockwise or clockwise):
    jittered even angles, so every angular gap is below π and the origin is inside."""
    m = draw(st.integers(3, 12))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    a = 2 * np.pi * (np.arange(m) + rng.uniform(-0.2, 0.2, m)) / m
    rad = rng.uniform(0.4, 1.0, m)
    p = np.c_[rad * np.cos(a), rad * np.sin(a)]
    return p[::-1] if draw(st.booleans()) else p


@st.composite
def gentle_curves(draw):
    """Random walks turning by less than ~25° per step, chords within a factor 5."""
    n = draw(st.integers(2, 60))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    pts = [rng.normal(size=3) * 10]
    kick = draw(st.sampled_from([0.0, 0.05, 0.15]))
    for _ in range(n - 1):
        d = d + np.clip(rng.normal(size=3) * kick, -0.25, 0.25)
        d /= np.linalg.norm(d)
        pts.append(pts[-1] + d * rng.uniform(0.2, 1.0))
    return np.array(pts)


@settings(max_examples=120, deadline=None)
@given(gentle_curves(), profiles(), st.booleans())
def test_random_sweeps_are_clean_watertight_meshes(x, prof, caps):
    """Any smooth spine and star profile, thin enough not to fold: a watertight (when
    capped), consistently wound, outward mesh with unit normals; trimesh and libigl agree."""
    import warnings

    import igl
    import trimesh

    chord = np.linalg.norm(np.diff(x, axis=0), axis=1).min()
    size = 0.2 * chord
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no fold-over may be reported here
        mesh = spinal.sweep(x, prof, scale=size, caps=caps)
    m = len(prof)
    assert mesh.vertices.shape == (len(x) * m, 3)
    assert np.isfinite(mesh.vertices).all() and np.isfinite(mesh.normals).all()
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1, atol=1e-12)
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert tm.is_winding_consistent
    assert tm.is_watertight == caps
    # normals point away from the spine (the profiles are star-shaped about the origin)
    off = mesh.vertices.reshape(len(x), m, 3) - x[:, None]
    assert (np.einsum("ijk,ijk->ij", off, mesh.normals.reshape(len(x), m, 3)) > 0).all()
    if caps:
        _, vol = igl.centroid(mesh.vertices, mesh.faces)
        assert tm.volume > 0
        assert abs(tm.volume - vol) <= 1e-9 * abs(vol)
