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


def small_rotation(rng, size=0.2):
    """A rotation by a random angle of about ``size`` (Rodrigues' formula)."""
    w = size * rng.normal(size=3)
    t = np.linalg.norm(w)
    K = np.cross(np.eye(3), w / t)
    return np.eye(3) + np.sin(t) * K + (1 - np.cos(t)) * K @ K


def test_frames_and_given_directions_equal_the_grid_model_where_both_are_exact():
    """A flat grid posed by an affine map of its plane, the offsets laid along the posed
    frames' normal column tilted by a rotation ``Q``: constant directions ``D``, so both
    models give ``h1 = h0 A0/A1`` with ``A = (S_u × S_v)·D`` at the same foot."""
    rng = np.random.default_rng(11)
    for n in (2, 7, 20):
        rest, posed = affine_grid(rng, n), affine_grid(rng, n)
        frame = spinal.SurfaceBinding(np.zeros((1, 3)), rest).rest_frames[0, 0]
        c = rest.reshape(-1, 3).mean(axis=0)
        local = np.c_[rng.uniform(-0.5, 0.5, (400, 2)), rng.uniform(-0.4, 0.4, 400)]
        V = c + local @ (frame * [0.9, 0.5, 1.0]).T
        grid, mesh = spinal.SurfaceBinding(V, rest), spinal.SurfaceBinding(V, tri(rest))
        # the frames: the grid's at every sample but the corner (0, nv − 1), where the only
        # face's S_u edge is a diagonal of the cell
        fg, fm = grid.rest_frames.reshape(-1, 3, 3), mesh.rest_frames
        assert fm.shape == (n * n, 3, 3)
        corner = n - 1
        assert np.abs(np.delete(fg - fm, corner, axis=0)).max() < 1e-12
        assert np.abs(fg[corner, :, 2] - fm[corner, :, 2]).max() < 1e-12
        Q = small_rotation(rng)
        pg = Q @ spinal.SurfaceBinding(V[:1], posed).rest_frames
        pm = Q @ spinal.SurfaceBinding(V[:1], tri(posed)).rest_frames
        pv = posed.reshape(-1, 3)
        for sol in ("offset", "none"):
            a = grid.deform(posed, solution=sol, posed_frames=pg)
            b = mesh.deform(pv, solution=sol, posed_frames=pm)
            assert np.abs(a - grid.deform(posed, solution=sol)).max() > 0.02  # a real tilt
            assert np.abs(a - b).max() < 1e-9, (n, sol, np.abs(a - b).max())
            up = pg[0, 0, :, 2]
            a = grid.deform(posed, solution=sol, posed_up=up)
            b = mesh.deform(pv, solution=sol, posed_up=up)
            assert np.abs(a - b).max() < 1e-9, (n, sol, np.abs(a - b).max())
        # R @ rest_frames with the surface moved by x ↦ Rx + t moves the shape rigidly
        R, t = small_rotation(rng, 2.0), rng.normal(size=3)
        out = mesh.deform(rest.reshape(-1, 3) @ R.T + t, posed_frames=R @ fm)
        assert np.abs(out - (V @ R.T + t)).max() < 1e-10


def test_frames_on_a_bent_surface_are_rotations_with_the_vertex_normals():
    """Angle-weighted vertex normals computed here (Thürmer & Wüthrich 1998) and the
    lowest face's ``S_b − S_a`` projected: orthonormal, determinant +1."""
    g = bent_stretched(plane_grid(9))
    sv, F = tri(g)
    fr = spinal.SurfaceBinding(np.zeros((1, 3)), (sv, F)).rest_frames
    assert fr.shape == (len(sv), 3, 3)
    assert np.abs(np.swapaxes(fr, 1, 2) @ fr - np.eye(3)).max() < 1e-12
    assert np.abs(np.linalg.det(fr) - 1).max() < 1e-12
    normals = np.zeros_like(sv)
    for f in F:
        p = sv[f]
        nf = np.cross(p[1] - p[0], p[2] - p[0])
        nf /= np.linalg.norm(nf)
        for k in range(3):
            a, b = p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]
            normals[f[k]] += np.arccos(a @ b / np.linalg.norm(a) / np.linalg.norm(b)) * nf
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    assert np.abs(fr[:, :, 2] - normals).max() < 1e-12
    first = np.full(len(sv), -1)
    for k in range(len(F) - 1, -1, -1):
        first[F[k]] = k
    edge = sv[F[first, 1]] - sv[F[first, 0]]
    assert np.all(np.einsum("ij,ij->i", fr[:, :, 0], edge) > 0)
    assert np.abs(np.einsum("ij,ij->i", np.cross(fr[:, :, 0], edge), normals)).max() < 1e-12
    # a vertex no face uses gets the identity
    extra = spinal.SurfaceBinding(np.zeros((1, 3)), (np.r_[sv, [[5.0, 5, 5]]], F)).rest_frames
    assert np.array_equal(extra[-1], np.eye(3)) and np.array_equal(extra[:-1], fr)


def test_given_directions_keep_the_jacobian_on_a_bent_plate():
    """Offsets laid along tilted frames on a bent, stretched plate: the face's volume element
    ``det[S_u + hD_u, S_v + hD_v, D]`` is solved for, so the finite-difference Jacobian
    determinant is 1 (and not 1 uncorrected)."""
    rng = np.random.default_rng(8)
    g = plane_grid(31)
    sv, F = tri(g)
    posed = bent_stretched(g).reshape(-1, 3)
    pts = points(rng, 200)
    eps = 1e-5
    probes = [pts] + [pts + s * eps * e for e in np.eye(3) for s in (1, -1)]
    b = spinal.SurfaceBinding(np.concatenate(probes), (sv, F))
    faces = b.face.reshape(7, -1)
    same = (faces == faces[0]).all(axis=0)
    frames = spinal.SurfaceBinding(pts[:1], (posed, F)).rest_frames
    # tilted by a rotation that turns along the plate
    x = sv[:, 0]
    tilt = np.array([small_rotation(np.random.default_rng(1), 0.3 + 0.2 * xi) for xi in x])
    for sol, expect in (("offset", True), ("none", False)):
        out, clamped = b.deform(posed, solution=sol, posed_frames=tilt @ frames,
                                return_clamped=True)
        assert clamped.size == 0
        out = out.reshape(7, -1, 3)
        J = np.stack([(out[1 + 2 * k] - out[2 + 2 * k]) / (2 * eps) for k in range(3)], -1)
        det = np.linalg.det(J)[same]
        if expect:
            assert np.abs(det - 1).max() < 1e-6
        else:
            assert np.abs(det - 1).max() > 0.05


def test_bad_directions_are_named_as_on_grids():
    sv, F = tri(plane_grid(6))
    b = spinal.SurfaceBinding([[0.0, 0.0, 0.1]], (sv, F))
    frames = b.rest_frames
    with pytest.raises(TypeError, match="posed_frames, posed_up"):
        b.deform(sv, posed_frames=frames, posed_up=[0, 0, 1])
    with pytest.raises(ValueError, match=r"^posed_frames: expected shape \(36, 3, 3\) like "
                                         r"posed_surface's vertices"):
        b.deform(sv, posed_frames=frames[:-1])
    with pytest.raises(ValueError, match=r"^posed_frames: expected shape"):
        b.deform(sv, posed_frames=frames.reshape(6, 6, 3, 3))
    bad = frames.copy()
    bad[7] *= 1.1
    with pytest.raises(ValueError, match=r"^posed_frames: vertex 7 is not a rotation"):
        b.deform(sv, posed_frames=bad)
    bad = frames.copy()
    bad[9] = bad[9] @ np.diag([1.0, 1.0, -1.0])
    with pytest.raises(ValueError, match=r"^posed_frames: vertex 9 is not a rotation"):
        b.deform(sv, posed_frames=bad)
    bad = frames.copy()
    bad[8] = bad[8][:, [2, 0, 1]]  # a rotation whose normal column lies in the plane
    with pytest.raises(ValueError, match=r"^posed_frames: vertex 8: .*parallel to the surface"):
        b.deform(sv, posed_frames=bad)
    with pytest.raises(ValueError, match=r"^posed_frames: vertex 0: .*other side"):
        b.deform(sv, posed_frames=frames @ np.diag([1.0, -1.0, -1.0]))
    with pytest.raises(ValueError, match=r"^posed_up: expected shape \(3,\) or \(36, 3\)"):
        b.deform(sv, posed_up=[0, 1])
    with pytest.raises(ValueError, match="^posed_up: vertex 0: .*parallel to the surface"):
        b.deform(sv, posed_up=[1.0, 0.0, 0.0])
    up = np.broadcast_to([0.0, 0, 1], (36, 3)).copy()
    up[4] = np.nan
    with pytest.raises(ValueError, match=r"^posed_up: vertex 4: not a finite non-zero"):
        b.deform(sv, posed_up=up)
    # each vertex passes, but a face's corner direction is on the other side of that face
    kinked = sv.copy()
    kinked[14, 2] = 3.0  # a spike: its vertex normal leans far from its faces' normals
    up = np.broadcast_to([0.0, 0, 1], (36, 3)).copy()
    up[14] = [1.0, 0.0, 0.02]
    with pytest.raises(ValueError, match=r"^posed_up: face \d+: the direction of vertex 14 "
                                         r"is not on the face's normal side"):
        b.deform(kinked, posed_up=up)
