"""Tools moving along a path: spinal.fields.along_path with spinal.advect.

Checked against independent references: the plain translation tool (a straight spine), a
NumPy Hermite interpolation of the spine (the carried centre and interior points), divergence
by central differences at random points and times, mesh volumes from trimesh and libigl.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_deform import div, icosphere, volumes

import spinal
from spinal import fields

RNG = np.random.default_rng(44)


def ball(center, radius, n, rng=RNG):
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    return np.asarray(center) + d * (radius * rng.random(n) ** (1 / 3))[:, None]


def arc(n, lift=0.0):
    """A spatial arc over the unit sphere: the distance from the origin dips from 1.32 to 1.2
    and back, with a sideways wobble (torsion), angle −0.5 … 0.5 rad."""
    th = np.linspace(-0.5, 0.5, n)
    r = 1.32 - 0.12 * np.sin(np.pi * (th + 0.5)) + lift
    return np.c_[r * np.sin(th), 0.15 * np.sin(2 * th) * r, r * np.cos(th)]


def hermite(points, frames, sigma):
    """Independent Hermite evaluation of the tool centre at chord length sigma."""
    s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]
    k = np.clip(np.searchsorted(s, sigma, side="right") - 1, 0, len(s) - 2)
    ds = s[k + 1] - s[k]
    lam = ((sigma - s[k]) / ds)[:, None]
    t = frames[:, :, 2]
    return ((2 * lam**3 - 3 * lam**2 + 1) * points[k] + (lam**3 - 2 * lam**2 + lam)
            * t[k] * ds[:, None] + (-2 * lam**3 + 3 * lam**2) * points[k + 1]
            + (lam**3 - lam**2) * t[k + 1] * ds[:, None])


def test_straight_path_is_the_plain_translation_tool():
    c, u, T = np.array([0.1, -0.2, 1.32]), np.array([0.3, 0.1, -1.0]), 0.3
    pts = c + np.linspace(0, 1, 5)[:, None] * (u * T)
    for kind in ("translate", "rotate"):  # straight spine: constant frames, ω = 0
        f = fields.along_path(pts, 0.3, T, kind=kind)
        g = fields.translation(c, 0.3, u)
        x = ball(c + 0.5 * u * T, 0.8, 2000)
        for t in RNG.uniform(0, T, 5):
            np.testing.assert_allclose(f(x, t), g(x, t), rtol=0, atol=1e-13)
        # 4 equal segments, 32 steps: the same RK4 steps as the plain tool
        np.testing.assert_allclose(spinal.advect(x, f, T, 32), spinal.advect(x, g, T, 32),
                                   rtol=0, atol=1e-13)
    assert not f(x, -0.01).any() and not f(x, T + 0.01).any()  # at rest outside [t0, t0+T]
    np.testing.assert_allclose(f.breakpoints(), np.linspace(0, T, 5), atol=1e-15)
    # carried region = von Funck's sphere
    f = fields.along_path(pts, 0.3, T, tool="carry", reach=0.4)
    g = fields.sphere(c, 0.3, u, reach=0.4)
    np.testing.assert_allclose(f(x, 0.1), g(x, 0.1), rtol=0, atol=1e-13)


def test_carried_region_follows_the_curved_spine():
    pts = arc(12)
    F = spinal.frames(pts)
    T, t0 = 0.8, 0.25
    f = fields.along_path(pts, 0.2, T, tool="carry", t0=t0)
    s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]
    inside = pts[0] + ball([0, 0, 0], 0.18, 50)  # rigidly carried: v = ȯ(t) exactly
    # at rest before t0; then every interior point is translated by o(t) − o(0)
    np.testing.assert_array_equal(spinal.advect(inside, f, t0, 3), inside)
    for frac in (0.37, 0.5, 1.0):
        sig = frac * s[-1]
        o = hermite(pts, F, np.array([sig]))[0]
        x = spinal.advect(inside, f, frac * T, 8, t0=t0)
        # RK4 integrates the cubic ȯ(t) exactly when steps end at the sample times
        np.testing.assert_allclose(x, inside + (o - pts[0]), rtol=0, atol=1e-12)
    np.testing.assert_allclose(spinal.advect(pts[:1], f, T, t0=t0), pts[-1:], atol=1e-12)


def test_divergence_free_at_random_points_and_times():
    pts = arc(9)
    T = 1.0
    for kind, tool, rate in (("translate", "push", 0), ("rotate", "push", 0),
                             ("twist", "push", 3.0), ("bend", "carry", 5.0),
                             ("translate", "carry", 0)):
        f = fields.along_path(pts, 0.25, T, kind=kind, tool=tool, rate=rate, falloff_power=4)
        for t in RNG.uniform(0, T, 4):
            sig = t / T * np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()
            o = hermite(pts, spinal.frames(pts), np.array([sig]))[0]
            x = ball(o, 0.5, 1500)
            r = np.linalg.norm(x - o, axis=1)
            x = x[np.abs(r - 0.25) > 1e-3]  # C¹ kinks of the blends at ρ and ρ + R
            x = x[np.abs(np.linalg.norm(x - o, axis=1) - 0.5) > 1e-3]
            v = f(x, t)
            assert np.abs(v).max() > 0.1
            assert np.abs(div(lambda y, t=t, f=f: f(y, t), x)).max() < 1e-6 * np.abs(v).max()


def test_push_tool_normal_velocity_matches_the_rigid_motion():
    """On the tool surface, translate + rotate gives the full rigid normal velocity (ȯ + ω×Y)·n
    with ȯ from the Hermite derivative; for a sphere ω×Y ⟂ n, so it is ȯ·n."""
    pts = arc(9)
    F = spinal.frames(pts)
    T = 0.7
    L = np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()
    f = fields.along_path(pts, 0.25, T, kind="rotate")
    for t in (0.1, 0.33, 0.6):
        sig = np.array([t / T * L])
        o = hermite(pts, F, sig)[0]
        odot = (hermite(pts, F, sig + 1e-6) - hermite(pts, F, sig - 1e-6))[0] / 2e-6 * (L / T)
        n = RNG.normal(size=(200, 3))
        n /= np.linalg.norm(n, axis=1)[:, None]
        v = f(o + n * (0.25 + 1e-12), t)
        np.testing.assert_allclose(np.einsum("ij,ij->i", v, n), n @ odot, atol=1e-7)


def test_rk4_is_fourth_order_with_steps_ending_at_the_samples(seed=7):
    """Away from the swept tube (no separatrix in front of the tool), 4th order when steps end
    at the sample times; plain equal steps straddle the jumps of ω and d²o/dt²."""
    pts = arc(7)
    L = np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()
    dense = hermite(pts, spinal.frames(pts), np.linspace(0, L, 2001))
    x = ball(pts[3], 0.5, 3000, np.random.default_rng(seed))
    x = x[np.linalg.norm(x[:, None] - dense[None], axis=2).min(axis=1) > 0.33][:300]
    for kind, tool, rate in (("translate", "push", 0), ("rotate", "push", 0),
                             ("twist", "push", 2.0), ("bend", "carry", 5.0)):
        f = fields.along_path(pts, 0.25, 1.0, kind=kind, tool=tool, rate=rate,
                              falloff_power=4)
        ref = spinal.advect(x, f, 1.0, 8192)
        err = [np.abs(spinal.advect(x, f, 1.0, n) - ref).max() for n in (64, 128, 256, 512)]
        ratios = np.divide(err[:-1], err[1:])
        # translate/rotate with p = 4 are C²: 16×; the rate-form swirls (and the C¹ blend of
        # "carry") are only C¹ at the edge of the moving support, which every path line
        # crosses: one O(h³) local error, so the ratio falls from ~16 towards 8
        lo = 13 if kind in ("translate", "rotate") else 7
        assert np.all((ratios > lo) & (ratios < 19)), (kind, err, ratios)
        plain = np.abs(spinal._core.advect(x, f, 0.0, 1 / 256, 256, "rk4") - ref).max()
        assert plain > 5 * err[2], (kind, plain, err[2])


def test_volume_of_a_40k_icosphere_pushed_along_a_curved_path():
    import igl.predicates

    V, Fc = icosphere(6)
    assert len(V) == 40962
    pts = arc(16)
    f = fields.along_path(pts, 0.3, 1.0, kind="rotate")
    V0 = V.copy()
    W = spinal.advect(V, f, 1.0)  # default steps, ending at the 15 segment ends
    np.testing.assert_array_equal(V, V0)
    steps = f.steps(1.0)
    ref = spinal.advect(V, f, 1.0, 4 * steps)
    (v0t, v0i), (vt, vi), (vrt, vri) = volumes(V, Fc), volumes(W, Fc), volumes(ref, Fc)
    for a, b in ((v0t, v0i), (vt, vi), (vrt, vri)):
        assert abs(a / b - 1) < 1e-12
    total, integration, mesh = vt / v0t - 1, vt / vrt - 1, vrt / v0t - 1
    # measured: total −1.96e-6 = integration 2e-8 + mesh −1.98e-6 (111 steps)
    assert abs(total) < 1e-4, (total, integration, mesh)
    assert abs(integration) < abs(mesh) / 30, (integration, mesh)
    V5, F5 = icosphere(5)  # the mesh error is O(edge²): 4× larger on 10k vertices
    (a, _), (b, _) = volumes(V5, F5), volumes(spinal.advect(V5, f, 1.0, 4 * steps), F5)
    assert 3.5 < (b / a - 1) / mesh < 4.5, (b / a - 1, mesh)
    assert np.linalg.norm(W - V, axis=1).max() > 0.1  # dented
    assert not igl.predicates.find_self_intersections(W, Fc, first_only=True)[0]
    o_end = pts[-1]
    assert (np.linalg.norm(W - o_end, axis=1) - 0.3).min() > 0  # nothing inside the tool


@pytest.mark.parametrize("kw, match", [
    ({"points": [[0, 0, 0]]}, "points"),
    ({"points": [[0, 0, 0], [0, 0, 0], [1, 0, 0]]}, "points"),
    ({"radius": 0}, "radius"),
    ({"duration": 0}, "duration"),
    ({"duration": np.inf}, "duration"),
    ({"kind": "spin"}, "kind"),
    ({"tool": "drill"}, "tool"),
    ({"frames": np.zeros((3, 3, 3))}, "frames"),
    ({"frames": np.tile(2 * np.eye(3), (3, 1, 1))}, "frames"),
    ({"reach": -1}, "reach"),
])
def test_bad_input(kw, match):
    args = {"points": [[0, 0, 0], [1, 0, 0], [2, 0.5, 0]], "radius": 0.2, "duration": 1.0}
    args.update(kw)
    with pytest.raises(ValueError, match=match):
        fields.along_path(args.pop("points"), args.pop("radius"), args.pop("duration"), **args)


def test_core_path_constructor_names_the_argument():
    """The compiled constructor checks the samples and frames itself (called here without
    the Python wrapper)."""
    pts = np.array([[0, 0, 0], [1, 0, 0], [2, 0.5, 0]], dtype=float)
    frames = spinal.frames(pts)
    args = {"radius": 0.2, "duration": 1.0, "kind": "translate", "tool": "push", "rate": 0.0,
            "t0": 0.0, "reach": None, "falloff_power": 2, "blend": "c1"}
    with pytest.raises(ValueError, match="^points: need at least 2"):
        spinal._core.field_path(pts[:1], frames[:1], args)
    rep = pts.copy()
    rep[2] = rep[1]
    with pytest.raises(ValueError, match="^points: consecutive samples 1 and 2 coincide"):
        spinal._core.field_path(rep, frames, args)
    bad = frames.copy()
    bad[1] *= 2
    with pytest.raises(ValueError, match="^frames: frame 1 is not a rotation"):
        spinal._core.field_path(pts, bad, args)
    with pytest.raises(ValueError, match="^duration"):
        spinal._core.field_path(pts, frames, {**args, "duration": -1.0})


# ---- contact stamper (Zheng's thesis §11.2.6) -----------------------------------------------

def test_stamper_keeps_the_volume_per_frame_and_stays_outside_the_tool():
    import igl.predicates

    V, Fc = icosphere(5)
    V0 = V.copy()
    c0, c1, rho = np.array([0, 0, 1.32]), np.array([0, 0, 1.1]), 0.3
    res = []
    for it in (0, 1, 2):
        m, r = spinal.stamp((V, Fc), c0, c1, rho, frames=10, iterations=it)
        W = np.asarray(m.vertices)
        (v0, _), (v1, _) = volumes(V, Fc), volumes(W, Fc)  # trimesh, independent of Rust
        np.testing.assert_allclose(r.relative_change, v1 / v0 - 1, rtol=1e-6, atol=1e-14)
        np.testing.assert_allclose(r.residual.sum(), v1 - v0, rtol=1e-6, atol=1e-13)
        assert r.dent.sum() > 0.02 and (r.contact > 0).all() and (r.time > 0).all()
        assert (np.linalg.norm(W - c1, axis=1) - rho).min() > -1e-12  # contact, no gap
        assert not igl.predicates.find_self_intersections(W, Fc, first_only=True)[0]
        res.append(np.abs(r.residual).max())
    np.testing.assert_array_equal(V, V0)
    # measured: 5.6e-5, 3.6e-7, 2.3e-9 (the dents total 0.0248 of a volume of 4.18)
    assert res[0] < 1e-4 and res[1] < res[0] / 30 and res[2] < res[1] / 30, res
    assert abs(r.relative_change) < 1e-8
    # the protrusion moves along the tool's divergence-free curl field (the snap is no flow)
    f = fields.translation(c1, rho, (c1 - c0) / np.linalg.norm(c1 - c0), moving=False)
    x = ball(c1, 0.6, 2000)
    x = x[np.abs(np.linalg.norm(x - c1, axis=1) - rho) > 1e-3]
    assert np.abs(div(f, x)).max() < 1e-7 * np.abs(f(x)).max() / rho


@pytest.mark.parametrize("kw, exc, match", [
    ({"end": [0, 0, 1.32]}, ValueError, "end"),
    ({"radius": 0}, ValueError, "radius"),
    ({"frames": 0}, ValueError, "frames"),
    ({"iterations": -1}, ValueError, "iterations"),
    ({"start": [0, np.nan, 1]}, ValueError, "start"),
    ({"mesh": "sphere"}, TypeError, "mesh"),
])
def test_stamper_bad_input(kw, exc, match):
    V, Fc = icosphere(2)
    args = {"mesh": (V, Fc), "start": [0, 0, 1.32], "end": [0, 0, 1.1], "radius": 0.3}
    args.update(kw)
    with pytest.raises(exc, match=match):
        spinal.stamp(args.pop("mesh"), args.pop("start"), args.pop("end"), args.pop("radius"),
                     **args)


# ---- volume-exact splitting (method="split") ------------------------------------------------

def test_split_is_volume_exact_pointwise_second_order_and_matches_the_mesh_floor():
    from spinal import _core

    c = np.array([0, 0, 1.32])
    rng = np.random.default_rng(5)
    d = rng.normal(size=(2000, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    # in the support, a step's displacement (≤ 0.04) away from the tool surface, where the
    # potential φ(d)(Y × u)/… has a gradient jump the directional sub-flows (unlike the exact
    # flow) may cross, and from the edge |d| = R where v is only C⁰ (p = 2) or C¹ (p = 3), so
    # the one-step map has no Jacobian to difference (measured there: 2e-3, 2e-8; p = 4: 3e-11)
    x = c + d * (0.35 + 0.2 * rng.random(2000))[:, None]
    h, eps = 0.3 / 16, 2e-5

    def det(f, method):  # 4th-order central differences of the one-step map

        def step(y):
            return _core.advect(y, f, 0.0, h, 1, method)

        cols = [(8 * (step(x + eps * e) - step(x - eps * e))
                 - (step(x + 2 * eps * e) - step(x - 2 * eps * e))) / (12 * eps)
                for e in np.eye(3)]
        return np.linalg.det(np.stack(cols, -1))

    for p in (2, 3, 4):
        f = fields.translation(c, 0.3, [0, 0, -1], falloff_power=p)
        e_split, e_rk4 = np.abs(det(f, "split") - 1).max(), np.abs(det(f, "rk4") - 1).max()
        # measured 2.6e-11 (the FD limit) against 0.9e-7 … 1.0e-6 for one RK4 step
        assert e_split < 1e-9
        assert e_rk4 > 1000 * e_split
    V, F = icosphere(5)
    f = fields.translation(c, 0.3, [0, 0, -1])
    ref = spinal.advect(V, f, 0.3, 4096)
    err = [np.abs(spinal.advect(V, f, 0.3, n, method="split") - ref).max() for n in (8, 16, 32)]
    ratios = np.divide(err[:-1], err[1:])
    assert np.all((ratios > 3.7) & (ratios < 4.3)), (err, ratios)  # 2nd order (RK4: 4th)
    # the mesh volume is the exact flow's (the O(edge²) floor) already at 8 steps
    v0, vref = volumes(V, F)[0], volumes(ref, F)[0]
    vs = volumes(spinal.advect(V, f, 0.3, 8, method="split"), F)[0]
    assert abs(vs / v0 - vref / v0) < 1e-6 and abs(vref / v0 - 1) > 1e-4
    with pytest.raises(ValueError, match="method"):
        spinal.advect(V, fields.twist([0, 0, 0], [0, 0, 1], 1.0, 1.0), 0.1, method="split")


def test_path_tool_progress_and_backwards():
    pts = arc(5)
    f = fields.along_path(pts, 0.25, 1.0, tool="carry")
    x = ball(pts[0], 0.2, 20)
    seen = []
    y = spinal.advect(x, f, 1.0, 8, progress=lambda d, n: seen.append((d, n)))
    # one core call for the 4 segments: the steps of all of them counted together, each
    # reported (fewer than 100 steps)
    total = seen[-1][1]
    assert total >= 8 and seen == [(d, total) for d in range(1, total + 1)]
    np.testing.assert_allclose(y, spinal.advect(x, f, 1.0, 8), rtol=0, atol=0)
    # backwards from t = 1 undoes it (carried rigidly: exact up to round-off)
    np.testing.assert_allclose(spinal.advect(y, f, -1.0, 8, t0=1.0), x, atol=1e-12)
