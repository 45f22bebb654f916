"""Fleshing: the normal–binormal blend (``solution="blend"``, Zhuo 2014 Ch. VIII).

Independent checks: finite-difference Jacobian determinants of the full map for several
weights on a curved rest spine bent, twisted and stretched; the end points against the
normal and binormal solutions; trimesh/libigl volumes of closed meshes; a naive linear mix
of the two solutions as the counter-example the determinant test must catch; bad weights.
"""

import warnings

import numpy as np
import pytest
from test_flesh import (
    arc3,
    bent3,
    curve3,
    fd_det,
    off_centre_parts,
    relative_volume_error,
    straight,
    straight3,
)

import spinal

WEIGHTS = (0.0, 0.25, 0.5, 0.75, 1.0)


def stretched_pose(n=120):
    """``bent3`` with an uneven speed along the spine (stretch varies with the parameter)."""
    s = np.linspace(-1, 1, n)
    s = s + 0.15 * np.sin(np.pi * s)
    return np.c_[np.sin(1.1 * s) * 0.9, 0.5 * (1 - np.cos(1.3 * s)), 0.3 * s**3 + 0.2 * s]


def sample(rest, k=300, seed=7, spread=0.12):
    rng = np.random.default_rng(seed)
    n = len(rest)
    return rest[rng.integers(n // 12, n - n // 12, k)] + rng.normal(size=(k, 3)) * spread


@pytest.mark.parametrize("stretchable", [False, True])
def test_jacobian_is_one_for_every_weight(stretchable):
    rest = curve3(120)  # curved and twisted at rest: the unbend stages are not trivial
    posed = stretched_pose() if stretchable else bent3(120)
    pts = sample(rest)
    twist = np.linspace(0, np.pi / 2, 120)
    for w in WEIGHTS:
        det = fd_det(rest, pts, posed, solution="blend", blend=w, stretchable=stretchable,
                     twist=twist)
        ok = np.isfinite(det)
        assert ok.sum() > 250, w
        assert np.abs(det[ok] - 1).max() < 1e-6, (w, np.abs(det[ok] - 1).max())


def test_a_linear_mix_of_the_two_solutions_is_not_volume_preserving():
    """The counter-example: ``w·normal + (1 − w)·binormal`` (the end points are right, the
    middle is not) has |det J − 1| far above the tolerance of the test above."""
    rest, posed = curve3(120), stretched_pose()
    pts = sample(rest, k=200)
    eps = 1e-5
    probes = np.concatenate([pts] + [pts + s * eps * e for e in np.eye(3) for s in (1, -1)])
    b = spinal.SpineBinding(probes, rest)
    kw = {"stretchable": True, "twist": np.linspace(0, np.pi / 2, 120), "return_clamped": True}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        (n, cn), (bn, cb) = (b.deform(posed, solution=s, **kw) for s in ("normal", "binormal"))
    mix = (0.5 * n + 0.5 * bn).reshape(7, -1, 3)
    J = np.stack([(mix[1 + 2 * j] - mix[2 + 2 * j]) / (2 * eps) for j in range(3)], -1)
    edges = b.edge.copy()
    edges[np.r_[cn, cb]] = -1
    edges = edges.reshape(7, -1)
    same = (edges == edges[0]).all(axis=0) & (edges[0] >= 0)
    assert same.sum() > 150
    assert np.abs(np.linalg.det(J)[same] - 1).max() > 1e-2


# some vertices lie past the fold limits: the clamped values must agree too
@pytest.mark.filterwarnings("ignore::spinal.FoldOverWarning")
@pytest.mark.parametrize("stretchable", [False, True])
def test_end_points_are_the_normal_and_binormal_solutions(stretchable):
    rest = curve3(120)
    posed = stretched_pose() if stretchable else bent3(120)
    pts = sample(rest, k=500, seed=3, spread=0.15)
    kw = {"stretchable": stretchable, "twist": np.linspace(0, 1.0, 120)}
    b = spinal.SpineBinding(pts, rest)
    normal = b.deform(posed, solution="normal", **kw)
    binormal = b.deform(posed, solution="binormal", **kw)
    assert np.abs(normal - binormal).max() > 1e-2  # the two ends differ
    assert np.abs(b.deform(posed, solution="blend", blend=1.0, **kw) - normal).max() < 1e-12
    assert np.abs(b.deform(posed, solution="blend", blend=0, **kw) - binormal).max() < 1e-12
    # in between: continuous in w, and neither end
    mid = b.deform(posed, solution="blend", blend=0.5, **kw)
    assert np.abs(mid - normal).max() > 1e-3 and np.abs(mid - binormal).max() > 1e-3
    near = b.deform(posed, solution="blend", blend=1 - 1e-9, **kw)
    assert np.abs(near - normal).max() < 1e-8
    # one-shot and the binding agree; identity pose is the identity
    assert np.array_equal(spinal.flesh(pts, rest, posed, solution="blend", blend=0.5, **kw), mid)
    same = spinal.flesh(pts, rest, rest, solution="blend", blend=0.3)
    assert np.abs(same - pts).max() < 1e-12


def test_volume_of_closed_meshes_is_kept_as_with_the_other_solutions():
    rest, posed = straight3(), arc3(1.0)
    for mesh in off_centre_parts(4):
        assert mesh.is_watertight
        assert abs(relative_volume_error(mesh, rest, posed, solution="none")) > 0.09
        for w in (0.25, 0.5, 0.75):
            err = relative_volume_error(mesh, rest, posed, solution="blend", blend=w)
            assert abs(err) < 1.2e-4, (w, err)  # the bound of the other solutions


def test_planar_blend_is_the_planar_quadratic():
    rest = straight(101)[:, :2]
    posed = arc3(1.0)[::3, :2]
    rng = np.random.default_rng(0)
    V = rng.uniform(-0.4, 0.4, (200, 2))
    ref = spinal.flesh(V, rest, posed, solution="normal")
    for w in (0.0, 0.5):
        assert np.array_equal(spinal.flesh(V, rest, posed, solution="blend", blend=w), ref)
    with pytest.raises(ValueError, match="^blend:"):
        spinal.flesh(V, rest, posed, solution="blend", blend=2.0)


def test_threads_give_the_same_bits():
    rest, posed = curve3(120), stretched_pose()
    pts = sample(rest, k=5000, seed=1)
    b = spinal.SpineBinding(pts, rest)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        with spinal.threads(1):
            one = b.deform(posed, solution="blend", blend=0.4, stretchable=True)
        many = b.deform(posed, solution="blend", blend=0.4, stretchable=True)
    assert np.array_equal(one, many)


def test_bad_blend_is_refused_by_name():
    rest = straight(20)
    V = np.zeros((5, 3)) + [0, 0.1, 0]
    for w in (np.nan, -0.1, 1.0 + 1e-12, np.inf, -np.inf):
        with pytest.raises(ValueError, match=r"^blend: .*\[0, 1\]"):
            spinal.flesh(V, rest, rest, solution="blend", blend=w)
    for w in ("0.5", True, [0.5], 1j):
        with pytest.raises(TypeError, match="^blend:"):
            spinal.flesh(V, rest, rest, solution="blend", blend=w)
    with pytest.raises(ValueError, match="^blend: .*needs"):
        spinal.flesh(V, rest, rest, solution="blend")
    for sol in ("radial", "normal", "binormal", "none"):
        with pytest.raises(ValueError, match="^blend: only with solution=\"blend\""):
            spinal.flesh(V, rest, rest, solution=sol, blend=0.5)
    b = spinal.SpineBinding(V, rest)
    with pytest.raises(ValueError, match="^blend:"):
        b.deform(rest, solution="blend", blend=1.5)
    with pytest.raises(ValueError, match="^blend:"):
        b.animate(np.stack([rest, rest]), solution="blend", blend=-1)
    with pytest.raises(ValueError, match="^blend:"):
        b.animate(np.stack([rest, rest]), solution="radial", blend=0.5)
    anim = b.animate(np.stack([rest, rest]), solution="blend", blend=0.5)
    assert np.abs(anim - V).max() < 1e-12
