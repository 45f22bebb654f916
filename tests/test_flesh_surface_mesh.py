"""Fleshing with a spine surface given as a triangle mesh (Zhuo 2014 Ch. VI, §7.2).

Independent checks: finite-difference Jacobian determinants on a bent, stretched
triangulated plate; trimesh/libigl volumes of closed boxes bound to a plate bent into a
cylinder arc; the grid model on triangulated grids (equal where both are exact, a
difference that falls with refinement elsewhere); identity, rigid motions, clamping and bad
input.
"""

import numpy as np
import pytest
import trimesh
from test_flesh import cylinder_grid, plane_grid, subdivided, vols

import spinal


def grid_faces(nu, nv):
    """Two triangles per cell of an ``(nu, nv)`` grid (row-major vertices), wound so that
    their normals are ``S_u × S_v`` like the grid model's."""
    i, j = np.meshgrid(np.arange(nu - 1), np.arange(nv - 1), indexing="ij")
    a = (i * nv + j).ravel()
    b, c, d = a + nv, a + 1, a + nv + 1
    return np.r_[np.c_[a, b, d], np.c_[a, d, c]]


def tri(g):
    """A grid surface as ``(vertices, faces)``."""
    return g.reshape(-1, 3), grid_faces(*g.shape[:2])


def bent_stretched(g):
    X, Y = g[..., 0], g[..., 1]
    return np.stack([1.1 * X, 0.9 * Y + 0.1 * X, 0.25 * X**2 - 0.15 * Y**2 + 0.1 * X * Y],
                    axis=-1)


def points(rng, k=300, h=0.3):
    return np.c_[rng.uniform(-0.8, 0.8, (k, 2)), rng.uniform(-h, h, k)]


def test_identity_rigid_motion_and_mesh_types():
    rng = np.random.default_rng(0)
    g = plane_grid(21)
    V = points(rng)
    V0 = V.copy()
    sv, F = tri(g)
    posed = cylinder_grid(21).reshape(-1, 3)
    for surf in ((sv, F), spinal.Mesh(sv, F), trimesh.Trimesh(sv, F, process=False)):
        b = spinal.SurfaceBinding(V, surf)
        assert np.abs(b.deform(sv) - V).max() < 1e-12
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        R = q * np.sign(np.linalg.det(q))
        assert np.abs(b.deform(sv @ R.T + [1, 2, 3]) - (V @ R.T + [1, 2, 3])).max() < 1e-10
    # the posed surface may be a mesh with the same faces; inputs are not modified
    out = b.deform(posed)
    assert np.array_equal(b.deform((posed, F)), out)
    assert np.array_equal(spinal.flesh_surface(V, (sv, F), posed), out)
    assert np.array_equal(V, V0) and np.array_equal(sv, g.reshape(-1, 3))
    assert b.face.shape == (300,) and np.allclose(b.barycentric.sum(axis=1), 1)
    with spinal.threads(1):
        assert np.array_equal(spinal.SurfaceBinding(V, (sv, F)).deform(posed), out)


def test_jacobian_on_a_bent_stretched_plate():
    rng = np.random.default_rng(6)
    g = plane_grid(31)
    sv, F = tri(g)
    posed = bent_stretched(g).reshape(-1, 3)
    pts = points(rng, 200)
    eps = 1e-5
    probes = [pts] + [pts + s * eps * e for e in np.eye(3) for s in (1, -1)]
    b = spinal.SurfaceBinding(np.concatenate(probes), (sv, F))
    faces = b.face.reshape(7, -1)
    same = (faces == faces[0]).all(axis=0)  # all probes in one face's normal prism
    assert same.sum() > 150
    for sol, expect in (("offset", True), ("none", False)):
        out = b.deform(posed, solution=sol).reshape(7, -1, 3)
        J = np.stack([(out[1 + 2 * k] - out[2 + 2 * k]) / (2 * eps) for k in range(3)], -1)
        det = np.linalg.det(J)[same]
        if expect:
            assert np.abs(det - 1).max() < 1e-6
        else:
            assert np.abs(det - 1).max() > 0.05


def test_boxes_on_a_plate_bent_into_a_cylinder_keep_their_volume():
    """A flat triangulated plate bent into a cylinder arc (radius 2): closed boxes above and
    below keep their volume up to the boxes' own sampling error, which falls 4× per
    subdivision as with the grid model; the uncorrected map is 10–13 % off."""
    g, cyl = plane_grid(21), cylinder_grid(21)
    sv, F = tri(g)
    turn = trimesh.transformations.rotation_matrix(0.37, [0.1, 0.2, 1])
    for shift in ([0.1234, 0.0567, 0.2591], [-0.1234, 0.0567, -0.2191]):
        box = trimesh.creation.box(extents=[0.8, 0.6, 0.3])
        box.apply_transform(turn)
        box.apply_translation(shift)
        errs = []
        for times in (3, 4, 5):
            m = subdivided(box, times)
            v0 = vols(m)[0]
            e = {}
            for sol in ("offset", "none"):
                out = spinal.flesh_surface(m.vertices, (sv, F), cyl.reshape(-1, 3),
                                           solution=sol)
                v1_tm, v1_igl = vols(trimesh.Trimesh(out, m.faces, process=False))
                assert abs(v1_tm - v1_igl) < 1e-12 * v1_tm
                e[sol] = v1_tm / v0 - 1
            grid = spinal.flesh_surface(m.vertices, g, cyl)
            e["grid"] = vols(trimesh.Trimesh(grid, m.faces, process=False))[0] / v0 - 1
            assert abs(e["none"]) > 0.09, e
            assert abs(e["offset"] - e["grid"]) < 0.1 * abs(e["grid"]), e
            errs.append(abs(e["offset"]))
        assert errs[0] / errs[1] > 3.5 and errs[1] / errs[2] > 3.5, errs
        assert errs[-1] < 1e-4, errs


def affine_grid(rng, n):
    """A flat grid in a general position (rotated, sheared, stretched plane)."""
    x = np.linspace(-1, 1, n)
    X, Y = np.meshgrid(x, 0.8 * x, indexing="ij")
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    A = np.array([[1.3, 0.4, 0.0], [-0.2, 0.7, 0.0], [0.0, 0.0, 1.0]])
    return np.stack([X, Y, np.zeros_like(X)], axis=-1) @ A.T @ q.T + rng.normal(size=3)


def test_equals_the_grid_model_where_both_are_exact():
    """A flat grid posed by an affine map of its plane: the grid model's bicubic cells with
    central differences reproduce affine data, its normals are constant, so both models give
    ``h1 = h0 A0/A1`` at the same foot."""
    rng = np.random.default_rng(3)
    for n in (2, 7, 20):
        rest = affine_grid(rng, n)
        posed = affine_grid(rng, n)
        frame = spinal.SurfaceBinding(np.zeros((1, 3)), rest).rest_frames[0, 0]
        c = rest.reshape(-1, 3).mean(axis=0)
        local = np.c_[rng.uniform(-0.5, 0.5, (400, 2)), rng.uniform(-0.4, 0.4, 400)]
        V = c + local @ (frame * [0.9, 0.5, 1.0]).T
        a = spinal.flesh_surface(V, rest, posed)
        b = spinal.flesh_surface(V, tri(rest), posed.reshape(-1, 3))
        assert np.abs(a - V).max() > 0.1  # a real pose
        assert np.abs(a - b).max() < 1e-9, (n, np.abs(a - b).max())


def test_difference_from_the_grid_model_falls_with_refinement():
    """On a bent grid the two models differ (bicubic cells against flat faces with
    interpolated normals); the difference is a discretisation error, first order in the
    grid step (measured: 1.1e-2, 3.8e-3, 1.8e-3, 8.6e-4 for n = 11, 21, 41, 81)."""
    rng = np.random.default_rng(0)
    V = points(rng)
    diffs = []
    for n in (11, 21, 41):
        g = plane_grid(n)
        X, Y = g[..., 0], g[..., 1]
        posed = np.stack([X, 1.1 * Y, 0.35 * X**2 + 0.05 * Y**2], axis=-1)
        a = spinal.flesh_surface(V, g, posed)
        b = spinal.flesh_surface(V, tri(g), posed.reshape(-1, 3))
        diffs.append(np.abs(a - b).max())
    assert diffs[0] > 1e-3  # the models do differ
    assert diffs[0] / diffs[1] > 1.8 and diffs[1] / diffs[2] > 1.8, diffs


def test_clamped_and_outside_vertices_are_reported():
    # plate → spherical cap of radius 0.5: 0.45 above the centre cannot fit (focal point 0.5)
    g = plane_grid(21, 1.0)
    X, Y = g[..., 0], g[..., 1]
    R = 0.5
    r = np.hypot(X, Y)
    sc = np.where(r > 0, np.sin(r / R) / np.where(r > 0, r, 1), 1 / R) * R
    cap = np.stack([X * sc, Y * sc, R * (1 - np.cos(r / R))], axis=-1)
    V = np.array([[0.01, 0.02, 0.45], [0.01, 0.02, 0.1], [0.9, 0.0, 0.1]])  # last: outside
    with pytest.warns(spinal.FoldOverWarning):
        out, clamped = spinal.flesh_surface(V, tri(g), cap.reshape(-1, 3),
                                            return_clamped=True)
    assert np.array_equal(clamped, [0, 2]) and np.isfinite(out).all()
    assert abs(out[0, 2] - 0.5) < 2e-2  # at the focal point (the sphere's centre)
    with pytest.raises(ValueError, match="^posed_surface: .*clamped"):
        spinal.flesh_surface(V, tri(g), cap.reshape(-1, 3), strict=True)
    # the outside vertex moves rigidly with a rigid motion of the surface
    sv, F = tri(g)
    with pytest.warns(spinal.FoldOverWarning, match="e.g. vertex 2"):
        out = spinal.flesh_surface(V, (sv, F), sv + [0, 0, 1])
    assert np.abs(out - (V + [0, 0, 1])).max() < 1e-12


def test_bad_input_is_refused_by_name():
    g = plane_grid(6)
    sv, F = tri(g)
    V = np.array([[0.0, 0.0, 0.1]])

    def bind(surf, vertices=V):
        return spinal.SurfaceBinding(vertices, surf)

    bad = F.copy()
    bad[3, 1] = len(sv)
    with pytest.raises(ValueError, match="^rest_surface: face 3 refers to vertex 36"):
        bind((sv, bad))
    bad[3, 1] = -1
    with pytest.raises(ValueError, match="^rest_surface: face 3 refers to vertex -1"):
        bind((sv, bad))
    bad = F.copy()
    bad[4, 2] = bad[4, 0]
    with pytest.raises(ValueError, match="^rest_surface: face 4 repeats"):
        bind((sv, bad))
    flat = sv.copy()
    flat[F[5, 1]] = 0.5 * (flat[F[5, 0]] + flat[F[5, 2]])  # a face on a line
    with pytest.raises(ValueError, match="^rest_surface: face 5 is degenerate"):
        bind((flat, F))
    nan = sv.copy()
    nan[7, 2] = np.nan
    with pytest.raises(ValueError, match="^rest_surface: vertex 7 is not finite"):
        bind((nan, F))
    flipped = F.copy()
    flipped[::2] = flipped[::2, ::-1]
    with pytest.raises(ValueError, match="^rest_surface: "):
        bind((sv, flipped))
    with pytest.raises(ValueError, match="^rest_surface: .*faces of shape"):
        bind((sv, F[:, :2]))
    with pytest.raises(ValueError, match="^rest_surface: .*faces of shape"):
        bind((sv, F[:0]))
    with pytest.raises(ValueError, match="^rest_surface: .*vertices of shape"):
        bind((sv[:, :2], F))
    class FloatFaces:
        vertices, faces = sv, F.astype(float)

    with pytest.raises(TypeError, match="^rest_surface: .*integer faces"):
        bind(FloatFaces())
    with pytest.raises(ValueError, match="^vertices:"):
        bind((sv, F), [[np.nan, 0, 0]])
    b = bind((sv, F))
    with pytest.raises(ValueError, match="^posed_surface: expected the rest surface's 36"):
        b.deform(sv[:-1])
    with pytest.raises(ValueError, match="^posed_surface: its faces differ"):
        b.deform((sv, F[::-1]))
    nan = sv.copy()
    nan[2] = np.inf
    with pytest.raises(ValueError, match="^posed_surface: vertex 2 is not finite"):
        b.deform(nan)
    squash = sv.copy()
    squash[:, 0] = 0.0  # every face collapses onto a line
    with pytest.raises(ValueError, match="^posed_surface: face 0 is degenerate"):
        b.deform(squash)
    with pytest.raises(TypeError, match="^posed_up: only with a grid"):
        b.deform(sv, posed_up=[0, 0, 1])
    with pytest.raises(TypeError, match="^uv: only for a grid"):
        _ = b.uv
    with pytest.raises(TypeError, match="^face: only for a triangulated"):
        _ = spinal.SurfaceBinding(V, g).face


def test_seams_across_edges_shrink_with_refinement():
    """The faces' volume elements jump across edges, so the map does too (except where the
    pose keeps them: here a plate rolled into a cylinder about an axis parallel to the
    edges); the jump is first order in the edge length (measured 5.4e-3, 1.9e-3, 8.5e-4)."""
    rng = np.random.default_rng(1)
    jumps = []
    for n in (11, 21, 41):
        g = plane_grid(n)
        x0 = -1 + 2 / (n - 1) * ((n - 1) // 2 + 1)  # a grid line: edges between faces
        P = np.c_[np.full(200, x0), rng.uniform(-0.7, 0.7, 200), rng.uniform(-0.3, 0.3, 200)]
        a = spinal.flesh_surface(P - [1e-9, 0, 0], tri(g), bent_stretched(g).reshape(-1, 3))
        b = spinal.flesh_surface(P + [1e-9, 0, 0], tri(g), bent_stretched(g).reshape(-1, 3))
        jumps.append(np.abs(a - b).max())
        a = spinal.flesh_surface(P - [1e-9, 0, 0], tri(g), cylinder_grid(n).reshape(-1, 3))
        b = spinal.flesh_surface(P + [1e-9, 0, 0], tri(g), cylinder_grid(n).reshape(-1, 3))
        assert np.abs(a - b).max() < 1e-8
    assert jumps[0] > 1e-3 and jumps[0] / jumps[1] > 1.8 and jumps[1] / jumps[2] > 1.8, jumps


@pytest.mark.parametrize("scale", [1e-200, 1e-30, 1e30, 1e200])
def test_any_scale_gives_the_scaled_result(scale):
    rng = np.random.default_rng(0)
    g = plane_grid(11)
    sv, F = tri(g)
    V = points(rng, 50)
    posed = bent_stretched(g).reshape(-1, 3)
    ref = spinal.flesh_surface(V, (sv, F), posed)
    out = spinal.flesh_surface(V * scale, (sv * scale, F), posed * scale)
    assert np.abs(out / scale - ref).max() < 1e-14
