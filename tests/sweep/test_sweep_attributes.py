"""Sweeps for real pipelines: attributes on the mesh (point_data, cell_data, sample_of,
curve_of) through PLY/VTP/pyvista/trimesh, bundles as lists (float32, nibabel), per-curve
radius, short curves, fold-over reports by curve, Mesh checks, measures cross-checked with
trimesh on random and broken meshes, and Mesh.concatenate."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import pyvista as pv
import trimesh

import spinal
from spinal.curves import Helix


def bundle(sizes, seed=0, dtype=np.float64):
    """Smooth random curves (n_i, 3), one per size."""
    rng = np.random.default_rng(seed)
    out = []
    for c, n in enumerate(sizes):
        t = np.linspace(0, 1, n)
        a = np.linalg.qr(rng.normal(size=(3, 3)))[0]  # a random rotation
        x = np.c_[3 * t, 0.5 * np.sin(2 * t + c), 0.5 * np.cos(3 * t)] @ a.T * 4 + 3 * c
        out.append(x.astype(dtype))
    return out


def orientation(curves):
    """|unit tangent| per point of every curve (the usual streamline colouring)."""
    return np.concatenate([np.abs(spinal.estimate_tangents(c)) for c in curves])


# ---------------------------------------------------------------- point data


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("split_seams", [False, True])
def test_point_data_of_every_vertex_is_its_samples_value(closed, split_seams):
    x = Helix(1, 0.3, turns=1).sample(40)
    if closed:
        u = 2 * np.pi * np.arange(41) / 40
        x = np.c_[np.cos(u), np.sin(u), 0.1 * np.sin(2 * u)]  # repeated first point at the end
    n = len(x)
    data = {"scalar": np.arange(n) * 0.5, "rgb": np.abs(np.random.default_rng(1).normal(
        size=(n, 3))).astype(np.float32), "label": np.arange(n, dtype=np.uint8)}
    mesh = spinal.tube(x, 0.1, 7, closed=closed, split_seams=split_seams, point_data=data)
    s = mesh.sample_of
    assert s.shape == (len(mesh.vertices),) and s.dtype == np.int64
    for k, v in data.items():
        assert mesh.point_data[k].dtype == v.dtype
        np.testing.assert_array_equal(mesh.point_data[k], v[s])
    # the vertex is on the ring of its sample: its distance to that spine point is the radius
    # (up to the mitre stretch)
    d = np.linalg.norm(mesh.vertices - x[s], axis=1)
    assert np.all((d > 0.1 - 1e-12) & (d < 0.1 * 1.01))
    assert np.all(mesh.curve_of == 0)
    assert mesh.cell_data == {}  # one curve: no curve ids
    if closed:
        assert s.max() == n - 2  # the repeated point has no ring of its own
    # caps use the first and last rings: their vertices carry the end samples' values
    if not closed:
        cap = mesh.faces[-1]
        assert set(s[cap]) == {n - 1}


def test_point_data_in_bundles_per_sample_and_per_curve_and_cell_curve_ids():
    curves = bundle([30, 12, 50, 2])
    n, C = sum(map(len, curves)), len(curves)
    colour = orientation(curves)
    weight = np.array([1.0, 2.0, 3.0, 4.0])
    mesh = spinal.tube(curves, 0.05, 6, point_data={"colour": colour, "w": weight,
                                                   "pair": np.c_[weight, -weight]})
    np.testing.assert_array_equal(mesh.point_data["colour"], colour[mesh.sample_of])
    np.testing.assert_array_equal(mesh.point_data["w"], weight[mesh.curve_of])
    np.testing.assert_array_equal(mesh.point_data["pair"][:, 1], -weight[mesh.curve_of])
    starts = np.cumsum([0] + [len(c) for c in curves])
    np.testing.assert_array_equal(mesh.curve_of, np.searchsorted(starts, mesh.sample_of,
                                                                 side="right") - 1)
    cid = mesh.cell_data["curve_id"]
    assert cid.shape == (len(mesh.faces),)
    np.testing.assert_array_equal(cid, mesh.curve_of[mesh.faces[:, 0]])
    np.testing.assert_array_equal(mesh.curve_of[mesh.faces[:, 2]], cid)
    assert set(cid) == set(range(C)) and mesh.sample_of.max() == n - 1
    with pytest.raises(ValueError, match=r"point_data\['bad'\]: expected \(94,\) or \(94, k\)"):
        spinal.tube(curves, 0.05, 6, point_data={"bad": np.zeros(5)})
    with pytest.raises(TypeError, match="point_data: expected a dict"):
        spinal.tube(curves, 0.05, 6, point_data=[1, 2])
    with pytest.raises(TypeError, match=r"point_data\['s'\]: expected a numeric array"):
        spinal.tube(curves, 0.05, 6, point_data={"s": np.array(["a"] * n)})


def test_attributes_through_ply_vtp_pyvista_and_trimesh(tmp_path):
    curves = bundle([25, 40, 9])
    colour = orientation(curves)
    fa = np.linspace(0, 1, len(colour)).astype(np.float32)
    mesh = spinal.tube(curves, 0.05, 8, point_data={"orientation": colour, "fa": fa})
    # pyvista / trimesh objects
    poly = mesh.to_pyvista()
    np.testing.assert_array_equal(poly.point_data["orientation"], mesh.point_data["orientation"])
    np.testing.assert_array_equal(poly.cell_data["curve_id"], mesh.cell_data["curve_id"])
    tm = mesh.to_trimesh()
    np.testing.assert_array_equal(tm.vertex_attributes["fa"], mesh.point_data["fa"])
    np.testing.assert_array_equal(tm.face_attributes["curve_id"], mesh.cell_data["curve_id"])
    # VTK XML PolyData, read back by VTK
    back = pv.read(mesh.save(tmp_path / "b.vtp"))
    np.testing.assert_array_equal(back.points, mesh.vertices)
    np.testing.assert_array_equal(back.regular_faces, mesh.faces)
    np.testing.assert_array_equal(back.point_data["orientation"], colour[mesh.sample_of])
    assert back.point_data["fa"].dtype == np.float32
    np.testing.assert_array_equal(back.point_data["fa"], fa[mesh.sample_of])
    np.testing.assert_array_equal(back.point_data["Normals"], mesh.normals)
    np.testing.assert_array_equal(back.point_data["uv"], mesh.uv)
    np.testing.assert_array_equal(back.cell_data["curve_id"], mesh.cell_data["curve_id"])
    assert back.volume == pytest.approx(mesh.volume, rel=1e-12)
    # PLY: VTK reads the geometry, normals and uv (as float32); trimesh every property
    path = mesh.save(tmp_path / "b.ply")
    back = pv.read(path)
    np.testing.assert_allclose(back.points, mesh.vertices, rtol=1e-7, atol=1e-7)
    np.testing.assert_array_equal(back.regular_faces, mesh.faces)
    np.testing.assert_allclose(back.point_data["Normals"], mesh.normals, atol=1e-7)
    tm = trimesh.load(path, process=False)
    np.testing.assert_array_equal(tm.faces, mesh.faces)
    raw = tm.metadata["_ply_raw"]
    v, f = raw["vertex"]["data"], raw["face"]["data"]
    for j in range(3):
        np.testing.assert_array_equal(v[f"orientation_{j}"], colour[mesh.sample_of][:, j])
    assert v["fa"].dtype == np.float32
    np.testing.assert_array_equal(v["fa"], fa[mesh.sample_of])
    np.testing.assert_array_equal(f["curve_id"], mesh.cell_data["curve_id"])
    # names that clash with the PLY's own properties are refused by name
    clash = spinal.tube(curves[0], 0.05, 8, point_data={"s": np.zeros(25)})
    with pytest.raises(ValueError, match="point_data: the name 's' is taken"):
        clash.save(tmp_path / "c.ply")
    with pytest.raises(TypeError, match="path: expected a str"):
        mesh.save(5)


# ---------------------------------------------------------------- bundles as users hold them


def test_bundle_as_list_float32_and_tuple_equals_lengths():
    curves = bundle([20, 35, 11], seed=3)
    flat = np.concatenate(curves)
    lengths = [len(c) for c in curves]
    ref = spinal.tube(flat, 0.05, 6, lengths=lengths)
    for form in (curves, tuple(curves), [c.tolist() for c in curves]):
        mesh = spinal.tube(form, 0.05, 6)
        np.testing.assert_array_equal(mesh.vertices, ref.vertices)
        np.testing.assert_array_equal(mesh.faces, ref.faces)
    f32 = [c.astype(np.float32) for c in curves]
    mesh = spinal.tube(f32, 0.05, 6)
    ref32 = spinal.tube(np.concatenate(f32), 0.05, 6, lengths=lengths)
    np.testing.assert_array_equal(mesh.vertices, ref32.vertices)
    np.testing.assert_array_equal(spinal.frames(curves), spinal.frames(flat, lengths=lengths))
    u = 2 * np.pi * np.arange(30) / 30
    loops = [np.c_[np.cos(u), np.sin(u), 0.2 * np.sin(2 * u + c)] for c in range(3)]
    np.testing.assert_array_equal(spinal.closing_angle(loops),
                                  spinal.closing_angle(np.concatenate(loops), lengths=[30] * 3))
    tg = [spinal.estimate_tangents(c) for c in curves]
    np.testing.assert_array_equal(spinal.frames(curves, tg),
                                  spinal.frames(flat, np.concatenate(tg), lengths=lengths))
    prof = [(0.05, 0), (0, 0.05), (-0.05, 0), (0, -0.05)]
    np.testing.assert_array_equal(spinal.sweep(curves, prof).vertices,
                                  spinal.sweep(flat, prof, lengths=lengths).vertices)
    with pytest.raises(TypeError, match="lengths, offsets: not accepted with a sequence"):
        spinal.tube(curves, 0.05, 6, lengths=lengths)
    with pytest.raises(ValueError, match=r"points\[1\]: expected an array of shape \(n, 3\)"):
        spinal.tube([curves[0], curves[1][:, :2]], 0.05)


def test_nibabel_array_sequence():
    nib = pytest.importorskip("nibabel")
    curves = bundle([30, 8, 17], seed=5, dtype=np.float32)
    seq = nib.streamlines.ArraySequence(curves)
    ref = spinal.tube(curves, 0.1, 5)
    mesh = spinal.tube(seq, 0.1, 5)
    np.testing.assert_array_equal(mesh.vertices, ref.vertices)
    np.testing.assert_array_equal(spinal.frames(seq), spinal.frames(curves))
    # a slice of an ArraySequence is a view with its own offsets
    np.testing.assert_array_equal(spinal.tube(seq[1:], 0.1, 5).vertices,
                                  spinal.tube(curves[1:], 0.1, 5).vertices)


def test_per_curve_radius():
    curves = bundle([20, 30, 25], seed=7)
    lengths = [len(c) for c in curves]
    r = np.array([0.05, 0.1, 0.2])
    mesh = spinal.tube(curves, r, 8)
    ref = spinal.tube(np.concatenate(curves), np.repeat(r, lengths), 8, lengths=lengths)
    np.testing.assert_array_equal(mesh.vertices, ref.vertices)
    prof = [(1, 0), (0, 1), (-1, 0), (0, -1)]
    np.testing.assert_array_equal(spinal.sweep(curves, prof, scale=r).vertices,
                                  spinal.sweep(curves, prof, scale=np.repeat(r, lengths)).vertices)
    with pytest.raises(ValueError, match="radius: expected a scalar, "):
        spinal.tube(curves, [0.1, 0.2], 8)


def test_short_curves_raise_or_are_skipped_and_reported():
    curves = bundle([20, 1, 30, 0, 15], seed=2)
    with pytest.raises(ValueError, match="points: curve 1 .*at least 2"):
        spinal.tube(curves, 0.05, 6)
    with pytest.raises(ValueError, match="on_short: unknown value"):
        spinal.tube(curves, 0.05, 6, on_short="drop")
    value = np.arange(66.0)
    with pytest.warns(spinal.SkippedCurvesWarning, match="left out 2 curve.*: 1, 3") as rec:
        mesh = spinal.tube(curves, [0.1, 0.15, 0.2, 0.25, 0.3], 6, on_short="skip",
                           point_data={"v": value, "c": np.arange(5) * 10})
    np.testing.assert_array_equal(rec[0].message.curves, [1, 3])
    np.testing.assert_array_equal(mesh.skipped_curves, [1, 3])
    # rows and curves keep the numbering of the input
    assert set(mesh.curve_of) == {0, 2, 4}
    np.testing.assert_array_equal(mesh.point_data["v"], value[mesh.sample_of])
    np.testing.assert_array_equal(mesh.point_data["c"], 10 * mesh.curve_of)
    kept = spinal.tube([curves[0], curves[2], curves[4]], [0.1, 0.2, 0.3], 6)
    np.testing.assert_array_equal(mesh.vertices, kept.vertices)
    assert mesh.is_watertight
    # everything skipped gives an empty mesh
    with pytest.warns(spinal.SkippedCurvesWarning, match="fewer than 2 points"):
        empty = spinal.tube([curves[1], curves[3]], 0.1, on_short="skip")
    assert len(empty.vertices) == 0 and empty.volume == 0.0
    np.testing.assert_array_equal(empty.skipped_curves, [0, 1])


def test_short_closed_curves_are_skipped_below_three_points():
    """closed=True needs 3 points per curve: 0-, 1- and 2-point curves are skipped (2-point
    ones kept when open), and errors about kept curves name them as given."""
    u = 2 * np.pi * np.arange(20) / 20
    loop = np.c_[np.cos(u), np.sin(u), 0.1 * np.sin(2 * u)]
    w = 2 * np.pi * np.arange(3) / 3
    triangle = np.c_[np.cos(w), np.sin(w), np.zeros(3)] + 6  # equilateral
    curves = [loop, loop[:2], loop[::2] + 3, loop[:1], np.zeros((0, 3)), triangle]
    with pytest.raises(ValueError, match="points: curve 1 .*closed curve needs at least 3"):
        spinal.tube(curves, 0.05, 6, closed=True)
    with pytest.warns(spinal.SkippedCurvesWarning,
                      match=r"left out 3 curve.* fewer than 3 points .*: 1, 3–4;") as rec:
        mesh = spinal.tube(curves, 0.05, 6, closed=True, on_short="skip")
    np.testing.assert_array_equal(rec[0].message.curves, [1, 3, 4])
    np.testing.assert_array_equal(mesh.skipped_curves, [1, 3, 4])
    assert set(mesh.curve_of) == {0, 2, 5}
    kept = spinal.tube([loop, loop[::2] + 3, triangle], 0.05, 6, closed=True)
    np.testing.assert_array_equal(mesh.vertices, kept.vertices)
    np.testing.assert_array_equal(mesh.faces, kept.faces)
    assert mesh.is_watertight  # closed tubes: no caps, and every curve's seam joined
    # the same bundle open keeps the 2-point curve
    with pytest.warns(spinal.SkippedCurvesWarning, match=r"fewer than 2 points .*: 3–4;"):
        assert set(spinal.tube(curves, 0.05, 6, on_short="skip").curve_of) == {0, 1, 2, 5}
    # an error about a kept curve names it and its rows as given, past the skipped ones
    bad = curves[:5] + [np.r_[loop[:2], [[np.nan, 0, 0]]] * 2 + 6]
    with (pytest.warns(spinal.SkippedCurvesWarning),
          pytest.raises(ValueError, match=r"points: curve 5 \(rows 33 to 35\): non-finite")):
        spinal.tube(bad, 0.05, 6, closed=True, on_short="skip")


def test_fold_over_warning_names_curves_and_local_rows():
    t = np.linspace(-3, 3, 121)
    bend = np.c_[t, 0.2 * np.exp(-t**2 / 0.02), np.zeros_like(t)]
    straight = np.c_[t, np.zeros_like(t), np.ones_like(t)]
    with pytest.warns(spinal.FoldOverWarning) as rec:
        alone = spinal.tube(bend, 0.15, 8)
    local = rec[0].message.indices
    with pytest.warns(spinal.FoldOverWarning, match=r"\(curve 1 rows ") as rec:
        mesh = spinal.tube([straight, bend], 0.15, 8)
    w = rec[0].message
    np.testing.assert_array_equal(w.indices, local + 121)
    np.testing.assert_array_equal(w.curves, np.ones_like(local))
    np.testing.assert_array_equal(w.rows, local)
    np.testing.assert_array_equal(mesh.fold_over, local + 121)
    assert alone.fold_over.size == local.size
    # rows and curves as given, also past a skipped curve
    with (pytest.warns(spinal.FoldOverWarning, match=r"\(curve 2 rows ") as rec,
          pytest.warns(spinal.SkippedCurvesWarning)):
        mesh = spinal.tube([straight, bend[:1], bend], 0.15, 8, on_short="skip")
    np.testing.assert_array_equal(rec[0].message.indices, local + 122)
    np.testing.assert_array_equal(mesh.fold_over, local + 122)
    np.testing.assert_array_equal(rec[0].message.rows, local)


# ---------------------------------------------------------------- Mesh checks and measures


def test_mesh_validates_its_arrays():
    V = np.eye(3)
    with pytest.raises(ValueError, match="faces: face 0 refers to vertex -1"):
        spinal.Mesh(V, [[0, 1, -1]])
    with pytest.raises(ValueError, match="faces: face 1 refers to vertex 3, but there are 3"):
        spinal.Mesh(V, [[0, 1, 2], [0, 1, 3]])
    with pytest.raises(TypeError, match="faces: expected integer vertex indices"):
        spinal.Mesh(V, [[0, 1, 2.5]])
    with pytest.raises(ValueError, match=r"faces: expected an array of shape \(F, 3\)"):
        spinal.Mesh(V, [[0, 1]])
    with pytest.raises(ValueError, match=r"vertices: expected an array of shape \(V, 3\)"):
        spinal.Mesh(np.zeros((3, 2)), [[0, 1, 2]])
    with pytest.raises(TypeError, match="vertices: expected an array of real numbers"):
        spinal.Mesh("abc", [[0, 1, 2]])
    with pytest.raises(ValueError, match=r"normals: expected shape \(3, 3\)"):
        spinal.Mesh(V, [[0, 1, 2]], normals=np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"point_data\['a'\]: expected a numeric \(3,\)"):
        spinal.Mesh(V, [[0, 1, 2]], point_data={"a": np.zeros(4)})
    with pytest.raises(ValueError, match=r"cell_data\['a'\]: expected a numeric \(1,\)"):
        spinal.Mesh(V, [[0, 1, 2]], cell_data={"a": np.zeros(3)})
    m = spinal.Mesh(V, np.array([[0, 1, 2]], dtype=np.uint16))
    assert m.faces.dtype == np.int64 and m.sample_of is None
    m32 = spinal.Mesh(V.astype(np.float32), np.array([[0, 1, 2]], dtype=np.int32))
    assert m32.vertices.dtype == np.float32 and m32.faces.dtype == np.int32
    assert m32.area == pytest.approx(np.sqrt(3) / 2, rel=1e-7)
    assert spinal.Mesh(np.zeros((0, 3)), np.zeros((0, 3), int)).is_watertight


def random_closed_mesh(seed):
    """A random convex hull (closed, outward) with its vertices shuffled."""
    rng = np.random.default_rng(seed)
    hull = trimesh.convex.convex_hull(rng.normal(size=(60, 3)) * rng.uniform(0.5, 2, 3))
    perm = rng.permutation(len(hull.vertices))
    inv = np.argsort(perm)
    return hull.vertices[perm], inv[hull.faces]


@pytest.mark.parametrize("seed", range(6))
def test_measures_match_trimesh_on_random_and_broken_meshes(seed):
    V, F = random_closed_mesh(seed)
    rng = np.random.default_rng(seed)
    hole = np.delete(F, rng.integers(len(F)), axis=0)
    flipped = F.copy()
    k = rng.integers(len(F))
    flipped[k] = flipped[k, ::-1]
    V = np.vstack([V, [[5.0, 5.0, 5.0]]])  # the tip of a fin on edge F[0, 0]–F[0, 1]
    fin = np.vstack([F, [[F[0, 0], F[0, 1], len(V) - 1]]])
    for faces, closed, consistent in ((F, True, True), (hole, False, True),
                                      (flipped, True, False), (fin, False, True)):
        m = spinal.Mesh(V, faces)
        tm = trimesh.Trimesh(V, faces, process=False)
        if closed and consistent:  # (else the "volume" depends on the reference point)
            assert m.volume == pytest.approx(tm.volume, rel=1e-12)
        assert m.area == pytest.approx(tm.area, rel=1e-12)
        assert m.is_closed == tm.is_watertight == closed
        if closed:
            assert m.is_winding_consistent == tm.is_winding_consistent == consistent
        assert m.is_watertight == (closed and consistent)
    e = spinal.Mesh(V, fin).edge_stats()
    assert e["non_manifold"] == 1 and e["boundary"] == 2
    e = spinal.Mesh(V, flipped).edge_stats()
    assert e["inconsistent"] == 3 and e["edges"] == 3 * len(F) // 2
    assert spinal.Mesh(V, hole).edge_stats()["boundary"] == 3
    # float32 vertices and int32 faces give the same topology and the volume to float32
    m32 = spinal.Mesh(V.astype(np.float32), F.astype(np.int32))
    assert m32.is_watertight
    assert m32.volume == pytest.approx(trimesh.Trimesh(V, F, process=False).volume, rel=1e-5)


def test_measures_of_sweeps_match_trimesh():
    curves = bundle([200, 150, 90], seed=11)
    mesh = spinal.tube(curves, 0.05, 12)
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert mesh.volume == pytest.approx(tm.volume, rel=1e-12)
    assert mesh.area == pytest.approx(tm.area, rel=1e-12)
    assert mesh.is_watertight and tm.is_watertight
    uncapped = spinal.tube(curves, 0.05, 12, caps=False)
    assert uncapped.edge_stats()["boundary"] == 3 * 2 * 12
    assert not uncapped.is_watertight and uncapped.is_winding_consistent


# ---------------------------------------------------------------- concatenate


def test_concatenate_chunks_equals_whole_bundle():
    curves = bundle([20, 1, 35, 11, 40, 9], seed=4)
    value = np.arange(sum(map(len, curves)), dtype=np.float64)
    lengths = np.array([len(c) for c in curves])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.SkippedCurvesWarning)
        whole = spinal.tube(curves, 0.05, 6, on_short="skip", point_data={"v": value})
        chunks = []
        for a, b in ((0, 2), (2, 3), (3, 6)):
            rows = slice(lengths[:a].sum(), lengths[:b].sum())
            chunks.append(spinal.tube(curves[a:b], 0.05, 6, on_short="skip",
                                      point_data={"v": value[rows]}))
    joined = spinal.Mesh.concatenate(chunks)
    for attr in ("vertices", "faces", "normals", "uv", "sample_of", "curve_of",
                 "skipped_curves", "fold_over"):
        np.testing.assert_array_equal(getattr(joined, attr), getattr(whole, attr))
    np.testing.assert_array_equal(joined.point_data["v"], whole.point_data["v"])
    np.testing.assert_array_equal(joined.cell_data["curve_id"], whole.cell_data["curve_id"])
    assert joined.is_watertight and joined.volume == pytest.approx(whole.volume, rel=1e-13)
    # plain meshes: faces offset, attributes only where all have them
    a = spinal.Mesh(np.eye(3), [[0, 1, 2]], point_data={"p": np.ones(3)})
    b = spinal.Mesh(np.eye(3) + 1, [[0, 2, 1]])
    ab = spinal.Mesh.concatenate([a, b])
    np.testing.assert_array_equal(ab.faces, [[0, 1, 2], [3, 5, 4]])
    assert ab.point_data == {} and ab.normals is None and ab.sample_of is None
    with pytest.raises(TypeError, match="meshes: expected a non-empty sequence"):
        spinal.Mesh.concatenate([])


def _as_bundles(curves):
    """The same bundle as a list, a float32 list and (if nibabel is there) an ArraySequence."""
    forms = {"list": curves, "float32": [c.astype(np.float32) for c in curves]}
    try:
        import nibabel as nib
        forms["ArraySequence"] = nib.streamlines.ArraySequence(curves)
    except ImportError:
        pass
    return forms


def test_estimate_tangents_of_a_curve_list():
    curves = bundle([30, 8, 17], seed=11)
    lengths = [len(c) for c in curves]
    for form, seq in _as_bundles(curves).items():
        flat = np.concatenate([np.asarray(c, dtype=float) for c in seq])
        np.testing.assert_array_equal(spinal.estimate_tangents(seq),
                                      spinal.estimate_tangents(flat, lengths=lengths),
                                      err_msg=form)
        np.testing.assert_array_equal(
            spinal.estimate_tangents(seq, method="circle"),
            spinal.estimate_tangents(flat, method="circle", lengths=lengths), err_msg=form)
    # a one-curve list is a bundle of one curve, not the curve's rows
    np.testing.assert_array_equal(spinal.estimate_tangents([curves[0]]),
                                  spinal.estimate_tangents(curves[0], lengths=[30]))
    with pytest.raises(TypeError, match="lengths, offsets: not accepted with a sequence"):
        spinal.estimate_tangents(curves, lengths=lengths)
    with pytest.raises(ValueError, match=r"points\[1\]: expected an array of shape \(n, 3\)"):
        spinal.estimate_tangents([curves[0], curves[1][:, :2]])


def test_steered_frames_of_a_curve_list():
    """Every steered path of frames (guide, constraints, previous, twist_rule, per-interval
    turns) takes a curve sequence as the concatenated rows with lengths=."""
    curves = bundle([30, 8, 17], seed=12)
    lengths = [len(c) for c in curves]
    n = sum(lengths)
    flat = np.concatenate(curves)
    prev = spinal.frames(flat + 0.01, lengths=lengths)
    cons = [{0: (0.0, 0.0, 1.0), -1: (0.0, 1.0, 0.0)}, None, {3: (1.0, 0.0, 0.0)}]
    calls = {
        "guide": {"guide": (0.0, 0.0, 1.0)},
        "guide per row": {"guide": np.tile([0.0, 1.0, 0.2], (n, 1))},
        "constraints": {"constraints": cons},
        "previous": {"previous": prev},
        "previous_twist": {"previous": prev, "previous_twist": True},
        "twist_rule": {"end": (0.0, 0.0, 1.0), "twist_rule": "min_angular_speed"},
        "turns per interval": {"constraints": cons, "turns": [1]},
    }
    for form, seq in _as_bundles(curves).items():
        rows = np.concatenate([np.asarray(c, dtype=float) for c in seq])
        for what, kw in calls.items():
            ref = spinal.frames(rows, lengths=lengths, **kw)
            np.testing.assert_array_equal(spinal.frames(seq, **kw), ref,
                                          err_msg=f"{form}, {what}")
        tg = [spinal.estimate_tangents(c) for c in curves]
        np.testing.assert_array_equal(
            spinal.frames(seq, tg, guide=(0.0, 0.0, 1.0)),
            spinal.frames(rows, np.concatenate(tg), lengths=lengths, guide=(0.0, 0.0, 1.0)),
            err_msg=form)
    with pytest.raises(TypeError, match="lengths, offsets: not accepted with a sequence"):
        spinal.frames(curves, lengths=lengths, guide=(0.0, 0.0, 1.0))


def test_point_data_as_a_list_of_per_curve_arrays():
    """A list of one array per curve, as dipy's values_from_volume returns them: one row per
    point (scalars or (n_c, k) rows), or one value per curve; the same mesh data as the
    concatenated (stacked) arrays."""
    rng = np.random.default_rng(4)
    curves = [np.cumsum(rng.normal(size=(m, 3)), axis=0) for m in (4, 7, 5)]
    fa = [rng.uniform(size=len(c)) for c in curves]
    rgb = [rng.integers(0, 255, size=(len(c), 3)).astype(np.uint8) for c in curves]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        listed = spinal.tube(curves, 0.1, 6, point_data={"fa": fa, "rgb": rgb,
                                                          "id": [10, 11, 12]})
        flat = spinal.tube(curves, 0.1, 6, point_data={"fa": np.concatenate(fa),
                                                        "rgb": np.concatenate(rgb),
                                                        "id": np.array([10, 11, 12])})
    for k in ("fa", "rgb", "id"):
        assert listed.point_data[k].dtype == flat.point_data[k].dtype
        np.testing.assert_array_equal(listed.point_data[k], flat.point_data[k])
    np.testing.assert_array_equal(listed.point_data["fa"], np.concatenate(fa)[listed.sample_of])
    # a list whose arrays do not match the curves' rows is refused, naming the key
    with pytest.raises(ValueError, match=r"point_data\['fa'\]"):
        spinal.tube(curves, 0.1, 6, point_data={"fa": [f[:-1] for f in fa]})


def test_tangents_and_frames_as_lists_of_per_curve_arrays():
    """T3-11: a bundle given as a list of curves takes its tangents and frames as lists too
    (one array per curve), like spinal.frames; a list that does not match is named."""
    u = np.linspace(0, 4 * np.pi, 60)
    H = np.c_[np.cos(u), np.sin(u), 0.2 * u]
    curves = [H, H[:30] + 3]
    T = [spinal.estimate_tangents(c) for c in curves]
    F = [spinal.frames(c) for c in curves]
    ref_t = spinal.tube(curves, 0.1, 6, tangents=np.concatenate(T))
    np.testing.assert_array_equal(spinal.tube(curves, 0.1, 6, tangents=T).vertices,
                                  ref_t.vertices)
    ref_f = spinal.tube(curves, 0.1, 6, frames=np.concatenate(F))
    np.testing.assert_array_equal(spinal.tube(curves, 0.1, 6, frames=F).vertices,
                                  ref_f.vertices)
    with pytest.raises(ValueError, match=r"tangents: a list of 2 arrays of \[60, 29\] rows "
                                         r"does not match"):
        spinal.tube(curves, 0.1, 6, tangents=[T[0], T[1][:-1]])


def test_ply_refuses_non_ascii_attribute_names_and_vtp_keeps_them(tmp_path):
    """T3-12: a non-ASCII point_data key is a ValueError naming point_data for PLY (whose
    header is ASCII), not a UnicodeEncodeError; the .vtp writer keeps the name."""
    mesh = spinal.Mesh(np.eye(3), [[0, 1, 2]], point_data={"é": np.zeros(3)})
    with pytest.raises(ValueError, match="point_data: the name 'é' is not ASCII"):
        mesh.save(tmp_path / "a.ply")
    assert not (tmp_path / "a.ply").exists()
    mesh.save(tmp_path / "a.vtp")
    assert "é".encode() in (tmp_path / "a.vtp").read_bytes()


def test_concatenate_names_meshes_for_a_bare_mesh_and_mismatched_columns():
    """T3-13: Mesh.concatenate of one Mesh (not a list) and of point_data arrays of different
    ranks under one key say what is wrong, naming meshes and the key."""
    x = np.c_[np.linspace(0, 1, 5), np.zeros(5), np.zeros(5)]
    m = spinal.tube(x, 0.1, 6)
    with pytest.raises(TypeError, match="meshes: expected a sequence of spinal.Mesh, got one"):
        spinal.Mesh.concatenate(m)
    with pytest.raises(TypeError, match="meshes: expected a sequence of spinal.Mesh, got int"):
        spinal.Mesh.concatenate(3)
    a = spinal.tube(x, 0.1, 6, point_data={"t": np.arange(5.0)})
    b = spinal.tube(x, 0.1, 6, point_data={"t": np.ones((5, 2))})
    with pytest.raises(ValueError, match=r"meshes: point_data\['t'\] has rows of different"):
        spinal.Mesh.concatenate([a, b])
    both = spinal.Mesh.concatenate([a, a])
    assert both.point_data["t"].shape == (2 * len(a.vertices),)
