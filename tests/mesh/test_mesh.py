"""spinal.Mesh: area and volume at any scale of the coordinates, vertex colours in the
files, and the faces that cross (against libigl's exact predicates)."""

import pathlib

import numpy as np
import pytest

import spinal

TETRA_F = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]]  # wound outwards


def _helix(n=60):
    t = np.linspace(0.0, 6.0, n)
    return np.c_[np.cos(t), np.sin(t), 0.2 * t]


@pytest.mark.parametrize("scale", [1e-150, 1e-100, 1e-80, 1e-40, 1.0, 1e40, 1e77, 1e80,
                                   1e102, 1e103, 1e150])
def test_area_and_volume_scale_with_the_coordinates(scale):
    """T3-01: the area of the corner tetrahedron scaled by s is (3 + √3)/2 · s² and its
    volume s³/6 wherever those are representable (the plain sums were NaN from 1e77 (area)
    and 1e103 (volume) and 0 below 1e-80); beyond the range of float64 they are ±inf or 0,
    never NaN."""
    V = np.eye(4)[:, :3] * scale
    m = spinal.Mesh(V, TETRA_F)
    area = (3 + np.sqrt(3)) / 2 * scale * scale  # nan-free: numpy's scalar product
    with np.errstate(over="ignore", under="ignore"):
        volume = np.float64(scale) * scale * (scale / 6)
    assert not np.isnan(m.area) and not np.isnan(m.volume)
    if np.isfinite(area) and area > 1e-300:
        assert m.area == pytest.approx(area, rel=1e-14)
    if np.isfinite(volume) and volume > 1e-300:
        assert m.volume == pytest.approx(volume, rel=1e-14)
    elif volume == np.inf:
        assert m.volume == np.inf


def test_power_of_two_scaling_changes_no_bit():
    """T3-01: the measures are taken on coordinates scaled by a power of two, which is exact:
    a mesh scaled by 2**k has the area × 4**k and volume × 8**k bit for bit."""
    m = spinal.tube(_helix(), 0.1)
    for k in (-300, -40, -1, 3, 60, 300):
        w = spinal.Mesh(np.ldexp(m.vertices, k), m.faces)
        assert w.area == np.ldexp(m.area, 2 * k)
        assert w.volume == np.ldexp(m.volume, 3 * k)


def test_sweeps_far_from_unit_scale_have_finite_measures():
    """T3-01: a tube around a helix scaled by 1e100 (radius 1e99) has area and volume
    100²⁰⁰ and 100³⁰⁰ times those of the unit one; it used to report area NaN."""
    unit = spinal.tube(_helix(), 0.1)
    big = spinal.tube(_helix() * 1e100, 1e99)
    small = spinal.tube(_helix() * 1e-100, 1e-101)
    assert big.area == pytest.approx(unit.area * 1e200, rel=1e-12)
    assert big.volume == pytest.approx(unit.volume * 1e300, rel=1e-12)
    assert small.area == pytest.approx(unit.area * 1e-200, rel=1e-12)
    assert small.volume / 1e-300 == pytest.approx(unit.volume, rel=1e-12)


def _coloured_tube(dtype, uv=False):
    X = _helix(40)
    T = np.gradient(X, axis=0)
    orient = np.abs(T / np.linalg.norm(T, axis=1, keepdims=True))  # floats in [0, 1]
    if dtype == np.uint8:
        orient = np.rint(orient * 255).astype(np.uint8)
    return spinal.tube(X, 0.1, uv=uv, point_data={"colors": orient, "arc": np.arange(40.0)})


@pytest.mark.parametrize("dtype", [np.float64, np.uint8])
def test_vertex_colors_open_as_colours_in_trimesh_and_pyvista(tmp_path, dtype):
    """T3-12 family / item 7: a point_data array `colors` (RGB floats in [0, 1] or uint8) is
    written as PLY red/green/blue uchar properties, a VTK UInt8 active-scalars array and OBJ
    vertex colours, which trimesh and pyvista read back as the vertex colours (the other
    attributes keep their names)."""
    trimesh = pytest.importorskip("trimesh")
    pv = pytest.importorskip("pyvista")
    m = _coloured_tube(dtype)
    c = m.point_data["colors"]
    want = c if c.dtype == np.uint8 else np.rint(c * 255).astype(np.uint8)
    m.save(tmp_path / "t.ply")
    header = (tmp_path / "t.ply").read_bytes().split(b"end_header")[0].decode()
    assert "property uchar red\nproperty uchar green\nproperty uchar blue" in header
    assert "colors_0" not in header and "property double arc" in header
    t = trimesh.load(tmp_path / "t.ply", process=False)
    np.testing.assert_array_equal(t.visual.vertex_colors[:, :3], want)
    p = pv.read(tmp_path / "t.ply")
    np.testing.assert_array_equal(p.point_data["RGB"], want)
    m.save(tmp_path / "t.vtp")
    p = pv.read(tmp_path / "t.vtp")
    assert p.point_data.active_scalars_name == "colors"
    assert p.point_data["colors"].dtype == np.uint8
    np.testing.assert_array_equal(p.point_data["colors"], want)
    np.testing.assert_array_equal(p.point_data["arc"], m.point_data["arc"])
    m.save(tmp_path / "t.obj")
    t = trimesh.load(tmp_path / "t.obj", process=False)
    np.testing.assert_array_equal(t.visual.vertex_colors[:, :3], want)
    np.testing.assert_array_equal(m.to_trimesh().visual.vertex_colors[:, :3], want)
    # with texture coordinates too (trimesh then reads the texture, pyvista both)
    m = _coloured_tube(dtype, uv=True)
    m.save(tmp_path / "u.ply")
    p = pv.read(tmp_path / "u.ply")
    np.testing.assert_array_equal(p.point_data["RGB"], want)
    assert p.active_texture_coordinates is not None


def test_colors_argument_and_its_errors(tmp_path):
    """`colors=` names a point_data array or gives the colours (RGBA kept as alpha);
    anything else is refused naming `colors`."""
    trimesh = pytest.importorskip("trimesh")
    m = _coloured_tube(np.float64)
    n = len(m.vertices)
    rgba = np.c_[np.zeros((n, 3), np.uint8), np.full(n, 7, np.uint8)]
    m.save(tmp_path / "a.ply", colors=rgba)
    t = trimesh.load(tmp_path / "a.ply", process=False)
    np.testing.assert_array_equal(t.visual.vertex_colors, rgba)
    # the default `colors` array is then an ordinary attribute
    header = (tmp_path / "a.ply").read_bytes().split(b"end_header")[0].decode()
    assert "colors_0" in header and "property uchar alpha" in header
    m.point_data["paint"] = m.point_data.pop("colors")
    m.save(tmp_path / "b.ply", colors="paint")
    assert "paint_0" not in (tmp_path / "b.ply").read_bytes()[:2000].decode("ascii", "replace")
    for bad, words in (("nope", "no point_data array named 'nope'"),
                       (np.zeros((n, 2)), r"expected shape \(\d+, 3\) or"),
                       (np.full((n, 3), 1.5), r"must lie in \[0, 1\]; row 0"),
                       (np.full((n, 3), np.nan), r"must lie in \[0, 1\]"),
                       (np.zeros((n, 3), np.int64), "expected uint8")):
        with pytest.raises(ValueError, match="^colors: .*" + words):
            m.save(tmp_path / "c.ply", colors=bad)


# ------------------------------------------------------------------ self-intersections


def _pairs_igl(m):
    igl_pred = pytest.importorskip("igl.predicates")
    _, pairs, *_ = igl_pred.find_self_intersections(np.asarray(m.vertices, np.float64),
                                                     np.asarray(m.faces, np.int64))
    p = np.sort(np.asarray(pairs, np.int64).reshape(-1, 2), axis=1)
    return p[np.lexsort(p.T[::-1])]


@pytest.mark.filterwarnings("ignore::spinal.FoldOverWarning")
def test_self_intersections_are_libigls_pairs():
    """Mesh.self_intersections gives libigl's exact pairs (igl.predicates.
    find_self_intersections) on tubes of rough random walks (thousands of crossings where
    hairpins and returns overlap), two overlapping spheres and an embedded sphere."""
    trimesh = pytest.importorskip("trimesh")
    rng = np.random.default_rng(0)
    meshes = [spinal.tube(np.cumsum(rng.normal(size=(200, 3)) * 0.2, 0), 0.05, 8)
              for _ in range(3)]
    a = trimesh.creation.icosphere(3)
    meshes.append(spinal.Mesh(np.r_[a.vertices, a.vertices + [0.7, 0.2, 0.1]],
                              np.r_[a.faces, a.faces + len(a.vertices)]))
    meshes.append(spinal.Mesh(a.vertices, a.faces))
    counts = []
    for m in meshes:
        got = m.self_intersections()
        assert got.dtype == np.int64 and got.ndim == 2 and got.shape[1] == 2
        assert np.all(got[:, 0] < got[:, 1])
        np.testing.assert_array_equal(got, _pairs_igl(m))
        counts.append(len(got))
    assert min(counts[:3]) > 500 and counts[3] > 100 and counts[4] == 0


@pytest.mark.parametrize("name", ["cow.obj", "fandisk.obj", "rocker-arm.obj"])
def test_self_intersections_of_the_shared_meshes(name):
    """The shared meshes: the same pairs as libigl (81 on the cow, none on the others)."""
    trimesh = pytest.importorskip("trimesh")
    path = pathlib.Path(__file__).resolve().parents[2].parent / "shared/data/meshes" / name
    if not path.exists():
        pytest.skip(f"{path} is not available")
    t = trimesh.load(path, process=False, force="mesh")
    m = spinal.Mesh(t.vertices, t.faces)
    np.testing.assert_array_equal(m.self_intersections(), _pairs_igl(m))


def test_self_intersection_cases_decided_exactly():
    """Touching, coplanar and nearly coplanar cases, where a tolerance would guess: a corner
    touching a face counts, a triangle 1e-300 above another does not, a fold onto a
    neighbour in its plane counts, a neighbour across the shared edge does not."""
    V = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0],          # 0-2: a face in z = 0
                  [0.5, 0.5, 0], [0.5, 0.5, 1], [1.5, 0.5, 1],  # 3-5: a corner on it
                  [0.2, 0.2, 1e-300], [0.4, 0.2, 1e-300], [0.2, 0.4, 1e-300],  # 6-8: above
                  [0.3, 0.3, 0], [1, -1, 0.0]])               # 9: folded, 10: across
    cases = {((0, 1, 2), (3, 4, 5)): 1, ((0, 1, 2), (6, 7, 8)): 0,
             ((0, 1, 2), (1, 0, 9)): 1, ((0, 1, 2), (1, 0, 10)): 0}
    for (s, t), n in cases.items():
        assert len(spinal.Mesh(V, [s, t]).self_intersections()) == n, (s, t)


@pytest.mark.filterwarnings("ignore::spinal.FoldOverWarning")
def test_self_intersections_same_on_any_thread_count_and_limited():
    walk = np.cumsum(np.random.default_rng(3).normal(size=(900, 3)) * 0.2, 0)
    m = spinal.tube(walk, 0.05, 8)  # ~29k faces: several blocks of 4,096
    runs = []
    for n in (1, 2, 3):
        with spinal.threads(n):
            runs.append(m.self_intersections())
    for r in runs[1:]:
        np.testing.assert_array_equal(r, runs[0])
    with pytest.warns(RuntimeWarning, match="stopped at limit=10 pairs"):
        first = m.self_intersections(limit=10)
    assert len(first) == 10
    with pytest.raises(ValueError, match="^limit: "):
        m.self_intersections(limit=-1)


def _orient_exact(a, b, c, d):
    """The sign of det[a − d; b − d; c − d] in rational arithmetic (an independent exact
    reference for the float predicates)."""
    from fractions import Fraction

    m = [[Fraction(float(p[k])) - Fraction(float(d[k])) for k in range(3)] for p in (a, b, c)]
    det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
           - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
           + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    return (det > 0) - (det < 0)


def test_self_intersections_where_libigl_is_conservative():
    """On the 10k sphere dragged by a translation tool (its torn strip folds: thousands of
    crossings) every pair libigl reports that this does not shares one vertex, and exact
    rational arithmetic shows one face lies on one side of the other's plane touching it
    only there: not a crossing. Every pair reported here libigl reports too."""
    trimesh = pytest.importorskip("trimesh")
    s = trimesh.creation.icosphere(5)
    drag = spinal.fields.translation([0, 0, 1.0], 0.9, [0.5, 0, 0])
    with pytest.warns(spinal.RefinementWarning):
        m, _ = spinal.deform(s, drag, 1.0, check="intersections")
    ours = set(map(tuple, m.self_intersections()))
    theirs = set(map(tuple, _pairs_igl(m)))
    assert len(ours) > 1000 and ours <= theirs
    for i, j in theirs - ours:
        a, b = m.vertices[m.faces[i]], m.vertices[m.faces[j]]
        shared = set(m.faces[i]) & set(m.faces[j])
        assert len(shared) == 1
        # one face's two other corners strictly on one side of the other's plane: the
        # faces meet at most in the shared vertex
        def apart(t, u):
            o = sorted(_orient_exact(*t, x) for x in u)
            return o in ([-1, -1, 0], [0, 1, 1])

        assert apart(a, b) or apart(b, a), (i, j)
