"""Files in and out: streamlines from .trk/.tck/.trx/.vtp (spinal.io), meshes through
Mesh.save/Mesh.load in every format, and the whole-file command line (python -m spinal
tube/frames/info), each checked against nibabel's, trx-python's, trimesh's or pyvista's own
reading of the same file."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import spinal

nib = pytest.importorskip("nibabel")
pv = pytest.importorskip("pyvista")
trimesh = pytest.importorskip("trimesh")

RNG = np.random.default_rng(11)
STREAMLINES = [np.cumsum(RNG.normal(size=(n, 3)), 0).astype(np.float32) + 20
               for n in (12, 30, 5, 17)]
# a voxel-to-RAS affine with anisotropic voxels and an offset, as scanners write them
AFFINE = np.array([[1.5, 0, 0, -30.0], [0, 2.0, 0, 12.0], [0, 0, 2.5, 4.0], [0, 0, 0, 1]])


def _tractogram():
    t = nib.streamlines.Tractogram(STREAMLINES, affine_to_rasmm=np.eye(4))
    t.data_per_point["fa"] = [np.linspace(0.2, 0.9, len(s))[:, None].astype(np.float32)
                              for s in STREAMLINES]
    t.data_per_point["rgb"] = [RNG.uniform(size=(len(s), 3)).astype(np.float32)
                               for s in STREAMLINES]
    t.data_per_streamline["bundle"] = np.arange(len(STREAMLINES), dtype=np.float32)[:, None]
    return t


@pytest.fixture(scope="module")
def trk(tmp_path_factory):
    """A .trk with a non-trivial voxel-to-RAS affine, per-point and per-streamline data."""
    path = tmp_path_factory.mktemp("io") / "bundle.trk"
    header = {nib.streamlines.Field.VOXEL_TO_RASMM: AFFINE,
              nib.streamlines.Field.VOXEL_SIZES: (1.5, 2.0, 2.5),
              nib.streamlines.Field.DIMENSIONS: (60, 50, 40)}
    nib.streamlines.save(_tractogram(), str(path), header=header)
    return path


def test_trk_points_are_nibabels_ras_mm_with_their_data(trk):
    """The points of a .trk are those of nibabel's Tractogram (RAS+ mm, the file's affine
    applied), per-point data per streamline ((n,) for scalars), per-streamline data (S,)."""
    s = spinal.io.read_streamlines(trk)
    ref = nib.streamlines.load(str(trk)).tractogram
    assert len(s.points) == len(ref.streamlines) == len(STREAMLINES)
    for a, b in zip(s.points, ref.streamlines, strict=True):
        assert a.dtype == np.float64 and a.shape == b.shape
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(s.lengths, [len(x) for x in STREAMLINES])
    assert s.points[1] == pytest.approx(STREAMLINES[1], abs=1e-4)  # saved in RAS+ mm
    assert set(s.point_data) == {"fa", "rgb"} and set(s.streamline_data) == {"bundle"}
    for fa, want in zip(s.point_data["fa"], ref.data_per_point["fa"], strict=True):
        assert fa.ndim == 1
        np.testing.assert_array_equal(fa, np.asarray(want)[:, 0])
    assert s.point_data["rgb"][2].shape == (5, 3)
    np.testing.assert_array_equal(s.streamline_data["bundle"], [0, 1, 2, 3])
    # the list goes straight into a bundle tube
    m = spinal.tube(s.points, 0.2, 6)
    assert m.is_watertight and m.curve_of.max() == 3


def test_fornix_reads_as_nibabel_gives_it():
    """dipy's bundled fornix (300 streamlines) reads to nibabel's points bit for bit."""
    dipy_data = pytest.importorskip("dipy.data")
    path = dipy_data.get_fnames(name="fornix")
    s = spinal.io.read_streamlines(path)
    ref = nib.streamlines.load(path).streamlines
    assert len(s.points) == 300
    assert all(np.array_equal(a, b) for a, b in zip(s.points, ref, strict=True))


def test_tck_round_trip(tmp_path):
    path = tmp_path / "b.tck"
    nib.streamlines.save(nib.streamlines.Tractogram(STREAMLINES, affine_to_rasmm=np.eye(4)),
                         str(path))
    s = spinal.io.read_streamlines(path)
    for a, b in zip(s.points, nib.streamlines.load(str(path)).streamlines, strict=True):
        np.testing.assert_array_equal(a, b)
    assert s.point_data == {} and s.streamline_data == {}


def test_trx_points_and_data_as_trx_python_reads_them(tmp_path, trk):
    tmm = pytest.importorskip("trx.trx_file_memmap")
    path = tmp_path / "b.trx"
    t = nib.streamlines.load(str(trk)).tractogram
    f = tmm.TrxFile.from_tractogram(t, reference=str(trk))
    tmm.save(f, str(path))
    f.close()
    s = spinal.io.read_streamlines(path)
    g = tmm.load(str(path))
    try:
        for a, b in zip(s.points, g.streamlines, strict=True):
            np.testing.assert_array_equal(a, np.asarray(b, dtype=np.float64))
        assert set(s.point_data) == set(g.data_per_vertex)
        assert set(s.streamline_data) == set(g.data_per_streamline)
    finally:
        g.close()
    for a, b in zip(s.points, STREAMLINES, strict=True):
        assert a == pytest.approx(b, abs=1e-3)


def test_vtp_polylines_with_point_and_cell_data(tmp_path):
    """Every line cell of a PolyData is one streamline (its points in the order of the cell,
    which need not be the order of the points), its point data cut per line and its cell
    data one value per line."""
    pts = np.concatenate(STREAMLINES).astype(np.float64)
    order = RNG.permutation(len(pts))  # the lines' points stored shuffled
    where = np.empty_like(order)
    where[order] = np.arange(len(pts))
    lines, k = [], 0
    for x in STREAMLINES:
        lines += [len(x), *where[k:k + len(x)]]
        k += len(x)
    poly = pv.PolyData(pts[order], lines=np.array(lines))
    poly.point_data["w"] = order.astype(np.float64)
    poly.cell_data["id"] = np.arange(len(STREAMLINES)) * 10
    path = tmp_path / "lines.vtp"
    poly.save(str(path))
    s = spinal.io.read_streamlines(path)
    k = 0
    for p, w, x in zip(s.points, s.point_data["w"], STREAMLINES, strict=True):
        np.testing.assert_array_equal(p, x.astype(np.float64))
        np.testing.assert_array_equal(w, np.arange(k, k + len(x)))
        k += len(x)
    np.testing.assert_array_equal(s.streamline_data["id"], [0, 10, 20, 30])


def test_streamline_reader_errors_name_the_path(tmp_path):
    with pytest.raises(ValueError, match=r"^path: unknown streamline format '\.xyz'"):
        spinal.io.read_streamlines(tmp_path / "a.xyz")
    with pytest.raises(FileNotFoundError, match="^path: no such file"):
        spinal.io.read_streamlines(tmp_path / "missing.trk")
    with pytest.raises(TypeError, match="^path: expected a str or os.PathLike"):
        spinal.io.read_streamlines(3)
    mesh = tmp_path / "sphere.vtp"
    pv.Sphere().save(str(mesh))
    with pytest.raises(ValueError, match="^path: sphere.vtp holds no polylines"):
        spinal.io.read_streamlines(mesh)


# ---------------------------------------------------------------------------- meshes


def _tube():
    X = np.c_[np.cos(np.linspace(0, 6, 40)), np.sin(np.linspace(0, 6, 40)),
              np.linspace(0, 2, 40)]
    T = np.gradient(X, axis=0)
    c = np.abs(T / np.linalg.norm(T, axis=1, keepdims=True))
    m = spinal.tube(X, 0.1, point_data={"colors": c, "arc": np.arange(40.0), "tan": T})
    m.cell_data["side"] = np.arange(len(m.faces), dtype=np.int32) % 16
    return m, np.rint(c * 255).astype(np.uint8)[m.sample_of]


@pytest.mark.parametrize("suffix", [".ply", ".vtp"])
def test_ply_and_vtp_round_trip_every_array(tmp_path, suffix):
    m, rgb = _tube()
    back = spinal.Mesh.load(m.save(tmp_path / f"t{suffix}"))
    np.testing.assert_array_equal(back.vertices, m.vertices)
    np.testing.assert_array_equal(back.faces, m.faces)
    np.testing.assert_array_equal(back.normals, m.normals)
    np.testing.assert_array_equal(back.uv, m.uv)
    np.testing.assert_array_equal(back.point_data["colors"], rgb)
    np.testing.assert_array_equal(back.point_data["arc"], m.point_data["arc"])
    np.testing.assert_array_equal(back.point_data["tan"], m.point_data["tan"])
    np.testing.assert_array_equal(back.cell_data["side"], m.cell_data["side"])


def test_obj_stl_and_glb_keep_the_solid(tmp_path):
    """OBJ keeps the float64 rows; STL (float32 corners, shared corners merged on reading)
    and glTF (float32) keep the volume to float32 rounding and the mesh closed; trimesh reads
    the glTF's vertex colours and pyvista its normals."""
    m, rgb = _tube()
    back = spinal.Mesh.load(m.save(tmp_path / "t.obj"))
    np.testing.assert_array_equal(back.vertices, m.vertices)
    np.testing.assert_array_equal(back.point_data["colors"], rgb)
    for suffix in (".stl", ".glb"):
        back = spinal.Mesh.load(m.save(tmp_path / f"t{suffix}"))
        assert back.is_watertight and back.is_winding_consistent
        assert back.volume == pytest.approx(m.volume, rel=1e-6)
        assert len(back.vertices) == len(m.vertices)
    t = trimesh.load(tmp_path / "t.glb", force="mesh", process=False)
    np.testing.assert_array_equal(t.visual.vertex_colors[:, :3], rgb)
    np.testing.assert_allclose(t.vertices, m.vertices, rtol=0, atol=1e-6)
    block = pv.read(tmp_path / "t.glb")
    while isinstance(block, pv.MultiBlock):
        block = block[0]
    np.testing.assert_allclose(block.point_data["NORMAL"], m.normals, atol=1e-6)
    stl = trimesh.load(tmp_path / "t.stl")
    assert stl.is_watertight and stl.volume == pytest.approx(m.volume, rel=1e-6)


def test_mesh_file_errors_name_the_path(tmp_path):
    m, _ = _tube()
    with pytest.raises(ValueError, match=r"^path: unknown format '\.xyz'; use one of "):
        m.save(tmp_path / "a.xyz")
    with pytest.raises(ValueError, match=r"^path: unknown mesh format '\.xyz'"):
        spinal.Mesh.load(tmp_path / "a.xyz")
    with pytest.raises(FileNotFoundError, match="^path: no such file"):
        spinal.Mesh.load(tmp_path / "missing.ply")


# ---------------------------------------------------------------------- command line


def _spinal(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "spinal", *map(str, args)], cwd=cwd, check=False,
                          capture_output=True, text=True, timeout=300)


@pytest.mark.filterwarnings("ignore::spinal.FoldOverWarning")  # rough random walks
def test_cli_tube_writes_coloured_meshes_that_viewers_open(tmp_path, trk):
    """`python -m spinal tube IN OUT --color orientation` gives the same mesh as
    spinal.tube on the read streamlines, with |tangent| colours that pyvista (.vtp) and
    trimesh (.glb) read as vertex colours."""
    r = _spinal("tube", trk, tmp_path / "b.vtp", "--radius", 0.3, "--sides", 6, "--color",
                "orientation")
    assert r.returncode == 0, r.stderr
    assert "wrote" in r.stderr
    s = spinal.io.read_streamlines(trk)
    want = spinal.tube(s.points, 0.3, 6)
    got = pv.read(tmp_path / "b.vtp")
    np.testing.assert_array_equal(got.points, want.vertices)
    assert got.point_data.active_scalars_name == "colors"
    rgb = np.asarray(got.point_data["colors"])
    assert rgb.dtype == np.uint8 and rgb.shape == (len(want.vertices), 3)
    # the colour of every vertex is that of its spine row
    t = np.abs(np.concatenate([spinal.estimate_tangents(p) for p in s.points]))
    np.testing.assert_array_equal(rgb, np.rint(t[want.sample_of] * 255).astype(np.uint8))
    r = _spinal("tube", trk, tmp_path / "b.glb", "--float32", "--color", "fa", "-q")
    # quiet: no progress or summary; warnings (a fold of these rough curves) in one line each
    assert r.returncode == 0, r.stderr
    assert all(line.startswith("spinal tube: warning: ") for line in r.stderr.splitlines())
    g = trimesh.load(tmp_path / "b.glb", force="mesh", process=False)
    assert g.visual.kind == "vertex" and len(np.unique(g.visual.vertex_colors, axis=0)) > 10
    r = _spinal("tube", trk, tmp_path / "r.ply", "--radius-from", "fa", "--join", "miter")
    assert r.returncode == 0, r.stderr
    m = spinal.Mesh.load(tmp_path / "r.ply")
    assert m.is_watertight


def test_cli_frames_and_info(tmp_path, trk):
    r = _spinal("frames", trk, tmp_path / "f.npz")
    assert r.returncode == 0, r.stderr
    z = np.load(tmp_path / "f.npz")
    s = spinal.io.read_streamlines(trk)
    np.testing.assert_array_equal(z["lengths"], s.lengths)
    np.testing.assert_array_equal(z["frames"], spinal.frames(np.concatenate(s.points),
                                                             lengths=s.lengths))
    r = _spinal("info", trk)
    assert r.returncode == 0 and "curves         4" in r.stdout, r.stdout
    m, _ = _tube()
    m.save(tmp_path / "t.ply")
    r = _spinal("info", tmp_path / "t.ply")
    assert r.returncode == 0, r.stderr
    assert "watertight     True" in r.stdout and f"{m.volume:.6g}" in r.stdout


def test_cli_errors_exit_1_with_one_line_and_help_has_examples(tmp_path, trk):
    r = _spinal("tube", tmp_path / "missing.trk", tmp_path / "o.ply")
    assert r.returncode == 1 and r.stderr.strip() == (
        f"spinal tube: error: IN: no such file: {str(tmp_path / 'missing.trk')!r}")
    r = _spinal("tube", trk, tmp_path / "o.xyz")
    assert r.returncode == 1 and "OUT: unknown format '.xyz'" in r.stderr
    assert not (tmp_path / "o.xyz").exists()
    r = _spinal("tube", trk, tmp_path / "o.ply", "--radius-from", "nope")
    assert r.returncode == 1 and "no data named 'nope' (it has fa, rgb, bundle)" in r.stderr
    r = _spinal("tube", "--help")
    assert r.returncode == 0 and "examples:" in r.stdout and "--radius-from" in r.stdout


@pytest.mark.filterwarnings("ignore::spinal.FoldOverWarning")
def test_cli_tube_in_blocks_writes_the_one_call_mesh(tmp_path, trk, monkeypatch):
    """The command tubes a bundle in blocks of whole curves (its progress steps and Ctrl-C
    points); the blocks' meshes, concatenated, are the mesh of one call on all curves."""
    from spinal import __main__ as cli
    from spinal import _cli

    monkeypatch.setattr(_cli, "BLOCK_ROWS", 20)
    assert cli.main(["tube", str(trk), str(tmp_path / "b.ply"), "--radius", "0.3",
                     "--color", "fa", "-q"]) == 0
    s = spinal.io.read_streamlines(trk)
    one = spinal.tube(s.points, 0.3, 8)
    got = spinal.Mesh.load(tmp_path / "b.ply")
    np.testing.assert_array_equal(got.vertices, one.vertices)
    np.testing.assert_array_equal(got.faces, one.faces)
    np.testing.assert_array_equal(got.normals, one.normals)


# ------------------------------------------------------------------ streamed tubes


def _walks(n=60, seed=5):
    rng = np.random.default_rng(seed)
    return [np.cumsum(rng.normal(size=(int(k), 3)) * 0.3, 0) for k in rng.integers(2, 80, n)]


@pytest.mark.filterwarnings("ignore::spinal.FoldOverWarning")  # rough walks
@pytest.mark.parametrize("suffix", [".ply", ".vtp"])
def test_tube_file_writes_the_bytes_of_one_call(tmp_path, suffix, trk):
    """Chunk by chunk (here 100 points per chunk: many chunks) the file has the bytes that
    Mesh.save writes for one spinal.tube call on all streamlines: from a list (a curve that
    cannot be swept included: its curve id stays free) and from a .trk read lazily, with
    orientation colours and a per-point radius."""
    walks = _walks()
    walks[9] = np.zeros((4, 3))  # one repeated point: skipped
    with pytest.warns(spinal.SkippedCurvesWarning):
        out = spinal.io.tube_file(walks, tmp_path / f"s{suffix}", 0.05, 6,
                                  chunk_points=100, dtype="float64", colors="orientation")
    assert out == tmp_path / f"s{suffix}"
    rgb = np.concatenate([np.abs(spinal.estimate_tangents(w)) if i != 9 else np.zeros((4, 3))
                          for i, w in enumerate(walks)])
    with pytest.warns(spinal.SkippedCurvesWarning):
        one = spinal.tube(walks, 0.05, 6, point_data={"colors": rgb}, on_short="skip",
                          on_invalid="skip")
    one.save(tmp_path / f"one{suffix}")
    assert (tmp_path / f"s{suffix}").read_bytes() == (tmp_path / f"one{suffix}").read_bytes()
    # a file, read lazily
    spinal.io.tube_file(trk, tmp_path / f"t{suffix}", "fa", 8, chunk_points=20)
    s = spinal.io.read_streamlines(trk)
    with pytest.warns(spinal.FoldOverWarning):
        one = spinal.tube(s.points, np.concatenate(s.point_data["fa"]), 8, dtype="float32")
    one.save(tmp_path / f"one_t{suffix}")
    assert (tmp_path / f"t{suffix}").read_bytes() == (tmp_path / f"one_t{suffix}").read_bytes()


def test_tube_file_warns_once_for_the_whole_file(tmp_path):
    """The chunks' warnings come as one per kind, naming streamlines by their index in src."""
    walks = _walks(200, seed=6)
    walks[150] = np.full((3, 3), np.nan)
    with pytest.warns(spinal.SkippedCurvesWarning, match="1 streamlines .* skipped .*: 150"), \
            pytest.warns(spinal.FoldOverWarning, match="segments of") as rec:
        spinal.io.tube_file(walks, tmp_path / "w.ply", 0.2, 6, chunk_points=500)
    folds = [w.message for w in rec if isinstance(w.message, spinal.FoldOverWarning)]
    assert len(folds) == 1
    w = folds[0]
    starts = np.r_[0, np.cumsum([len(x) for x in walks])]
    np.testing.assert_array_equal(w.indices, starts[w.curves] + w.rows)


def test_tube_file_interrupted_leaves_no_file(tmp_path):
    """Ctrl-C (here from the streamlines' generator) leaves neither dst nor a temporary
    file; an existing dst is kept as it was."""
    def walks():
        for i, w in enumerate(_walks()):
            if i == 40:
                raise KeyboardInterrupt
            yield w

    with pytest.raises(KeyboardInterrupt):
        spinal.io.tube_file(walks(), tmp_path / "x.ply", 0.05, chunk_points=50)
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "x.vtp").write_bytes(b"old")
    with pytest.raises(KeyboardInterrupt):
        spinal.io.tube_file(walks(), tmp_path / "x.vtp", 0.05, chunk_points=50)
    assert [p.name for p in tmp_path.iterdir()] == ["x.vtp"]
    assert (tmp_path / "x.vtp").read_bytes() == b"old"


@pytest.mark.filterwarnings("ignore::spinal.FoldOverWarning")  # rough walks
def test_tube_file_memory_is_that_of_a_chunk(tmp_path):
    """Python-side peak memory (tracemalloc: NumPy's buffers) of a streamed tube is a small
    fraction of the one-call tube's: it holds one chunk, not the file."""
    import tracemalloc

    rng = np.random.default_rng(1)
    walks = [np.cumsum(rng.normal(size=(200, 3)) * 0.2, 0) for _ in range(400)]
    tracemalloc.start()
    try:
        spinal.io.tube_file(walks, tmp_path / "a.ply", 0.01, 8, chunk_points=4000)
        streamed = tracemalloc.get_traced_memory()[1]
        tracemalloc.reset_peak()
        spinal.tube(walks, 0.01, 8, dtype="float32").save(tmp_path / "b.ply")
        whole = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert (tmp_path / "a.ply").stat().st_size == (tmp_path / "b.ply").stat().st_size
    assert streamed < whole / 8, (streamed, whole)


def test_tube_file_errors_name_the_argument(tmp_path, trk):
    with pytest.raises(ValueError, match=r"^dst: streamed meshes are written as \.ply or "):
        spinal.io.tube_file(_walks(), tmp_path / "a.obj")
    with pytest.raises(FileNotFoundError, match="^src: no such file"):
        spinal.io.tube_file(tmp_path / "none.trk", tmp_path / "a.ply")
    with pytest.raises(ValueError, match="^radius: src has no per-point data named 'r'"):
        spinal.io.tube_file(trk, tmp_path / "a.ply", "r")
    with pytest.raises(ValueError, match="^chunk_points: "):
        spinal.io.tube_file(_walks(), tmp_path / "a.ply", chunk_points=0)
    with pytest.raises(ValueError, match="^src: no streamline could be swept"):
        spinal.io.tube_file([np.zeros((3, 3))], tmp_path / "a.ply")
    assert not (tmp_path / "a.ply").exists()


def test_tube_file_pairs_carry_data_of_their_own_length_and_files_get_normal_permissions(
        tmp_path):
    """Per-point data given with each streamline must have one row per point (a mismatch
    would shift radii onto the next streamline); the written file has the permissions a
    plain open() gives, not the temporary file's private ones."""
    a, b = np.c_[np.arange(5.0), np.zeros((5, 2))], np.c_[np.arange(5.0), np.ones((5, 2))]
    with pytest.raises(ValueError, match="^src: streamline 0: its 'r' data has 6 rows for 5"):
        spinal.io.tube_file([(a, {"r": np.full(6, 0.1)}), (b, {"r": np.full(4, 0.1)})],
                            tmp_path / "a.ply", "r")
    out = spinal.io.tube_file([(a, {"r": np.full(5, 0.1)}), (b, {"r": np.full(5, 0.2)})],
                              tmp_path / "a.ply", "r")
    with open(tmp_path / "plain", "w"):
        pass
    assert (out.stat().st_mode & 0o777) == ((tmp_path / "plain").stat().st_mode & 0o777)
