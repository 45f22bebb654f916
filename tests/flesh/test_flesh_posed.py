"""Fleshing with the posed spine's roll given (posed_frames / posed_up) and on closed spines.

Independent references: the rigidly moved mesh itself (x ↦ Rx + c), the rotation by θ
about a straight spine, the twist= argument (a roll of the frames is a twist of the
sections), and trimesh volumes of closed meshes.
"""

import numpy as np
import pytest
import trimesh

import spinal

SOLS = ("radial", "normal", "binormal", "none")


def _rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def _about(axis, theta):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(theta) * k + (1 - np.cos(theta)) * k @ k


def straight(n, length=2.0):
    x = np.linspace(-length / 2, length / 2, n)
    return np.c_[x, np.zeros(n), np.zeros(n)]


def curve3(n):
    u = np.linspace(-1, 1, n)
    return np.c_[u, 0.3 * np.sin(1.5 * u) + 0.2 * u**2, 0.25 * np.cos(2 * u) - 0.1 * u]


def _tube_mesh(spine, radius, sides=12, closed=False):
    m = spinal.tube(spine, radius, sides, closed=closed)
    return m.vertices, m.faces


@pytest.mark.parametrize("solution", SOLS)
def test_rigid_motions_move_the_shape_rigidly(solution):
    rng = np.random.default_rng(7)
    for sp in (straight(40), curve3(60)):
        V, _ = _tube_mesh(sp, 0.15)
        V = V + rng.normal(size=V.shape) * 0.02
        b = spinal.SpineBinding(V, sp)
        F = b.rest_frames
        for _ in range(4):
            R, c = _rotation(rng), rng.normal(size=3) * 3
            moved = V @ R.T + c
            posed = sp @ R.T + c
            for stretchable in (False, True):
                kw = {"solution": solution, "stretchable": stretchable}
                out = b.deform(posed, posed_frames=R @ F, **kw)
                assert np.abs(out - moved).max() < 1e-9
                # the first frame alone (the RMF started from it), and up vectors
                assert np.abs(b.deform(posed, posed_frames=R @ F[0], **kw) - moved).max() < 1e-9
                assert np.abs(b.deform(posed, posed_up=F[:, :, 0] @ R.T, **kw) - moved).max() < 1e-9
            # the one-shot form
            out = spinal.flesh(V, sp, posed, solution=solution, posed_frames=R @ F)
            assert np.abs(out - moved).max() < 1e-9


def test_straight_spine_default_roll_is_not_the_rigid_motion_but_the_given_one_is():
    # the default (best-fit) roll cannot see a turn about a straight spine's axis
    rng = np.random.default_rng(2)
    sp = straight(30)
    V = rng.normal(size=(200, 3)) * 0.2
    R = _about([1, 0, 0], 0.8) @ _about([0, 0, 1], 0.3)
    posed = sp @ R.T
    default = spinal.flesh(V, sp, posed)
    assert np.abs(default - V @ R.T).max() > 0.05
    F = spinal.SpineBinding(V, sp).rest_frames
    assert np.abs(spinal.flesh(V, sp, posed, posed_frames=R @ F) - V @ R.T).max() < 1e-9


@pytest.mark.parametrize("theta", [0.3, -1.1, 2.5, np.pi])
def test_a_rig_rolls_the_shape_about_a_straight_spine(theta):
    rng = np.random.default_rng(3)
    sp = straight(25) + [0.0, 0.4, -0.2]
    V = sp[rng.integers(0, 25, 300)] + rng.normal(size=(300, 3)) * 0.15
    b = spinal.SpineBinding(V, sp)
    Q = _about([1, 0, 0], theta)
    centre = np.array([0.0, 0.4, -0.2])
    expect = (V - centre) @ Q.T + centre
    for sol in SOLS:
        out = b.deform(sp, posed_frames=Q @ b.rest_frames, solution=sol)
        assert np.abs(out - expect).max() < 1e-9
        # a single up vector (a level horizon) drives the same roll
        out = b.deform(sp, posed_up=Q @ b.rest_frames[0][:, 0], solution=sol)
        assert np.abs(out - expect).max() < 1e-9


def test_a_roll_of_the_frames_is_a_twist_of_the_sections():
    rng = np.random.default_rng(4)
    sp = curve3(50)
    V = sp[rng.integers(0, 50, 300)] + rng.normal(size=(300, 3)) * 0.08
    b = spinal.SpineBinding(V, sp)
    posed = curve3(50) * [1.0, 1.3, 0.7]
    F = spinal.frames(posed)
    phi = np.linspace(0.0, 1.2, 50)  # a roll that varies along the spine
    c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
    rolled = F.copy()
    rolled[:, :, 0] = c * F[:, :, 0] + s * F[:, :, 1]
    rolled[:, :, 1] = c * F[:, :, 1] - s * F[:, :, 0]
    at_samples = (b.param == 0.0) | (b.param == 1.0)
    assert at_samples.sum() > 0
    # (radial and none treat the section isotropically; normal and binormal stretch along
    # the frame's axes where λ ≠ 1, so there a roll is not a twist)
    for sol in ("radial", "none"):
        a = b.deform(posed, posed_frames=rolled, stretchable=True, solution=sol)
        ref = b.deform(posed, posed_frames=F, stretchable=True, twist=phi, solution=sol)
        # the given r are blended linearly between samples, the twist angle is: O(Δφ³)
        assert np.abs(a - ref).max() < 1e-6
        assert np.abs(a[at_samples] - ref[at_samples]).max() < 1e-12


def _torus(R=1.0, r=0.3, sections=64):
    m = trimesh.creation.torus(major_radius=R, minor_radius=r, major_sections=sections,
                               minor_sections=3 * sections // 8)
    assert m.is_watertight and m.volume > 0
    return m


def _circle(n, R=1.0, z=0.0):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[R * np.cos(a), R * np.sin(a), np.full(n, z)]


def test_ring_on_a_closed_spine_moves_rigidly():
    rng = np.random.default_rng(5)
    ring = _torus()
    V = ring.vertices
    sp = _circle(48)
    b = spinal.SpineBinding(V, sp, closed=True)
    assert b.edge.max() == 47 and (b.edge == 47).any()  # the closing edge holds sections
    assert np.abs(b.deform(sp) - V).max() < 1e-12  # identity, whatever the seam
    assert np.abs(b.deform(np.r_[sp, sp[:1]]) - V).max() < 1e-12  # a repeated first point
    for _ in range(3):
        R, c = _rotation(rng), rng.normal(size=3)
        for sol in SOLS:
            for kw in ({}, {"posed_frames": R @ b.rest_frames}, {"stretchable": True}):
                out = b.deform(sp @ R.T + c, solution=sol, **kw)
                assert np.abs(out - (V @ R.T + c)).max() < 1e-9, (sol, kw)


@pytest.mark.parametrize("scale", [1.25, 1.5])
def test_ring_on_a_scaled_closed_spine_keeps_its_volume(scale):
    sp = _circle(96)
    errs = []
    for sections in (64, 128):
        ring = _torus(sections=sections)
        e = {}
        for sol in SOLS:
            out = spinal.flesh(ring.vertices, sp, scale * sp, closed=True, solution=sol)
            posed = trimesh.Trimesh(out, ring.faces, process=False)
            assert posed.is_watertight
            e[sol] = posed.volume / ring.volume - 1
        errs.append(e)
    # the uncorrected map changes the volume with the length of the ring, the flesh keeps it
    # up to the mesh's flat faces (O(h²): 4× smaller per halving)
    assert abs(errs[0]["none"] - (scale - 1)) < 1e-3
    for sol in ("radial", "normal", "binormal"):
        assert abs(errs[0][sol]) < 1.5e-4, errs
        assert abs(errs[0][sol]) > 3.5 * abs(errs[1][sol]), errs
    # the closed loop is continuous across its seam: the same ring bound with its seam
    # elsewhere poses to the same shape
    ring = _torus()
    shifted = np.roll(sp, 31, axis=0)
    a = spinal.flesh(ring.vertices, sp, scale * sp, closed=True)
    b = spinal.flesh(ring.vertices, shifted, scale * shifted, closed=True)
    assert np.abs(a - b).max() < 1e-9


def test_tentacle_loop_bends_with_its_closed_spine():
    # a 3D loop posed into another loop with the same sample count (stretchable), rigidly
    # moved with a given roll, then bent: no NaN, the seam stays closed
    u = np.linspace(0, 2 * np.pi, 80, endpoint=False)
    loop = np.c_[np.cos(u), np.sin(u), 0.3 * np.sin(2 * u)]
    bent = np.c_[1.2 * np.cos(u), 0.8 * np.sin(u), 0.2 * np.sin(3 * u)]
    mesh = trimesh.Trimesh(*_tube_mesh(loop, 0.12, 10, closed=True), process=False)
    assert mesh.is_watertight
    out = spinal.flesh(mesh.vertices, loop, bent, closed=True, stretchable=True)
    posed = trimesh.Trimesh(out, mesh.faces, process=False)
    assert np.isfinite(out).all() and posed.is_watertight
    err = posed.volume / mesh.volume - 1
    plain = spinal.flesh(mesh.vertices, loop, bent, closed=True, stretchable=True,
                         solution="none")
    err_none = trimesh.Trimesh(plain, mesh.faces, process=False).volume / mesh.volume - 1
    assert abs(err) < 3e-4 and abs(err_none) > 20 * abs(err), (err, err_none)


def test_bad_posed_roll_inputs_are_named():
    sp = curve3(30)
    V = sp[::3] + 0.05
    b = spinal.SpineBinding(V, sp)
    F = b.rest_frames
    with pytest.raises(ValueError, match=r"posed_frames: expected shape \(3, 3\) or \(30, 3, 3\)"):
        b.deform(sp, posed_frames=F[:-1])
    bad = F.copy()
    bad[7] *= 2
    with pytest.raises(ValueError, match="posed_frames: row 7 is not a rotation"):
        b.deform(sp, posed_frames=bad)
    with pytest.raises(ValueError, match="posed_frames: row 0 is not a rotation"):
        b.deform(sp, posed_frames=-F)  # det −1
    with pytest.raises(ValueError, match=r"posed_frames: row \d+: its t column is"):
        b.deform(sp, posed_frames=np.swapaxes(F, 1, 2))  # rows for columns
    with pytest.raises(ValueError, match="posed_frames: the roll turns by 120° or more"):
        flip = F.copy()
        flip[10:, :, :2] *= -1  # a half turn between samples 9 and 10
        b.deform(sp, posed_frames=flip)
    with pytest.raises(ValueError, match=r"posed_up: expected shape \(3,\) or \(30, 3\)"):
        b.deform(sp, posed_up=np.ones((3, 3)))
    with pytest.raises(ValueError, match="posed_up: row 4 is not a finite non-zero vector"):
        up = F[:, :, 0].copy()
        up[4] = 0
        b.deform(sp, posed_up=up)
    with pytest.raises(ValueError, match=r"posed_up: row 0: the reference vector is parallel"):
        b.deform(sp, posed_up=F[:, :, 2])
    with pytest.raises(TypeError, match="posed_frames, posed_up: pass one of them"):
        b.deform(sp, posed_frames=F, posed_up=[0, 0, 1])
    with pytest.raises(TypeError, match="posed_frames: not used in the plane"):
        spinal.flesh(V[:, :2], sp[:, :2], sp[:, :2], posed_frames=F)
    with pytest.raises(TypeError, match="posed_frames: expected an array of real numbers"):
        b.deform(sp, posed_frames="x")
    with pytest.raises(ValueError, match="rest_spine: a closed spine needs at least 3"):
        spinal.SpineBinding(V, sp[:2], closed=True)
    with pytest.raises(TypeError, match="closed: expected True or False"):
        spinal.SpineBinding(V, sp, closed=1)


def test_posed_up_is_a_direction_whatever_its_length():
    """T3-14: posed_up of length 1e300 or 1e-300 poses the flesh as the unit vector does
    (it was refused as "parallel to the tangent" or "not a finite non-zero vector")."""
    rest = np.c_[np.linspace(-1, 1, 41), np.zeros(41), np.zeros(41)]
    u = np.linspace(-1, 1, 41)
    posed = np.c_[np.sin(u), 1 - np.cos(u), np.zeros(41)]
    b = spinal.SpineBinding([[0, 0.1, 0.05], [0.3, -0.05, 0.02]], rest)
    ref = b.deform(posed, posed_up=[0, 0, 1.0])
    for s in (1e300, 1e-300, 7.0):
        np.testing.assert_array_equal(b.deform(posed, posed_up=[0, 0, s]), ref)
