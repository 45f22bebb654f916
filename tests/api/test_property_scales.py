"""Property tests over scales 1e-150 … 1e150 (flesh: 1e-300 … 1e300): a valid input scaled by 10^k gives the answer
of the unscaled input (scaled back where the answer has units) and never a NaN; quaternions
of any size give their rotation. Kept to about a minute in all (``max_examples``)."""

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import spinal
from spinal import fields as fl
from spinal import quaternions as Q

SETTINGS = settings(max_examples=200, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])
EXPONENTS = st.integers(-150, 150)
SEEDS = st.integers(0, 2**32 - 1)


def walk(seed: int, n: int, closed: bool = False) -> np.ndarray:
    """A smooth random curve: a random walk with small turns and step ratios up to 20 (a
    closed one: a random closed Fourier curve)."""
    rng = np.random.default_rng(seed)
    if closed:
        u = np.linspace(0, 2 * np.pi, n, endpoint=False)
        c = rng.normal(size=(3, 3, 2)) / np.arange(1, 4)[None, :, None]
        x = sum(np.outer(np.cos((k + 1) * u), c[:, k, 0]) + np.outer(np.sin((k + 1) * u), c[:, k, 1])
                for k in range(3))
        return x + np.outer(np.cos(u), [3.0, 0, 0]) + np.outer(np.sin(u), [0, 3.0, 0])
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    pts = [rng.normal(size=3)]
    for _ in range(n - 1):
        d = d + rng.normal(size=3) * 0.1
        d /= np.linalg.norm(d)
        pts.append(pts[-1] + d * rng.uniform(0.1, 2.0))
    return np.array(pts)


def same_or_named_error(call_scaled, call_ref, back=1.0, atol=1e-9):
    """The scaled call gives the reference (times ``back``) or both raise the same named
    ValueError; never a NaN."""
    try:
        ref = call_ref()
    except ValueError as e:
        with pytest.raises(ValueError) as got:
            call_scaled()
        assert str(got.value).split(":")[0] == str(e).split(":")[0]
        return
    out = call_scaled()
    assert np.isfinite(out).all()
    np.testing.assert_allclose(np.asarray(out) / back, ref, rtol=1e-9, atol=atol)


@SETTINGS
@given(SEEDS, st.integers(2, 40), EXPONENTS,
       st.sampled_from(["double_reflection", "rotation", "projection", "frenet"]),
       st.booleans())
def test_frames_are_scale_invariant(seed, n, k, method, with_tangents):
    x = walk(seed, n)
    s = 10.0**k
    t = spinal.estimate_tangents(x) if with_tangents else None
    same_or_named_error(lambda: spinal.frames(x * s, t, method=method),
                        lambda: spinal.frames(x, t, method=method))
    same_or_named_error(lambda: spinal.estimate_tangents(x * s),
                        lambda: spinal.estimate_tangents(x))


@SETTINGS
@given(SEEDS, st.integers(6, 40), EXPONENTS, st.integers(-2, 2))
def test_closed_frames_and_closing_angle_are_scale_invariant(seed, n, k, turns):
    x = walk(seed, n, closed=True)
    s = 10.0**k
    same_or_named_error(lambda: spinal.frames(x * s, closed=True, turns=turns),
                        lambda: spinal.frames(x, closed=True, turns=turns))
    same_or_named_error(lambda: np.array(spinal.closing_angle(x * s)),
                        lambda: np.array(spinal.closing_angle(x)))
    same_or_named_error(lambda: Q.quaternion_frames(x * s, closed=True),
                        lambda: Q.quaternion_frames(x, closed=True))


@SETTINGS
@given(SEEDS, st.integers(2, 30), st.integers(-300, 300), st.booleans())
def test_sweeps_and_tubes_scale(seed, n, k, caps):
    x = walk(seed, n)
    s = 10.0**k
    prof = 0.05 * np.array([[1, 0], [0, 1], [-1, 0.2], [0, -1.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # fold-over warnings: the same at every scale
        same_or_named_error(lambda: spinal.sweep(x * s, prof * s, caps=caps).vertices,
                            lambda: spinal.sweep(x, prof, caps=caps).vertices, back=s)
        same_or_named_error(lambda: spinal.tube(x * s, 0.05 * s, 6, caps=caps).vertices,
                            lambda: spinal.tube(x, 0.05, 6, caps=caps).vertices, back=s)
        same_or_named_error(lambda: spinal.tube(x * s, 0.05 * s, 6, caps=caps).normals,
                            lambda: spinal.tube(x, 0.05, 6, caps=caps).normals)


@SETTINGS
@given(SEEDS, st.integers(3, 30), EXPONENTS, st.sampled_from(["transport", "up"]))
def test_camera_and_quaternion_frames_are_scale_invariant(seed, n, k, mode):
    x = walk(seed, n)
    s = 10.0**k
    same_or_named_error(lambda: Q.camera_frames(x * s, mode=mode),
                        lambda: Q.camera_frames(x, mode=mode))
    same_or_named_error(lambda: Q.quaternion_frames(x * s), lambda: Q.quaternion_frames(x))


@SETTINGS
@given(SEEDS, st.integers(-300, 300), st.sampled_from(["radial", "normal", "binormal", "none"]),
       st.booleans())
def test_flesh_scales(seed, k, solution, stretchable):
    rng = np.random.default_rng(seed)
    s = 10.0**k
    m = 31
    rest = np.c_[np.linspace(-1, 1, m), np.zeros(m), np.zeros(m)]
    bend = rng.uniform(0.2, 1.2)
    v = np.linspace(-1, 1, m) * bend
    posed = np.c_[np.sin(v), 1 - np.cos(v), 0.1 * rng.normal() * v**2] / bend
    verts = rng.uniform(-0.2, 0.2, size=(5, 3)) * [4, 1, 1]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        same_or_named_error(
            lambda: spinal.flesh(verts * s, rest * s, posed * s, solution=solution,
                                 stretchable=stretchable),
            lambda: spinal.flesh(verts, rest, posed, solution=solution, stretchable=stretchable),
            back=s)


UNIT_BOX = st.lists(st.floats(-1, 1, allow_subnormal=False), min_size=4, max_size=4)


@SETTINGS
@given(UNIT_BOX, UNIT_BOX, st.integers(-300, 300), st.integers(-300, 300))
def test_quaternions_of_any_size(q, q2, k0, k1):
    q, q2 = np.array(q), np.array(q2)
    if np.linalg.norm(q) < 1e-3:
        q = q + np.array([0, 0, 0, 1.0])
    if np.linalg.norm(q2) < 1e-3:
        q2 = q2 + np.array([1.0, 0, 0, 0])
    ref = Q.from_quaternions(q)
    assert np.abs(Q.from_quaternions(q * 10.0**k0) - ref).max() < 1e-13
    length = Q.quaternion_length(np.stack([q, q2]))
    got = Q.quaternion_length(np.stack([q * 10.0**k0, q2 * 10.0**k1]))
    assert got == pytest.approx(length, abs=1e-12)
    if abs(q @ q2) > 1e-6 * np.linalg.norm(q) * np.linalg.norm(q2):  # the short arc is defined
        mid = Q.slerp(q * 10.0**k0, q2 * 10.0**k1, 0.3)
        np.testing.assert_allclose(np.abs(mid @ Q.slerp(q, q2, 0.3)), 1.0, atol=1e-12)


def _unit(rng):
    a = rng.normal(size=3)
    return a / np.linalg.norm(a)


def _ball_grid(c, radius, n=24):
    """The signed distance of the ball (c, radius) sampled on n³ nodes over the cube of side
    10·radius about c: (grid, origin, spacing)."""
    h = 10 * radius / (n - 1)
    o = c - 5 * radius
    x = o[:, None] + h * np.arange(n)[None, :]
    X = np.stack(np.meshgrid(x[0], x[1], x[2], indexing="ij"), -1)
    return np.linalg.norm(X - c, axis=-1) - radius, o, h


#: name -> builder(rng draws, s): the field of every constructor with positions, radii
#: and speeds scaled by s (angular speeds unscaled, a twist rate (rad/(length·time)) by 1/s,
#: a bend rate (rad/(length²·time)) by 1/s²). Velocities then scale by s.
FIELD_BUILDERS = {
    "translation": lambda d, s: fl.translation(d["c"] * s, 0.4 * s, d["u"] * s,
                                               falloff_power=d["p"]),
    "rotation": lambda d, s: fl.rotation(d["c"] * s, 0.4 * s, d["a"], d["w"],
                                         falloff_power=d["p"]),
    "sphere": lambda d, s: fl.sphere(d["c"] * s, 0.4 * s, d["u"] * s, blend=d["blend"]),
    "capsule": lambda d, s: fl.capsule(d["c"] * s, (d["c"] + 0.6 * d["a"]) * s, 0.3 * s,
                                       d["u"] * s, blend=d["blend"]),
    "strip_along": lambda d, s: fl.strip(d["c"] * s, (d["c"] + d["a"]) * s, 0.3 * s,
                                         d["a"] * d["w"] * s),
    "strip_across": lambda d, s: fl.strip(d["c"] * s, (d["c"] + d["a"]) * s, 0.3 * s,
                                          d["n"] * d["w"] * s, kind="across"),
    "torus": lambda d, s: fl.torus(d["c"] * s, d["a"], 0.5 * s, 0.15 * s, d["w"] * s),
    "twist": lambda d, s: fl.twist(d["c"] * s, d["a"], d["w"] / s, 0.6 * s, form=d["form"]),
    "bend": lambda d, s: fl.bend(d["c"] * s, d["a"], d["w"] / s**2, 0.6 * s, form=d["form"]),
    "rod": lambda d, s: fl.rod(d["axis"] * s, 0.2 * s, velocity=d["u"] * s),
    "strip_curve": lambda d, s: fl.strip_curve(d["axis"] * s, 0.3 * s, d["w"] * s),
    "along_path": lambda d, s: fl.along_path(d["axis"] * s, 0.3 * s, 2.0, kind="twist",
                                             rate=d["w"] / s),
    "sdf_tool": lambda d, s: fl.sdf_tool(d["grid"][0] * s, d["grid"][1] * s,
                                         d["grid"][2] * s, d["u"] * s, reach=0.6 * s),
    "sdf_curl": lambda d, s: fl.sdf_curl(d["grid"][0] * s, d["grid"][1] * s,
                                         d["grid"][2] * s, angular_velocity=d["a"] * d["w"],
                                         reach=0.6 * s),
}


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(SEEDS, st.integers(-150, 150), st.floats(0.0, 0.3))
@pytest.mark.parametrize("tool", sorted(FIELD_BUILDERS))
def test_fields_scale(tool, seed, k, t):
    """Every field constructor with its positions, radii and speeds scaled alike: the
    velocity at the scaled points (and time) is the unscaled velocity times s (each falloff
    is a function of ratios of lengths), finite everywhere."""
    rng = np.random.default_rng(seed)
    s = 10.0**k
    c = rng.normal(size=3)
    a = _unit(rng)
    n = np.cross(a, _unit(rng))
    u = np.linspace(0, 1, 9)
    d = {"c": c, "u": rng.normal(size=3), "a": a, "n": n / np.linalg.norm(n),
         "w": rng.uniform(0.5, 2.0) * rng.choice([-1, 1]), "p": int(rng.choice([2, 4])),
         "blend": str(rng.choice(["c1", "linear"])), "form": str(rng.choice(["rate", "curl"])),
         "axis": c + np.c_[u, 0.3 * np.sin(2 * u), 0.2 * u**2] @ np.linalg.qr(
             rng.normal(size=(3, 3)))[0],
         "grid": _ball_grid(c, 0.3)}
    f, fs = FIELD_BUILDERS[tool](d, 1.0), FIELD_BUILDERS[tool](d, s)
    pts = c + rng.normal(size=(30, 3)) * 0.4
    pts[15:] += d["u"] * t  # about a tool moving with u
    ref = np.concatenate([f(pts, 0.0), f(pts, t)])
    got = np.concatenate([fs(pts * s, 0.0), fs(pts * s, t * 1.0)])
    assert np.isfinite(got).all()
    assert np.abs(ref).max() > 0  # the points meet the tool
    np.testing.assert_allclose(got / s, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())


def _sheet(rng, n=13):
    """A random smooth height-field sheet over [-1, 1]² and a random smooth bend of it."""
    x = np.linspace(-1, 1, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    a = rng.uniform(-0.3, 0.3, 5)
    rest = np.stack([X, Y, a[0] * X**2 + a[1] * Y**2 + a[2] * X * Y], -1)
    b = rng.uniform(-0.3, 0.3, 4)
    posed = np.stack([X * (1 + b[0] * Y), Y + b[1] * X, rest[..., 2] + b[2] * X**2
                      - b[3] * Y**2], -1)
    return rest, posed


def _sheet_points(rng, rest, k=40, h=0.15):
    """Points within h of the sheet's middle (above and below it)."""
    i = rng.integers(2, rest.shape[0] - 2, (k, 2))
    return rest[i[:, 0], i[:, 1]] + np.c_[rng.uniform(-0.05, 0.05, (k, 2)),
                                         rng.uniform(-h, h, k)]


@SETTINGS
@given(SEEDS, st.integers(-300, 300), st.sampled_from(["offset", "none"]))
def test_flesh_surface_scales(seed, k, solution):
    """flesh_surface of a sheet, its bend and the points scaled by 10^k: the unscaled
    answer times 10^k (or the same named error), never a NaN; the binding gives the same."""
    rng = np.random.default_rng(seed)
    s = 10.0**k
    rest, posed = _sheet(rng)
    V = _sheet_points(rng, rest)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # fold-over warnings: the same at every scale
        same_or_named_error(
            lambda: spinal.flesh_surface(V * s, rest * s, posed * s, solution=solution),
            lambda: spinal.flesh_surface(V, rest, posed, solution=solution), back=s)
        same_or_named_error(
            lambda: spinal.SurfaceBinding(V * s, rest * s).deform(posed * s,
                                                                  solution=solution),
            lambda: spinal.flesh_surface(V, rest, posed, solution=solution), back=s)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(SEEDS, st.sampled_from(["offset", "none"]))
def test_flesh_surface_rigid_motion(seed, solution):
    """A sheet moved rigidly (x ↦ Rx + c, R a random rotation) carries the bound points
    with it: flesh_surface gives R V + c (an independent closed form), finite."""
    rng = np.random.default_rng(seed)
    rest, _ = _sheet(rng)
    V = _sheet_points(rng, rest)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    R = q * np.sign(np.linalg.det(q))
    c = rng.normal(size=3) * 3
    out = spinal.flesh_surface(V, rest, rest @ R.T + c, solution=solution)
    assert np.isfinite(out).all()
    assert np.abs(out - (V @ R.T + c)).max() < 1e-9
