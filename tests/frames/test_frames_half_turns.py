"""Half-integer ``turns`` on closed curves: frames that close up to a half turn about the
tangent, and closed sweeps of profiles symmetric under that half turn, against closed forms
(the circle's frames, Pappus' volume) and trimesh's checks."""

import numpy as np
import pytest
import trimesh

import spinal

R = 3.0


def circle(n, radius=R):
    u = 2 * np.pi * np.arange(n) / n
    return np.c_[radius * np.cos(u), radius * np.sin(u), np.zeros(n)]


def torus_knot(n):
    """The (2, 3) torus knot of Wang et al. (2008), §6.2."""
    u = 2 * np.pi * np.arange(n) / n
    return np.c_[(2 + np.cos(3 * u)) * np.cos(2 * u), (2 + np.cos(3 * u)) * np.sin(2 * u),
                 np.sin(3 * u)]


def angles(a, b):
    """The signed angle from ``a``'s r column to ``b``'s about their (shared) tangent."""
    ra, rb, t = a[:, :, 0], b[:, :, 0], a[:, :, 2]
    return np.arctan2(np.einsum("ij,ij->i", np.cross(ra, rb), t), np.einsum("ij,ij->i", ra, rb))


def arc_fraction(x):
    """``s_i / L``: the chord length from row 0 to row i over the loop's length."""
    chords = np.linalg.norm(np.roll(x, -1, axis=0) - x, axis=1)
    return np.r_[0.0, np.cumsum(chords)[:-1]] / chords.sum()


def test_circle_half_turn_closed_form():
    # a planar circle's RMF is its principal normal N (closing angle 0); turns=½ turns it by
    # π s/L about t: r = cos(πs/L) N + sin(πs/L) t × N, with t × N = e_z
    n = 96
    x = circle(n)
    u = 2 * np.pi * np.arange(n) / n
    normal = -np.c_[np.cos(u), np.sin(u), np.zeros(n)]
    f = spinal.frames(x, closed=True, turns=0.5, initial=normal[0])
    phase = np.pi * np.arange(n) / n
    want = np.cos(phase)[:, None] * normal + np.sin(phase)[:, None] * [0.0, 0.0, 1.0]
    assert np.abs(f[:, :, 0] - want).max() < 1e-12
    # continued to s = L the frame is the first turned by π: r_n = −r_0
    last = np.cos(np.pi) * normal[0] + np.sin(np.pi) * np.array([0.0, 0.0, 1.0])
    assert np.allclose(last, -f[0][:, 0], atol=1e-15)
    for k in (-0.5, 1.5):
        g = spinal.frames(x, closed=True, turns=k, initial=normal[0])
        d = angles(f, g) - 2 * np.pi * (k - 0.5) * np.arange(n) / n
        assert np.abs(np.angle(np.exp(1j * d))).max() < 1e-12


@pytest.mark.parametrize("k", [0.5, -0.5, 1.5, -2.5])
def test_torus_knot_spreads_alpha_plus_half_turns(k):
    x = torus_knot(400)
    alpha = spinal.closing_angle(x)
    whole = spinal.frames(x, closed=True)  # α spread: closes
    half = spinal.frames(x, closed=True, turns=k)
    w = arc_fraction(x)
    # the total is α + 2πk: on top of the closing frames, 2πk s/L
    d = angles(whole, half)
    want = np.angle(np.exp(1j * 2 * np.pi * k * w))
    assert np.abs(np.angle(np.exp(1j * (d - want)))).max() < 1e-11
    assert np.array_equal(half[:, :, 2], whole[:, :, 2])
    # the last frame carried across the closing segment by one double-reflection step (the
    # RMF's own step) is the first turned by the rest of the spread, (α + 2πk)(1 − w), less
    # 2πk: a half turn for half k
    r, t = half[-1][:, 0], half[-1][:, 2]
    v1 = x[0] - x[-1]
    r_l = r - 2 * (v1 @ r) / (v1 @ v1) * v1
    t_l = t - 2 * (v1 @ t) / (v1 @ v1) * v1
    v2 = half[0][:, 2] - t_l
    carried = r_l - 2 * (v2 @ r_l) / (v2 @ v2) * v2
    t0, r0 = half[0][:, 2], half[0][:, 0]
    got = np.arctan2(np.cross(carried, r0) @ t0, carried @ r0)
    rest = (alpha + 2 * np.pi * k) * (1 - w[-1])
    assert abs(np.angle(np.exp(1j * (got - rest - np.pi)))) < 1e-9


def test_whole_turns_bit_identical():
    x = torus_knot(300)
    for k in (0, 1, -2, 3):
        ref = spinal.frames(x, closed=True, turns=k)
        for same in (float(k), np.float64(k), np.int32(k)):
            assert np.array_equal(spinal.frames(x, closed=True, turns=same), ref)
        m = spinal.tube(x, radius=0.2, closed=True, turns=same)
        assert np.array_equal(m.vertices, spinal.tube(x, radius=0.2, closed=True,
                                                      frames=ref).vertices)


def test_min_angular_speed_and_in_time_take_half_turns():
    x = torus_knot(300)
    ms0 = spinal.frames(x, closed=True, twist_rule="min_angular_speed")
    ms = spinal.frames(x, closed=True, twist_rule="min_angular_speed", turns=0.5)
    t = ms0[:, :, 2]
    turn = np.arccos(np.clip(np.einsum("ij,ij->i", t, np.roll(t, -1, axis=0)), -1, 1))
    w = np.r_[0.0, np.cumsum(turn)[:-1]] / turn.sum()
    assert np.abs(angles(ms0, ms) - np.pi * w).max() < 1e-11
    steps = np.stack([x, 1.1 * x, 1.2 * x])
    f = spinal.frames_in_time(steps, closed=True, turns=0.5, previous_twist=False)
    for k in range(3):
        assert f[k][-1][:, 0] @ f[k][0][:, 0] < -0.9  # a half turn across the seam
    g = spinal.frames_in_time(steps, closed=True, turns=0.5)  # following the step before
    assert np.abs(g - f).max() < 1e-3


def test_half_turns_refused_where_they_do_not_apply():
    x = torus_knot(64)
    with pytest.raises(ValueError, match="turns: expected a whole or half number"):
        spinal.frames(x, closed=True, turns=0.25)
    with pytest.raises(ValueError, match="turns: expected a whole or half number"):
        spinal.frames(x, closed=True, turns=float("nan"))
    with pytest.raises(TypeError, match="turns: expected a whole or half number"):
        spinal.frames(x, closed=True, turns=True)
    with pytest.raises(ValueError, match="turns: applies to a closed curve"):
        spinal.frames(x, turns=0.5)
    with pytest.raises(ValueError, match="turns: a half number of turns"):
        spinal.frames(x, end=[0.0, 0.0, 1.0], turns=0.5)
    with pytest.raises(ValueError, match="turns: a half number of turns"):
        spinal.frames(x, closed=True, constraints={5: [0.0, 0.0, 1.0]}, turns=0.5)
    with pytest.raises(TypeError, match="turns: expected an integer or a 1-D sequence"):
        spinal.frames(x, closed=True, constraints={5: [0.0, 0.0, 1.0]}, turns=[0.5])
    with pytest.raises(ValueError, match="turns: expected a whole or half number"):
        spinal.frames_in_time(np.stack([x, x]), closed=True, turns=0.75)


def pappus_error(n, profile, area, turns):
    m = spinal.sweep(circle(n), profile, closed=True, turns=turns)
    mesh = trimesh.Trimesh(m.vertices, m.faces, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    exact = area * 2 * np.pi * R  # Pappus: the profile's centroid is on the spine
    return abs(mesh.volume - exact) / exact


@pytest.mark.parametrize("turns", [0.5, -0.5, 1.5])
def test_twisted_rectangle_keeps_pappus_volume_at_second_order(turns):
    a, b = 1.0, 0.5
    rect = np.array([[a, b], [-a, b], [-a, -b], [a, -b]])
    errs = np.array([pappus_error(n, rect, 4 * a * b, turns) for n in (64, 128, 256)])
    order = np.log2(errs[:-1] / errs[1:])
    assert np.all(np.abs(order - 2) < 0.01), order
    assert errs[-1] < 1e-3


def test_twisted_ellipse_keeps_pappus_volume_at_second_order():
    a, b = 1.0, 0.5
    errs = []
    for n, sides in ((64, 32), (128, 64), (256, 128)):
        u = 2 * np.pi * np.arange(sides) / sides
        errs.append(pappus_error(n, np.c_[a * np.cos(u), b * np.sin(u)], np.pi * a * b, 0.5))
    order = np.log2(np.array(errs[:-1]) / errs[1:])
    assert np.all(np.abs(order - 2) < 0.01), order


def test_tube_seam_is_shifted_by_half_the_sides():
    n, sides = 64, 16
    m = spinal.tube(circle(n), radius=0.7, sides=sides, closed=True, turns=0.5)
    v = m.vertices.reshape(n, sides, 3)
    # the closing segment's faces join column j of the last ring to j + sides/2 of the first
    seam = [f for f in m.faces if f.max() < sides or f.min() >= (n - 1) * sides or
            (f.min() < sides and f.max() >= (n - 1) * sides)]
    pairs = {(int(a) % sides, int(b) % sides) for f in seam for a in f for b in f
             if a >= (n - 1) * sides and b < sides}
    # (a quad's diagonal joins neighbouring columns: j + sides/2 ± 1 too)
    diffs = {(b - a) % sides for a, b in pairs}
    assert sides // 2 in diffs and diffs <= {sides // 2 - 1, sides // 2, sides // 2 + 1}
    # and the first ring's column j + sides/2 is where the last ring's column j is heading
    step = v[0, np.arange(sides) + sides // 2 - sides * (np.arange(sides) >= sides // 2)]
    assert np.linalg.norm(step - v[-1], axis=1).max() < 2 * np.linalg.norm(v[1] - v[0],
                                                                           axis=1).max()


def test_tube_normals_across_the_seam():
    # normals of the torus, exact up to O(h²): the rings at the seam as good as the others
    n, sides = 64, 16
    m = spinal.tube(circle(n), radius=0.7, sides=sides, closed=True, turns=0.5)
    c = m.vertices * [1.0, 1.0, 0.0]
    c = R * c / np.linalg.norm(c, axis=1)[:, None]
    exact = (m.vertices - c) / np.linalg.norm(m.vertices - c, axis=1)[:, None]
    err = np.linalg.norm(m.normals - exact, axis=1).reshape(n, sides).max(axis=1)
    assert max(err[0], err[-1]) <= 1.01 * err[1:-1].max()
    assert err.max() < 1e-3


def test_split_seams_with_a_half_turn():
    n, sides = 48, 12
    m = spinal.tube(circle(n), radius=0.5, sides=sides, closed=True, turns=0.5,
                    split_seams=True)
    mesh = trimesh.Trimesh(m.vertices, m.faces)  # merges the seams' copies
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    rings = m.vertices.reshape(n + 1, sides + 1, 3)
    # the copy of ring 0 at u = L is ring 0 turned by π: its column j at column j + sides/2
    shifted = np.roll(rings[0, :sides], -(sides // 2), axis=0)
    assert np.abs(rings[n, :sides] - shifted).max() < 1e-12
    uv = m.uv.reshape(n + 1, sides + 1, 2)
    assert np.allclose(uv[n, :, 0], uv[n, 0, 0]) and uv[n, 0, 0] > uv[n - 1, 0, 0]


def test_sweep_refuses_asymmetric_profiles_and_odd_tubes():
    x = circle(64)
    u = 2 * np.pi * np.arange(24) / 24
    ellipse = np.c_[np.cos(u), 0.4 * np.sin(u)]
    with pytest.raises(ValueError, match="profile: turns=0.5 .*symmetric under a half turn"):
        spinal.sweep(x, ellipse + [0.1, 0.0], closed=True, turns=0.5)
    with pytest.raises(ValueError, match="profile: .*odd number of vertices"):
        spinal.sweep(x, ellipse[:-1], closed=True, turns=0.5)
    with pytest.raises(ValueError, match="profile: .*Möbius"):
        spinal.sweep(x, ellipse[:12], closed=True, turns=0.5, profile_closed=False)
    with pytest.raises(ValueError, match="turns: .*even number of sides"):
        spinal.tube(x, sides=15, closed=True, turns=0.5)
    with pytest.raises(ValueError, match="turns: .*closed"):
        spinal.tube(x, turns=0.5)
    with pytest.raises(ValueError, match="turns: expected a whole or half number"):
        spinal.tube(x, closed=True, turns=1 / 3)
    square = 3.0 * np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0], [2, 2, 0], [1, 2, 0],
                             [0, 2, 0], [0, 1, 0.0]])
    with pytest.raises(ValueError, match="turns: .*corner joins"):
        spinal.tube(square, radius=0.3, sides=8, closed=True, turns=0.5)


def test_given_frames_that_close_up_to_a_half_turn():
    x = torus_knot(200)
    u = 2 * np.pi * np.arange(16) / 16
    ellipse = np.c_[0.2 * np.cos(u), 0.1 * np.sin(u)]
    f = spinal.frames(x, closed=True, turns=0.5)
    own = spinal.sweep(x, ellipse, closed=True, turns=0.5)
    given = spinal.sweep(x, ellipse, frames=f, closed=True, turns=0.5)
    assert np.array_equal(own.vertices, given.vertices)
    assert np.array_equal(own.faces, given.faces)
    mesh = trimesh.Trimesh(given.vertices, given.faces, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    with pytest.raises(ValueError, match="frames: with a half number of turns"):
        spinal.sweep(x, ellipse, frames=spinal.frames(x, closed=True), closed=True,
                     turns=0.5)
    with pytest.raises(TypeError, match="turns: with frames= only a half number"):
        spinal.sweep(x, ellipse, frames=f, closed=True, turns=1)


def test_bundle_and_float32_sweeps_with_a_half_turn():
    a, b = 1.0, 0.5
    rect = np.array([[a, b], [-a, b], [-a, -b], [a, -b]])
    one = spinal.sweep(circle(64), rect, closed=True, turns=0.5)
    both = spinal.sweep(np.r_[circle(64), circle(64) + [0.0, 0.0, 5.0]], rect, closed=True,
                        turns=0.5, lengths=[64, 64])
    mesh = trimesh.Trimesh(both.vertices, both.faces, process=False)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert np.isclose(mesh.volume, 2 * one.volume, rtol=1e-12)
    assert np.array_equal(both.faces[: len(one.faces)], one.faces)
    single = spinal.sweep(circle(64), rect, closed=True, turns=0.5, dtype=np.float32)
    assert np.array_equal(single.faces, one.faces)
    assert np.abs(single.vertices - one.vertices).max() < 1e-6


def test_quaternion_frames_take_half_turns_like_frames():
    from scipy.spatial.transform import Rotation

    from spinal import quaternions

    x = torus_knot(300)
    q = quaternions.quaternion_frames(x, closed=True, turns=0.5)
    # an independent recurrence: the rotation-method frames with the same spread
    f = spinal.frames(x, closed=True, method="rotation", turns=0.5)
    assert np.abs(Rotation.from_quat(q).as_matrix() - f).max() < 1e-12
    assert f[-1][:, 0] @ f[0][:, 0] < -0.9
    with pytest.raises(ValueError, match="turns: a half number of turns"):
        quaternions.quaternion_frames(x, turns=0.5)
    with pytest.raises(ValueError, match="turns: expected a whole or half number"):
        quaternions.quaternion_frames(x, closed=True, turns=0.3)
