"""Property tests of sweeps over random spines, profiles and radii: a watertight, outward
mesh with unit normals and finite uv, or a named error — never NaN, never a silent drop."""

import warnings

import numpy as np
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from test_frames_hypothesis import smooth_curves

import spinal


@st.composite
def star_profiles(draw):
    """Star-shaped closed polygons (always simple), either orientation."""
    m = draw(st.integers(3, 12))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    a = np.sort(rng.uniform(0, 2 * np.pi, m))
    a += np.linspace(0, 2 * np.pi, m, endpoint=False) - a  # keep the angles apart
    a += rng.uniform(-0.2, 0.2, m) * (2 * np.pi / m)
    r = rng.uniform(0.3, 1.0, m)
    p = np.c_[r * np.cos(a), r * np.sin(a)]
    return p[::-1] if draw(st.booleans()) else p


@settings(max_examples=60, deadline=None)
@given(smooth_curves(), star_profiles(), st.floats(1e-3, 0.5))
def test_random_sweeps_are_watertight_or_refused(x, profile, size):
    scale = size * np.median(np.linalg.norm(np.diff(x, axis=0), axis=1))
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            mesh = spinal.sweep(x, profile, scale=scale)
    except ValueError as e:
        # the documented refusals of the frames (a segment running against its tangents)
        assert str(e).startswith("points"), e
        return
    n, m = len(x), len(profile)
    # one ring per sample, then the rings of the corner joins (each at an interior sample);
    # the faces of a segment or a join band, less those flattened on a join's crease
    rings = len(mesh.vertices) // m
    assert mesh.vertices.shape == (rings * m, 3) and rings >= n
    np.testing.assert_array_equal(mesh.sample_of[:n * m], np.repeat(np.arange(n), m))
    assert np.all((mesh.sample_of[n * m:] > 0) & (mesh.sample_of[n * m:] < n - 1))
    full = 2 * (rings - 1) * m + 2 * (m - 2)
    assert mesh.faces.shape[1] == 3 and (len(mesh.faces) == full) == (rings == n)
    assert len(mesh.faces) <= full
    for a in (mesh.vertices, mesh.normals, mesh.uv):
        assert np.isfinite(a).all()
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1, atol=1e-12)
    tm = mesh.to_trimesh()
    assert tm.is_watertight and tm.is_winding_consistent
    # trimesh's volume of the mesh moved to the origin (the curves sit far from it and the
    # signed-volume sum would lose digits to cancellation)
    tm = trimesh.Trimesh(mesh.vertices - mesh.vertices.mean(axis=0), mesh.faces, process=False)
    folded = [w for w in caught if issubclass(w.category, spinal.FoldOverWarning)]
    assert bool(folded) == bool(mesh.fold_over.size)
    if not mesh.fold_over.size:
        # without fold-over the sweep is a union of prisms round the spine: positive volume
        assert tm.volume > 0
        # agreement to the round-off of the signed-volume sums (terms of size extent³)
        extent = np.ptp(mesh.vertices, axis=0).max()
        assert abs(tm.volume - mesh.volume) < 1e-12 * extent**3


@st.composite
def planar_polylines(draw):
    """Random polylines in a random plane: turns up to 150°, step ratios up to 100."""
    n = draw(st.integers(2, 40))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    turn = rng.uniform(-1, 1, n) * np.radians(draw(st.sampled_from([5.0, 60.0, 150.0])))
    ang = np.cumsum(turn)
    step = rng.uniform(0.02, 2.0, n - 1)
    xy = np.r_[[[0.0, 0.0]], np.cumsum(step[:, None] * np.c_[np.cos(ang[1:]), np.sin(ang[1:])], 0)]
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return np.c_[xy, np.zeros(n)] @ q.T + rng.normal(size=3) * 5


@settings(max_examples=60, deadline=None)
@given(planar_polylines(), st.integers(3, 24))
def test_planar_polyline_tubes_are_exact_prism_chains(x, sides):
    """On a planar polyline with rings in the bisector (mitre) planes, stretched by the mitre,
    the tube is a chain of straight prisms cut by the mitre planes: its volume is (polygon
    area) × (polyline length) exactly (Cavalieri), whatever the turns and spacing."""
    c = np.diff(x, axis=0)
    h = np.linalg.norm(c, axis=1)
    u = c / h[:, None]
    rho = 0.05 * h.min()
    t = np.r_[u[:1], u[:-1] + u[1:], u[-1:]]  # bisector planes at the corners
    mesh = spinal.tube(x, rho, sides, frames=spinal.frames(x, t), strict=True, join="miter")
    tm = trimesh.Trimesh(mesh.vertices - mesh.vertices.mean(axis=0), mesh.faces, process=False)
    assert tm.is_watertight and tm.is_winding_consistent
    area = 0.5 * sides * rho**2 * np.sin(2 * np.pi / sides)
    assert abs(tm.volume / (area * h.sum()) - 1) < 1e-9
