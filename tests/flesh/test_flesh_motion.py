"""A bound shape moving along its spine: ``SpineBinding.deform(slide=)`` and
``SpineBinding.animate`` (Zhuo 2014 §5.2.2), against closed forms (translation along a line,
rotation about an arc's centre) and the per-pose ``deform``."""

import warnings

import numpy as np
import pytest

import spinal


def tube_shape(rings=120, sides=24, length=4.0, radius=0.3):
    x = np.linspace(0.0, length, rings)
    m = spinal.tube(np.c_[x, np.zeros(rings), np.zeros(rings)], radius, sides)
    return m.vertices, m.faces


def line(n, length=4.0, start=-1.0, stop=5.0):
    s = np.linspace(start, stop, n)
    return np.c_[s, np.zeros(n), np.zeros(n)]


def arc(n, rho, length, phase=0.0):
    s = np.linspace(0.0, length, n) + phase
    return np.c_[rho * np.sin(s / rho), rho * (1 - np.cos(s / rho)), np.zeros(n)]


def volume(V, F):
    return spinal.Mesh(V, F).volume


@pytest.mark.parametrize("ds", [0.37, -0.8, 1.9, 3.5])
def test_sliding_along_a_straight_spine_translates_the_shape(ds):
    V, _ = tube_shape()
    rest = line(61, start=0.0, stop=4.0)
    b = spinal.SpineBinding(V, rest)
    # a long straight posed spine: the slid sections stay on it, or on its extension
    out = b.deform(line(400, start=0.0, stop=6.0), slide=ds)
    np.testing.assert_allclose(out, V + [ds, 0, 0], atol=1e-9)


def test_sliding_round_a_circular_arc_turns_the_shape_about_its_centre():
    """On a circle the slid shape is the bent one turned by ds/ρ about the centre: the
    posed spine is a fine polyline of the circle, so they agree to its sampling error."""
    V, F = tube_shape()
    rest = line(81, start=0.0, stop=4.0)
    b = spinal.SpineBinding(V, rest)
    rho, ds = 3.0, 0.9
    posed = arc(6000, rho, 2 * np.pi * rho * 0.9)  # most of the circle, finely sampled
    bent = b.deform(posed)
    slid = b.deform(posed, slide=ds)
    a = ds / rho
    rot = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    centre = np.array([0.0, rho, 0.0])
    want = (bent - centre) @ rot.T + centre
    err = np.abs(slid - want).max()
    assert err < 2e-5, err
    # and the volume is kept as for the bend
    v0, vb, vs = volume(V, F), volume(bent, F), volume(slid, F)
    assert abs(vs / v0 - 1) <= 1.05 * abs(vb / v0 - 1) + 1e-7


def test_slide_and_bend_keep_the_volume_as_bending_does():
    V, F = tube_shape(rings=200, sides=48)
    rest = line(101, start=0.0, stop=4.0)
    b = spinal.SpineBinding(V, rest)
    u = np.linspace(0.0, 7.0, 700)
    posed = np.c_[u, 0.6 * np.sin(1.3 * u), 0.3 * np.cos(0.9 * u)]  # bends and twists
    v0 = volume(V, F)
    bent = abs(volume(b.deform(posed), F) / v0 - 1)
    for ds in (0.5, 1.7, 2.9):
        slid = abs(volume(b.deform(posed, slide=ds), F) / v0 - 1)
        assert slid <= 2 * bent + 1e-6, (ds, slid, bent)


def test_sliding_round_a_loop_wraps_and_a_whole_turn_is_no_slide():
    ring = np.c_[np.cos(np.linspace(0, 2 * np.pi, 73)[:-1]),
                 np.sin(np.linspace(0, 2 * np.pi, 73)[:-1]), np.zeros(72)]
    rng = np.random.default_rng(3)
    V = ring[rng.integers(0, 72, 500)] * (1 + 0.1 * rng.uniform(-1, 1, (500, 1))) + \
        [0, 0, 0.05] * rng.uniform(-1, 1, (500, 1))
    b = spinal.SpineBinding(V, ring, closed=True)
    posed = ring * 1.0
    L = np.linalg.norm(np.diff(np.r_[ring, ring[:1]], axis=0), axis=1).sum()
    np.testing.assert_allclose(b.deform(posed, slide=L), b.deform(posed), atol=1e-9)
    # a quarter of the loop: the ring's shape turned by a quarter turn about its axis
    q = b.deform(posed, slide=L / 4)
    rot = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    np.testing.assert_allclose(q, V @ rot.T, atol=1e-9)


def test_slide_is_checked():
    V, _ = tube_shape(rings=10, sides=6)
    b = spinal.SpineBinding(V, line(11, start=0.0, stop=4.0))
    with pytest.raises(ValueError, match="^slide: "):
        b.deform(line(11), slide=np.nan)
    with pytest.raises(TypeError, match="^slide: "):
        b.deform(line(11), slide="far")
    with pytest.raises(TypeError, match="^slide: not with stretchable=True"):
        b.deform(line(11, start=0.0, stop=4.0), slide=0.5, stretchable=True)


def test_animate_starts_as_deform_and_follows_the_spine_without_flicker():
    """Pose 0 is deform's; later poses turn each section by about its tangent's turn: the
    vertices move between poses by at most the spine's own motion plus the offset times the
    tangents' turn. The spine passes through a straight pose, where a per-pose best fit of
    the roll is undefined."""
    V, _ = tube_shape(rings=80, sides=16)
    rest = line(41, start=0.0, stop=4.0)
    b = spinal.SpineBinding(V, rest)
    s = np.linspace(0.0, 4.0, 41)
    poses = []
    for t in np.linspace(-1.0, 1.0, 31):  # bend one way, straight, the other way, rolling
        ax = np.array([0.0, np.cos(2 * t), np.sin(2 * t)])
        poses.append(np.c_[s, np.zeros(41), np.zeros(41)] + 0.25 * t * np.sin(s)[:, None] * ax)
    poses = np.array(poses)
    calls = []
    out = b.animate(poses, progress=lambda d, n: calls.append((d, n)))
    assert out.shape == (31, len(V), 3) and calls[-1] == (31, 31)
    np.testing.assert_array_equal(out[0], b.deform(poses[0]))
    R = np.linalg.norm(V[:, 1:], axis=1).max()
    for k in range(1, 31):
        move = np.abs(poses[k] - poses[k - 1]).max()
        t0 = np.diff(poses[k - 1], axis=0)
        t1 = np.diff(poses[k], axis=0)
        cos = np.einsum("ij,ij->i", t0, t1) / np.linalg.norm(t0, axis=1) / np.linalg.norm(t1,
                                                                                        axis=1)
        turn = np.arccos(np.clip(cos, -1, 1)).max()
        jump = np.linalg.norm(out[k] - out[k - 1], axis=1).max()
        assert jump <= 1.5 * (move + R * turn) + 1e-9, (k, jump, move, turn)


def test_animate_crawls_with_a_slide_per_pose_and_checks_its_input():
    V, _ = tube_shape(rings=40, sides=8)
    rest = line(21, start=0.0, stop=4.0)
    b = spinal.SpineBinding(V, rest)
    posed = np.repeat(line(200, start=0.0, stop=8.0)[None], 5, axis=0)
    out = b.animate(posed, slide=np.linspace(0.0, 2.0, 5))
    for k, ds in enumerate(np.linspace(0.0, 2.0, 5)):
        np.testing.assert_allclose(out[k], V + [ds, 0, 0], atol=1e-9)
    with pytest.raises(ValueError, match="^posed_spines_t: expected shape"):
        b.animate(posed[0])
    with pytest.raises(ValueError, match="^slide: "):
        b.animate(posed, slide=[0.0, 1.0])
    bad = posed.copy()
    bad[3, 5] = np.nan
    with pytest.raises(ValueError, match="^posed_spines_t: pose 3: "):
        b.animate(bad)


def test_slides_per_pose_must_be_finite_and_clamp_warnings_point_at_the_caller():
    V, _ = tube_shape(rings=20, sides=6)
    b = spinal.SpineBinding(V, line(11, start=0.0, stop=4.0))
    posed = np.repeat(line(50, start=0.0, stop=8.0)[None], 3, axis=0)
    with pytest.raises(ValueError, match="^slide: the slide of pose 1 is not finite"):
        b.animate(posed, slide=[0.0, np.nan, 0.0])
    # points 0.9 off the spine, bent to radius 1 towards them: past the fold limit
    W = np.c_[np.linspace(0, 4, 50), np.full(50, 0.9), np.zeros(50)]
    rest = line(21, start=0.0, stop=4.0)
    c = spinal.SpineBinding(W, rest)
    th = np.linspace(0, 4, 21)
    tight = np.c_[np.sin(th), 1 - np.cos(th), 0 * th]
    for call in (lambda: c.deform(tight), lambda: c.animate(tight[None]),
                 lambda: spinal.flesh(W, rest, tight)):
        with pytest.warns(spinal.FoldOverWarning) as rec:
            call()
        assert rec[0].filename == __file__


def test_animate_warns_once_for_the_vertices_clamped_in_any_pose():
    """A bar bent tighter pose after pose: the later poses clamp vertices past the fold limit.
    One FoldOverWarning for the call (not one per pose) holds every vertex clamped in some
    pose, the same as ``deform`` reports pose by pose."""
    x = np.linspace(0, 4, 201)
    rest = np.c_[x, 0 * x, 0 * x]
    V = np.random.default_rng(0).uniform([0, -0.3, -0.3], [4, 0.3, 0.3], (5_000, 3))
    b = spinal.SpineBinding(V, rest)
    a = np.linspace(0, 1, 12)[:, None]
    P = np.stack([x + 0 * a, 0.3 * np.sin(3 * x * a), 0 * x + 0 * a], -1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        b.animate(P)
    folds = [w for w in caught if issubclass(w.category, spinal.FoldOverWarning)]
    assert len(folds) == 1
    per_pose = []
    for t in range(len(P)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            _, c = b.deform(P[t], return_clamped=True)
        per_pose.append(c)
    every = np.unique(np.concatenate(per_pose))
    assert 0 < every.size < len(V)
    np.testing.assert_array_equal(folds[0].message.indices, every)
    hit = sum(c.size > 0 for c in per_pose)
    assert f"in {hit} of {len(P)} poses" in str(folds[0].message)
    assert folds[0].filename == __file__
