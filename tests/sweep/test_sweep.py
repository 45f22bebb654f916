"""Sweeps and tubes: volumes against closed forms (trimesh, libigl), curvature of a torus
tube (libigl), normals, topology, uv, fold-over, bundles and bad input."""

from __future__ import annotations

import warnings

import igl
import numpy as np
import pytest
import trimesh

import spinal
from spinal.curves import Helix, TorusKnot


def circle(R, n, z=0.0):
    u = 2 * np.pi * np.arange(n) / n
    return np.c_[R * np.cos(u), R * np.sin(u), np.full(n, z)]


def polygon_area(sides, rho=1.0):
    return 0.5 * sides * rho**2 * np.sin(2 * np.pi / sides)


def volumes(mesh):
    """Enclosed volume from trimesh and from libigl."""
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    _, vol = igl.centroid(mesh.vertices, mesh.faces)
    return tm.volume, float(vol)


def assert_clean(mesh, watertight=True):
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert tm.is_watertight == watertight
    assert mesh.is_watertight == watertight
    assert tm.is_winding_consistent
    assert trimesh.triangles.area(mesh.vertices[mesh.faces]).min() > 1e-12 * tm.area
    assert np.isfinite(mesh.vertices).all() and np.isfinite(mesh.normals).all()
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-12)
    if watertight:
        assert tm.volume > 0


# ---------------------------------------------------------------- volumes


def test_torus_tube_volume_is_exact_prism_volume_and_converges_to_pappus():
    """Mitred rings in the bisector planes make every segment an exact prism: the volume is
    (polygon area) × (spine polygon perimeter) to round-off, from trimesh and libigl, and it
    tends to Pappus' 2πR·A at second order."""
    R, r, sides = 2.0, 0.5, 24
    A = polygon_area(sides, r)
    errors = []
    for n in (32, 64, 128, 256):
        mesh = spinal.tube(circle(R, n), r, sides, closed=True)
        assert_clean(mesh)
        perimeter = n * 2 * R * np.sin(np.pi / n)
        for v in volumes(mesh) + (mesh.volume,):
            assert abs(v - A * perimeter) < 1e-12 * A * perimeter
        errors.append(abs(mesh.volume - 2 * np.pi * R * A) / (2 * np.pi * R * A))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all(np.abs(ratios - 4) < 0.05), ratios


def test_variable_radius_tube_volume():
    """Straight spine, radius ρ(z): each segment is a frustum of a polygonal pyramid,
    V = h/3 (A₁ + A₂ + √(A₁A₂)) exactly; the total tends to ∫ A(ρ(z)) dz at 2nd order."""
    sides, L = 16, 3.0

    def rho(z):
        return 0.4 + 0.2 * np.sin(z)

    exact = polygon_area(sides) * (0.16 * L + 0.16 * (1 - np.cos(L))
                                   + 0.02 * (L - np.sin(2 * L) / 2))
    errors = []
    for n in (25, 50, 100, 200):
        z = np.linspace(0, L, n)
        x = np.c_[0.1 * np.ones(n), -0.2 * np.ones(n), z]
        mesh = spinal.tube(x, rho(z), sides)
        assert_clean(mesh)
        a = polygon_area(sides, rho(z))
        frusta = np.sum(np.diff(z) / 3 * (a[:-1] + a[1:] + np.sqrt(a[:-1] * a[1:])))
        for v in volumes(mesh):
            assert abs(v - frusta) < 1e-12 * frusta
        errors.append(abs(mesh.volume - exact) / exact)
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all(np.abs(ratios - 4) < 0.3), ratios


@pytest.mark.parametrize("reverse", [False, True])
def test_nonconvex_prism_volume_and_mitred_square_loop(reverse):
    """An L-shaped (non-convex) profile swept along a straight line with caps: volume =
    area × length; a centred star swept around a square loop given by its 4 corners: the
    mitred corners make it exact, volume = area × perimeter. Clockwise profiles give the
    same outward-facing mesh."""
    L = np.array([(0, 0), (2, 0), (2, 1), (1, 1), (1, 3), (0, 3)], float) - [0.5, 0.5]
    if reverse:
        L = L[::-1]
    line = np.c_[np.zeros(7), np.zeros(7), np.linspace(0, 5, 7)]
    mesh = spinal.sweep(line, L, frames=np.repeat(np.eye(3)[None], 7, axis=0))
    assert_clean(mesh)
    for v in volumes(mesh):
        assert abs(v - 4.0 * 5.0) < 1e-12
    k = np.arange(10)
    star = np.c_[np.cos(np.pi * k / 5), np.sin(np.pi * k / 5)] * np.where(k % 2, 0.15, 0.4)[:, None]
    if reverse:
        star = star[::-1]
    square = np.array([(0, 0, 0), (4, 0, 0), (4, 4, 0), (0, 4, 0)], float)
    loop = spinal.sweep(square, star, closed=True, join="miter")
    assert_clean(loop)
    area = abs(0.5 * np.sum(star[:, 0] * np.roll(star[:, 1], -1) - np.roll(star[:, 0], -1) * star[:, 1]))
    for v in volumes(loop):
        assert abs(v - area * 16.0) < 1e-12 * area * 16


# ---------------------------------------------------------------- curvature


def torus_tube(n, sides, R=2.0, r=0.5):
    return spinal.tube(circle(R, n), r, sides, closed=True)


def test_torus_gaussian_and_mean_curvature_from_libigl():
    """Pointwise K = cos v / (r (R + r cos v)) and H = (R + 2r cos v) / (2r (R + r cos v))
    from libigl's discrete operators, converging under refinement; Gauss–Bonnet total 0."""
    R, r = 2.0, 0.5
    errs_k, errs_h = [], []
    for n, sides in ((64, 32), (128, 64), (256, 128)):
        mesh = torus_tube(n, sides, R, r)
        V, F = mesh.vertices, mesh.faces
        defect = igl.gaussian_curvature(V, F)
        assert abs(defect.sum()) < 1e-9  # Gauss–Bonnet, χ = 0
        M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)
        K = defect / M.diagonal()
        cv = np.clip((np.hypot(V[:, 0], V[:, 1]) - R) / r, -1, 1)  # cos v at the vertex
        K_exact = cv / (r * (R + r * cv))
        errs_k.append(np.abs(K - K_exact).max())
        Lc = igl.cotmatrix(V, F)
        Hn = -(Lc @ V) / M.diagonal()[:, None] / 2
        H = np.einsum("ij,ij->i", Hn, mesh.normals)  # signed by our outward normals
        H_exact = (R + 2 * r * cv) / (2 * r * (R + r * cv))
        errs_h.append(np.abs(H - H_exact).max())
    assert errs_k[-1] < 2e-3 and errs_h[-1] < 2e-3
    assert errs_k[0] / errs_k[-1] > 10 and errs_h[0] / errs_h[-1] > 10


def test_torus_normals_are_exact_and_outward():
    R, r, n, sides = 2.0, 0.5, 48, 20
    mesh = torus_tube(n, sides, R, r)
    # normals of the smooth torus at the un-mitred ring points (the mitre only moves vertices)
    V = spinal.tube(circle(R, n), r, sides, closed=True, miter_limit=1.0).vertices
    assert np.abs(np.hypot(np.hypot(V[:, 0], V[:, 1]) - R, V[:, 2]) - r).max() < 1e-14
    centre = np.c_[V[:, :2] / np.linalg.norm(V[:, :2], axis=1)[:, None] * R, np.zeros(len(V))]
    exact = (V - centre) / np.linalg.norm(V - centre, axis=1)[:, None]
    np.testing.assert_allclose(mesh.normals, exact, atol=1e-12)
    tm = mesh.to_trimesh()
    # area-weighted face normals agree to the mesh resolution
    assert np.einsum("ij,ij->i", tm.vertex_normals, mesh.normals).min() > 0.99


def test_variable_radius_normals_are_tilted_by_the_slope():
    """A cone ρ(z) = 1 − z/2: n = (e_ρ + (1/2) e_z) / √(1 + 1/4) exactly."""
    z = np.linspace(0, 1.5, 9)
    x = np.c_[np.zeros(9), np.zeros(9), z]
    mesh = spinal.tube(x, 1 - z / 2, 12, caps=False)
    V = mesh.vertices
    er = np.c_[V[:, :2], np.zeros(len(V))]
    er /= np.linalg.norm(er, axis=1)[:, None]
    exact = (er + 0.5 * np.array([0, 0, 1.0])) / np.sqrt(1.25)
    np.testing.assert_allclose(mesh.normals, exact, atol=1e-12)
    const = spinal.tube(x, 0.5, 12, caps=False)
    assert np.abs(const.normals[:, 2]).max() < 1e-12


# ---------------------------------------------------------------- topology and uv


def test_open_capped_closed_and_uncapped_topology():
    k = TorusKnot()
    x = k.sample(400)
    closed = spinal.tube(x, 0.05, 12, closed=True)
    assert_clean(closed)
    assert len(closed.vertices) == 399 * 12  # the repeated end point is dropped
    h = Helix(1.0, 0.3, turns=2).sample(200)
    capped = spinal.tube(h, 0.1, 9)
    assert_clean(capped)
    open_ = spinal.tube(h, 0.1, 9, caps=False)
    assert_clean(open_, watertight=False)
    assert len(open_.faces) == len(capped.faces) - 2 * 7
    ribbon = spinal.sweep(h, [(-0.1, 0.0), (0.1, 0.0)], profile_closed=False)
    assert len(ribbon.faces) == 2 * 199 and not ribbon.is_watertight


def test_closed_knot_tube_has_no_seam_twist():
    """The rail through vertex j of ring n−1 continues into vertex j of ring 0: the last
    closing quads are as regular as all others."""
    x = TorusKnot().sample(801)
    mesh = spinal.tube(x, 0.04, 16, closed=True)
    V = mesh.vertices.reshape(800, 16, 3)
    rails = np.linalg.norm(np.diff(np.concatenate([V, V[:1]]), axis=0), axis=2)
    closing = rails[-1]
    assert closing.max() < 1.05 * rails[:-1].max() and closing.min() > 0.95 * rails[:-1].min()


def test_uv_by_arc_length_and_split_seams():
    x = circle(1.0, 40)
    mesh = spinal.tube(x, 0.1, 8, closed=True)
    L = np.sum(np.linalg.norm(np.diff(np.vstack([x, x[:1]]), axis=0), axis=1))
    u = mesh.uv[:, 0].reshape(40, 8)[:, 0]
    np.testing.assert_allclose(u, np.r_[0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))])
    np.testing.assert_allclose(mesh.uv[:8, 1], np.arange(8) / 8)
    split = spinal.tube(x, 0.1, 8, closed=True, split_seams=True)
    assert len(split.vertices) == 41 * 9
    assert not split.is_watertight
    assert trimesh.Trimesh(split.vertices, split.faces).is_watertight  # after merging
    assert split.uv[:, 0].max() == pytest.approx(L) and split.uv[:, 1].max() == 1.0
    du = np.ptp(split.uv[split.faces][:, :, 0], axis=1)
    dv = np.ptp(split.uv[split.faces][:, :, 1], axis=1)
    assert du.max() < 1.01 * L / 40 and dv.max() < 1 / 8 + 1e-12  # no face spans a seam
    assert split.volume == pytest.approx(mesh.volume, rel=1e-12)


def test_twist_and_scale_place_the_profile():
    z = np.linspace(0, 2, 5)
    x = np.c_[np.zeros(5), np.zeros(5), z]
    F = np.repeat(np.eye(3)[None], 5, axis=0)
    prof = np.array([(1.0, 0), (0, 1), (-1, 0), (0, -1)])
    tw = np.linspace(0, np.pi / 2, 5)
    sc = np.c_[np.linspace(1, 2, 5), np.ones(5)]
    mesh = spinal.sweep(x, prof, frames=F, twist=tw, scale=sc)
    V = mesh.vertices.reshape(5, 4, 3)
    np.testing.assert_allclose(V[:, 0], np.c_[sc[:, 0] * np.cos(tw), sc[:, 0] * np.sin(tw), z],
                               atol=1e-15)
    np.testing.assert_allclose(V[:, 1], np.c_[-np.sin(tw), np.cos(tw), z], atol=1e-15)


def test_bundle_equals_separate_calls():
    curves = [Helix(1.0, 0.2 + 0.1 * c, turns=1).sample(50 + 10 * c) + c for c in range(4)]
    radii = [np.linspace(0.05, 0.1, len(c)) for c in curves]
    bundle = spinal.tube(np.concatenate(curves), np.concatenate(radii), 7,
                         lengths=[len(c) for c in curves])
    base = 0
    for c, r in zip(curves, radii, strict=True):
        one = spinal.tube(c, r, 7)
        k = len(one.vertices)
        np.testing.assert_array_equal(bundle.vertices[base:base + k], one.vertices)
        base += k
    assert base == len(bundle.vertices)
    assert_clean(bundle)
    tm = trimesh.Trimesh(bundle.vertices, bundle.faces, process=False)
    assert len(tm.split(only_watertight=True)) == 4


# ---------------------------------------------------------------- fold-over and corners


def test_fold_over_is_reported_with_spine_rows():
    x = circle(0.5, 40)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        spinal.tube(x, 0.45, 8, closed=True)  # inside the radius of curvature: fine
    with pytest.warns(spinal.FoldOverWarning, match="spine rows 0–39") as rec:
        mesh = spinal.tube(x, 0.6, 8, closed=True)
    np.testing.assert_array_equal(rec[0].message.indices, np.arange(40))
    np.testing.assert_array_equal(mesh.fold_over, np.arange(40))
    with pytest.raises(ValueError, match="points: the profile reaches past"):
        spinal.tube(x, 0.6, 8, closed=True, strict=True)
    # a local tight bend: only the segments around it
    t = np.linspace(-3, 3, 121)
    bend = np.c_[t, 0.2 * np.exp(-t**2 / 0.02), np.zeros_like(t)]
    with pytest.warns(spinal.FoldOverWarning) as rec:
        spinal.tube(bend, 0.15, 8)
    rows = rec[0].message.indices
    assert rows.size and np.all(np.abs(t[rows]) < 0.5)


def test_corner_is_not_pinched():
    """At a 90° corner the mitred ring keeps the radius from both legs' axes (VTK's pinch is
    a ring of radius r·cos 45° there)."""
    leg = np.linspace(0, 1, 11)
    x = np.r_[np.c_[leg, 0 * leg, 0 * leg], np.c_[np.ones(10), leg[1:], 0 * leg[1:]]]
    mesh = spinal.tube(x, 0.05, 8, join="miter")
    ring = mesh.vertices[10 * 8:11 * 8]
    np.testing.assert_allclose(np.hypot(ring[:, 1], ring[:, 2]), 0.05, rtol=1e-12)
    np.testing.assert_allclose(np.hypot(ring[:, 0] - 1, ring[:, 2]), 0.05, rtol=1e-12)
    flat = spinal.tube(x, 0.05, 8, miter_limit=1.0, join="miter")
    ring = flat.vertices[10 * 8:11 * 8]
    assert np.hypot(ring[:, 1], ring[:, 2]).min() < 0.05 * 0.75


# ---------------------------------------------------------------- conversions and rendering


def test_conversions_keep_the_data():
    mesh = spinal.tube(Helix(1, 0.3, turns=1).sample(60), 0.1, 10)
    tm = mesh.to_trimesh()
    np.testing.assert_array_equal(tm.faces, mesh.faces)
    np.testing.assert_allclose(tm.vertex_normals, mesh.normals, atol=1e-12)
    pv_mesh = mesh.to_pyvista()
    np.testing.assert_array_equal(pv_mesh.regular_faces, mesh.faces)
    np.testing.assert_allclose(pv_mesh.point_data["Normals"], mesh.normals)
    assert pv_mesh.volume == pytest.approx(mesh.volume, rel=1e-9)


def test_render_off_screen(tmp_path, request):
    mesh = spinal.tube(TorusKnot().sample(400), 0.05, 16, closed=True)
    out = tmp_path / "tube.png"
    img = mesh.plot(screenshot=out)
    assert out.exists() and img.ndim == 3
    background = img[0, 0]
    covered = np.any(np.abs(img.astype(int) - background) > 30, axis=2).mean()
    assert covered > 0.03, covered
    assert len(np.unique(img.reshape(-1, img.shape[2]), axis=0)) > 100  # shaded, not flat
    art = request.config.rootpath / "tests" / "artifacts"
    art.mkdir(exist_ok=True)
    (art / "tube.png").write_bytes(out.read_bytes())


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("kwargs", "exc", "match"),
    [
        ({"profile": [(0, 0), (1, 1), (1, 0), (0, 1)]}, ValueError, "profile: the polygon intersects"),
        ({"profile": [(0, 0), (1, 1), (2, 2)]}, ValueError, "profile: .*zero area"),
        ({"profile": [(0, 0), (1, 0)]}, ValueError, "profile: .*at least 3"),
        ({"profile": [(0, 0), (1, np.nan), (0, 1)]}, ValueError, "profile: non-finite"),
        ({"profile": [(0, 0, 0), (1, 0, 0), (0, 1, 0)]}, ValueError, r"profile: expected .*\(m, 2\)"),
        ({"scale": 0.0}, ValueError, "scale: must be positive"),
        ({"scale": np.ones(3)}, ValueError, "scale: expected"),
        ({"twist": np.ones((30, 2))}, ValueError, "twist: expected"),
        ({"twist": np.full(30, np.inf)}, ValueError, "twist: non-finite"),
        ({"frames": np.ones((30, 3, 3))}, ValueError, "frames: row 0 is not a rotation"),
        ({"frames": np.zeros((29, 3, 3))}, ValueError, "frames: expected shape"),
        ({"miter_limit": 0.5}, ValueError, "miter_limit"),
        ({"caps": "yes"}, TypeError, "caps"),
    ],
)
def test_sweep_bad_input(kwargs, exc, match):
    x = Helix(1, 0.3, turns=1).sample(30)
    args = {"profile": [(0.1, 0), (0, 0.1), (-0.1, 0)]} | kwargs
    with pytest.raises(exc, match=match):
        spinal.sweep(x, **args)


def test_tube_bad_input_and_inputs_untouched():
    x = Helix(1, 0.3, turns=1).sample(30)
    # the radius is named with the value the user gave, not the internal (x, y) scale pair
    with pytest.raises(ValueError, match=r"radius: must be positive and finite, got -1 at row 0"):
        spinal.tube(x, -1.0)
    r = np.full(len(x), 0.1)
    r[7] = np.nan
    with pytest.raises(ValueError, match=r"radius: .*got NaN at row 7"):
        spinal.tube(x, r)
    with pytest.raises(ValueError, match=r"scale: .*got \[0\.1, -0\.2\] at row 0"):
        spinal.sweep(x, [(0.1, 0), (0, 0.1), (-0.1, 0)], scale=np.tile([0.1, -0.2], (30, 1)))
    with pytest.raises(ValueError, match="sides: a tube needs at least 3"):
        spinal.tube(x, 0.1, 2)
    bad = x.copy()
    bad[5] = np.nan
    with pytest.raises(ValueError, match="points: non-finite"):
        spinal.tube(bad, 0.1)
    with pytest.raises(ValueError, match="points: .*at least"):
        spinal.tube(x[:1], 0.1)
    keep = x.copy()
    r = np.full(30, 0.1)
    spinal.tube(x, r)
    np.testing.assert_array_equal(x, keep)
    assert np.all(r == 0.1)


@pytest.mark.parametrize("ext", ["ply", "obj"])
def test_save_round_trips_through_trimesh(tmp_path, ext):
    mesh = spinal.tube(TorusKnot().sample(201), 0.1, 8, closed=True)
    path = mesh.save(tmp_path / f"knot.{ext}")
    back = trimesh.load(path, process=False)
    np.testing.assert_array_equal(back.vertices, mesh.vertices)
    np.testing.assert_array_equal(back.faces, mesh.faces)
    assert back.volume == pytest.approx(mesh.volume, rel=1e-12)
    with pytest.raises(ValueError, match="path: unknown format"):
        mesh.save(tmp_path / "knot.xyz")


def _star(m, inner=0.2):
    t = 2 * np.pi * np.arange(m) / m
    r = np.where(np.arange(m) % 2 == 0, 1.0, inner)
    return np.c_[r * np.cos(t), r * np.sin(t)]


def _comb(k):
    x = np.repeat(np.arange(k)[::-1] / k, 4) + np.tile([0.5, 0.5, 0.0, 0.0], k) / k
    y = np.tile([0.1, 1.1, 1.1, 0.1], k)
    return np.r_[[[0.0, 0.0], [1.0, 0.0], [1.0, 0.1]], np.c_[x, y]]


def _shoelace(p):
    x, y = p.T
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


def _cap_areas(mesh, k):
    """Twice the signed areas, seen from +z, of the first cap's and the last cap's ``k``
    triangles (the last ``2 k`` faces of a one-spine sweep along z)."""
    v = mesh.vertices[mesh.faces[-2 * k:]]
    (ax, ay), (bx, by) = (v[:, 1, :2] - v[:, 0, :2]).T, (v[:, 2, :2] - v[:, 0, :2]).T
    z = ax * by - ay * bx
    return z[:k], z[k:]


@pytest.mark.parametrize("kind", ["star", "comb"])
def test_caps_of_100k_spike_profiles(kind):
    """The capped sweep of a profile of 100,000 packed spikes (the size at which ear
    clipping took tens of seconds): m − 2 triangles per cap on the profile's vertices, all of
    them facing out of the end (none flat), covering the profile's area, in either
    orientation; watertight with volume = area × length."""
    p = _star(100_000) if kind == "star" else _comb(25_000)
    m = len(p)
    spine = np.c_[np.zeros(3), np.zeros(3), np.arange(3.0)]
    for q in (p, p[::-1]):
        mesh = spinal.sweep(spine, q)
        assert len(mesh.vertices) == 3 * m
        assert len(mesh.faces) == 2 * 2 * m + 2 * (m - 2)
        first, last = _cap_areas(mesh, m - 2)
        assert np.all(first < 0) and np.all(last > 0)
        area = abs(_shoelace(q))
        assert 0.5 * np.sum(last) == pytest.approx(area, rel=1e-12)
        assert -0.5 * np.sum(first) == pytest.approx(area, rel=1e-12)
        assert mesh.is_watertight
        assert mesh.volume == pytest.approx(area * 2.0, rel=1e-9)


@pytest.mark.parametrize("kind", ["star", "comb", "random star-shaped"])
def test_packed_spike_profiles_sweep_closed(kind):
    """Profiles of many packed spikes (checked for self-intersection by a sweep line): the
    capped sweep along a straight spine is watertight (trimesh agrees) with volume = area ×
    length, in either orientation; a swapped pair of vertices is refused."""
    rng = np.random.default_rng(7)
    if kind == "star":
        p = _star(4000)
    elif kind == "comb":
        p = _comb(1000)
    else:
        t = np.sort(rng.uniform(0, 2 * np.pi, 3000))
        r = rng.uniform(0.05, 1.0, t.size)
        p = np.c_[r * np.cos(t), r * np.sin(t)]
    spine = np.c_[np.zeros(3), np.zeros(3), np.linspace(0.0, 2.5, 3)]
    for q in (p, p[::-1]):
        mesh = spinal.sweep(spine, q)
        assert mesh.is_watertight
        tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
        assert tm.is_watertight and tm.is_winding_consistent
        assert mesh.volume == pytest.approx(abs(_shoelace(q)) * 2.5, rel=1e-9)
        assert tm.volume == pytest.approx(mesh.volume, rel=1e-9)
    bad = p.copy()
    k = (len(p) // 2) & ~1
    bad[[k + 1, k + 5]] = bad[[k + 5, k + 1]]
    with pytest.raises(ValueError, match="profile: the polygon intersects itself"):
        spinal.sweep(spine, bad)
