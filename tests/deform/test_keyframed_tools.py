"""Keyframed rigid poses for every tool kind (thesis §11.2.6: tools move rigidly with their
object space; the curl fields of Ch. 12): spinal.fields.keyframed on the shape tools sphere,
capsule, strip, torus and strip_curve (the curl tool of the moving shape) and on shape-less
fields — twist, bend, along_path, sums — carried rigidly, ``v = Q v₀(C + Qᵀ(X − c), t)``.

Independent references: the pose from SciPy's Hermite spline (Bessel tangents) and slerp,
distances to the shapes computed in NumPy/SciPy (the strip's axis by SciPy's clamped spline
and a Newton foot point), closed-form fields written out in NumPy, central-difference
divergences, RK4 orders measured from three step counts, mesh volumes from trimesh and
libigl.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp
from test_deform import icosphere, jacobian, volumes
from test_deform_curl import bessel_hermite
from test_deform_tools import Axis

import spinal
from spinal import fields

C0 = np.array([0.1, -0.2, 0.3])
A = np.array([0.3, -0.4, 0.8]) / np.linalg.norm([0.3, -0.4, 0.8])
HALF = np.array([0.25, 0.1, -0.05])  # half a segment (capsule, strips)
TIMES = np.array([0.0, 0.3, 0.7, 1.0])
POS = C0 + np.c_[0.2 * np.sin(TIMES), 0.1 * TIMES, 0.15 * TIMES**2]
ROT = Rotation.from_rotvec(np.c_[0.4 * TIMES, -0.3 * TIMES**2, 0.2 * TIMES])
MID = 0.5 * (TIMES[1:] + TIMES[:-1])

_th = np.linspace(-0.5, 0.5, 6)
CURVE = C0 + np.c_[0.6 * np.sin(_th), 0.1 * np.sin(2 * _th), 0.6 * np.cos(_th) - 0.55]
CURVE_AXIS = Axis(CURVE)
_len = np.linalg.norm(np.diff(CURVE, axis=0), axis=1)
CURVE_CENTRE = (0.5 * (CURVE[1:] + CURVE[:-1]) * _len[:, None]).sum(0) / _len.sum()
SPINE = np.array([C0 - [0.4, 0, 0], C0 + [0.4, 0, 0]])
C1 = C0 + np.array([0.35, 0.1, 0.0])  # the second swirl of the sum


def rng_ball(center, radius, n, seed=0):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    return np.asarray(center) + d * (radius * rng.random(n) ** (1 / 3))[:, None]


def segment_distance(x, a, b):
    """Distance to the segment a–b and the segment parameter (unclamped)."""
    lam = (x - a) @ (b - a) / ((b - a) @ (b - a))
    foot = a + np.clip(lam, 0, 1)[:, None] * (b - a)
    return np.linalg.norm(x - foot, axis=1), lam


def ring_distance(x, c, axis, major):
    y = x - c
    z = y @ axis
    rho = np.linalg.norm(y - z[:, None] * axis, axis=1)
    return np.hypot(rho - major, z)


# Each kind: the tool, the radius of a ball about C holding its support (where the points are
# drawn), the reach (the divergence scale), and the distances (in the tool's frame as built)
# to the places where the field is not smooth: the divergence is checked 1e-3 away from them.
def _segment_kinks(x, rho, reach):
    r, lam = segment_distance(x, C0 - HALF, C0 + HALF)
    d = r - rho
    return np.minimum.reduce([np.abs(d), np.abs(np.abs(d) - reach), r,
                              np.abs(lam) * 0.5, np.abs(lam - 1) * 0.5])


def _curve_kinks(x, rho, reach):
    u = CURVE_AXIS.foot(x)
    r = np.linalg.norm(x - CURVE_AXIS.cs(u), axis=1)
    d = r - rho
    k = np.minimum.reduce([np.abs(d), np.abs(np.abs(d) - reach), r])
    for s in CURVE_AXIS.s:
        k = np.minimum(k, np.abs(u - s))
    for s in (0.0, CURVE_AXIS.s[-1]):  # beyond the ends: the end planes
        k = np.minimum(k, np.abs((x - CURVE_AXIS.cs(s)) @ CURVE_AXIS.cs(s, 1)))
    return k


def _ball_kinks(x, c, rho, reach):
    r = np.linalg.norm(x - c, axis=1)
    return np.minimum.reduce([np.abs(r - rho), np.abs(r - rho - reach), r])


def _ring_kinks(x):
    dist = ring_distance(x, C0, A, 0.6)
    d = dist - 0.12
    return np.minimum.reduce([np.abs(d), np.abs(np.abs(d) - 0.15), dist])


SHAPES = {
    "sphere": (lambda: fields.sphere(C0, 0.3, [1, 0, 0], reach=0.25), C0, 0.6, 0.25,
               lambda x: _ball_kinks(x, C0, 0.3, 0.25)),
    "capsule": (lambda: fields.capsule(C0 - HALF, C0 + HALF, 0.2, [0, 0, 1], reach=0.25), C0,
                0.8, 0.25, lambda x: _segment_kinks(x, 0.2, 0.25)),
    "strip": (lambda: fields.strip(C0 - HALF, C0 + HALF, 0.2, HALF, reach=0.25), C0, 0.8, 0.25,
              lambda x: _segment_kinks(x, 0.2, 0.25)),
    "strip_across": (lambda: fields.strip(C0 - HALF, C0 + HALF, 0.2, np.cross(HALF, A),
                                          kind="across", reach=0.25), C0, 0.8, 0.25,
                     lambda x: _segment_kinks(x, 0.2, 0.25)),
    "torus": (lambda: fields.torus(C0, A, 0.6, 0.12, 1.0, reach=0.15), C0, 0.9, 0.15,
              _ring_kinks),
    "strip_curve": (lambda: fields.strip_curve(CURVE, 0.1, 1.0, reach=0.15), CURVE_CENTRE, 0.75,
                    0.15, lambda x: _curve_kinks(x, 0.1, 0.15)),
}

CARRIED = {
    "twist": (lambda: fields.twist(C0, A, 2.0, 0.6), C0, 0.6, 0.6,
              lambda x: _ball_kinks(x, C0, 0.0, 0.6)),
    "bend": (lambda: fields.bend(C0, A, 1.5, 0.6, form="curl"), C0, 0.6, 0.6,
             lambda x: _ball_kinks(x, C0, 0.0, 0.6)),
    # a straight spine: the tool's centre moves from SPINE[0] (t0 = 0.1) to SPINE[1] (1.1)
    "along_path": (lambda: fields.along_path(SPINE, 0.2, 1.0, kind="twist", rate=3.0, t0=0.1),
                   C0, 0.85, 0.2, None),
    "sum": (lambda: fields.twist(C0, A, 2.0, 0.4) + fields.bend(C1, [0, 0, 1], 1.0, 0.3), C0,
            0.8, 0.3,
            lambda x: np.minimum(_ball_kinks(x, C0, 0.0, 0.4), _ball_kinks(x, C1, 0.0, 0.3))),
}

NEEDS_CENTER = {"along_path", "sum"}


def path_kinks(x, t):
    """along_path's pushing tool at time t (centre on the straight spine, held at the ends)."""
    s = np.clip((t - 0.1) / 1.0, 0, 1)
    return _ball_kinks(x, SPINE[0] + s * (SPINE[1] - SPINE[0]), 0.2, 0.2)


def keyed(kind, tool=None, times=TIMES, pos=POS, rot=ROT, **kw):
    build, centre = {**SHAPES, **CARRIED}[kind][:2]
    if kind in NEEDS_CENTER:
        kw.setdefault("center", centre)
    tool = build() if tool is None else tool
    return fields.keyframed(tool, times, pos, None if rot is None else rot.as_matrix(), **kw)


def bessel_spline(times=TIMES, pos=POS):
    """SciPy's cubic Hermite spline through the keys with Bessel tangents."""
    return bessel_hermite(times, pos)


def scipy_pose(t, times=TIMES, pos=POS, rot=ROT):
    """c, ċ, Q (a Rotation), ω: Bessel-tangent Hermite positions and slerp, in SciPy."""
    cs = bessel_spline(times, pos)
    k = min(max(np.searchsorted(times, t) - 1, 0), len(times) - 2)
    om = (rot[k + 1] * rot[k].inv()).as_rotvec() / (times[k + 1] - times[k])
    return cs(t), cs(t, 1), Slerp(times, rot)([t])[0], om


def world_points(kind, t, n=3000, seed=0):
    """Points of the kind's support at the pose of time t (held outside the keys), 1e-3 away
    from its kinks, drawn in the tool's own frame and mapped by the pose."""
    _, centre, radius, _, kinks = {**SHAPES, **CARRIED}[kind]
    xb = rng_ball(centre, radius, n, seed)
    keep = (kinks(xb) if kinks is not None else path_kinks(xb, t)) > 1e-3
    c, _, q, _ = scipy_pose(np.clip(t, TIMES[0], TIMES[-1]))
    return c + q.apply(xb[keep] - centre)


# ---- breakpoints ---------------------------------------------------------------------------

@pytest.mark.parametrize("kind", [*SHAPES, *CARRIED])
def test_breakpoints_are_the_keys_and_the_tools_own(kind):
    f = keyed(kind)
    own = {**SHAPES, **CARRIED}[kind][0]().breakpoints()
    expect = np.union1d(TIMES, [0.1, 1.1]) if kind == "along_path" else TIMES
    np.testing.assert_array_equal(f.breakpoints(), expect)
    np.testing.assert_array_equal(f.breakpoints(), np.union1d(TIMES, own))


def test_the_step_rule_counts_the_speed_of_the_carried_pattern():
    """A carried twist's speed bound is the twist's plus the speed at which the pose moves
    its support (radius R about C) past the material, max|ċ| + max|ω| R (max|ċ| sampled
    densely from SciPy's spline, the core samples 17 points per interval with a 5 % margin):
    the default steps grow with the keys' speed; identity keys add nothing."""
    tw = CARRIED["twist"][0]()
    vmax = np.linalg.norm(bessel_spline()(np.linspace(0, 1, 2001), 1), axis=1).max()
    wmax = max(np.linalg.norm(scipy_pose(t)[3]) for t in MID)
    low = tw.max_speed + vmax + wmax * 0.6
    assert low <= keyed("twist").max_speed <= low + 0.1 * vmax
    still = keyed("twist", pos=np.tile(C0, (4, 1)), rot=None)
    assert still.max_speed == tw.max_speed and still.steps(1.0) == tw.steps(1.0)
    assert keyed("twist").steps(1.0) > 2 * tw.steps(1.0)


# ---- divergence ----------------------------------------------------------------------------

@pytest.mark.parametrize("kind", [*SHAPES, *CARRIED])
def test_keyframed_fields_are_divergence_free(kind):
    """Central differences (h = 1e-6) of the velocity at mid-interval times (and, for the
    carried fields, before and after the keys, where the pose is held): |div v| below 1e-7 of
    max|v| / reach."""
    f = keyed(kind)
    reach = {**SHAPES, **CARRIED}[kind][3]
    ts = list(MID) + ([1.05] if kind in CARRIED else [])
    ts += [-0.2] if kind in CARRIED and kind != "along_path" else []  # (it starts at 0.1)
    for t in ts:
        x = world_points(kind, t, seed=int(100 * t) % 7)
        v = f(x, t)
        d = np.trace(jacobian(lambda X, t=t: f(X, t), x, h=1e-6), axis1=1, axis2=2)
        assert (np.linalg.norm(v, axis=1) > 1e-2 * np.abs(v).max()).sum() > 150, t
        assert np.abs(d).max() < 1e-7 * np.abs(v).max() / reach, (t, np.abs(d).max())


# ---- identity keys, constant poses ---------------------------------------------------------

@pytest.mark.parametrize("kind", list(CARRIED))
def test_identity_keys_reproduce_the_carried_field(kind):
    """c_k = C and Q_k = I: the untransformed field, inside and outside the keys."""
    base = CARRIED[kind][0]()
    centre = CARRIED[kind][1]
    f = keyed(kind, base, pos=np.tile(centre, (4, 1)),
              rot=Rotation.from_rotvec(np.zeros((4, 3))))
    x = rng_ball(centre, 1.0, 4000)
    top = 0.0
    for t in (-0.3, 0.15, 0.5, 0.9, 1.05, 1.4):
        v0 = base(x, t)
        top = max(top, np.abs(v0).max())
        np.testing.assert_allclose(f(x, t), v0, rtol=0, atol=1e-13 * np.abs(v0).max())
    assert top > 5e-3
    # a single tool with a natural centre needs no center=; the same field
    if kind in ("twist", "bend"):
        g = fields.keyframed(base, TIMES, np.tile(centre, (4, 1)))
        np.testing.assert_array_equal(g(x, 0.5), base(x, 0.5))


def test_a_constant_pose_carries_the_twist_to_its_closed_form():
    """Every key at (c*, Q*): v = h (Q*a) × (X − c*), h = κ z (1 − r/R)², z = Q*a·(X − c*),
    r = |X − c*|, before, between and after the keys; and the sum of a twist and a bend
    carried the same way is the sum of the two closed forms about their moved centres."""
    cs = np.array([0.4, 0.3, -0.2])
    qs = Rotation.from_rotvec([0.5, -1.1, 0.7])
    k, R = 2.0, 0.6
    f = keyed("twist", pos=np.tile(cs, (4, 1)), rot=Rotation.concatenate([qs] * 4))
    x = rng_ball(cs, 0.8, 4000)
    y = x - cs
    a = qs.apply(A)
    r = np.linalg.norm(y, axis=1)
    h = k * (y @ a) * np.clip(1 - r / R, 0, None) ** 2
    ref = h[:, None] * np.cross(a, y)
    for t in (-1.0, 0.5, 2.0):
        np.testing.assert_allclose(f(x, t), ref, rtol=0, atol=1e-14)
    # the sum: a twist about C0 (radius 0.4) and a rate-form bend about C1 (radius 0.3)
    g = keyed("sum", pos=np.tile(cs, (4, 1)), rot=Rotation.concatenate([qs] * 4))
    c1 = cs + qs.apply(C1 - C0)
    y1 = x - c1
    r1 = np.linalg.norm(y1, axis=1)
    b = qs.apply([0, 0, 1])
    hb = 1.0 * r1**2 * np.clip(1 - r1 / 0.3, 0, None) ** 2
    ht = k * (y @ a) * np.clip(1 - r / 0.4, 0, None) ** 2
    ref = ht[:, None] * np.cross(a, y) + hb[:, None] * np.cross(b, y1)
    np.testing.assert_allclose(g(x, 0.5), ref, rtol=0, atol=1e-14)


def curl_translation(d, g, y, u, reach, p=2):
    """(e^{p−1}/R^p)[e u + (p/2) sgn(d)((g·u)Y − (g·Y)u)] for |d| < R, else 0."""
    e = np.clip(reach - np.abs(d), 0, None)
    k = e ** (p - 1) / reach**p
    s = 0.5 * p * np.sign(d)
    return k[:, None] * (e[:, None] * u + s[:, None] * ((g @ u)[:, None] * y
                                                        - (g * y).sum(1)[:, None] * u))


def test_a_constant_turn_and_velocity_move_the_turned_shapes_by_their_closed_forms():
    """Keys on a line at constant speed with one orientation Q*: the curl translation of the
    turned torus (axis Q*a, centre c(t)) and of the turned capsule, written out in NumPy."""
    qs = Rotation.from_rotvec([0.5, -1.1, 0.7])
    u = np.array([0.3, -0.5, 0.2])
    pos = C0 + np.outer(TIMES, u)
    rots = Rotation.concatenate([qs] * 4)
    t = 0.45
    c = C0 + u * t
    x = rng_ball(c, 0.95, 6000)
    y = x - c
    # torus: d = √((ρ − R_t)² + z²) − r_t, g = ((ρ − R_t) e_ρ + z k)/dist
    a = qs.apply(A)
    z = y @ a
    yp = y - z[:, None] * a
    rho = np.linalg.norm(yp, axis=1)
    dist = np.hypot(rho - 0.6, z)
    g = ((rho - 0.6) / rho)[:, None] * yp + z[:, None] * a
    g /= dist[:, None]
    ref = curl_translation(dist - 0.12, g, y, u, 0.15)
    f = keyed("torus", pos=pos, rot=rots)
    assert np.abs(ref).max() > 0.1
    np.testing.assert_allclose(f(x, t), ref, rtol=0, atol=1e-13)
    # capsule: the segment c ± Q* HALF, power 3
    r, lam = segment_distance(x, c - qs.apply(HALF), c + qs.apply(HALF))
    foot = c - qs.apply(HALF) + np.clip(lam, 0, 1)[:, None] * (2 * qs.apply(HALF))
    g = (x - foot) / r[:, None]
    ref = curl_translation(r - 0.2, g, y, u, 0.25, p=3)
    f = keyed("capsule", pos=pos, rot=rots, falloff_power=3)
    np.testing.assert_allclose(f(x, t), ref, rtol=0, atol=1e-13)
    # before the first and after the last key the tool rests
    assert not f(x, -0.1).any() and not f(x, 1.1).any()


def test_center_moves_the_point_taken_to_the_keys():
    """center= C for a shape: keys at constant velocity put the sphere's centre at
    c(t) − (C − C_s) and the curl translation has Y = X − c(t), in NumPy; a carried twist
    about another point: v(X) = v₀(X − w) for keys at C + w."""
    other = C0 + np.array([0.2, 0.0, -0.1])
    u = np.array([0.3, -0.5, 0.2])
    pos = other + np.outer(TIMES, u)
    f = keyed("sphere", pos=pos, rot=None, center=other, falloff_power=4)
    t = 0.55
    c = other + u * t
    x = rng_ball(c - (other - C0), 0.6, 4000)
    ys = x - (c - (other - C0))
    r = np.linalg.norm(ys, axis=1)
    ref = curl_translation(r - 0.3, ys / r[:, None], x - c, u, 0.25, p=4)
    assert np.abs(ref).max() > 0.1
    np.testing.assert_allclose(f(x, t), ref, rtol=0, atol=1e-13)
    # without center=: Y = X − c_s(t), a different field with the same placement
    g = keyed("sphere", pos=pos - (other - C0), rot=None, falloff_power=4)
    assert np.abs(g(x, t) - ref).max() > 1e-2
    w = np.array([0.05, -0.1, 0.2])
    tw = fields.twist(C0, A, 2.0, 0.6)
    x = rng_ball(C0, 1.0, 3000)
    a = fields.keyframed(tw, TIMES, np.tile(other, (4, 1)), center=other)
    np.testing.assert_allclose(a(x, 0.5), tw(x, 0.5), rtol=0, atol=1e-14)
    b = fields.keyframed(tw, TIMES, np.tile(other + w, (4, 1)), center=other)
    np.testing.assert_allclose(b(x + w, 0.5), tw(x, 0.5), rtol=0, atol=1e-14)
    assert np.abs(tw(x, 0.5)).max() > 1e-2


# ---- RK4 order -----------------------------------------------------------------------------

def measured_orders(f, x, t0, T, n):
    """log2 of the ratio of successive differences of runs with n, 2n, 4n steps: the order
    p from x_n − x_2n ≈ (2^p − 1) e_2n."""
    runs = [spinal.advect(x, f, T, k, t0=t0) for k in (n, 2 * n, 4 * n)]
    d1 = np.abs(runs[0] - runs[1]).max()
    d2 = np.abs(runs[1] - runs[2]).max()
    return np.log2(d1 / d2), d1


def test_rk4_is_fourth_order_for_a_keyframed_torus_and_a_carried_twist():
    """Across three key intervals (t 0.1 … 0.9, whole steps in each, so that the runs are
    exact halvings): a torus (falloff_power=4, C² at the support edge),
    path lines 0.03 off its surface and off its core circle; a carried twist (rate form), path
    lines between 0.1 and 0.8 of its radius about the moving centre (its edge is only C¹, and
    ``r = |Y|`` in ``(1 − r/R)²`` makes the field C² only at the centre). Measured orders
    4.14 (torus, 64/128/256 steps) and 4.01 (twist, 8/16/32 steps)."""
    T, t0 = 0.8, 0.1
    f = keyed("torus", falloff_power=4)
    xb = rng_ball(C0, 0.9, 4000)
    c, _, q, _ = scipy_pose(t0)
    x = c + q.apply(xb - C0)
    ok = np.ones(len(x), bool)
    for k in range(17):
        t = t0 + T * k / 16
        W = spinal.advect(x, f, t - t0, 8 * k, t0=t0) if k else x
        c, _, q, _ = scipy_pose(t)
        wb = C0 + q.inv().apply(W - c)
        dist = ring_distance(wb, C0, A, 0.6)
        ok &= (np.abs(dist - 0.12) > 0.03) & (dist > 0.03)
    moving = np.linalg.norm(spinal.advect(x, f, T, 64, t0=t0) - x, axis=1) > 1e-2
    assert (ok & moving).sum() > 200
    p, d1 = measured_orders(f, x[ok], t0, T, 64)
    assert 3.7 < p < 4.3 and d1 > 1e-9, (p, d1)
    g = keyed("twist")
    xb = rng_ball(C0, 0.45, 2000)
    c, _, q, _ = scipy_pose(t0)
    x = c + q.apply(xb - C0)
    ok = np.ones(len(x), bool)
    for k in range(17):
        t = t0 + T * k / 16
        W = spinal.advect(x, g, t - t0, 8 * k, t0=t0) if k else x
        c, _, q, _ = scipy_pose(t)
        r = np.linalg.norm(W - c, axis=1)
        ok &= (r < 0.8 * 0.6) & (r > 0.1 * 0.6)
    assert ok.sum() > 1000
    p, d1 = measured_orders(g, x[ok], t0, T, 8)
    assert 3.7 < p < 4.3 and d1 > 1e-9, (p, d1)


# ---- pickling ------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", [*SHAPES, *CARRIED])
def test_keyframed_fields_pickle(kind):
    f = keyed(kind, center=[0.1, 0.2, 0.0]) if kind == "sphere" else keyed(kind)
    g = pickle.loads(pickle.dumps(f))
    x = rng_ball(C0, 1.0, 2000)
    for t in (-0.1, 0.2, 0.8, 1.3):
        np.testing.assert_array_equal(g(x, t), f(x, t))
    np.testing.assert_array_equal(g.breakpoints(), f.breakpoints())
    assert g.max_speed == f.max_speed and repr(g) == repr(f)


# ---- bad input -----------------------------------------------------------------------------

@pytest.mark.parametrize("call, match", [
    (lambda: fields.keyframed(CARRIED["sum"][0](), TIMES, POS), "center: required for a sum"),
    (lambda: fields.keyframed(CARRIED["along_path"][0](), TIMES, POS), "center: required"),
    (lambda: fields.keyframed(fields.sum([]), TIMES, POS), "center: required"),
    (lambda: fields.keyframed(fields.twist(C0, A, 1.0, 0.5), TIMES, POS, falloff_power=2),
     "falloff_power: only applies"),
    (lambda: fields.keyframed(fields.twist(C0, A, 1.0, 0.5), TIMES, POS, center=[1, 2]),
     "center"),
    (lambda: fields.keyframed(fields.twist(C0, A, 1.0, 0.5), [0, 1e-300],
                              [[0, 0, 0], [1e300, 0, 0]]), "times"),
    # a turning key pose about a centre 1e300 from the twist's support: w·E overflows
    (lambda: fields.keyframed(fields.twist(C0, A, 1.0, 0.5), [0.0, 1.0], POS[:2],
                              [[0, 0, 0, 1], [0, 0, np.sin(0.5), np.cos(0.5)]],
                              center=[1e300, 0, 0]), "^center: too far"),
])
def test_bad_input_names_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()


# ---- volume on a 40k mesh ------------------------------------------------------------------

def _volume_change(f, T, t0=0.0):
    V, F = icosphere(6)
    assert len(V) == 40962
    v0t, v0i = volumes(V, F)
    W = spinal.advect(V, f, T, t0=t0)
    vt, vi = volumes(W, F)
    assert abs(vt / vi - 1) < 1e-12 and abs(v0t / v0i - 1) < 1e-12
    return vt / v0t - 1, np.linalg.norm(W - V, axis=1).max(), f.steps(T)


def test_volume_of_a_40k_icosphere_under_a_keyframed_twist():
    """A twist (radius 0.8, κ 6) about a tangent of the unit sphere through a point of its
    surface, carried 0.3 along it and turned by 0.6 rad over the keys, at default steps (11).
    Measured: relative volume change −6.68e-7 (−6.68e-7 with twice the steps: mesh error),
    largest displacement 0.109."""
    times = np.array([0.0, 0.4, 1.0])
    th = 0.3 * times
    pos = np.c_[np.sin(th), 0 * th, np.cos(th)]
    rot = Rotation.from_rotvec(np.outer(0.6 * times, [0.0, 1.0, 0.2]))
    f = fields.keyframed(fields.twist([0, 0, 1], [1, 0, 0], 6.0, 0.8), times, pos,
                         rot.as_matrix())
    rel, moved, steps = _volume_change(f, 1.0)
    assert moved > 0.1
    assert abs(rel) <= 7e-5, (rel, steps)


def test_volume_of_a_40k_icosphere_under_a_keyframed_torus():
    """A torus (major 0.5, tube 0.1, reach 0.2) on a curved, turning key path pressing 0.15
    into the unit sphere, at default steps (68). Measured: relative volume change 2.201e-5
    (2.201e-5 with twice the steps: mesh error), largest displacement 0.162."""
    times = np.array([0.0, 0.3, 0.6])
    pos = np.c_[0.1 * np.sin(2 * times), 0 * times, 1.25 - 0.25 * times]
    rot = Rotation.from_rotvec(np.outer(times, [0.3, 0.2, 0.0]))
    f = fields.keyframed(fields.torus([0, 0, 1.25], [0, 0, 1], 0.5, 0.1, 1.0, reach=0.2),
                         times, pos, rot.as_matrix())
    rel, moved, steps = _volume_change(f, 0.6)
    assert moved > 0.05
    assert abs(rel) <= 7e-5, (rel, steps)
