"""Profile (moulding) surfaces: spinal.profile_surface (Mäurer & Jüttler 1999, §2.2–2.3).

Closed forms (torus, the developable ribbon of a helix), finite differences of the explicit
surface for the exact PH path, libigl's discrete curvatures with a measured order, the
parabolic lines of the paper's Fig. 2 construction against its equation (14), singular
points against its condition (9), convexity against Cor. 9, and refused input."""

from __future__ import annotations

import numpy as np
import pytest

import spinal
from spinal import curves, ph

R, RT = 2.0, 0.5  # torus: spine (centre-line) radius, tube radius


def torus_closed_form(theta):
    """K and H of the torus at the angle θ from the outward direction (outward normal,
    II = X_ij · N)."""
    c = np.cos(theta)
    K = c / (RT * (R + RT * c))
    H = -(R + 2 * RT * c) / (2 * RT * (R + RT * c))
    return K, H


def fd_curvatures(X, u, v, hu, hv):
    """K, H, normal of the explicit surface X(u, v) (arrays of one shape -> (..., 3)) by
    4th-order central differences; normal X_v × X_u / |·| (the orientation of
    ProfileSurface.normals where μ > 0)."""
    def d1(f, x, h):
        return (-f(x + 2 * h) + 8 * f(x + h) - 8 * f(x - h) + f(x - 2 * h)) / (12 * h)

    def d2(f, x, h):
        return (-f(x + 2 * h) + 16 * f(x + h) - 30 * f(x) + 16 * f(x - h) - f(x - 2 * h)) / (
            12 * h * h)

    Xu = d1(lambda w: X(w, v), u, hu)
    Xv = d1(lambda w: X(u, w), v, hv)
    Xuu = d2(lambda w: X(w, v), u, hu)
    Xvv = d2(lambda w: X(u, w), v, hv)
    Xuv = d1(lambda w: d1(lambda z: X(z, w), u, hu), v, hv)
    N = np.cross(Xv, Xu)
    N /= np.linalg.norm(N, axis=-1, keepdims=True)

    def dot(p, q):
        return np.einsum("...i,...i->...", p, q)

    E, F, G = dot(Xu, Xu), dot(Xu, Xv), dot(Xv, Xv)
    L, M, Nn = dot(Xuu, N), dot(Xuv, N), dot(Xvv, N)
    W = E * G - F * F
    return (L * Nn - M * M) / W, (E * Nn - 2 * F * M + G * L) / (2 * W), N


# ---------------------------------------------------------------------------------------
# closed forms


def test_torus_analytic_spine_and_profile_closed_form():
    u = np.linspace(0, 2 * np.pi, 60)
    v = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    ps = spinal.profile_surface(curves.Helix(a=R, b=0.0), curves.Helix(a=RT, b=0.0), u=u,
                                v=v, profile_closed=True)
    # r is the principal normal (towards the axis), so the profile's angle from the
    # outward direction is π − v
    np.testing.assert_allclose(ps.frames[:, :, 0], -curves.Helix(a=R, b=0.0).point(u) / R,
                               atol=1e-12)
    K, H = torus_closed_form(np.pi - v)
    np.testing.assert_allclose(ps.gaussian, np.broadcast_to(K, ps.gaussian.shape), atol=1e-12)
    np.testing.assert_allclose(ps.mean, np.broadcast_to(H, ps.mean.shape), atol=1e-12)
    np.testing.assert_allclose(ps.k1 * ps.k2, ps.gaussian, atol=1e-12)
    assert np.all(ps.k1 >= ps.k2)
    # the profile direction has curvature −1/r (outward normal), the other one is Meusnier's
    np.testing.assert_allclose(ps.curvature_v, -1 / RT, rtol=1e-12)
    # outward unit normals, in the normal plane
    centre = curves.Helix(a=R, b=0.0).point(u)[:, None, :]
    out = (ps.points - centre) / RT
    np.testing.assert_allclose(ps.normals, out, atol=1e-12)
    np.testing.assert_allclose(np.abs(ps.mu - (1 - RT * np.cos(v) / R)), 0, atol=1e-12)
    assert ps.singularity_free and not ps.convex
    # parabolic lines: the top and bottom circles θ = ±π/2 (v = π/2, 3π/2), along all of u
    lines = ps.parabolic_lines()
    assert len(lines) == 2
    got = sorted(float(np.mean(line[:, 1])) for line in lines)
    np.testing.assert_allclose(got, [np.pi / 2, 3 * np.pi / 2], atol=1e-12)
    for line in lines:
        np.testing.assert_allclose(line[:, 1], line[0, 1], atol=1e-12)
        assert line[:, 0].min() == u[0] and line[:, 0].max() == u[-1]
        p3 = ps.parabolic_lines("points")[0]
        np.testing.assert_allclose(np.abs(p3[:, 2]), RT, atol=1e-12)  # z = ±r
    # the sign field, as point data of the mesh of the grid
    flat = np.abs(np.cos(v)) < 1e-9  # v = π/2, 3π/2: K = 0 up to rounding, sign 0
    assert flat.sum() == 2 and np.all(ps.parabolic_sign[:, flat] == 0)
    np.testing.assert_array_equal(ps.parabolic_sign[:, ~flat], np.sign(ps.gaussian[:, ~flat]))
    m = ps.mesh()
    np.testing.assert_array_equal(m.point_data["parabolic_sign"], ps.parabolic_sign.ravel())
    assert len(m.vertices) == 60 * 48 and len(m.faces) == 2 * 59 * 48


def test_spindle_torus_poles_are_singular_points_not_parabolic_lines():
    """R < r: the profile crosses the curvature axis (the torus' axis) where
    R + r cos θ = 0; K has poles there (sign change through ∞), its zeros stay θ = ±π/2."""
    Rs, rs = 1.0, 1.5
    v = np.linspace(0, 2 * np.pi, 61, endpoint=False) + 0.01
    ps = spinal.profile_surface(curves.Helix(a=Rs, b=0.0), curves.Helix(a=rs, b=0.0),
                                u=40, v=v, profile_closed=True)
    th = np.pi - v
    np.testing.assert_allclose(ps.gaussian[0], np.cos(th) / (rs * (Rs + rs * np.cos(th))),
                               rtol=1e-10)
    assert not ps.singularity_free
    sing = ps.singular_points
    assert len(sing) == 2 * 40  # two crossings of the axis on every ring
    np.testing.assert_allclose(np.cos(np.pi - sing[:, 1]), -Rs / rs, atol=1e-3)  # 6.6e-4
    lines = ps.parabolic_lines()
    assert len(lines) == 2
    np.testing.assert_allclose(np.cos(np.concatenate(lines)[:, 1]), 0, atol=1e-4)  # 1.6e-5


def test_sign_field_is_point_data_of_the_sweep_of_the_same_samples():
    u = np.linspace(0, 4 * np.pi, 200)
    pts = np.c_[np.cos(u), np.sin(u), 0.2 * u]
    a = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    prof = 0.1 * np.c_[np.cos(a), 0.5 * np.sin(a)]
    for closed_prof, p in ((True, prof), (False, prof[:13])):
        ps = spinal.profile_surface(pts, p, profile_closed=closed_prof)
        swept = spinal.sweep(pts, p, frames=ps.frames, caps=False, miter_limit=1.0,
                             profile_closed=closed_prof)
        np.testing.assert_allclose(swept.vertices, ps.points.reshape(-1, 3), atol=1e-15)
        swept.point_data["parabolic_sign"] = ps.parabolic_sign.ravel()
        grid = ps.mesh()
        np.testing.assert_array_equal(grid.vertices, ps.points.reshape(-1, 3))
        assert grid.is_watertight is False and len(grid.faces) == len(swept.faces)
        V, Fc = grid.vertices, grid.faces
        fn = np.cross(V[Fc[:, 1]] - V[Fc[:, 0]], V[Fc[:, 2]] - V[Fc[:, 0]])
        assert np.all(np.einsum("ij,ij->i", fn, grid.normals[Fc].sum(axis=1)) > 0)


def test_torus_from_samples_is_exact_on_circles():
    """Sampled spine and profile: the circle through three samples is exact on circles."""
    u = np.linspace(0, 2 * np.pi, 90, endpoint=False)
    v = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    pts = np.c_[R * np.cos(u), R * np.sin(u), 0 * u]
    prof = np.c_[RT * np.cos(v), RT * np.sin(v)]
    ps = spinal.profile_surface(pts, prof, closed=True, profile_closed=True)
    K, H = torus_closed_form(np.pi - v)
    np.testing.assert_allclose(ps.gaussian, np.broadcast_to(K, ps.gaussian.shape), atol=1e-11)
    np.testing.assert_allclose(ps.mean, np.broadcast_to(H, ps.mean.shape), atol=1e-11)
    np.testing.assert_allclose(ps.u[1], 2 * R * np.sin(np.pi / 90), rtol=1e-14)  # arc length
    np.testing.assert_allclose(ps.profile_curvature, 1 / RT, rtol=1e-12)


def _ribbon(n_u=81, n_v=21, gamma=0.7, width=0.6):
    helix = curves.Helix(a=1.0, b=0.5)
    u = np.linspace(0.0, 4.0, n_u)
    prof = curves.Polynomial([[0, 0, 0], [np.cos(gamma), np.sin(gamma), 0]],
                             domain=(-width, width))
    v = np.linspace(-width, width, n_v)
    F = helix.rmf(u)
    return helix, u, v, prof, F


def test_helix_ribbon_is_developable_with_the_closed_form_mean_curvature():
    """A straight profile on the RMF of a helix: MJ Prop. 2 (K ≡ 0) and
    H = κ sin(Ω + γ)/(2(1 − vκ cos(Ω + γ))), Ω = −τ c u; checked against finite differences
    of the explicit surface too."""
    helix, u, v, prof, F = _ribbon()
    ps = spinal.profile_surface(helix, prof, u=u, v=v, frames=F)
    kappa, tau, c = 1 / 1.25, 0.5 / 1.25, np.sqrt(1.25)
    om = (-tau * c * u)[:, None]
    g = 0.7
    H = kappa * np.sin(om + g) / (2 * (1 - v[None] * kappa * np.cos(om + g)))
    np.testing.assert_allclose(ps.gaussian, 0, atol=1e-14)
    np.testing.assert_allclose(ps.mean, H, rtol=1e-12, atol=1e-14)
    assert np.all(ps.parabolic_sign == 0) and ps.parabolic_lines() == []
    np.testing.assert_allclose(ps.spine_curvature[:, 0], kappa * np.cos(om[:, 0]), atol=1e-14)

    def X(uu, vv):
        shape = np.broadcast(uu, vv).shape
        uu, vv = np.broadcast_to(uu, shape).ravel(), np.broadcast_to(vv, shape).ravel()
        order = np.argsort(uu, kind="stable")
        Fr = np.empty((len(uu), 3, 3))
        Fr[order] = helix.rmf(np.r_[0.0, uu[order]])[1:]  # the angle is set at u = 0
        p = helix.point(uu) + vv[:, None] * (np.cos(g) * Fr[:, :, 0] + np.sin(g) * Fr[:, :, 1])
        return p.reshape(*shape, 3)

    uu, vv = np.meshgrid(u[1:-1:8], v[1:-1:4], indexing="ij")
    Kf, Hf, Nf = fd_curvatures(X, uu, vv, 1e-3, 1e-3)
    np.testing.assert_allclose(Kf, 0, atol=1e-7)
    np.testing.assert_allclose(ps.mean[1:-1:8, 1:-1:4], Hf, atol=1e-7)
    np.testing.assert_allclose(ps.normals[1:-1:8, 1:-1:4], Nf, atol=1e-9)


def test_helix_ribbon_from_samples_converges_at_second_order():
    """The sampled path: curvature vectors from circles through three samples (2nd order)."""
    errs = []
    for n in (41, 81, 161):
        helix, u, v, prof, F = _ribbon(n_u=n)
        exact = spinal.profile_surface(helix, prof, u=u, v=v, frames=F)
        pts = helix.point(u)
        ps = spinal.profile_surface(pts, prof.point(v)[:, :2], frames=F)
        np.testing.assert_allclose(ps.gaussian, 0, atol=1e-12)
        errs.append(np.abs(ps.mean - exact.mean).max())
    orders = np.log2(np.array(errs[:-1]) / errs[1:])
    assert np.all(orders > 1.8), (errs, orders)
    assert errs[-1] < 1e-4


def test_sampled_profile_converges_at_second_order_ends_included():
    """Tangents and signed curvature of a sampled open profile (circles through three
    samples; at the ends the end circle's tangent and the curvature extrapolated in arc
    length) against the exact ones of the Bézier section, at the same samples."""
    section = curves.Bezier([[0.0, 0.0, 0], [0.1, 0.2, 0], [0.25, -0.1, 0], [0.3, 0.1, 0]])
    pts = curves.Helix(a=1.0, b=0.5).point(np.linspace(0, 1, 9))
    errs = []
    for n in (41, 81, 161):
        v = np.linspace(0, 1, n)
        exact = spinal.profile_surface(pts, section, v=v)
        ps = spinal.profile_surface(pts, section.point(v)[:, :2])
        ek = np.abs(ps.profile_curvature - exact.profile_curvature)
        et = np.abs(ps.profile_tangents - exact.profile_tangents).max(axis=1)
        errs.append([ek[[0, -1]].max(), ek[1:-1].max(), et[[0, -1]].max(), et[1:-1].max()])
    errs = np.array(errs)
    orders = np.log2(errs[:-1] / errs[1:])
    assert np.all(orders > 1.8), (errs, orders)


def test_closed_spine_uses_the_rmf_not_the_closed_up_frames():
    """A torus knot (closing angle −2.88): closed=True drops the repeated first point (equal
    up to rounding), estimates across the seam and uses the RMF from row 0; frames that
    spread the closing angle (spinal.frames(..., closed=True)) twist, and are refused."""
    knot = curves.TorusKnot().sample(1025)
    assert not np.array_equal(knot[0], knot[-1])  # the same point up to rounding
    a = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    prof = 0.02 * np.c_[np.cos(a), np.sin(a)]
    ps = spinal.profile_surface(knot, prof, closed=True, profile_closed=True)
    assert ps.u.shape == (1024,) and ps.singularity_free
    F = spinal.frames(knot[:-1], spinal.estimate_tangents(knot[:-1], closed=True))
    np.testing.assert_allclose(ps.frames, F, atol=1e-15)
    # the seam: the curvature there comes from the neighbours across it, like everywhere
    kn = np.linalg.norm(ps.spine_curvature, axis=1)
    exact = curves.TorusKnot().curvature(np.linspace(0, 2 * np.pi, 1025)[:-1])
    err = np.abs(kn / exact - 1)
    assert err.max() < 2.5e-4  # 1.7e-4 measured: 2nd order in a non-uniform spacing
    assert err[[0, -1]].max() < 1e-4  # 3.8e-5 (an open spine's ends: 4.1e-4, extrapolated)
    with pytest.raises(ValueError, match="^frames: not rotation-minimising"):
        spinal.profile_surface(knot, prof, closed=True, profile_closed=True,
                               frames=spinal.frames(knot[:-1], closed=True))


def test_analytic_spine_default_rk4_frames_converge_at_fourth_order():
    errs = []
    for n in (41, 81, 161):
        helix, u, v, prof, F = _ribbon(n_u=n)
        exact = spinal.profile_surface(helix, prof, u=u, v=v, frames=F)
        rk4 = spinal.profile_surface(helix, prof, u=u, v=v)
        errs.append(np.abs(rk4.mean - exact.mean).max())
    orders = np.log2(np.array(errs[:-1]) / errs[1:])
    assert np.all(orders > 3.7), (errs, orders)


def test_twisted_frames_are_refused():
    helix, u, v, prof, _ = _ribbon()
    frenet = helix.frenet(u)  # columns (N, B, T): it turns about t at the torsion's rate
    with pytest.raises(ValueError, match="^frames: not rotation-minimising"):
        spinal.profile_surface(helix, prof, u=u, v=v, frames=frenet)
    # and spinal.frames' default is accepted for the samples
    pts = helix.point(u)
    spinal.profile_surface(pts, prof.point(v)[:, :2], frames=spinal.frames(pts))


# ---------------------------------------------------------------------------------------
# the exact PH path against finite differences


def _ph_spline():
    return ph.fit(curves.Helix(a=1.0, b=0.5, turns=0.75), segments=3)


SECTION = curves.Bezier([[0.0, 0.05, 0], [0.15, 0.25, 0], [0.3, -0.2, 0], [0.4, 0.05, 0]])


def test_ph_spline_exact_path_against_finite_differences():
    sp = _ph_spline()
    u = np.linspace(0.1, 0.9, 9) + 1.0  # inside cubic 1 (the spline is only G¹ at joints)
    v = np.linspace(0.05, 0.95, 10)
    ps = spinal.profile_surface(sp, SECTION, u=u, v=v)

    def X(uu, vv):
        shape = np.broadcast(uu, vv).shape
        uu, vv = np.broadcast_to(uu, shape).ravel(), np.broadcast_to(vv, shape).ravel()
        Fr = sp.rmf(uu, exact=True)
        c = SECTION.point(vv)
        p = sp.evaluate(uu) + c[:, :1] * Fr[:, :, 0] + c[:, 1:2] * Fr[:, :, 1]
        return p.reshape(*shape, 3)

    uu, vv = np.meshgrid(u, v, indexing="ij")
    Kf, Hf, Nf = fd_curvatures(X, uu, vv, 1e-3, 1e-3)
    scale = np.abs(ps.gaussian).max()
    np.testing.assert_allclose(ps.gaussian, Kf, atol=1e-7 * scale)
    np.testing.assert_allclose(ps.mean, Hf, atol=1e-7 * np.abs(ps.mean).max())
    np.testing.assert_allclose(ps.normals, Nf, atol=1e-8)
    np.testing.assert_allclose(ps.points, X(uu, vv), atol=1e-15)
    # MJ Prop. 3: the parameter lines are lines of curvature (d1 ⟂ d2, both ⟂ N)
    np.testing.assert_allclose(np.einsum("...i,...i", ps.d1, ps.d2), 0, atol=1e-15)
    np.testing.assert_allclose(np.einsum("...i,...i", ps.d1, ps.normals), 0, atol=1e-15)
    # the spine's curvature is MJ's κ = 6 L₂ sθ / σ², its angle Ω that of spline.angle
    k = ps.spine_curvature
    om = sp.angle(u, exact=True)
    cp = sp.control_points[1]
    sigma = np.linalg.norm(sp.evaluate(u, 1), axis=1)
    inv = ph.invariants(cp)
    kappa = 6 * inv["L2"] * inv["sin_theta"] / sigma**2
    np.testing.assert_allclose(k[:, 0], kappa * np.cos(om), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(k[:, 1], -kappa * np.sin(om), rtol=1e-12, atol=1e-14)


# ---------------------------------------------------------------------------------------
# libigl on dense meshes of the same surface


igl = pytest.importorskip("igl")


def test_discrete_curvatures_of_libigl_converge_at_second_order():
    """K by the angle defect over the Voronoi area (igl.gaussian_curvature, igl.massmatrix),
    H by the cotangent Laplacian (igl.cotmatrix), on the grid meshes of a PH-spline moulding
    with a convex cubic profile; the largest error over interior vertices (two grid rows
    from the border), at three nested resolutions."""
    sp = _ph_spline()
    section = curves.Bezier([[0.0, -0.2, 0], [0.25, -0.15, 0], [0.25, 0.15, 0], [0.0, 0.2, 0]])
    errs = []
    for n in (24, 48, 96):
        ps = spinal.profile_surface(sp, section, u=np.linspace(0.0, 3.0, 3 * n + 1),
                                    v=np.linspace(0.0, 1.0, n + 1))
        m = ps.mesh()
        V, F = m.vertices, m.faces
        M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
        Kd = (igl.gaussian_curvature(V, F) / M).reshape(ps.mu.shape)
        Hd = np.einsum("ij,ij->i", (igl.cotmatrix(V, F) @ V) / (2 * M[:, None]),
                       m.normals).reshape(ps.mu.shape)
        step = n // 24  # the vertices of the coarsest grid, two of its rows in
        sel = (slice(2 * step, -2 * step, step), slice(2 * step, -2 * step, step))
        # skip the joints' rows: the spline is only G¹ there (the curvature jumps)
        rows = np.arange(ps.mu.shape[0])[sel[0]]
        keep = np.abs(ps.u[rows] - np.round(ps.u[rows])) > 1.5 / n
        eK = np.abs(Kd[sel] - ps.gaussian[sel])[keep]
        eH = np.abs(Hd[sel] - ps.mean[sel])[keep]
        errs.append((eK.max(), eH.max()))
    errs = np.array(errs)
    orders = np.log2(errs[:-1] / errs[1:])
    assert np.all(orders > 1.7), (errs, orders)
    assert errs[-1, 0] < 2e-2 * np.abs(ps.gaussian).max()


def test_principal_curvatures_of_libigl_converge_on_the_torus():
    """igl.principal_curvature (quadric fitting; its signs are opposite to II = X_ij · N
    with the outward normal) against the torus' k1, k2 at vertices away from the seam."""
    errs = []
    for n in (32, 64, 128):
        ps = spinal.profile_surface(curves.Helix(a=R, b=0.0), curves.Helix(a=RT, b=0.0),
                                    u=np.linspace(0, 2 * np.pi, 2 * n, endpoint=False),
                                    v=np.linspace(0, 2 * np.pi, n, endpoint=False),
                                    profile_closed=True)
        m = ps.mesh()
        _, _, p1, p2, _ = igl.principal_curvature(m.vertices, m.faces)
        sel = slice(n // 2, 3 * n // 2)
        errs.append((np.abs(-p2.reshape(ps.mu.shape) - ps.k1)[sel].max(),
                     np.abs(-p1.reshape(ps.mu.shape) - ps.k2)[sel].max()))
    errs = np.array(errs)
    orders = np.log2(errs[:-1] / errs[1:])
    assert np.all(orders[-1] > 1.8), (errs, orders)


# ---------------------------------------------------------------------------------------
# parabolic lines (MJ Fig. 2, (14))


def _fig2(section, n_u=97, n_v=100, **kw):
    sp = ph.PHSpline(_ph_spline().control_points[:1])  # one PH cubic, as in Fig. 2
    return sp, spinal.profile_surface(sp, section, u=np.linspace(0, 1, n_u), v=n_v, **kw)


def test_fig2a_inflected_section_gives_the_iso_parabolic_line_and_those_of_14():
    """An S-shaped cubic cross-section (inflection at v = 1/2 by symmetry) swept along a PH
    cubic: one parabolic line is v = 1/2 along the whole spine, K changes sign across it;
    the two other lines satisfy MJ (14) ċ₃ cos Ω + ċ₂ sin Ω = 0 (N ∥ b), with Ω from
    spinal.ph's closed-form angle: the residual at their vertices falls at 2nd order in
    the grid spacing (linear interpolation along the grid edges)."""
    section = curves.Bezier([[0.0, 0.0, 0], [0.1, 0.2, 0], [0.2, -0.2, 0], [0.3, 0.0, 0]])
    d1, d2 = section.d1([0.5]), section.d2([0.5])
    assert abs(d1[0, 0] * d2[0, 1] - d1[0, 1] * d2[0, 0]) < 1e-15  # the inflection
    sp, ps = _fig2(section)
    lines = ps.parabolic_lines()
    iso = [line for line in lines if np.ptp(line[:, 1]) < 1e-3]
    assert len(iso) == 1
    np.testing.assert_allclose(iso[0][:, 1], 0.5, atol=2e-4)
    assert iso[0][:, 0].min() == 0 and iso[0][:, 0].max() == 1
    j = np.searchsorted(ps.v, 0.5)
    flips = ps.parabolic_sign[:, j - 1] * ps.parabolic_sign[:, j]
    assert np.all(flips == -1)
    residuals = []
    for n in (1, 2):
        sp, ps = _fig2(section, n_u=96 * n + 1, n_v=99 * n + 1)
        others = [line for line in ps.parabolic_lines() if np.ptp(line[:, 1]) >= 1e-3]
        assert len(others) == 2  # as in Fig. 2(a): "two more lines come from (14)"
        worst = 0.0
        for line in others:
            assert line[:, 0].min() == 0 and line[:, 0].max() == 1
            om = sp.angle(line[:, 0], exact=True)
            cd = section.d1(line[:, 1])
            g = (cd[:, 1] * np.cos(om) + cd[:, 0] * np.sin(om)) / np.hypot(cd[:, 0], cd[:, 1])
            worst = max(worst, np.abs(g).max())
        residuals.append(worst)
    assert residuals[0] / residuals[1] > 3.5, residuals
    assert residuals[1] < 1e-3


def test_fig2b_convex_section_with_delta_pi_has_parabolic_lines():
    """A convex section whose tangent turns by δ = π (a half circle): MJ Cor. 9, no turn of
    the section avoids parabolic points; here lines of (14) appear."""
    half = curves.Helix(a=0.1, b=0.0, turns=0.5)
    _, ps = _fig2(half)
    np.testing.assert_allclose(ps.profile_turning, np.pi, rtol=1e-12)
    assert not ps.convexity_criterion and ps.convex_turns is None
    assert len(ps.parabolic_lines()) >= 1 and not ps.convex
    assert np.any(ps.gaussian > 0) and np.any(ps.gaussian < 0)


# ---------------------------------------------------------------------------------------
# singular points (MJ Cor. 7, (9))


def test_profile_reaching_the_curvature_axis_is_flagged():
    """A segment along the principal normal of a circle of radius 1: μ = 1 − a vanishes at
    a = 1, the centre of curvature (on the curvature axis)."""
    t = np.linspace(0, np.pi, 50)
    pts = np.c_[np.cos(t), np.sin(t), np.zeros_like(t)]
    F = spinal.frames(pts)
    # r = n (towards the centre), to the accuracy of the estimated end tangents
    np.testing.assert_allclose(F[:, :, 0], -pts, atol=1e-6)
    reach = np.c_[np.linspace(0, 1.5, 16), np.zeros(16)]
    ps = spinal.profile_surface(pts, reach)
    assert not ps.singularity_free
    sp_ = ps.singular_points
    assert sp_.shape == (50, 2)
    np.testing.assert_allclose(sp_[:, 0], ps.u, rtol=1e-15)
    np.testing.assert_allclose(sp_[:, 1], 1.0, atol=1e-9)
    inside = np.c_[np.linspace(0, 0.8, 16), np.zeros(16)]
    ok = spinal.profile_surface(pts, inside)
    assert ok.singularity_free and ok.singular_points.shape == (0, 2)


def test_ph_cor7_sufficient_radius_and_condition_9():
    """A circular section about the spine of a PH cubic: radius 0.9/κ_max is free of singular
    points (MJ Cor. 7's sufficient condition); 1.2/κ_max is flagged, and at the flagged
    points MJ (9) holds with equality, κ(a cos Ω − b sin Ω) = 1 (spinal.ph's κ and Ω)."""
    sp = ph.PHSpline(_ph_spline().control_points[:1])
    kmax = ph.invariants(sp.control_points[0])["kappa_max"]
    u = np.linspace(0, 1, 201)
    v = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    ok = spinal.profile_surface(sp, curves.Helix(a=0.9 / kmax, b=0.0), u=u, v=v,
                                profile_closed=True)
    assert ok.singularity_free and len(ok.singular_points) == 0
    rho = 1.2 / kmax
    bad = spinal.profile_surface(sp, curves.Helix(a=rho, b=0.0), u=u, v=v,
                                 profile_closed=True)
    assert not bad.singularity_free
    pts = bad.singular_points
    assert len(pts) > 0
    om = sp.angle(pts[:, 0], exact=True)
    sigma = np.linalg.norm(sp.evaluate(pts[:, 0], 1), axis=1)
    inv = ph.invariants(sp.control_points[0])
    kappa = 6 * inv["L2"] * inv["sin_theta"] / sigma**2
    a, b = rho * np.cos(pts[:, 1]), rho * np.sin(pts[:, 1])
    np.testing.assert_allclose(kappa * (a * np.cos(om) - b * np.sin(om)), 1.0, atol=1e-4)


# ---------------------------------------------------------------------------------------
# convexity (MJ Prop. 8, Cor. 9)


def _arc(delta, radius=0.1, n=60, turn=0.0, start=0.0):
    th = start + np.linspace(0, delta, n)
    c = radius * np.c_[np.cos(th), np.sin(th)]
    rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    return c @ rot.T


def _short_helix():
    u = np.linspace(0.0, 1.0, 41)
    return curves.Helix(a=1.0, b=0.5).point(u)


def test_convex_profile_turned_into_the_interval_is_convex():
    pts = _short_helix()
    base = spinal.profile_surface(pts, _arc(1.5))
    np.testing.assert_allclose(base.profile_turning, 1.5, rtol=1e-12)
    # the curvature vector turns by τ·length in the RMF (0.4 · √1.25)
    np.testing.assert_allclose(base.frame_turning, 0.4 * np.sqrt(1.25), rtol=1e-3)
    assert base.convexity_criterion
    lo, hi = base.convex_turns
    assert hi - lo == pytest.approx(np.pi - 1.5 - base.frame_turning, rel=1e-9)
    mid = 0.5 * (lo + hi)
    conv = spinal.profile_surface(pts, _arc(1.5, turn=mid))
    assert conv.convex and np.all(conv.gaussian > 0) and conv.singularity_free
    anti = spinal.profile_surface(pts, _arc(1.5, turn=mid + np.pi))
    assert not anti.convex and np.all(anti.gaussian < 0)  # Ω₀ + π: K < 0 everywhere
    outside = spinal.profile_surface(pts, _arc(1.5, turn=hi + 0.2))
    assert not outside.convex and np.any(outside.gaussian > 0)
    # the profile run clockwise (κ_c < 0 and N reversed) is the same surface: same turns
    cw = spinal.profile_surface(pts, _arc(1.5)[::-1])
    assert cw.convexity_criterion and np.all(cw.profile_curvature < 0)
    np.testing.assert_allclose(cw.convex_turns, base.convex_turns, atol=1e-9)
    np.testing.assert_allclose(cw.gaussian, base.gaussian[:, ::-1], rtol=1e-9)


def test_ph_cubic_frame_turning_is_the_closed_form_angle_change():
    """For a PH cubic Ω is monotone, so Ω_max − Ω_min of MJ Cor. 9 is |Ω(1) − Ω(0)| of the
    closed form (MJ (30)); the criterion and the interval then follow for a short arc."""
    sp = ph.PHSpline(_ph_spline().control_points[:1])
    ps = spinal.profile_surface(sp, SECTION, u=np.linspace(0, 1, 33), v=20)
    om = sp.angle([0.0, 1.0], exact=True)
    np.testing.assert_allclose(ps.frame_turning, abs(om[1] - om[0]), rtol=1e-12)
    arc = spinal.profile_surface(sp, _arc(0.5), u=np.linspace(0, 1, 33))
    assert arc.convexity_criterion
    turned = spinal.profile_surface(sp, _arc(0.5, turn=arc.convex_turns.mean()),
                                    u=np.linspace(0, 1, 33))
    assert turned.convex and turned.singularity_free


def test_non_convex_profiles_are_not_convex_for_any_turn():
    pts = _short_helix()
    s_curve = np.r_[_arc(1.0, start=-np.pi / 2)[:-1],
                    _arc(-1.0, start=np.pi / 2 + 1.0) + 2 * _arc(1.0, start=-np.pi / 2)[-1]]
    wide = _arc(3.3)  # convex, but δ > π
    for prof in (s_curve, wide):
        ps = spinal.profile_surface(pts, prof)
        assert not ps.convexity_criterion and ps.convex_turns is None
        for turn in np.linspace(0, 2 * np.pi, 72, endpoint=False):
            rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
            assert not spinal.profile_surface(pts, prof @ rot.T).convex


# ---------------------------------------------------------------------------------------
# input


def test_inputs_are_not_modified_and_outputs_are_read_only():
    pts = _short_helix()
    prof = _arc(1.5)
    F = spinal.frames(pts)
    copies = [pts.copy(), prof.copy(), F.copy()]
    ps = spinal.profile_surface(pts, prof, frames=F)
    for a, b in zip((pts, prof, F), copies, strict=True):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError):
        ps.gaussian[0, 0] = 1.0


@pytest.mark.parametrize("call, name", [
    (lambda: spinal.profile_surface(np.zeros((5, 2)), _arc(1.0)), "spine"),
    (lambda: spinal.profile_surface(_short_helix()[:2], _arc(1.0)), "spine"),
    (lambda: spinal.profile_surface(np.r_[_short_helix(), [[np.nan] * 3]], _arc(1.0)),
     "spine"),
    (lambda: spinal.profile_surface(np.repeat(_short_helix(), 2, axis=0), _arc(1.0)), "spine"),
    (lambda: spinal.profile_surface(_short_helix(), np.zeros((5, 3))), "profile"),
    (lambda: spinal.profile_surface(_short_helix(), _arc(1.0)[:2]), "profile"),
    (lambda: spinal.profile_surface(_short_helix(), np.repeat(_arc(1.0), 2, axis=0)),
     "profile"),
    (lambda: spinal.profile_surface(_short_helix(), curves.Helix()), "profile"),
    (lambda: spinal.profile_surface(curves.Helix(), SECTION, u=[0.0, 0.2, 0.1]), "u"),
    (lambda: spinal.profile_surface(curves.Helix(), SECTION, v=np.array([[0.1, 0.2]])), "v"),
    (lambda: spinal.profile_surface(curves.Helix(), SECTION, v=1), "v"),
    (lambda: spinal.profile_surface(_ph_spline(), SECTION, u=[0.0, 4.0]), "u"),
    (lambda: spinal.profile_surface(_short_helix(), _arc(1.0), frames=np.zeros((41, 3))),
     "frames"),
    (lambda: spinal.profile_surface(_short_helix(), _arc(1.0),
                                    frames=spinal.frames(_short_helix()) * 2), "frames"),
    (lambda: spinal.profile_surface(_short_helix(), _arc(1.0), initial=[1.0, 0]), "initial"),
])
def test_bad_input_is_refused_by_name(call, name):
    with pytest.raises(ValueError, match=f"^{name}:"):
        call()


@pytest.mark.parametrize("call, name", [
    (lambda: spinal.profile_surface(_short_helix(), _arc(1.0), u=5), "u"),
    (lambda: spinal.profile_surface(_short_helix(), _arc(1.0), v=5), "v"),
    (lambda: spinal.profile_surface(_ph_spline(), SECTION, frames=np.eye(3)), "frames"),
    (lambda: spinal.profile_surface(_ph_spline(), SECTION, closed=True), "closed"),
    (lambda: spinal.profile_surface(_short_helix(), _arc(1.0), closed=1), "closed"),
    (lambda: spinal.profile_surface(_short_helix(), _arc(1.0)).parabolic_lines("xyz"), "space"),
])
def test_arguments_that_do_not_apply_are_refused_by_name(call, name):
    with pytest.raises((TypeError, ValueError), match=f"^{name}:"):
        call()
