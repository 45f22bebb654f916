"""Strip of type I along a curved axis and free-form tools from a distance grid (Zheng's
thesis §11.2.1, §11.2.2, §11.2.5): spinal.fields.strip_curve, sdf_tool, mesh_tool.

Independent references: the clamped cubic spline of SciPy for the axis, the thesis's
``p = (1 − D) N·(X − c(X))``, ``q = (1 − D) B·(X − c(X))`` with double-reflection frames of
spinal.frames (smoothed by SciPy's RotationSpline) differentiated by finite differences; for the
grid tools SciPy's natural cubic splines applied axis by axis, the analytic sphere field, and
mesh volumes from trimesh and libigl.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation, RotationSpline
from test_deform import ball, blend, grad, icosphere, jacobian, volumes

import spinal
from spinal import _core, _fields_grid, fields

RNG = np.random.default_rng(11)

# ---- strip along a curved axis ---------------------------------------------------------------

TH = np.linspace(-0.8, 0.8, 12)
ARC = np.c_[np.sin(TH), 0.2 * np.sin(2 * TH), np.cos(TH)] * 1.05  # a bent, non-planar axis
RHO, RF, SPEED = 0.1, 0.15, 1.3


class Axis:
    """The axis as SciPy's clamped spline (end tangents of spinal.estimate_tangents) with its
    closest-point map and a smooth RMF from double reflection on 3001 spline samples."""

    def __init__(self, points):
        self.s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]
        t = spinal.estimate_tangents(points)
        self.cs = CubicSpline(self.s, points, bc_type=((1, t[0]), (1, t[-1])))
        self.ss = np.linspace(0, self.s[-1], 3001)
        frames = spinal.frames(self.cs(self.ss), self.cs(self.ss, 1))
        self.rmf = RotationSpline(self.ss, Rotation.from_matrix(frames))

    def foot(self, x):
        coarse = self.ss[::10]
        g = self.cs(coarse)
        u = coarse[np.argmin(((x[:, None] - g[None]) ** 2).sum(-1), axis=1)]
        for _ in range(40):  # Newton on (X − γ)·γ′ = 0, clamped to the axis
            g, g1, g2 = self.cs(u), self.cs(u, 1), self.cs(u, 2)
            w = x - g
            u = np.clip(u - (w * g1).sum(1) / ((w * g2).sum(1) - (g1 * g1).sum(1)), 0,
                        self.s[-1])
        return u

    def pq(self, x, rho, rf):
        u = self.foot(x)
        frame = self.rmf(u).as_matrix()
        y = x - self.cs(u)
        g = 1 - blend(np.linalg.norm(y, axis=1) - rho, rf)
        return (g * np.einsum("ij,ij->i", frame[:, :, 0], y),
                g * np.einsum("ij,ij->i", frame[:, :, 1], y))


AXIS = Axis(ARC)


def tube_points(axis, n, rho, rf, eps=1e-3, caps=True):
    """Random points in the support, away (eps) from the kinks r = ρ, r = ρ + R_f and the
    normal planes at the samples (where the axis' second derivative jumps)."""
    x = np.concatenate([ball(p, rho + rf, 4 * n // len(axis.s)) for p in axis.cs(axis.s)])
    u = axis.foot(x)
    r = np.linalg.norm(x - axis.cs(u), axis=1)
    keep = (r < rho + rf) & (np.abs(r - rho) > eps) & (np.abs(r - rho - rf) > eps)
    interior = (u > 0) & (u < axis.s[-1])
    for sk in axis.s:
        keep &= ~interior | (np.abs(u - sk) > eps)
    if caps:  # beyond the ends: keep away from the end planes
        for k, sk in ((0, 0.0), (-1, axis.s[-1])):
            t = axis.cs(sk, 1)
            keep &= np.abs((x - axis.cs(sk)) @ t) > eps
    return x[keep]


def test_strip_curve_is_grad_p_cross_grad_q_with_double_reflection_frames():
    """The closed form s (1 − D)(1 − D − rD′) T equals the thesis's ∇p × ∇q built from an
    independent spline, closest point and the double-reflection RMF, by finite differences
    (caps included)."""
    f = fields.strip_curve(ARC, RHO, SPEED, reach=RF)
    x = tube_points(AXIS, 1500, RHO, RF)
    u = AXIS.foot(x)
    assert ((u == 0) | (u == AXIS.s[-1])).sum() > 20  # both caps sampled
    v = f(x)
    g = grad(lambda X: np.stack(AXIS.pq(X, RHO, RF), axis=1), x, 1e-6)  # (n, 2, 3)
    ref = SPEED * np.cross(g[:, 0], g[:, 1])
    assert np.abs(ref - v).max() < 1e-8 * np.abs(v).max()


def test_strip_curve_closed_form_flow_along_the_axis_and_zero_flux():
    f = fields.strip_curve(ARC, RHO, SPEED, reach=RF)
    # inside the tube: exactly speed × the unit tangent of SciPy's spline at the closest point
    x = tube_points(AXIS, 3000, RHO, 0.0, caps=False)
    u = AXIS.foot(x)
    inner = (u > 0) & (u < AXIS.s[-1])
    t = AXIS.cs(u[inner], 1)
    t /= np.linalg.norm(t, axis=1)[:, None]
    assert inner.sum() > 300
    np.testing.assert_allclose(f(x[inner]), SPEED * t, atol=1e-13)
    # the net flux through a cross-section vanishes (the return flow outside the tube):
    # Gauss–Legendre in r (exact for the polynomial J(r) r), uniform in the angle
    for k in (3, 7):
        s0 = 0.5 * (AXIS.s[k] + AXIS.s[k + 1])
        c, t = AXIS.cs(s0), AXIS.cs(s0, 1)
        t /= np.linalg.norm(t)
        e1 = np.cross(t, [0.0, 1.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(t, e1)
        gx, gw = np.polynomial.legendre.leggauss(12)
        flux = []
        for a, b in ((0.0, RHO), (RHO, RHO + RF)):
            r = 0.5 * (b - a) * gx + 0.5 * (a + b)
            w = 0.5 * (b - a) * gw
            phi = np.linspace(0, 2 * np.pi, 64, endpoint=False)
            R_, P_ = np.meshgrid(r, phi, indexing="ij")
            X = c + (R_ * np.cos(P_)).reshape(-1, 1) * e1 + (R_ * np.sin(P_)).reshape(-1, 1) * e2
            vn = (f(X) @ t).reshape(R_.shape)
            flux.append(((vn * R_).mean(axis=1) * w).sum() * 2 * np.pi)
        inner = SPEED * np.pi * RHO**2
        assert abs(flux[0] / inner - 1) < 1e-12 and abs(sum(flux)) < 1e-12 * inner, flux
    # negative control: without the return flow (J = (1 − D)², still divergence-free inside
    # the tube, as is any J(r) T) the same quadrature finds a net flux
    r = 0.5 * RF * gx + RHO + 0.5 * RF
    wrong = (((1 - blend(r - RHO, RF)) ** 2) * r * 0.5 * RF * gw).sum() * 2 * np.pi * SPEED
    assert (inner + wrong) / inner > 0.1
    # a straight axis (uneven samples) gives the straight strip (the capsule field)
    a, b = np.array([0.1, -0.2, 0.3]), np.array([1.0, 0.4, -0.2])
    lam = np.array([0.0, 0.1, 0.35, 0.4, 0.8, 1.0])
    line = a + lam[:, None] * (b - a)
    unit = (b - a) / np.linalg.norm(b - a)
    x = ball(0.5 * (a + b), 1.0, 20000)
    for bl in ("c1", "linear"):
        g = fields.strip_curve(line, 0.2, -0.7, reach=0.25, blend=bl)
        h = fields.strip(a, b, 0.2, -0.7 * unit, reach=0.25, blend=bl)
        vg, vh = g(x), h(x)
        assert (np.linalg.norm(vh, axis=1) > 0.1).sum() > 1000
        np.testing.assert_allclose(vg, vh, atol=1e-14)
        np.testing.assert_allclose(spinal.advect(x[:500], g, 0.3, 9), spinal.advect(x[:500], h, 0.3, 9),
                                   atol=1e-13)


def test_strip_curve_is_divergence_free():
    f = fields.strip_curve(ARC, RHO, SPEED, reach=RF)
    x = tube_points(AXIS, 4000, RHO, RF)
    v = f(x)
    assert len(x) > 2000 and (np.linalg.norm(v, axis=1) > 1e-2).sum() > 1000
    d = np.trace(jacobian(f, x, h=1e-6), axis1=1, axis2=2)
    assert np.abs(d).max() < 1e-7 * np.abs(v).max() / RF


def test_volume_of_a_40k_icosphere_under_a_curved_strip():
    """The strip lies along an arc on the sphere's surface; default steps. Integration error
    from a 16×-steps reference, the rest is the O(edge²) mesh error (4× per subdivision)."""
    import igl.predicates

    th = np.linspace(-0.6, 0.6, 13)
    axis = np.c_[np.sin(th), 0.15 * np.sin(2 * th), np.cos(th)]
    f = fields.strip_curve(axis, 0.3, 1.0, reach=0.3)
    T = 0.2
    assert f.steps(T) == 7
    mesh = []
    for sub in (5, 6):
        V, F = icosphere(sub)
        V0 = V.copy()
        W = spinal.advect(V, f, T)
        np.testing.assert_array_equal(V, V0)
        ref = spinal.advect(V, f, T, 16 * f.steps(T))
        (v0t, v0i), (vt, vi), (vrt, vri) = volumes(V, F), volumes(W, F), volumes(ref, F)
        for a, b in ((v0t, v0i), (vt, vi), (vrt, vri)):
            assert abs(a / b - 1) < 1e-12  # trimesh and libigl agree
        total, integration, m = vt / v0t - 1, vt / vrt - 1, vrt / v0t - 1
        mesh.append(m)
        assert np.linalg.norm(W - V, axis=1).max() > 0.2
        assert abs(integration) < 1e-7 and abs(integration) < abs(m) / 100
        if sub == 6:
            assert len(V) == 40962 and abs(total) < 1e-4, total
            assert not igl.predicates.find_self_intersections(W, F, first_only=True)[0]
    assert 3.5 < mesh[0] / mesh[1] < 4.5, mesh


@pytest.mark.parametrize("kw, match", [
    ({"points": ARC[:1]}, "points: need at least 2"),
    ({"points": np.r_[ARC[:3], ARC[2:3], ARC[3:]]}, "points: consecutive samples 2 and 3"),
    ({"points": np.r_[ARC[:3], [[np.nan, 0, 0]]]}, "points: row 3 is not finite"),
    ({"points": ARC[:, :2]}, "points"),
    ({"radius": -0.1}, "radius"),
    ({"speed": np.inf}, "speed"),
    ({"speed": "1"}, "speed"),
    ({"reach": 0.0}, "reach"),
    ({"blend": "c2"}, "blend"),
    ({"radius": 0.5, "reach": 0.5}, "points: the axis bends too sharply"),
    ({"points": np.c_[np.cos(np.linspace(0, 5.5, 40)), np.sin(np.linspace(0, 5.5, 40)),
                       np.zeros(40)], "radius": 0.2, "reach": 0.2},
     "points: the axis comes within"),
])
def test_strip_curve_bad_input(kw, match):
    args = {"points": ARC, "radius": RHO, "speed": SPEED, "reach": RF} | kw
    points = args.pop("points")
    before = np.array(points, copy=True)
    with pytest.raises((ValueError, TypeError), match=f"^{match}"):
        fields.strip_curve(points, args.pop("radius"), args.pop("speed"), **args)
    np.testing.assert_array_equal(points, before)  # inputs never modified


# ---- free-form tools from a distance grid ----------------------------------------------------

C = np.array([0.1, -0.2, 0.3])
U = np.array([0.3, -1.0, 0.5])


def sphere_grid(h, rho=0.4, reach=None, pad=6):
    reach = rho if reach is None else reach
    L = rho + reach + pad * h
    ax = np.arange(-L, L + h / 2, h)
    g = np.stack(np.meshgrid(ax, ax, ax, indexing="ij"), -1)
    return np.linalg.norm(g, axis=-1) - rho, C - L


def test_sampled_sphere_distance_reproduces_the_sphere_field_at_third_order():
    rho = 0.4
    ref = fields.sphere(C, rho, U, moving=False)
    x = ball(C, 2 * rho, 20000)
    r = np.linalg.norm(x - C, axis=1)
    x = x[(np.abs(r - rho) > 1e-3) & (np.abs(r - 2 * rho) > 1e-3)]
    vr = ref(x)
    errs = []
    for h in (0.05, 0.025, 0.0125):
        d, o = sphere_grid(h)
        f = fields.sdf_tool(d, o, h, U, moving=False)  # default centre and reach: C, ρ
        # the default centre and reach are C and ρ: the same field as when given
        given = fields.sdf_tool(d, o, h, U, moving=False, center=C, reach=rho)
        np.testing.assert_allclose(f(x), given(x), rtol=0, atol=1e-12)
        errs.append(np.abs(f(x) - vr).max() / np.abs(vr).max())
    orders = np.log2(np.divide(errs[:-1], errs[1:]))
    assert np.all((orders > 2.8) & (orders < 3.3)), (errs, orders)
    assert errs[-1] < 1e-6


def natural_spline_3d(axes, values, x):
    """SciPy's natural cubic splines, axis by axis (the same interpolant as the B-spline
    with natural end conditions, computed independently)."""
    out = []
    z = CubicSpline(axes[2], values, axis=2, bc_type="natural")
    for p in x:
        a = z(p[2])
        a = CubicSpline(axes[1], a, axis=1, bc_type="natural")(p[1])
        out.append(CubicSpline(axes[0], a, axis=0, bc_type="natural")(p[0]))
    return np.array(out)


def test_grid_tool_is_grad_p_cross_grad_q_of_the_interpolated_distance():
    """Any smooth samples (here not even a distance): v = ∇p × ∇q with p, q from SciPy's
    natural-spline interpolant of the samples, by finite differences."""
    h = 0.06
    ax = [C[i] + np.arange(-0.9, 0.9 + h / 2, h) for i in range(3)]
    y = np.stack(np.meshgrid(*ax, indexing="ij"), -1) - C
    d = (np.sqrt((y[..., 0] / 1.2) ** 2 + y[..., 1] ** 2 + (y[..., 2] / 0.8) ** 2) - 0.3
         + 0.03 * np.sin(7 * y[..., 0]))
    cc = C + [0.02, 0.01, -0.03]
    n = np.cross(U, [1, 0.3, 0.2])
    n /= np.linalg.norm(n)
    b = np.cross(U / np.linalg.norm(U), n)
    x = ball(C, 0.6, 400)
    dd = natural_spline_3d(ax, d, x)
    for bl in ("c1", "linear"):
        f = fields.sdf_tool(d, [a[0] for a in ax], h, U, center=cc, reach=0.3, moving=False,
                            blend=bl)
        xs = x[(dd > 1e-3) & (dd < 0.3 - 1e-3)][:80]
        v = f(xs)

        def p(X, bl=bl):
            return (1 - blend(natural_spline_3d(ax, d, X), 0.3, bl == "linear")) * ((X - cc) @ n)

        def q(X, bl=bl):
            return (1 - blend(natural_spline_3d(ax, d, X), 0.3, bl == "linear")) * ((X - cc) @ b)

        ref = np.linalg.norm(U) * np.cross(grad(p, xs, 1e-6), grad(q, xs, 1e-6))
        assert np.abs(ref - v).max() < 1e-8 * np.abs(v).max()
        # rigid inside (d < 0), zero beyond the reach
        inside, out = x[dd < -1e-3], x[dd > 0.3 + 1e-3]
        np.testing.assert_array_equal(f(inside), np.broadcast_to(U, inside.shape))
        assert not f(out).any()


def torus_mesh():
    import trimesh

    m = trimesh.creation.torus(major_radius=0.35, minor_radius=0.15, major_sections=48,
                               minor_sections=24)
    return np.asarray(m.vertices) + C, np.asarray(m.faces)


def test_mesh_tools_are_divergence_free_and_move_with_the_tool():
    import igl

    V, F = torus_mesh()
    f = fields.mesh_tool((V, F), U, reach=0.2)
    x = ball(C, 0.8, 20000)
    d = igl.signed_distance(x, V, F)[0]
    x = x[(np.abs(d) > 5e-3) & (np.abs(d - 0.2) > 5e-3)]
    v = f(x)
    assert (np.linalg.norm(v, axis=1) > 1e-2).sum() > 2000
    # h = 1e-6: the interpolant's third derivatives jump across cell faces (C² B-spline)
    dv = np.trace(jacobian(f, x, h=1e-6), axis1=1, axis2=2)
    assert np.abs(dv).max() < 1e-7 * np.abs(v).max() / 0.2
    np.testing.assert_allclose(f(x + 0.3 * U, t=0.3), v, atol=1e-13)
    # a sphere mesh converges to the sphere field as the mesh is refined, at first order in
    # the edge length: above each face the mesh's distance gradient is the face normal, tilted
    # by O(edge/ρ) from the radius at every distance (the grid only smooths sub-cell facets)
    # (points of their own generator, many enough that the largest error is near the
    # field's: the max over 5,000 points of the shared generator gave ratios 2.0–3.1)
    ref = fields.sphere(C, 0.3, U, moving=False)
    rng = np.random.default_rng(0)
    d = rng.normal(size=(40000, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    x = C + d * (0.6 * rng.random(40000) ** (1 / 3))[:, None]
    r = np.linalg.norm(x - C, axis=1)
    x = x[(r > 0.31) & (r < 0.59)]
    errs = []
    for sub in (2, 3, 4):
        S, G = icosphere(sub)
        g = fields.mesh_tool((0.3 * S + C, G), U, moving=False, resolution=80)
        errs.append(np.abs(g(x) - ref(x)).max())
    ratios = np.divide(errs[:-1], errs[1:])
    assert np.all((ratios > 1.6) & (ratios < 2.8)) and errs[-1] < 0.05, (errs, ratios)


def test_volume_of_a_40k_icosphere_under_a_mesh_tool():
    """von Funck's stroke of tests/deform/test_deform.py with the sphere given as a 2,562-vertex
    mesh (64-node grid): the same mesh floor, the integration error 3 orders below it."""
    import igl.predicates

    V, F = icosphere(6)
    S, G = icosphere(4)
    f = fields.mesh_tool((0.3 * S + [0, 0, 0.9], G), [1, 0, 0], reach=0.6, moving=False)
    T = 0.6
    W = spinal.advect(V, f, T)
    ref = spinal.advect(V, f, T, 16 * f.steps(T))
    (v0t, v0i), (vt, vi), (vrt, vri) = volumes(V, F), volumes(W, F), volumes(ref, F)
    for a, b in ((v0t, v0i), (vt, vi), (vrt, vri)):
        assert abs(a / b - 1) < 1e-12
    total, integration, mesh = vt / v0t - 1, vt / vrt - 1, vrt / v0t - 1
    assert abs(total) < 1e-4 and abs(integration) < abs(mesh) / 1000, (total, integration)
    assert abs(mesh / -6.23e-5 - 1) < 0.02  # the analytic sphere's floor (test_deform.py)
    assert np.linalg.norm(W - V, axis=1).max() > 0.3
    assert not igl.predicates.find_self_intersections(W, F, first_only=True)[0]
    # the same stroke with the analytic sphere: the paths agree within the faceting error
    peer = fields.sphere([0, 0, 0.9], 0.3, [1, 0, 0], reach=0.6, moving=False)
    assert np.abs(ref - spinal.advect(V, peer, T, 16 * f.steps(T))).max() < 5e-3


def test_sums_steps_and_lock_step_advection():
    d, o = sphere_grid(0.05)
    g = fields.sdf_tool(d, o, 0.05, U)
    s = fields.strip_curve(ARC, RHO, SPEED, reach=RF)
    x = np.r_[ball(C, 0.9, 300), ball(ARC[5], 0.3, 300)]
    np.testing.assert_array_equal((g + s)(x, 0.2), g(x, 0.2) + s(x, 0.2))
    np.testing.assert_array_equal(fields.sum([s, g])(x), s(x) + g(x))
    assert (g + s).max_speed == g.max_speed + s.max_speed
    assert (g + s).steps(0.5) == max(4, int(np.ceil(0.5 * 8 * (g + s).max_speed / RF)))
    assert s.max_speed == fields.sphere(C, RHO, [SPEED, 0, 0], reach=RF).max_speed
    # the grid's speed bound covers the field
    assert np.abs(np.linalg.norm(g(ball(C, 0.8, 5000)), axis=1)).max() <= g.max_speed
    # lock-step batches (any count, not a multiple of 16) = one point at a time
    y = x[:37]
    for f in (g, s, g + s):
        one = np.array([spinal.advect(p[None], f, 0.3, 7)[0] for p in y])
        np.testing.assert_array_equal(spinal.advect(y, f, 0.3, 7), one)
    assert "strip_curve" in repr(g + s) and "sdf_tool" in repr(g + s)


def test_grid_and_mesh_tool_bad_input():
    d, o = sphere_grid(0.05)
    ok = {"grid": d, "origin": o, "spacing": 0.05, "velocity": U}

    def call(**kw):
        a = ok | kw
        return fields.sdf_tool(a.pop("grid"), a.pop("origin"), a.pop("spacing"),
                               a.pop("velocity"), **a)

    bad = d.copy()
    bad[3, 4, 5] = np.nan
    for kw, exc, match in [
        ({"grid": bad}, ValueError, r"grid: value at node \(3, 4, 5\) is not finite"),
        ({"grid": d[0]}, ValueError, "grid: expected a 3-D array"),
        ({"grid": d[:5]}, ValueError, "grid: expected a 3-D array"),
        ({"grid": d + 1.0}, ValueError, "grid: no node is inside"),
        ({"spacing": -0.05}, ValueError, "spacing"),
        ({"spacing": 0.2, "reach": 0.5}, ValueError, "spacing: grid too coarse"),
        ({"reach": 0.6}, ValueError, "grid: the field's support"),
        ({"origin": [0, 0]}, ValueError, "origin"),
        ({"velocity": [0, np.nan, 0]}, ValueError, "velocity"),
        ({"center": [0, 0, np.inf]}, ValueError, "center"),
        ({"blend": "x"}, ValueError, "blend"),
    ]:
        with pytest.raises(exc, match=f"^{match}"):
            call(**kw)
    V, F = icosphere(2)
    V0, F0 = V.copy(), F.copy()
    for mesh, kw, exc, match in [
        ((V, F[1:]), {}, ValueError, "mesh: not watertight"),
        ((V, np.r_[F[:1, ::-1], F[1:]]), {}, ValueError, "mesh: faces are not consistently"),
        ((V, F[:, ::-1]), {}, ValueError, "mesh: encloses a non-positive volume"),
        ((np.r_[V[:-1], [[np.nan, 0, 0]]], F), {}, ValueError, "mesh: vertices must be finite"),
        ("mesh", {}, TypeError, "mesh"),
        ((V, F), {"resolution": 20}, ValueError, "resolution: grid too coarse"),
        ((V, F), {"resolution": 10}, ValueError, "resolution: must be in"),
        ((V, F), {"resolution": 64.0}, TypeError, "resolution"),
        ((V, F), {"reach": -1.0}, ValueError, "reach"),
        ((V, F), {"reach": 0.05}, ValueError, "resolution: grid too coarse"),
    ]:
        with pytest.raises(exc, match=f"^{match}"):
            fields.mesh_tool(mesh, U, **kw)
    np.testing.assert_array_equal(V, V0)
    np.testing.assert_array_equal(F, F0)


def test_core_strip_and_grid_constructors_refuse_bad_input():
    """The compiled constructors check the axis and the grid themselves (called here without
    the Python wrappers), naming the argument, never panicking."""
    from spinal._fields_grid import _spline_prefilter

    x = np.ascontiguousarray(ARC)
    ok = (RHO, SPEED, RF, "c1")
    _core.field_strip_curve(x, *ok)
    rep = x.copy()
    rep[3] = rep[2]
    with pytest.raises(ValueError, match="^points: consecutive samples 2 and 3 coincide"):
        _core.field_strip_curve(rep, *ok)
    with pytest.raises(ValueError, match="^points: the axis bends too sharply"):
        _core.field_strip_curve(0.2 * x, *ok)
    with pytest.raises(ValueError, match="^radius"):
        _core.field_strip_curve(x, -RHO, SPEED, RF, "c1")
    with pytest.raises(ValueError, match="^speed"):
        _core.field_strip_curve(x, RHO, np.nan, RF, "c1")
    d, o = sphere_grid(0.05)
    coef = np.ascontiguousarray(_spline_prefilter(d))
    grid = {"origin": o, "spacing": 0.05, "velocity": U, "center": C, "reach": 0.4,
            "blend": "c1", "moving": True, "name": "sdf_tool"}
    _core.field_grid(coef, grid)
    with pytest.raises(ValueError, match="^grid: the field's support"):
        _core.field_grid(coef, {**grid, "reach": 2.0})
    with pytest.raises(ValueError, match="^spacing: grid too coarse"):
        _core.field_grid(coef, {**grid, "reach": 0.1})
    bad = coef.copy()
    bad[3, 3, 3] = np.nan
    with pytest.raises(ValueError, match="^grid"):
        _core.field_grid(bad, grid)
    with pytest.raises(ValueError, match="^grid"):
        _core.field_grid(coef[:4, :4, :4].copy(), grid)


def _prefilter_numpy(values):
    """The natural cubic B-spline prefilter in NumPy, axis by axis (Thomas algorithm over
    whole planes): the formulation the core reproduces operation by operation."""
    c = values
    for axis in range(3):
        a = np.moveaxis(c, axis, 0)
        n = a.shape[0]
        out = np.empty((n + 2,) + a.shape[1:])
        out[1], out[n] = a[0], a[-1]
        rhs = 6 * a[1:-1].copy()
        rhs[0] -= a[0]
        rhs[-1] -= a[-1]
        k = n - 2
        cp = np.zeros(k)
        cp[0] = 0.25
        rhs[0] *= 0.25
        for i in range(1, k):
            w = 4 - cp[i - 1]
            cp[i] = 1 / w
            rhs[i] = (rhs[i] - rhs[i - 1]) / w
        for i in range(k - 2, -1, -1):
            rhs[i] -= cp[i] * rhs[i + 1]
        out[2:n] = rhs
        out[0] = 2 * out[1] - out[2]
        out[n + 1] = 2 * out[n] - out[n - 1]
        c = np.moveaxis(out, 0, axis)
    return np.ascontiguousarray(c)


@pytest.mark.parametrize("shape", [(4, 4, 4), (5, 9, 4), (23, 7, 31), (64, 40, 52)])
def test_grid_coefficients_interpolate_and_match_the_numpy_formulation(shape):
    """The core's B-spline coefficients (parallel, line by line) have the bits of the NumPy
    formulation, and the spline they define passes through the samples: at a node the
    uniform cubic B-spline is (c_{i-1} + 4c_i + c_{i+1})/6 along each axis."""
    d = np.random.default_rng(sum(shape)).normal(size=shape)
    c = _fields_grid._spline_prefilter(d)
    assert c.shape == tuple(k + 2 for k in shape)
    np.testing.assert_array_equal(c, _prefilter_numpy(d))
    for axis in range(3):
        c = np.moveaxis(c, axis, 0)
        c = (c[:-2] + 4 * c[1:-1] + c[2:]) / 6
        c = np.moveaxis(c, 0, axis)
    np.testing.assert_allclose(c, d, rtol=0, atol=1e-12)
    # the input is not modified
    np.testing.assert_array_equal(d, np.random.default_rng(sum(shape)).normal(size=shape))


def test_grid_coefficients_refuse_small_grids():
    with pytest.raises(ValueError, match=r"^grid: expected at least 4 nodes per axis"):
        _core.field_grid_coefficients(np.zeros((3, 8, 8)))
