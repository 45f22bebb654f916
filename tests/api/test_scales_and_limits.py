"""Results at any scale and arguments at their limits: frames of tiny and huge curves are
those of the unit curve, quaternions of any size normalise, PH fits and fleshing stay
finite or raise named errors, and every message names its argument (row ids of the
robustness review in the docstrings)."""

import warnings

import numpy as np
import pytest
import trimesh

import spinal
from spinal import fields as fl
from spinal import ph
from spinal import quaternions as Q

u = np.linspace(0, 4 * np.pi, 60)
H = np.c_[np.cos(u), np.sin(u), 0.2 * u]
K = spinal.curves.TorusKnot().sample(80)
SQ = 0.1 * np.array([[1, 1], [-1, 1], [-1, -1], [1, -1.0]])
REST = np.c_[np.linspace(-1, 1, 41), np.zeros(41), np.zeros(41)]
_v = np.linspace(-1, 1, 41)
POSED = np.c_[np.sin(_v), 1 - np.cos(_v), np.zeros(41)]


def test_tiny_curves_with_tangents_give_the_frames_of_the_unit_curve():
    """D01: a curve scaled down to 1e-160 with its tangents gets the unit curve's frames."""
    t = spinal.estimate_tangents(H)
    for method in ("double_reflection", "frenet", "rotation", "projection"):
        f = spinal.frames(H * 1e-160, t, method=method)
        assert not np.isnan(f).any(), method
        np.testing.assert_allclose(f, spinal.frames(H, t, method=method), atol=1e-12)
    tk = spinal.estimate_tangents(K, closed=True)
    for s in (1e-153, 1e-160):
        a = spinal.closing_angle(K * s, tk)
        assert a == pytest.approx(spinal.closing_angle(K, tk), abs=1e-12)


def test_huge_and_tiny_curves_are_not_cusps():
    """D02: very large and very small curves are not taken for cusps."""
    ref = spinal.frames(H)
    for s in (1e80, 1e-80, 1e-100, 1e150, 1e-150):
        np.testing.assert_allclose(spinal.frames(H * s), ref, atol=1e-12)
        np.testing.assert_allclose(spinal.estimate_tangents(H * s), spinal.estimate_tangents(H),
                                   atol=1e-12)
    t = spinal.estimate_tangents(H)
    np.testing.assert_allclose(spinal.frames(H * 1e160, t), spinal.frames(H, t), atol=1e-12)
    for s in (1e80, 1e-100):
        v = spinal.tube(H * s, 0.1 * s).vertices / s
        np.testing.assert_allclose(v, spinal.tube(H, 0.1).vertices, atol=1e-12)
        np.testing.assert_allclose(Q.camera_frames(H * s), Q.camera_frames(H), atol=1e-12)
        np.testing.assert_allclose(Q.quaternion_frames(H * s), Q.quaternion_frames(H), atol=1e-12)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            got = spinal.flesh(np.array([[0, 0.3, 0]]) * s, REST * s, POSED * s) / s
            want = spinal.flesh([[0, 0.3, 0]], REST, POSED)
        np.testing.assert_allclose(got, want, atol=1e-12)


def test_default_reference_vector_is_scale_invariant():
    """D03: the default reference vector does not depend on the curve's scale."""
    assert np.abs(spinal.frames(H * 1e70) - spinal.frames(H)).max() < 1e-12
    t = spinal.estimate_tangents(H)
    for s in (1e100, 1e-100):
        assert np.abs(spinal.frames(H * s, t) - spinal.frames(H, t)).max() < 1e-12
    # a small helix far from the origin against the same (rounded) curve at the origin
    x = 0.01 * H + 1e9
    spin = Q.spin(spinal.frames(x), spinal.frames(x - 1e9))
    assert np.abs(spin).max() < 1e-4  # the rounding of x at 1e9, not a half turn


def test_from_quaternions_normalises_any_size():
    """D04: frames from quaternions of any size are normalised."""
    q = np.array([0.1, 0.2, 0.3, 0.9])
    want = Q.from_quaternions(q)
    assert not np.allclose(want, np.eye(3))
    for s in (1e155, 1e300, 1e-150, 1e-300, 1e-320):
        np.testing.assert_allclose(Q.from_quaternions(q / np.linalg.norm(q) * s), want,
                                   atol=1e-14 if s > 1e-310 else 1e-3)
    with pytest.raises(ValueError, match="quaternions: row 0 is zero"):
        Q.from_quaternions([0.0, 0, 0, 0])


def test_quaternion_length_of_scaled_quaternions():
    """D05: quaternion lengths of very large and very small quaternions."""
    q = np.array([[0.1, 0.2, 0.3, 0.9], [0, 0, 0, 1.0]])
    want = Q.quaternion_length(q)
    assert want == pytest.approx(0.394, abs=1e-3)
    for s in (1e300, 1e-300, 2.0):
        assert Q.quaternion_length(q * s) == pytest.approx(want, rel=1e-14)


def test_spin_checks_its_frames():
    """D06: spin checks the frames it is given."""
    f = spinal.frames(H)
    with pytest.raises(ValueError, match="^a: non-finite value in frame 0"):
        Q.spin(np.full((3, 3), np.nan), np.eye(3))
    for bad in (np.full((3, 3), np.inf), np.zeros((3, 3)), 2 * np.eye(3), np.diag([1, 1, -1.0])):
        with pytest.raises(ValueError, match="^b: "):
            Q.spin(np.eye(3), bad)
    with pytest.raises(ValueError, match="^b: has 4 frames but a has 3"):
        Q.spin(f[:3], f[:4])
    with pytest.raises(ValueError, match="^b: the tangent of frame 0"):
        Q.spin(f[0], f[10])
    # valid input: unchanged results
    assert abs(Q.spin(f[0], f[0])) < 1e-15
    assert Q.spin(f, f).shape == (60,)


def test_ph_from_quaternions_overflow_is_a_named_error():
    """D07: PH cubics from quaternions that overflow raise an error naming the argument."""
    with pytest.raises(ValueError, match="out of the representable range"):
        ph.from_quaternions([0, 0, 0, 1e300], [0, 0, 1e300, 0])
    # large but representable: the same curve scaled by |A|²
    b = ph.from_quaternions([0.1, 0.2, 0.3, 0.9], [0.4, -0.2, 0.1, 0.8])
    big = ph.from_quaternions(np.array([0.1, 0.2, 0.3, 0.9]) * 1e150,
                              np.array([0.4, -0.2, 0.1, 0.8]) * 1e150)
    assert np.isfinite(big).all()
    np.testing.assert_allclose(big / 1e300, b, rtol=1e-12, atol=1e-300)


def test_huge_integers_name_the_argument():
    """D09: integers too large for the core raise an error naming the argument."""
    b = trimesh.creation.box()
    tool = fl.translation([0, 0, 1], 0.3, [1, 0, 0])
    calls = {
        "turns": lambda: spinal.frames(K, closed=True, turns=2**70),
        "steps": lambda: spinal.advect(np.zeros((3, 3)), tool, 0.1, 2**64),
        "face": lambda: Q.walk_mesh(b.vertices, b.faces, 2**63, b.vertices[b.faces[0]].mean(0),
                                    [[0.1, 0.1]]),
    }
    calls["turns "] = lambda: Q.quaternion_frames(K, closed=True, turns=2**70)
    for name, call in calls.items():
        with pytest.raises(ValueError, match=f"^{name.strip()}: .*out of the representable range"):
            call()
    # stamp bounds its frame count itself (the message gives the bound)
    with pytest.raises(ValueError, match="^frames: must be at least 1 and at most"):
        spinal.stamp(trimesh.creation.icosphere(1), [0, 0, 1.32], [0, 0, 1.1], 0.3, frames=2**64)


def test_distinct_points_a_few_ulps_apart_far_from_the_origin():
    """D19: points a few ulps apart far from the origin stay distinct."""
    f = spinal.frames(spinal.curves.Helix(), u=[1e15, 1e15 + 1, 1e15 + 2])
    assert f.shape == (3, 3, 3) and np.isfinite(f).all()
    x = np.c_[1e12 + np.arange(5) * 1e-3, np.zeros(5), np.zeros(5)]
    f = spinal.frames(x)
    np.testing.assert_allclose(f[:, :, 2], np.tile([1.0, 0, 0], (5, 1)), atol=1e-12)
    # exact repeats (and samples within 2⁻⁴⁰ of the curve's size) are merged
    y = x.copy()
    y[3] = y[2]
    np.testing.assert_array_equal(spinal.frames(y), spinal.frames(np.delete(x, 3, axis=0))[
        [0, 1, 2, 2, 3]])
    y[3, 0] = y[2, 0] + 4e-3 * 2.0**-40 * 0.9  # 4e-3 long: under the floor
    assert np.array_equal(spinal.frames(y)[3], spinal.frames(y)[2])


def test_huge_finite_vectors_do_not_overflow():
    """D20: very large finite vectors do not overflow."""
    ref = spinal.frames(H, initial=[1, 1, 0])
    np.testing.assert_allclose(spinal.frames(H, initial=[1e300, 1e300, 0]), ref, atol=1e-14)
    t = spinal.estimate_tangents(H)
    np.testing.assert_allclose(spinal.frames(H, t * 1e300), spinal.frames(H, t), atol=1e-14)
    np.testing.assert_allclose(spinal.frames(H, t * 1e-300), spinal.frames(H, t), atol=1e-14)
    np.testing.assert_allclose(Q.camera_frames(H, up=[0, 0, 1e300]), Q.camera_frames(H),
                               atol=1e-14)
    m = spinal.sweep(H * 1e300, SQ * 1e300, caps=False)
    assert np.isfinite(m.vertices).all()
    np.testing.assert_allclose(m.vertices / 1e300, spinal.sweep(H, SQ, caps=False).vertices,
                               atol=1e-12)
    with pytest.raises(ValueError, match="^posed_spine: .*out of the representable range"):
        spinal.flesh([[0, 0.3, 0]], REST, POSED * 1e300)
    with pytest.raises(ValueError, match="^radius: must be positive and finite"):
        spinal.tube(H, np.inf)


def test_loose_arguments_are_refused():
    """D21: arguments out of range, non-finite or of the wrong type are refused by name."""
    with pytest.raises(ValueError, match="^singular_angle: must be >= 0"):
        Q.camera_frames(H, mode="up", singular_angle=-1)
    with pytest.raises(ValueError, match="^singular_angle: must be finite"):
        Q.camera_frames(H, mode="up", singular_angle=np.nan)
    with pytest.raises(TypeError, match="^singular_angle: "):
        Q.camera_frames(H, mode="up", singular_angle="x")
    tool = fl.translation([0, 0, 1], 0.3, [1, 0, 0])
    with pytest.raises(ValueError, match="^max_passes: "):
        spinal.deform(trimesh.creation.icosphere(1), tool, 0.1, max_passes=-1)
    with pytest.raises(TypeError, match="^estimate: "):
        spinal.deform(trimesh.creation.icosphere(1), tool, 0.1, estimate=1)
    with pytest.raises(TypeError, match="^return_clamped: "):
        spinal.flesh([[0, 0.3, 0]], REST, POSED, return_clamped="yes")
    with pytest.raises(TypeError, match="^progress: "):
        spinal.advect(np.zeros((3, 3)), tool, 0.1, progress="yes")
    with pytest.raises(ValueError, match="^turns: must be positive"):
        spinal.curves.Helix(turns=0)
    with pytest.raises(ValueError, match="^turns: applies to a closed curve"):
        spinal.frames(H, turns=3)
    assert spinal.frames(H, turns=3, end=[1, 0, 0]).shape == (60, 3, 3)
    length = Q.quaternion_length(np.array([[0, 0, 0, 1.0]]))
    assert length == 0.0 and np.copysign(1.0, length) == 1.0


def test_messages_name_the_argument():
    """D25: every error message names its argument."""
    with pytest.raises(TypeError, match="^miter_limit: "):
        spinal.sweep(H, SQ, miter_limit=[4, 4])
    f = spinal.frames(H)
    with pytest.raises(ValueError, match="^b: "):
        Q.spin(f[:3], f[:4])
    with pytest.raises(TypeError, match="^a: "):
        spinal.curves.Helix(a="1")
    with pytest.raises(ValueError, match="^control_points: non-finite value at row 1"):
        spinal.curves.Bezier([[0, 0, 0], [np.nan, 0, 0]])
    with pytest.raises(ValueError, match="^u: a sample count must be .* got 1099511627776"):
        spinal.frames(spinal.curves.Helix(), u=2**40)
    with pytest.raises(TypeError, match="^vertices: "):
        spinal.Mesh("abc", [[0, 1, 2]])
    with pytest.raises(ValueError, match="^vertices: "):
        spinal.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
    with pytest.raises(TypeError, match="^path: "):
        spinal.Mesh(np.eye(3), [[0, 1, 2]]).save(5)
    with pytest.raises(ValueError, match="^path: "):
        spinal.Mesh(np.eye(3), [[0, 1, 2]]).save("mesh.xyz")


# ------------------------------------------------------------- flesh beyond 1e±150

FLESH_SCALES = (1e-200, 1e-160, 1e160, 1e200)
_ring_u = np.linspace(0, 2 * np.pi, 24, endpoint=False)
RING = np.c_[np.cos(_ring_u), np.sin(_ring_u), 0 * _ring_u]
RING_POSED = np.c_[1.2 * np.cos(_ring_u), np.sin(_ring_u), 0.1 * np.sin(2 * _ring_u)]
POSED_3D = np.c_[np.sin(_v), 1 - np.cos(_v), 0.1 * _v**2]
FLESH_V = np.array([[0, 0.3, 0], [0.5, -0.1, 0.2], [1.3, 0.1, 0.0], [-1.2, 0, 0.1]])
_g = np.stack(np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 6), indexing="ij"), -1)
SURF_REST = np.concatenate([_g, 0.1 * _g[..., :1] ** 2], -1)
SURF_POSED = np.concatenate([_g, 0.3 * (_g[..., :1] ** 2 + _g[..., 1:] ** 2)], -1)
SURF_V = np.array([[0.3, 0.4, 0.1], [0.7, 0.2, -0.05], [2, 2, 0.3]])  # the last outside

FLESH_CALLS = {
    **{f"{sol} stretchable={st}": (
        lambda s, sol=sol, st=st: spinal.flesh(FLESH_V * s, REST * s, POSED_3D * s,
                                               solution=sol, stretchable=st))
       for sol in ("radial", "normal", "binormal", "none") for st in (False, True)},
    "closed": lambda s: spinal.flesh((FLESH_V[:2] + [1, 0, 0]) * s, RING * s, RING_POSED * s,
                                     closed=True),
    "posed_up": lambda s: spinal.flesh(FLESH_V * s, REST * s, POSED_3D * s, posed_up=[0, 0.3, 1]),
    "planar": lambda s: spinal.flesh(FLESH_V[:, :2] * s, REST[:, :2] * s, POSED[:, :2] * s),
    "offset": lambda s: spinal.SpineBinding(FLESH_V * s, REST * s).offset,
    "arc_length": lambda s: spinal.SpineBinding(FLESH_V * s, REST * s).arc_length,
    "surface": lambda s: spinal.flesh_surface(SURF_V * s, SURF_REST * s, SURF_POSED * s),
    "surface none": lambda s: spinal.flesh_surface(SURF_V * s, SURF_REST * s, SURF_POSED * s,
                                                   solution="none"),
    "surface posed_up": lambda s: spinal.flesh_surface(SURF_V * s, SURF_REST * s,
                                                       SURF_POSED * s, posed_up=[0.1, 0, 1]),
    "surface offset": lambda s: spinal.SurfaceBinding(SURF_V * s, SURF_REST * s).offset,
    "surface rest_frames": lambda s: spinal.SurfaceBinding(SURF_V * s, SURF_REST * s)
    .rest_frames * s,
}


@pytest.mark.parametrize("name", list(FLESH_CALLS))
def test_flesh_at_any_scale_is_the_unit_result_scaled(name):
    """The spine and surface models are built on the input divided by its power-of-two
    scale, so bending at 1e±200 is bending at 1 (before: off by 3.5e-4 at 1e-160, a
    misleading 'turns too fast' error from 1e160 up)."""
    call = FLESH_CALLS[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        want = call(1.0)
        for s in FLESH_SCALES:
            got = call(s)
            assert np.isfinite(got).all(), (name, s)
            np.testing.assert_allclose(got / s, want, rtol=1e-9, atol=1e-9 * np.abs(want).max(),
                                       err_msg=f"{name} at {s:g}")


def test_flesh_sizes_out_of_range_are_named():
    """A pose whose result is past float64 (a stretch of 1e600 between rest and pose) says
    so and names the argument, instead of returning inf or NaN."""
    with pytest.raises(ValueError, match="^posed_spine: vertex 0: .*out of range"):
        spinal.flesh(FLESH_V * 1e-300, REST * 1e-300, POSED_3D * 1e300, stretchable=True)
    with pytest.raises(ValueError, match="^posed_surface: vertex 1: .*out of range"):
        spinal.flesh_surface(SURF_V, SURF_REST, SURF_POSED * 1e-200)
    # very different but representable sizes are fine
    out = spinal.flesh(FLESH_V, REST, POSED_3D * 1e200, stretchable=True)
    assert np.isfinite(out).all() and np.abs(out).max() > 1e199
