"""Spine surfaces with the offset directions given (posed_frames / posed_up).

Independent references: the default map (the binding's own normals passed back), the
rigidly moved mesh itself (x ↦ Rx + c), the closed form of a plane sheared along a constant
direction (the offset laid along it, its length h0·A0/A1 with A = (S_u × S_v)·D), and the
map's Jacobian determinant by central differences.
"""

import numpy as np
import pytest

import spinal


def plane_grid(n=21, size=2.0):
    x = np.linspace(-size / 2, size / 2, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    return np.stack([X, Y, np.zeros_like(X)], axis=-1)


def curved(g):
    X, Y = g[..., 0], g[..., 1]
    return np.stack([1.1 * X, 0.9 * Y + 0.1 * X, 0.25 * X**2 - 0.15 * Y**2 + 0.1 * X * Y],
                    axis=-1)


def _rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def _roll_about_normal(frames, angle):
    """The frames turned about their third column by ``angle`` (per sample)."""
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    out = frames.copy()
    out[..., 0] = c * frames[..., 0] + s * frames[..., 1]
    out[..., 1] = c * frames[..., 1] - s * frames[..., 0]
    return out


def _points(rng, k=300, h=0.3):
    return np.c_[rng.uniform(-0.8, 0.8, (k, 2)), rng.uniform(-h, h, k)]


def test_own_frames_reproduce_the_default():
    rng = np.random.default_rng(1)
    rest = plane_grid()
    posed = curved(rest)
    V = _points(rng)
    b = spinal.SurfaceBinding(V, rest)
    frames = spinal.SurfaceBinding(V[:1], posed).rest_frames
    assert frames.shape == (21, 21, 3, 3)
    assert np.abs(np.swapaxes(frames, -1, -2) @ frames - np.eye(3)).max() < 1e-14
    for sol in ("offset", "none"):
        ref = b.deform(posed, solution=sol)
        assert np.abs(b.deform(posed, solution=sol, posed_frames=frames) - ref).max() < 1e-12
        # only the normal column is used
        rolled = _roll_about_normal(frames, rng.uniform(-np.pi, np.pi, (21, 21)))
        assert np.abs(b.deform(posed, solution=sol, posed_frames=rolled) - ref).max() < 1e-12
        assert np.abs(b.deform(posed, solution=sol, posed_up=frames[..., 2]) - ref).max() < 1e-12
        # directions need not be unit
        assert np.abs(b.deform(posed, solution=sol, posed_up=3 * frames[..., 2]) - ref).max() \
            < 1e-12


def test_rigid_motion_with_rotated_frames():
    rng = np.random.default_rng(2)
    rest = curved(plane_grid())
    V = _points(rng)
    V[:, 2] += 0.25 * V[:, 0] ** 2  # around the curved surface
    b = spinal.SurfaceBinding(V, rest)
    R, c = _rotation(rng), np.array([1.0, -2.0, 0.5])
    posed = rest @ R.T + c
    for frames in (b.rest_frames,
                   _roll_about_normal(b.rest_frames, rng.uniform(-3, 3, rest.shape[:2]))):
        for sol in ("offset", "none"):
            out = b.deform(posed, solution=sol, posed_frames=R @ frames)
            assert np.abs(out - (V @ R.T + c)).max() < 1e-9
            out = b.deform(posed, solution=sol, posed_up=frames[..., 2] @ R.T)
            assert np.abs(out - (V @ R.T + c)).max() < 1e-9


@pytest.mark.parametrize("d", [[0.0, 0.0, 1.0], [0.3, -0.2, 1.0]])
def test_plane_sheared_along_a_constant_up(d):
    """A plane sheared along ``d`` (``S1 = S0 + f d``, ``f`` linear): every point moves along
    ``d``; ``"none"`` keeps ``h``, ``"offset"`` lays ``h0/d_z`` (``A1 = (S_u × S_v)·d``
    is ``d_z`` times the rest cell's area), so a vertical ``d`` keeps the skin's thickness
    and the volume."""
    rng = np.random.default_rng(3)
    d = np.asarray(d) / np.linalg.norm(d)
    rest = plane_grid()
    f = lambda x, y: 0.4 * x - 0.7 * y + 0.2
    posed = rest + f(rest[..., 0], rest[..., 1])[..., None] * d
    V = _points(rng)
    b = spinal.SurfaceBinding(V, rest)
    foot = np.c_[V[:, :2], np.zeros(len(V))]
    shift = f(V[:, 0], V[:, 1])
    for up in (d, np.broadcast_to(d, posed.shape)):
        out = b.deform(posed, solution="none", posed_up=up)
        assert np.abs(out - (foot + (shift + V[:, 2])[:, None] * d)).max() < 1e-12
        out = b.deform(posed, solution="offset", posed_up=up)
        assert np.abs(out - (foot + (shift + V[:, 2] / d[2])[:, None] * d)).max() < 1e-12
    # the surface normal instead tilts the skin when the plane tilts
    assert np.abs(b.deform(posed) - (foot + (shift + V[:, 2] / d[2])[:, None] * d)).max() > 0.01


def test_given_directions_keep_the_volume():
    """A smoothly varying tilt of the offsets on a curved, stretched pose: the corrected map's
    Jacobian determinant is 1 (the volume element holds for any transverse unit field)."""
    rng = np.random.default_rng(6)
    rest = plane_grid(31)
    posed = curved(rest)
    frames = spinal.SurfaceBinding([[0.0, 0, 0]], posed).rest_frames
    X, Y = rest[..., 0], rest[..., 1]
    up = frames[..., 2] + 0.3 * np.sin(X + 2 * Y)[..., None] * frames[..., 0] \
        + 0.2 * (X * Y)[..., None] * frames[..., 1]
    pts = _points(rng, 200)
    eps = 1e-5
    probes = [pts] + [pts + s * eps * e for e in np.eye(3) for s in (1, -1)]
    b = spinal.SurfaceBinding(np.concatenate(probes), rest)
    cells = b.uv.astype(int).reshape(7, -1, 2)
    same = (cells == cells[0]).all(axis=(0, 2))
    for sol, expect in (("offset", True), ("none", False)):
        out = b.deform(posed, solution=sol, posed_up=up).reshape(7, -1, 3)
        J = np.stack([(out[1 + 2 * k] - out[2 + 2 * k]) / (2 * eps) for k in range(3)], -1)
        det = np.linalg.det(J)[same]
        assert same.sum() > 150
        if expect:
            assert np.abs(det - 1).max() < 1e-6
        else:
            assert np.abs(det - 1).max() > 0.05


def test_bad_directions_are_named():
    rest = plane_grid(11)
    V = [[0.0, 0.0, 0.1]]
    b = spinal.SurfaceBinding(V, rest)
    frames = b.rest_frames
    with pytest.raises(TypeError, match="posed_frames, posed_up"):
        b.deform(rest, posed_frames=frames, posed_up=[0, 0, 1])
    with pytest.raises(ValueError, match=r"^posed_frames: expected shape \(11, 11, 3, 3\)"):
        b.deform(rest, posed_frames=frames[:-1])
    with pytest.raises(ValueError, match=r"^posed_frames: expected shape"):
        b.deform(rest, posed_frames=frames[0, 0])
    bad = frames.copy()
    bad[2, 3] *= 1.1
    with pytest.raises(ValueError, match=r"^posed_frames: grid point \(2, 3\) is not a rotation"):
        b.deform(rest, posed_frames=bad)
    bad = frames.copy()
    bad[4, 5] = bad[4, 5] @ np.diag([1.0, 1.0, -1.0])  # a reflection: det −1
    with pytest.raises(ValueError, match=r"^posed_frames: grid point \(4, 5\) is not a rotation"):
        b.deform(rest, posed_frames=bad)
    bad = frames.copy()
    bad[1, 2] = bad[1, 2][:, [2, 0, 1]]  # a rotation whose normal column lies in the plane
    with pytest.raises(ValueError, match=r"^posed_frames: grid point \(1, 2\).*parallel to the "
                                         r"surface"):
        b.deform(rest, posed_frames=bad)
    with pytest.raises(ValueError, match=r"^posed_frames: grid point \(0, 0\).*other side"):
        b.deform(rest, posed_frames=frames @ np.diag([1.0, -1.0, -1.0]))
    with pytest.raises(ValueError, match=r"^posed_up: expected shape \(3,\) or \(11, 11, 3\)"):
        b.deform(rest, posed_up=[0, 1])
    with pytest.raises(ValueError, match="^posed_up: grid point .*parallel to the surface"):
        b.deform(rest, posed_up=[1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="^posed_up: grid point .*other side"):
        b.deform(rest, posed_up=[0.0, 0.0, -1.0])
    up = np.broadcast_to([0.0, 0, 1], (11, 11, 3)).copy()
    up[3, 4] = 0
    with pytest.raises(ValueError, match=r"^posed_up: grid point \(3, 4\): not a finite non-zero"):
        b.deform(rest, posed_up=up)
    up[3, 4] = np.nan
    with pytest.raises(ValueError, match=r"^posed_up: grid point \(3, 4\): not a finite non-zero"):
        b.deform(rest, posed_up=up)
    with pytest.raises(ValueError, match="^posed_up:"):
        spinal.flesh_surface(V, rest, rest, posed_up=[[0.0, 0.0, 1.0]])
