"""Quaternion frames (Hanson & Ma; Ma's thesis 1996, see docs/references.md): conversions,
continuity, slerp, parallel transport as a quaternion recurrence, closure, path length,
cameras and the mesh walker. Reference values computed independently (closed-curve holonomy
−∮τ ds mod 2π, quaternion path lengths on helices) and closed forms."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import spinal
from spinal import quaternions as Q

A, B = 1.0, 0.5  # helix radius and pitch/2π
C = np.hypot(A, B)


def helix(n_per_turn, turns=1.0):
    u = np.linspace(0, 2 * np.pi * turns, int(n_per_turn * turns) + 1)
    x = np.c_[A * np.cos(u), A * np.sin(u), B * u]
    t = np.c_[-A * np.sin(u), A * np.cos(u), np.full_like(u, B)] / C
    nrm = np.c_[-np.cos(u), -np.sin(u), np.zeros_like(u)]
    frenet = np.stack([nrm, np.cross(t, nrm), t], axis=2)
    return x, t, frenet


def central_tangents(x):
    t = np.roll(x, -1, axis=0) - np.roll(x, 1, axis=0)
    return t / np.linalg.norm(t, axis=1)[:, None]


def trefoil(n):
    t = 2 * np.pi * np.arange(n) / n
    return np.c_[np.sin(t) + 2 * np.sin(2 * t), np.cos(t) - 2 * np.cos(2 * t), -np.sin(3 * t)]


def torus_knot(p, q, n, big=2.0, r=1.0):
    t = 2 * np.pi * np.arange(n) / n
    rho = big + r * np.cos(q * t)
    return np.c_[rho * np.cos(p * t), rho * np.sin(p * t), -r * np.sin(q * t)]


# --- conversions ------------------------------------------------------------------------


@pytest.mark.parametrize("scalar_first", [False, True])
def test_conversions_match_scipy_and_round_trip(scalar_first):
    rng = np.random.default_rng(3)
    rot = Rotation.random(500, random_state=rng)
    # add exact half turns, where Ma's conversion fails
    axes = np.array([[1, 1, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, -2, 3]], float)
    half = Rotation.from_rotvec(np.pi * axes / np.linalg.norm(axes, axis=1)[:, None])
    f = np.concatenate([rot.as_matrix(), half.as_matrix()])
    q = Q.to_quaternions(f, scalar_first=scalar_first, continuous=False)
    ref = Rotation.from_matrix(f).as_quat(scalar_first=scalar_first, canonical=True)
    np.testing.assert_allclose(q, ref, atol=2e-15)
    np.testing.assert_allclose(Q.from_quaternions(q, scalar_first=scalar_first), f, atol=2e-15)
    back = Rotation.from_quat(q, scalar_first=scalar_first).as_matrix()
    np.testing.assert_allclose(back, f, atol=2e-15)
    # one frame in, one quaternion out
    assert Q.to_quaternions(f[0], scalar_first=scalar_first).shape == (4,)


def test_sign_continuity_along_a_curve():
    _, _, fr = helix(64, turns=2)
    q = Q.to_quaternions(fr)
    dots = np.einsum("ij,ij->i", q[1:], q[:-1])
    assert dots.min() > 0.99
    # the Frenet frame of a helix turns once about its axis per turn: q(end) = −q(start)
    one = Q.to_quaternions(helix(64)[2])
    assert one[-1] @ one[0] == pytest.approx(-1.0, abs=1e-12)
    flipped = q * np.where(np.arange(len(q)) % 3 == 0, -1.0, 1.0)[:, None]
    np.testing.assert_allclose(Q.make_continuous(flipped), q, atol=0)


def test_slerp_ends_speed_and_short_arc():
    a = Rotation.from_rotvec([0, 0, 0.3]).as_quat()
    b = -Rotation.from_rotvec([0, 0, 1.5]).as_quat()  # far sign: slerp must take the short arc
    u = np.linspace(0, 1, 7)
    q = Q.slerp(a, b, u)
    ang = Rotation.from_quat(q).as_rotvec()[:, 2]
    np.testing.assert_allclose(ang, 0.3 + 1.2 * u, atol=1e-14)  # constant angular speed
    # tiny angles use the linear branch without losing accuracy
    c = Rotation.from_rotvec([1e-10, 0, 0]).as_quat()
    np.testing.assert_allclose(Rotation.from_quat(Q.slerp(np.r_[0, 0, 0, 1.0], c, 0.5))
                               .as_rotvec(), [5e-11, 0, 0], atol=1e-20)


def test_slerp_frames_between_keys():
    keys = Rotation.from_rotvec([[0, 0, 0], [0, 0, 1.0], [0, 1.0, 1.0]]).as_matrix()
    out = Q.slerp_frames(keys, [0.0, 0.5, 1.0, 2.0], key_u=[0, 1, 2])
    np.testing.assert_allclose(out[[0, 2, 3]], keys, atol=1e-15)
    np.testing.assert_allclose(out[1], Rotation.from_rotvec([0, 0, 0.5]).as_matrix(), atol=1e-15)
    with pytest.raises(ValueError, match="new_u"):
        Q.slerp_frames(keys, [3.0], key_u=[0, 1, 2])
    with pytest.raises(ValueError, match="key_u"):
        Q.slerp_frames(keys, [0.5], key_u=[0, 2, 1])


# --- parallel transport -----------------------------------------------------------------


def test_transport_recurrence_equals_rotation_method():
    x, t, _ = helix(50, turns=3)
    q = Q.quaternion_frames(x, t)
    np.testing.assert_allclose(Q.from_quaternions(q),
                               spinal.frames(x, t, method="rotation"), atol=1e-12)
    # default tangents too, and scalar_first only reorders
    q2 = Q.quaternion_frames(x, scalar_first=True)
    np.testing.assert_allclose(Q.from_quaternions(q2, scalar_first=True),
                               spinal.frames(x, spinal.estimate_tangents(x), method="rotation"),
                               atol=1e-12)


def test_helix_spin_per_turn():
    """PT started at the Frenet frame, after one turn: spin from Frenet to PT = −τL =
    −2πb/c = −2.8099259 rad; with exact tangents the discrete PT is within ~1e-5 at 1024
    segments per turn and converges at 2nd order."""
    exact = -2 * np.pi * B / C
    assert exact == pytest.approx(-2.8099259, abs=1e-7)
    errs = []
    for n in (256, 512, 1024):
        x, t, fr = helix(n)
        q = Q.quaternion_frames(x, t, initial=fr[0])
        errs.append(abs(Q.spin(fr[-1], Q.from_quaternions(q[-1])) - exact))
    assert errs[-1] < 1e-5
    assert 3.8 < errs[0] / errs[1] < 4.2 and 3.8 < errs[1] / errs[2] < 4.2


def test_quaternion_path_length_per_helix_turn():
    """Frenet: π per turn for any pitch; parallel transport ½∫κ ds = πa/c (2.8099257 at 2000
    segments with exact tangents: n·θ/2 with cos θ = (a² cos(2π/n) + b²)/c²)."""
    x, t, fr = helix(2000)
    assert Q.quaternion_length(fr) == pytest.approx(np.pi, abs=1e-12)
    q = Q.quaternion_frames(x, t)
    theta = 2 * np.arcsin(A * np.sin(np.pi / 2000) / C)  # cos θ = (a² cos φ + b²)/c², stably
    assert Q.quaternion_length(q) == pytest.approx(2000 * theta / 2, abs=1e-12)
    assert Q.quaternion_length(q) == pytest.approx(2.8099257, abs=1e-7)


@pytest.mark.parametrize("curve, table", [
    (trefoil, {100: 4.056912, 400: 4.058067, 1600: 4.058140, 6400: 4.058144}),
    (lambda n: torus_knot(3, 5, n), {100: 0.021836, 400: 0.358550, 1600: 0.380373,
                                     6400: 0.381740}),
    (lambda n: torus_knot(5, 3, n), {100: 5.002761, 400: 5.024974, 1600: 5.026394,
                                     6400: 5.026483}),
])
def test_closure_mismatch_of_knots(curve, table):
    """Ma's table: the angle from V_0 to the vector carried once round (central-difference
    tangents), in [0, 2π). It is minus spinal's closing angle."""
    for n, ref in table.items():
        x = curve(n)
        t = central_tangents(x)
        # the recurrence alone, as an open curve with the first sample appended
        q = Q.quaternion_frames(np.vstack([x, x[:1]]), np.vstack([t, t[:1]]))
        f0, fe = Q.from_quaternions(q[[0, -1]])
        mismatch = Q.spin(f0, fe) % (2 * np.pi)
        assert mismatch == pytest.approx(ref, abs=1.5e-6), n
        alpha = spinal.closing_angle(x, t, method="rotation")
        assert (-alpha) % (2 * np.pi) == pytest.approx(ref, abs=1.5e-6)


@pytest.mark.parametrize("p, q, sign", [(2, 3, None), (3, 5, 1.0), (5, 3, -1.0)])
def test_closure_correction_closes_the_frames(p, q, sign):
    x = trefoil(1600) if sign is None else torus_knot(p, q, 1600)
    t = central_tangents(x)
    for turns in (0, 1):
        qq = Q.quaternion_frames(np.vstack([x, x[:1]]), np.vstack([t, t[:1]]), closed=True,
                                 turns=turns)
        ref = spinal.frames(x, t, method="rotation", closed=True, turns=turns)
        np.testing.assert_allclose(Q.from_quaternions(qq[:-1]), ref, atol=1e-12)
        # the carried-round frame is the first one again (to round-off), as ±q0
        d = qq[-1] @ qq[0]
        assert abs(abs(d) - 1) < 1e-12
        if sign is not None and turns == 0:
            assert np.sign(d) == sign  # the (5,3) knot closes at −q0 (q ≡ −q; Ma §3.5.4)


def test_closed_path_length_of_the_corrected_trefoil():
    """Closure-corrected PT of the trefoil, n = 6400, central tangents, closing arc included:
    7.082047, computed independently (continuum 7.0820479)."""
    x = trefoil(6400)
    q = Q.quaternion_frames(x, central_tangents(x), closed=True)
    assert Q.quaternion_length(q, closed=True) == pytest.approx(7.082047, abs=2e-6)


def test_frenet_quaternions():
    x = helix(200)[0]
    q = Q.quaternion_frames(x, method="frenet")
    f = Q.from_quaternions(q)
    assert np.abs(f - spinal.frames(x, method="frenet")).max() < 1e-13
    assert np.einsum("ij,ij->i", q[1:], q[:-1]).min() > 0


def test_quaternion_bad_input():
    with pytest.raises(ValueError, match="frames: row 1 is not a rotation"):
        Q.to_quaternions(np.stack([np.eye(3), np.diag([1.0, 1, -1])]))
    with pytest.raises(ValueError, match="quaternions: row 0 is zero"):
        Q.from_quaternions(np.zeros((1, 4)))
    with pytest.raises(ValueError, match="quaternions"):
        Q.from_quaternions(np.ones((3, 3)))
    with pytest.raises(ValueError, match="row 1 .*cusp"):
        Q.quaternion_frames(np.c_[np.arange(4.0), np.zeros(4), np.zeros(4)],
                            tangents=[[1, 0, 0], [1, 0, 0], [-1, 0, 0], [-1, 0, 0]])
    with pytest.raises(ValueError, match="initial"):
        x = helix(20)[0]
        Q.quaternion_frames(x, initial=spinal.estimate_tangents(x)[0])
    with pytest.raises(ValueError, match="method"):
        Q.quaternion_frames(helix(20)[0], method="bishop")
    f = Rotation.random(3, random_state=1).as_matrix()
    f0 = f.copy()
    Q.to_quaternions(f)
    np.testing.assert_array_equal(f, f0)


# --- cameras ------------------------------------------------------------------------------


def test_camera_transport_mode():
    x, t, _ = helix(100)
    cam = Q.camera_frames(x, up=[0, 0, 1])
    right, up, back = cam[:, :, 0], cam[:, :, 1], cam[:, :, 2]
    np.testing.assert_allclose(-back, t, atol=1e-3)  # estimated tangents
    np.testing.assert_allclose(np.einsum("ij,ij->i", up, back), 0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(cam), 1, atol=1e-12)
    r = spinal.frames(x, initial=[0, 0, 1])[:, :, 0]
    np.testing.assert_allclose(up, r, atol=1e-15)
    assert right[0] @ np.cross(-back[0], up[0]) == pytest.approx(1.0)


def test_camera_level_horizon_through_a_vertical_run():
    """Heading +x, a quarter circle up, a vertical stretch, a quarter circle over to −x (a
    loop's top). On the vertical stretch the level horizon is undefined: the frames there
    are carried and the half turn of `up` is spread along it; everywhere else right is
    horizontal and up is the projection of +z."""
    h = 0.025
    a = np.arange(0, np.pi / 2, h)
    arc1 = np.c_[np.sin(a), 0 * a, 1 - np.cos(a)]
    t1 = np.c_[np.cos(a), 0 * a, np.sin(a)]
    z = np.arange(0, 1, h)
    run = np.c_[1 + 0 * z, 0 * z, 1 + z]
    tr = np.tile([0.0, 0, 1], (len(z), 1))
    b = np.arange(0, np.pi / 2 + h / 2, h)
    arc2 = np.c_[np.cos(b), 0 * b, 2 + np.sin(b)]
    t2 = np.c_[-np.sin(b), 0 * b, np.cos(b)]
    x, t = np.vstack([arc1, run, arc2]), np.vstack([t1, tr, t2])
    cam = Q.camera_frames(x, mode="up", tangents=t)
    assert np.isfinite(cam).all()
    np.testing.assert_allclose(np.linalg.det(cam), 1, atol=1e-12)
    np.testing.assert_allclose(-cam[:, :, 2], t, atol=1e-12)
    np.testing.assert_allclose(cam[:, 2, 0], 0, atol=1e-12)  # right is horizontal
    regular = np.linalg.norm(np.cross(t, [0, 0, 1]), axis=1) > np.sin(1e-3)
    w = np.array([0, 0, 1.0]) - t[regular, 2:3] * t[regular]
    up = w / np.linalg.norm(w, axis=1, keepdims=True)
    np.testing.assert_allclose(cam[regular, :, 1], up, atol=1e-12)
    # the half turn of up is spread over the vertical stretch, no jump
    step = np.linalg.norm(np.diff(cam, axis=0), axis=(1, 2))
    assert step.max() < 0.15
    assert (~regular).sum() >= len(z) - 1


def test_camera_closed_path_returns_to_its_start():
    x = trefoil(400)
    cam = Q.camera_frames(np.vstack([x, x[:1]]), closed=True)
    np.testing.assert_allclose(cam[-1], cam[0], atol=1e-12)


def _relative_rotvec(cam_b, cam):
    """Rotation vectors of cam_b[i] · cam[i]ᵀ (world frame): the rotation taking each
    unbanked camera to the banked one."""
    return Rotation.from_matrix(np.einsum("nij,nkj->nik", cam_b, cam)).as_rotvec()


@pytest.mark.parametrize("mode", ["transport", "up"])
def test_camera_bank_is_a_roll_about_the_gaze_by_the_bank_angle(mode):
    """``bank`` rolls each camera about its own gaze and nothing else: the gaze is kept and
    the banked camera is the unbanked one turned about the gaze by |bank| (scipy's rotation
    vector of the relative rotation); a scalar is the same roll at every sample."""
    x, t, _ = helix(100)
    cam = Q.camera_frames(x, mode=mode, tangents=t)
    bank = np.linspace(-2.5, 2.5, len(x))
    bank[len(x) // 2] = 0.0
    cam_b = Q.camera_frames(x, mode=mode, tangents=t, bank=bank)
    np.testing.assert_allclose(np.linalg.det(cam_b), 1, atol=1e-12)
    np.testing.assert_allclose(np.einsum("nji,njk->nik", cam_b, cam_b), np.broadcast_to(
        np.eye(3), cam_b.shape), atol=1e-12)
    np.testing.assert_allclose(cam_b[:, :, 2], cam[:, :, 2], atol=1e-15)  # gaze kept
    rv = _relative_rotvec(cam_b, cam)
    gaze = -cam[:, :, 2]
    np.testing.assert_allclose(np.linalg.norm(rv, axis=1), np.abs(bank), atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(np.cross(rv, gaze), axis=1), 0, atol=1e-12)
    np.testing.assert_array_equal(cam_b[len(x) // 2], cam[len(x) // 2])
    # a scalar bank broadcasts; a full turn is the identity
    np.testing.assert_allclose(Q.camera_frames(x, mode=mode, tangents=t, bank=0.7),
                               Q.camera_frames(x, mode=mode, tangents=t,
                                               bank=np.full(len(x), 0.7)), atol=0)
    np.testing.assert_allclose(Q.camera_frames(x, mode=mode, tangents=t, bank=2 * np.pi),
                               cam, atol=1e-14)
    for bad in (np.zeros(3), np.full(len(x), np.nan), [[0.1]], "a"):
        with pytest.raises((ValueError, TypeError), match="^bank"):
            Q.camera_frames(x, mode=mode, tangents=t, bank=bad)


def test_camera_bank_sign_follows_the_docstring():
    """Independent expectation of the documented sign: a positive bank turns ``up`` towards
    ``right``, i.e. the camera turns right-handedly about its gaze (a pilot banking right):
    banked = R(b·gaze) · unbanked, with R from scipy. On a straight path along +x with up
    +z, right is −y, so a small positive bank tips up towards −y."""
    x = np.c_[np.linspace(0, 1, 5), np.zeros(5), np.zeros(5)]
    cam = Q.camera_frames(x)
    np.testing.assert_allclose(cam[0], [[0, 0, -1], [-1, 0, 0], [0, 1, 0]], atol=1e-15)
    b = 0.3
    cam_b = Q.camera_frames(x, bank=b)
    assert cam_b[0][:, 1] @ cam[0][:, 0] == pytest.approx(np.sin(b))  # up · old right
    h, t, _ = helix(100)
    bank = np.linspace(-1.0, 2.0, len(h))
    cam = Q.camera_frames(h, tangents=t)
    want = Rotation.from_rotvec(bank[:, None] * -cam[:, :, 2]).as_matrix() @ cam
    np.testing.assert_allclose(Q.camera_frames(h, tangents=t, bank=bank), want, atol=1e-12)


# --- walking on a mesh --------------------------------------------------------------------


def grid(n=6, fold=None):
    """A triangulated square [0, n]² in z = 0; `fold` bends the part x > n/2 up by an angle."""
    i, j = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0), indexing="ij")
    v = np.c_[i.ravel(), j.ravel(), np.zeros(i.size)]
    if fold is not None:
        h = n / 2
        m = v[:, 0] > h
        d = v[m, 0] - h
        v[m, 0] = h + d * np.cos(fold)
        v[m, 2] = d * np.sin(fold)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    f = np.concatenate([np.c_[a, b, c], np.c_[a, c, d]])
    return v, f


def locate(v, f, p):
    """Index of a face containing p (tests' meshes are small)."""
    for k, tri in enumerate(f):
        a, b, c = v[tri]
        n = np.cross(b - a, c - a)
        m = np.linalg.lstsq(np.c_[b - a, c - a, n], p - a, rcond=None)[0]
        if m[0] >= -1e-12 and m[1] >= -1e-12 and m[0] + m[1] <= 1 + 1e-12 and abs(m[2]) < 1e-9:
            return k
    raise AssertionError("point not on the mesh")


def test_walk_on_a_flat_mesh_is_a_straight_line():
    v, f = grid()
    p = np.array([0.6, 0.3, 0])
    res = Q.walk_mesh(v, f, locate(v, f, p), p, [[4.0, 1.0], [-1.0, 2.0]], direction=[1, 0, 0])
    np.testing.assert_allclose(res.points[1], [4.6, 1.3, 0], atol=1e-12)
    np.testing.assert_allclose(res.points[2], [3.6, 3.3, 0], atol=1e-12)
    np.testing.assert_allclose(res.frames, np.broadcast_to(np.eye(3), (3, 3, 3)), atol=1e-12)
    assert not res.stopped.any()
    assert len(res.path) > 4  # the crossings are reported


@pytest.mark.parametrize("fold", [0.3, 1.0, 2.0])
def test_walk_unfolds_a_fold(fold):
    v, f = grid(fold=fold)
    p = np.array([0.5, 2.2, 0])
    res = Q.walk_mesh(v, f, locate(v, f, p), p, [[4.0, 0.0]], direction=[1, 0, 0])
    # 2.5 along x to the fold line, then 1.5 along the folded half
    end = [3 + 1.5 * np.cos(fold), 2.2, 1.5 * np.sin(fold)]
    np.testing.assert_allclose(res.points[-1], end, atol=1e-12)
    e1, _, e3 = res.frames[-1].T
    np.testing.assert_allclose(e1, [np.cos(fold), 0, np.sin(fold)], atol=1e-12)
    np.testing.assert_allclose(e3, [-np.sin(fold), 0, np.cos(fold)], atol=1e-12)


def test_walk_around_a_cube_corner_turns_by_the_angle_deficit():
    """A loop round the corner (1, 1, 1) of the cube [−1, 1]³ over the faces x = 1 → z = 1 →
    y = 1 → x = 1 comes back to its start point with the frame turned about the face normal
    by the angle deficit π/2 (here −π/2 about +x: e₁ = +y becomes −z)."""
    import trimesh

    box = trimesh.creation.box(extents=[2, 2, 2])
    v, f = np.asarray(box.vertices), np.asarray(box.faces)
    p = np.array([1.0, 0.8, 0.8])
    start = None
    for k in np.flatnonzero(box.face_normals[:, 0] > 0.5):
        a, b, c = v[f[k]]
        m = np.linalg.solve(np.c_[b - a, c - a, [1.0, 0, 0]], p - a)
        if m[0] >= 0 and m[1] >= 0 and m[0] + m[1] <= 1:
            start = int(k)
    res = Q.walk_mesh(v, f, start, p, [[0, 0.4], [0.4, 0], [0, -0.4]], direction=[0, 1, 0])
    np.testing.assert_allclose(res.frames[0], np.eye(3)[:, [1, 2, 0]], atol=1e-15)
    np.testing.assert_allclose(res.points[1], [0.8, 0.8, 1], atol=1e-12)
    np.testing.assert_allclose(res.points[2], [0.8, 1, 0.8], atol=1e-12)
    np.testing.assert_allclose(res.points[3], p, atol=1e-12)
    np.testing.assert_allclose(res.frames[3], np.c_[[0, 0, -1], [0, 1, 0], [1, 0, 0]],
                               atol=1e-12)


def test_walk_stops_at_the_boundary_and_bad_input():
    v, f = grid()
    res = Q.walk_mesh(v, f, 0, [0.5, 0.2, 0], [[100.0, 0.0]], direction=[1, 0, 0])
    assert res.stopped[0]
    np.testing.assert_allclose(res.points[-1], [6, 0.2, 0], atol=1e-12)
    with pytest.raises(ValueError, match="point: is not on face 0"):
        Q.walk_mesh(v, f, 0, [3.0, 3.0, 0], [[1.0, 0]])
    with pytest.raises(ValueError, match="faces: face 1 refers to vertex"):
        Q.walk_mesh(v, np.r_[f[:1], [[0, 1, 999]]], 0, [0.5, 0.2, 0], [[1.0, 0]])
    with pytest.raises(ValueError, match="degenerate"):
        Q.walk_mesh(v, np.r_[f[:1], [[0, 0, 1]]], 0, [0.5, 0.2, 0], [[1.0, 0]])
    with pytest.raises(ValueError, match="manifold"):  # a third face on an inner edge
        extra = np.r_[v, [[0.5, 0.5, 1.0]]]
        Q.walk_mesh(extra, np.r_[f, [[f[0, 0], f[0, 2], len(v)]]], 0, [0.5, 0.2, 0],
                    [[1.0, 0]])
    with pytest.raises(ValueError, match="moves"):
        Q.walk_mesh(v, f, 0, [0.5, 0.2, 0], [[np.nan, 0]])
    with pytest.raises(ValueError, match="face"):
        Q.walk_mesh(v, f, 10_000, [0.5, 0.2, 0], [[1.0, 0]])


def test_walk_long_moves_on_a_closed_mesh():
    """A long move round a closed surface crosses many edges (no false 'malformed' error);
    an absurdly long one is refused instead of overflowing to NaN."""
    import trimesh

    torus = trimesh.creation.torus(major_radius=2, minor_radius=0.7, major_sections=32,
                                   minor_sections=16)
    p = torus.vertices[torus.faces[5]].mean(axis=0)
    res = Q.walk_mesh(torus.vertices, torus.faces, 5, p, [[60.0, 7.0]])
    assert np.isfinite(res.points).all() and np.isfinite(res.frames).all()
    assert len(res.path) > 200 and not res.stopped.any()
    # every point of the path lies on the surface: on the torus within the mesh error
    R = np.hypot(res.path[:, 0], res.path[:, 1])
    assert np.abs(np.hypot(R - 2, res.path[:, 2]) - 0.7).max() < 0.05
    with pytest.raises(ValueError, match="moves: a move of length"):
        Q.walk_mesh(torus.vertices, torus.faces, 5, p, [[1e300, 0.0]])


def _split_edge_near_a_corner(v, f, eps):
    """The mesh with the edge of face 0 from corner 0 to corner 1 split at ``eps`` of its
    length from corner 0, in both faces that share it: the same surface, one edge tiny."""
    a, b = f[0, 0], f[0, 1]
    v = np.vstack([v, v[a] + eps * (v[b] - v[a])])
    n = len(v) - 1
    out = []
    for tri in f.tolist():
        for k in range(3):
            x, y, z = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
            if {x, y} == {a, b}:
                out += [[x, n, z], [n, y, z]]
                break
        else:
            out.append(tri)
    return v, np.array(out)


@pytest.mark.parametrize("eps", [1e-3, 1e-6, 1e-9])
def test_walk_on_a_mesh_with_one_tiny_edge_is_the_walk_on_the_mesh_without_it(eps):
    """Splitting an edge leaves the surface as it was, so the walk must end where it ends on
    the unsplit mesh; a near-degenerate edge (as scanned meshes have) must not make ordinary
    moves look too long (a shortest-edge estimate refused a 0.5 move on the unit sphere)."""
    import trimesh

    s = trimesh.creation.icosphere(3)
    v, f = _split_edge_near_a_corner(s.vertices, s.faces, eps)
    t = trimesh.Trimesh(v, f, process=False)
    assert t.is_watertight and t.edges_unique_length.min() < 2 * eps
    start = s.vertices[s.faces[0]].mean(axis=0)
    moves = [[0.5, 0.0], [3.0, 1.0], [40.0, -7.0]]
    ref = Q.walk_mesh(s.vertices, s.faces, 0, start, moves)
    # face 0 of the split mesh is the old face 1; the start lies in the old face 0's part
    # on the side of corner 2 (its half [n, b, c] when split near corner 0)
    f0 = next(i for i, tri in enumerate(f) if set(tri) == {len(v) - 1, s.faces[0, 1], s.faces[0, 2]})
    res = Q.walk_mesh(v, f, f0, start, moves, direction=s.vertices[s.faces[0, 1]] - s.vertices[s.faces[0, 0]])
    assert np.abs(res.points - ref.points).max() < 1e-8
    assert np.abs(res.frames - ref.frames).max() < 1e-8
    assert len(res.path) >= len(ref.path)


def test_walk_moves_too_long_for_the_mesh_are_refused_by_name():
    """A move that would cross about 10⁹ edges (its length over the median edge) is refused
    before it is walked, by walk_mesh and, naming the walker, by walk_mesh_many."""
    import trimesh

    b = trimesh.creation.box()
    p = b.vertices[b.faces[0]].mean(axis=0)
    with pytest.raises(ValueError, match=r"^moves: a move of length 1\.000e9 would cross about"):
        Q.walk_mesh(b.vertices, b.faces, 0, p, [[1e9, 0.1]])
    with pytest.raises(ValueError, match=r"^moves: walker 1: a move of length 1\.000e9"):
        Q.walk_mesh_many(b.vertices, b.faces, np.zeros(2, int), np.repeat(p[None], 2, 0),
                         [[[0.1, 0.0], [0.2, 0.0]], [[0.1, 0.0], [1e9, 0.1]]])


def test_many_walkers_equal_one_walker_at_a_time():
    """walk_mesh_many is walk_mesh per walker (same states bit for bit), with shared or
    per-walker moves and directions; bad input names the walker or the argument."""
    import trimesh

    torus = trimesh.creation.torus(major_radius=2, minor_radius=0.7, major_sections=24,
                                   minor_sections=12)
    V, F = torus.vertices, torus.faces
    rng = np.random.default_rng(3)
    w, k = 40, 7
    fc = rng.integers(0, len(F), w)
    bary = rng.dirichlet([2, 2, 2], w)
    pts = np.einsum("wj,wjk->wk", bary, V[F[fc]])
    moves = rng.normal(scale=0.8, size=(w, k, 2))
    dirs = rng.normal(size=(w, 3))
    res = Q.walk_mesh_many(V, F, fc, pts, moves, directions=dirs)
    assert res.points.shape == (w, k + 1, 3) and res.frames.shape == (w, k + 1, 3, 3)
    assert res.faces.shape == (w, k + 1) and res.stopped.shape == (w, k)
    for i in range(w):
        one = Q.walk_mesh(V, F, int(fc[i]), pts[i], moves[i], direction=dirs[i])
        np.testing.assert_array_equal(res.points[i], one.points)
        np.testing.assert_array_equal(res.frames[i], one.frames)
        np.testing.assert_array_equal(res.faces[i], one.faces)
        np.testing.assert_array_equal(res.stopped[i], one.stopped)
    shared = Q.walk_mesh_many(V, F, fc, pts, moves[0], directions=dirs[0])
    one = Q.walk_mesh(V, F, int(fc[5]), pts[5], moves[0], direction=dirs[0])
    np.testing.assert_array_equal(shared.points[5], one.points)
    bad = fc.copy()
    bad[9] = len(F) + 3
    with pytest.raises(ValueError, match="walker 9"):
        Q.walk_mesh_many(V, F, bad, pts, moves)
    with pytest.raises(ValueError, match="^points"):
        Q.walk_mesh_many(V, F, fc, pts[:-1], moves)
    with pytest.raises(ValueError, match="^moves"):
        Q.walk_mesh_many(V, F, fc, pts, moves[:-1])
    nan = moves.copy()
    nan[3, 2, 0] = np.nan
    with pytest.raises(ValueError, match="walker 3"):
        Q.walk_mesh_many(V, F, fc, pts, nan)


def test_quaternion_and_camera_frames_merge_repeated_samples():
    """A repeated sample (a pause in a GPS track) gets the quaternion / camera of the row it
    repeats; the others are those of the track without it (per-row bank cut alike)."""
    u = np.linspace(0, 6, 60)
    x = np.c_[np.cos(u), np.sin(u), 0.1 * u]
    d = np.insert(x, 20, x[19], axis=0)
    rows = np.r_[np.arange(20), 19, np.arange(20, 60)]
    np.testing.assert_array_equal(Q.quaternion_frames(d), Q.quaternion_frames(x)[rows])
    np.testing.assert_array_equal(Q.camera_frames(d), Q.camera_frames(x)[rows])
    bank = np.arange(61.0) * 0.01
    np.testing.assert_array_equal(Q.camera_frames(d, mode="up", bank=bank),
                                  Q.camera_frames(x, mode="up", bank=np.delete(bank, 20))[rows])
    with pytest.raises(ValueError, match="points: an open curve needs at least 2 distinct"):
        Q.quaternion_frames(np.zeros((4, 3)))
