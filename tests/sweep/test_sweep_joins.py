"""Corner joins of spinal.sweep / spinal.tube: two straight legs meeting at a sharp corner,
sampled densely or coarsely, give the exact union of the two straight tubes (inner side cut
in the bisector plane, outer side round, bevelled or mitred), with no crossing faces
(libigl's exact predicates), no pinch, and a volume that converges to the union's."""

import warnings

import igl
import igl.predicates
import numpy as np
import pytest
import trimesh

import spinal

R = 0.05


def legs(deg, h, length=1.0):
    """Two straight legs of ``length`` meeting at the origin, turning by ``deg`` in the xy
    plane, sampled every ``h``; returns the points and the corner's row."""
    n = round(length / h)
    a = np.radians(deg)
    first = np.c_[np.linspace(-length, 0, n + 1), np.zeros(n + 1), np.zeros(n + 1)]
    second = np.linspace(0, length, n + 1)[1:, None] * [np.cos(a), np.sin(a), 0]
    return np.r_[first, second], n


def union_volume(deg, r=R, length=1.0):
    """Two cylinders of radius r and axis length ``length`` ending square at the corner,
    joined by the spherical wedge of the turn: each leg loses the wedge of its inner half
    past the bisector plane, ``tan(φ/2) ∫ s dA = tan(φ/2) 2r³/3``, and the round join adds
    the half disc turned by φ, ``(2/3) r³ φ``."""
    phi = np.radians(deg)
    return 2 * np.pi * r**2 * length - 4 / 3 * r**3 * np.tan(phi / 2) + 2 / 3 * r**3 * phi


def crossings(mesh):
    _, pairs, _ = igl.predicates.find_self_intersections(
        np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64))
    return len(pairs)


@pytest.mark.parametrize("join", ["round", "bevel", "miter"])
@pytest.mark.parametrize("deg", [30, 90, 150, 170])
@pytest.mark.parametrize("h", [0.5, 0.05, 0.005])
def test_corner_joins_have_no_crossing_faces(deg, h, join):
    x, _ = legs(deg, h)
    with warnings.catch_warnings():
        warnings.simplefilter("error", spinal.FoldOverWarning)
        mesh = spinal.tube(x, R, 16, join=join)
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert tm.is_watertight and tm.is_winding_consistent and tm.volume > 0
    assert crossings(mesh) == 0


def test_crossing_check_sees_a_tube_that_meets_itself():
    """The check above is not blind: a spine passing through its own tube crosses."""
    x = np.array([[0, 0, 0], [1, 0, 0], [0.5, -0.5, 0.01], [0.5, 0.5, 0.01]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        assert crossings(spinal.tube(x, R, 16)) > 0


@pytest.mark.parametrize("deg", [30, 90, 150, 170])
def test_round_join_volume_converges_to_the_union_at_second_order(deg):
    """The polygonal tube and the polygonal round join converge to the union of the two
    cylinders and the spherical wedge at second order in 1/sides, at every spacing."""
    for h in (0.5, 0.05):
        x, _ = legs(deg, h)
        err = []
        for sides in (32, 64, 128):
            mesh = spinal.tube(x, R, sides)
            err.append(union_volume(deg) - mesh.volume)
        err = np.array(err)
        assert np.all(err > 0)  # inscribed polygons
        order = np.log2(err[:-1] / err[1:])
        assert np.all(np.abs(order - 2) < 0.05), (h, order)


@pytest.mark.parametrize("deg", [30, 90, 150, 170])
def test_cross_section_never_pinches_through_the_corner(deg):
    """Every point of both legs' axes near the corner is at least 0.99 r from the surface:
    the cross-section keeps its width 2r through the join (a 64-gon's inscribed radius is
    r cos(π/64) = 0.9988 r)."""
    for h in (0.5, 0.05, 0.005):
        x, _ = legs(deg, h)
        mesh = spinal.tube(x, R, 64)
        a = np.radians(deg)
        reach = R * np.tan(a / 2) + 2 * R
        s = np.linspace(0, reach, 200)[:, None]
        axis = np.r_[-s * [1.0, 0, 0], s * [np.cos(a), np.sin(a), 0]]
        d2, _, _ = igl.point_mesh_squared_distance(
            axis, np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.int64))
        assert np.sqrt(d2.min()) >= 0.99 * R, (h, np.sqrt(d2.min()))


def test_joins_appear_only_at_corners_and_keep_the_ring_layout():
    """A corner's extra rings follow the curve's rings; sample_of maps them to the corner's
    row; vertex k*m + j of the rings per sample stays profile vertex j of sample k."""
    x, k = legs(90, 0.05)
    mesh = spinal.tube(x, R, 16)
    n = len(x)
    rings = len(mesh.vertices) // 16
    assert rings == n + 4  # 90° in steps of at most 360°/16: A and 3 more rings
    np.testing.assert_array_equal(mesh.sample_of[:n * 16], np.repeat(np.arange(n), 16))
    np.testing.assert_array_equal(mesh.sample_of[n * 16:], k)
    # the rings of every sample lie where the plain sweep puts them, away from the corner
    plain = spinal.tube(x, R, 16, join="miter")
    assert len(plain.vertices) == n * 16
    far = np.abs(np.arange(n) - k) > 2
    far = np.repeat(far, 16)
    np.testing.assert_array_equal(mesh.vertices[:n * 16][far], plain.vertices[far])
    # the extra rings' vertices in use lie on the sphere of radius R about the corner (the
    # others are their columns' crease vertices, in the bisector plane)
    extra = np.arange(n * 16, len(mesh.vertices))
    used = np.isin(extra, mesh.faces)
    assert 0 < used.sum() < used.size
    np.testing.assert_allclose(np.linalg.norm(mesh.vertices[extra[used]] - x[k], axis=1), R,
                               rtol=1e-12)
    crease = mesh.vertices[extra[~used]] - x[k]
    np.testing.assert_allclose(crease @ [np.sqrt(0.5), np.sqrt(0.5), 0], 0, atol=1e-15)


def test_join_rings_carry_uv_normals_point_data_and_float32():
    x, k = legs(150, 0.1)
    temp = np.arange(len(x), dtype=np.float64)
    mesh = spinal.tube(x, R, 12, point_data={"temp": temp})
    extra = mesh.sample_of >= 0
    np.testing.assert_array_equal(mesh.point_data["temp"], temp[mesh.sample_of[extra]])
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1, atol=1e-12)
    n = len(x)
    arc = np.r_[0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))]
    np.testing.assert_allclose(mesh.uv[n * 12:, 0], arc[k], rtol=1e-15)
    # outward: the normals of the round join point away from the corner
    extra = mesh.vertices[n * 12:] - x[k]
    used = np.isin(np.arange(n * 12, len(mesh.vertices)), mesh.faces)
    assert np.all((extra * mesh.normals[n * 12:]).sum(axis=1)[used] > 0.9 * R)
    single = spinal.tube(x, R, 12, dtype=np.float32)
    assert single.vertices.dtype == np.float32 and single.faces.dtype == np.int32
    np.testing.assert_array_equal(single.faces, mesh.faces)
    np.testing.assert_allclose(single.vertices, mesh.vertices, atol=1e-6)


def test_closed_polylines_and_bundles_with_corners_are_watertight_and_exact():
    """A closed 3D polyline made only of corners (the rolls carried round the loop and the
    closing mismatch spread over it) and a bundle mixing corners and smooth curves."""
    cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1], [0, 0, 1]], float)
    mesh = spinal.tube(cube, 0.05, 24, closed=True)
    assert mesh.is_watertight and crossings(mesh) == 0
    assert not mesh.fold_over.size
    # six legs of 1 and six right-angle corners: the union's volume, to the polygon's
    # second-order error
    corner = union_volume(90, 0.05, 0.5) - np.pi * 0.05**2
    exact = 6 * np.pi * 0.05**2 + 6 * corner
    assert abs(mesh.volume / exact - 1) < 0.02
    t = np.linspace(0, 2 * np.pi, 80)
    smooth = np.c_[np.cos(t), np.sin(t), 0.1 * t]
    curves = [legs(120, 0.1)[0], smooth + [0, 0, 3], legs(45, 0.02)[0] + [0, 0, 6]]
    bundle = spinal.tube(curves, 0.05, 12)
    assert bundle.is_watertight and crossings(bundle) == 0
    ids = bundle.cell_data["curve_id"]
    assert np.array_equal(np.unique(ids), [0, 1, 2]) and np.all(np.diff(ids) >= 0)
    alone = spinal.tube(curves[1], 0.05, 12)
    np.testing.assert_array_equal(bundle.faces[ids == 1] - bundle.faces[ids == 1].min(),
                                  alone.faces)


def test_random_walks_cross_only_where_they_fold_or_come_back():
    """Gaussian random walks tubed with round joins: watertight and outward always; faces
    cross only where the tube meets itself (two non-adjacent segments closer than 2r) or
    a FoldOverWarning names the row (a hairpin tighter than the radius)."""
    rng = np.random.default_rng(5)

    def gap(p, q, a, b):
        # the distance between segments p–q and a–b (sampled finely)
        s = np.linspace(0, 1, 41)[:, None]
        u, v = p + s * (q - p), a + s * (b - a)
        return np.sqrt(((u[:, None] - v[None]) ** 2).sum(-1)).min()

    clean = 0
    for _ in range(40):
        x = np.cumsum(rng.normal(size=(rng.integers(3, 30), 3)), axis=0)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            mesh = spinal.tube(x, 0.05, 12)
        assert mesh.is_watertight and mesh.volume > 0
        if caught:
            continue
        n = len(x)
        meets = any(gap(x[i], x[i + 1], x[j], x[j + 1]) < 0.1 + 1e-3
                    for i in range(n - 1) for j in range(i + 2, n - 1))
        if not meets:
            clean += 1
            assert crossings(mesh) == 0
    assert clean >= 20
