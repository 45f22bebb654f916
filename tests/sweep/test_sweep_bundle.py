"""Tubes of a bundle of streamlines: the frames computed spine by spine inside the sweep
give the mesh of the frames computed first (``spinal.frames``), bit for bit, with the same
errors; the meshes of a fixed set of bundles keep the bits of the version that computed the
frames in a call of their own (hashes of every array); and a bundle's peak memory is its
output (neither an ``(n, 3, 3)`` array of frames nor the faces' curve ids are made)."""

from __future__ import annotations

import hashlib
import json
import platform
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

import spinal


def grid(a):
    return np.round(np.asarray(a, dtype=np.float64) * 2.0**20) / 2.0**20

def bundle(curves, seed, per=(2, 40)):
    rng = np.random.default_rng(seed)
    lens = rng.integers(per[0], per[1], curves)
    lens[:4] = [2, 3, 4, 5]
    out = []
    for n in lens:
        d = rng.normal(size=3) + 0.3 * np.cumsum(rng.normal(size=(n, 3)) * 0.2, axis=0)
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        out.append(np.cumsum(d, axis=0) + rng.uniform(-5, 5, 3))
    return grid(np.concatenate(out)), lens

def loops(curves, seed, per=(5, 30)):
    """Closed curves: wobbly ellipses in random planes, every other one repeating its
    first point at the end."""
    rng = np.random.default_rng(seed)
    out, lens = [], []
    for k in range(curves):
        m = int(rng.integers(*per))
        t = 2 * np.pi * np.arange(m) / m
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        p = np.c_[2 * np.cos(t), np.sin(t), 0.3 * np.sin(3 * t)] @ q.T + rng.uniform(-5, 5, 3)
        if k % 2:
            p = np.r_[p, p[:1]]
        out.append(p)
        lens.append(len(p))
    return grid(np.concatenate(out)), np.array(lens)


def digest(m):
    h = hashlib.sha256()
    arrays = [m.vertices, m.faces, m.normals, m.uv, m.fold_over,
              m.cell_data.get("curve_id"), m.skipped_curves]
    for a in arrays:
        if a is None:
            h.update(b"none")
            continue
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    return h.hexdigest()[:24]

STAR = grid([(np.cos(a) * r, np.sin(a) * r) for a, r in
             zip(np.linspace(0, 2 * np.pi, 10, endpoint=False), [1, 0.45] * 5)])

def smooth_only(x, lens, closed):
    """The curves of a bundle that turn by less than 30° at every sample and by at most 10°
    at their open ends (closed: also across the closing chord, a repeated first point at the
    end dropped)."""
    keep, parts = [], np.split(x, np.cumsum(lens)[:-1])
    for p in parts:
        q = p[:-1] if closed and np.array_equal(p[0], p[-1]) else p
        q = np.r_[q, q[:2]] if closed else q
        c = np.diff(q, axis=0)
        c /= np.linalg.norm(c, axis=1, keepdims=True)
        turns = (c[1:] * c[:-1]).sum(1)
        ends = closed or len(q) < 3 or min(turns[0], turns[-1]) >= np.cos(np.radians(10))
        keep.append(len(q) < 3 or bool(np.all(turns > np.cos(np.pi / 6)) and ends))
    keep = np.array(keep)
    return np.concatenate([p for p, k in zip(parts, keep) if k]), np.asarray(lens)[keep]


def cases(smooth=False):
    x, lens = bundle(60, 1)
    xc, lc = loops(30, 2)
    if smooth:  # only curves that the chord guard leaves alone (denser loops)
        x, lens = smooth_only(x, lens, False)
        xc, lc = smooth_only(*loops(30, 2, (60, 120)), True)
    n, c = len(x), len(lens)
    offs = np.r_[0, np.cumsum(lens)]
    rng = np.random.default_rng(3)
    r_row = grid(rng.uniform(0.05, 0.2, n))
    r_cur = grid(rng.uniform(0.05, 0.2, c))
    tw = grid(rng.uniform(-2, 2, n))
    sc2 = grid(rng.uniform(0.05, 0.2, (n, 2)))
    tg = grid(3 * spinal.estimate_tangents(x, lengths=lens, method="circle"))
    fr = spinal.frames(x, lengths=lens)
    short = np.r_[x[offs[4]:offs[5]], x[offs[5]:offs[5] + 1], x[offs[6]:offs[7]]]
    sl = [lens[4], 1, lens[6]]
    yield "tube64", lambda: spinal.tube(x, 0.1, 8, lengths=lens)
    yield "tube32", lambda: spinal.tube(x, 0.1, 8, lengths=lens, dtype=np.float32)
    yield "tube32_nouv", lambda: spinal.tube(x, 0.1, 8, lengths=lens, dtype=np.float32, uv=False)
    yield "tube_nonormals", lambda: spinal.tube(x, 0.1, 5, lengths=lens, normals=False)
    yield "tube_rrow", lambda: spinal.tube(x, r_row, 6, lengths=lens)
    yield "tube_rcurve", lambda: spinal.tube(x, r_cur, 6, lengths=lens, caps=False)
    yield "tube_offsets", lambda: spinal.tube(x, 0.1, 7, offsets=offs, miter_limit=1.5)
    yield "tube_closed", lambda: spinal.tube(xc, 0.1, 6, lengths=lc, closed=True)
    yield "tube_closed_seams", lambda: spinal.tube(xc, 0.1, 6, lengths=lc, closed=True,
                                                   split_seams=True)
    yield "tube_seams", lambda: spinal.tube(x, 0.1, 6, lengths=lens, split_seams=True)
    yield "tube_tangents", lambda: spinal.tube(x, 0.1, 6, lengths=lens, tangents=tg)
    yield "tube_circle_rule", lambda: spinal.tube(x, 0.1, 6, lengths=lens,
                                                  tangent_rule="circle")
    yield "tube_frames", lambda: spinal.tube(x, 0.1, 6, lengths=lens, frames=fr)
    yield "tube_fold", lambda: spinal.tube(x, 0.9, 6, lengths=lens)
    yield "tube_big", lambda: spinal.tube(x * 2.0**600, 0.1 * 2.0**600, 6, lengths=lens)
    yield "tube_small", lambda: spinal.tube(x * 2.0**-600, 0.1 * 2.0**-600, 6, lengths=lens,
                                            dtype=np.float32)
    k = int(np.argmax(lens))
    yield "tube_one_of", lambda: spinal.tube(x[offs[k]:offs[k + 1]], 0.1, 6)
    u = np.linspace(0, 40, 5000)
    hx = grid(np.c_[np.cos(u), np.sin(u), 0.1 * u + 0.05 * np.sin(7 * u)])
    yield "tube_long", lambda: spinal.tube(hx, 0.05, 6, dtype=np.float32)
    yield "tube_long2", lambda: spinal.tube(np.r_[hx, hx[::-1] + 5], 0.05, 6,
                                            lengths=[5000, 5000], split_seams=True)
    yield "tube_list", lambda: spinal.tube(np.split(x, offs[1:-1]), 0.1, 6)
    yield "tube_skip", lambda: spinal.tube(short, 0.1, 6, lengths=sl,
                                           on_short="skip")
    yield "sweep_star", lambda: spinal.sweep(x, STAR, lengths=lens, scale=sc2, twist=tw)
    yield "sweep_open", lambda: spinal.sweep(x, STAR[:5], lengths=lens, profile_closed=False,
                                             dtype=np.float32, twist=tw)
    yield "sweep_closed", lambda: spinal.sweep(xc, STAR, lengths=lc, closed=True,
                                               scale=0.1, split_seams=True)

# sha256 (first 24 hex digits) of every array of the meshes of `cases`; re-recorded when
# the end tangents of coarse ends (end chords turning by more than 10°) were held within half
# that turn instead of the whole turn (the smooth inputs of RECORDED_SMOOTH kept their bits),
# before that when sharp corners became joins (the curves turning by 60° or more get round joins; the
# smooth inputs of RECORDED_SMOOTH kept their bits), and before that when
# estimated tangents began to turn towards the chords' bisector (ends: the end chord) where
# the chords turn by more than 30° (one curve of `bundle(60, 1)` turns by 67°, the loops by
# up to 87°): RECORDED_SMOOTH below holds the inputs without such turns to the old bits.
# First recorded with the
# version whose sweep took the frames from a call of `spinal.frames` before it; libm's
# sin/cos/atan2 enter the frames (the start of the transport), so only x86-64 Linux
# (glibc) is held to these bits
RECORDED = {
    "tube64": "49717c99430dc8de5aba1216",
    "tube32": "ca500ce8a63ad83f17749331",
    "tube32_nouv": "b579e87872deea17eaa5a982",
    "tube_nonormals": "e642c056c03b82263cc58b8c",
    "tube_rrow": "5e12ea69df136337542dd012",
    "tube_rcurve": "400486630014183baebc047e",
    "tube_offsets": "fd8083da28a1099f9d03148a",
    "tube_closed": "6ff424c7093d4d3dce913b17",
    "tube_closed_seams": "f6e5b24267bc331a29bf40ae",
    "tube_seams": "db60c1ad7dd13f55651867d5",
    "tube_tangents": "8628bb14c2cc5c956e853088",
    "tube_circle_rule": "8398747d0c79a4fc9df05fd8",
    "tube_frames": "3e70acf58e7d83a5404e2b97",
    "tube_fold": "355cb9f3cb548dc767b54cef",
    "tube_big": "4ef4a64d07a0cef2d4d31b3b",
    "tube_small": "e955d085c4fc47ad1d2c81a3",
    "tube_one_of": "d2f67e09ca6fb88761d56652",
    "tube_long": "9e4d91103de231311e5f67b7",
    "tube_long2": "c45b440f25d6c59efb4f0eef",
    "tube_list": "3e70acf58e7d83a5404e2b97",
    "tube_skip": "02472985a11ebd9bc6a67cc6",
    # re-recorded when the caps of non-convex profiles became monotone pieces (de Berg et al.
    # §3.2-3.3) instead of ear clipping: vertices, normals, uv and curve ids kept their bits,
    # only the 960 cap faces differ, and the volume agrees to 1.6e-14
    "sweep_star": "65746f9b5460796889a946c5",
    "sweep_open": "7641f1eaa23db1a780741c00",
    "sweep_closed": "9f3613ed88d946a3bd3c42fc",
}


# the same cases on smooth inputs only (`cases(smooth=True)`: every turn under 30°, the open
# ends' turns at most 10°), recorded with the version before the tangents' chord guard and
# its half-turn end cone (neither acts on them), bit for bit
RECORDED_SMOOTH = {
    "tube64": "f24c9b5af135825bb2c7a1b5",
    "tube32": "1d15f28b7adf100ca410e16e",
    "tube32_nouv": "b39a3d4b0388eda26cd3d8c3",
    "tube_nonormals": "22009743f3d2acfdca42346c",
    "tube_rrow": "6ac13c2d6f8fa996030db131",
    "tube_rcurve": "9ebd95f22d072f064b183d77",
    "tube_offsets": "7d5bd5c29a791e296f1a77ff",
    "tube_closed": "d3158f1cc5ae818eddbf5852",
    "tube_closed_seams": "a41492a3f159714a0fdfe210",
    "tube_seams": "0baf5469ddfffd53faa993e6",
    "tube_tangents": "f665f620fd7a3e60863906e7",
    "tube_circle_rule": "0e248a195ef8328c6a77b35c",
    "tube_frames": "638ad525dbd6f762076b3b53",
    "tube_fold": "f6af58027184c32002da9da4",
    "tube_big": "42c3fe3c4ca313006ce14244",
    "tube_small": "ef0b36c0151c88ac17b30abe",
    "tube_one_of": "d2f67e09ca6fb88761d56652",
    "tube_long": "9e4d91103de231311e5f67b7",
    "tube_long2": "c45b440f25d6c59efb4f0eef",
    "tube_list": "638ad525dbd6f762076b3b53",
    "tube_skip": "8f6ad706327086f5bc072a1f",
    "sweep_star": "089bbea7c32845289d07b98c",
    "sweep_open": "7dc0cb7450c3fa5b8a0ab382",
    "sweep_closed": "b57dbce6663d725e5a3a697c",
}


@pytest.mark.skipif(not (sys.platform == "linux" and platform.machine() == "x86_64"),
                    reason="the hashes were recorded with x86-64 glibc")
@pytest.mark.parametrize("name", sorted(RECORDED))
def test_meshes_keep_the_recorded_bits(name):
    f = dict(cases())[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = f()
    assert digest(m) == RECORDED[name]


@pytest.mark.skipif(not (sys.platform == "linux" and platform.machine() == "x86_64"),
                    reason="the hashes were recorded with x86-64 glibc")
@pytest.mark.parametrize("name", sorted(RECORDED_SMOOTH))
def test_smooth_meshes_keep_the_bits_they_had_before_the_chord_guard(name):
    f = dict(cases(smooth=True))[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = f()
    assert digest(m) == RECORDED_SMOOTH[name]


def same(a, b):
    for k in ("vertices", "faces", "normals", "uv", "fold_over", "skipped_curves"):
        x, y = getattr(a, k), getattr(b, k)
        assert (x is None) == (y is None), k
        if x is not None:
            assert x.dtype == y.dtype and x.tobytes() == y.tobytes(), k
    assert a.cell_data.keys() == b.cell_data.keys()
    for k in a.cell_data:
        np.testing.assert_array_equal(a.cell_data[k], b.cell_data[k])


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_frames_computed_in_the_sweep_are_those_of_spinal_frames(closed, dtype):
    x, lens = loops(40, 5) if closed else bundle(80, 4)
    x = np.r_[x, x[::-1] * 1.5]  # the same curves reversed and larger
    lens = np.r_[lens, lens[::-1]]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for kw in ({}, {"split_seams": True, "caps": False}, {"miter_limit": 1.0}):
            fr = spinal.frames(x, lengths=lens, closed=closed)
            a = spinal.tube(x, 0.1, 7, lengths=lens, closed=closed, dtype=dtype, **kw)
            b = spinal.tube(x, 0.1, 7, lengths=lens, closed=closed, dtype=dtype, frames=fr, **kw)
            same(a, b)
        t = spinal.estimate_tangents(x, lengths=lens, closed=closed, method="circle")
        a = spinal.sweep(x, STAR, lengths=lens, closed=closed, tangents=2 * t, scale=0.05)
        fr = spinal.frames(x, 2 * t, lengths=lens, closed=closed)
        same(a, spinal.sweep(x, STAR, lengths=lens, closed=closed, frames=fr, scale=0.05))
        a = spinal.tube(x, 0.1, 5, lengths=lens, closed=closed, tangent_rule="circle")
        fr = spinal.frames(x, t, lengths=lens, closed=closed)
        same(a, spinal.tube(x, 0.1, 5, lengths=lens, closed=closed, frames=fr))
        # one thread or all: the same bits
        with spinal.threads(1):
            same(spinal.tube(x, 0.1, 7, lengths=lens, closed=closed, dtype=dtype),
                 spinal.tube(x, 0.1, 7, lengths=lens, closed=closed, dtype=dtype,
                             frames=spinal.frames(x, lengths=lens, closed=closed)))


def broken(kind):
    """A bundle with one defect (or two): the curve of each is fixed."""
    x, lens = bundle(20, 1)
    offs = np.r_[0, np.cumsum(lens)]
    r = np.full(len(lens), 0.1)
    if "nan" in kind:
        x[offs[7] + 2, 1] = np.nan
    if "repeat" in kind:
        x[offs[9] + 3] = x[offs[9] + 2]
    if "cusp" in kind:
        k = offs[8] + 4
        x[k + 1] = x[k] - 0.5 * (x[k + 2] - x[k])
    if "radius" in kind:
        r[5] = -1
    return x, lens, r


def test_repeats_and_reversals_in_a_bundle_are_tubed():
    """A repeated sample is merged (the tube of the bundle without it); a sample that turns
    the curve back on itself is a corner like any other."""
    x, lens, r = broken("repeat")
    k = np.r_[0, np.cumsum(lens)][9] + 3
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        merged = spinal.tube(x, r, 6, lengths=lens)
        lens_without = lens.copy()
        lens_without[9] -= 1
        without = spinal.tube(np.delete(x, k, axis=0), r, 6, lengths=lens_without)
        np.testing.assert_array_equal(merged.vertices, without.vertices)
        assert k not in set(merged.sample_of)
        x, lens, r = broken("cusp")
        assert spinal.tube(x, r, 6, lengths=lens).is_watertight


@pytest.mark.parametrize("kind", ["nan", "radius", "radius+nan"])
def test_errors_are_those_of_the_frames_then_of_the_sweep(kind):
    x, lens, r = broken(kind)
    with pytest.raises(ValueError) as fused:
        spinal.tube(x, r, 6, lengths=lens)
    try:
        fr = spinal.frames(x, lengths=lens)
    except ValueError as e:  # the frames' error comes first, as when they were a call
        assert str(fused.value) == str(e)
        assert "curve 7" in str(e)
        return
    with pytest.raises(ValueError) as given:
        spinal.tube(x, r, 6, lengths=lens, frames=fr)
    assert str(fused.value) == str(given.value)
    assert str(fused.value).startswith("radius: curve 5 ")


def test_a_frames_error_comes_before_a_bad_profile():
    x, lens, _ = broken("nan")
    with pytest.raises(ValueError, match=r"^points: curve 7 .*non-finite"):
        spinal.sweep(x, [[0, 0], [1, 1], [1, 0], [0, 1]], lengths=lens)
    x, lens, _ = broken("")
    with pytest.raises(ValueError, match="^profile: "):
        spinal.sweep(x, [[0, 0], [1, 1], [1, 0], [0, 1]], lengths=lens)
    with pytest.raises(ValueError, match="^miter_limit: "):
        spinal.tube(x, 0.1, 6, lengths=lens, miter_limit=0.5)


def test_curve_ids_are_built_when_first_read():
    x, lens = bundle(30, 6)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = spinal.tube(x, 0.1, 6, lengths=lens)
    per_curve = 2 * (lens - 1) * 6 + 2 * 4
    want = np.repeat(np.arange(len(lens), dtype=np.int32), per_curve)
    assert m.__dict__["_cell_data"] == {}  # nothing built yet
    ids = m.cell_data["curve_id"]
    assert ids.dtype == np.int32
    np.testing.assert_array_equal(ids, want)
    assert m.cell_data["curve_id"] is ids  # built once
    both = spinal.Mesh.concatenate([m, m])
    np.testing.assert_array_equal(both.cell_data["curve_id"], np.r_[want, want + len(lens)])
    m.cell_data = {"a": np.zeros(len(m.faces))}  # replaced: the ids are not built over it
    assert list(m.cell_data) == ["a"]


PEAK = textwrap.dedent("""
    import json, sys
    import numpy as np
    import spinal
    curves, per = int(sys.argv[1]), int(sys.argv[2])
    rng = np.random.default_rng(0)
    d = rng.normal(size=(curves, 3))[:, None, :] + 0.3 * np.cumsum(
        rng.normal(size=(curves, per, 3)) * 0.2, axis=1)
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    x = (np.cumsum(d, axis=1) + rng.uniform(-50, 50, (curves, 1, 3))).reshape(-1, 3)
    lengths = np.full(curves, per)
    spinal.tube(x[:per], 0.2, 8)  # warm-up: imports, thread pool
    def status(key):  # bytes
        with open("/proc/self/status") as f:
            return next(int(l.split()[1]) for l in f if l.startswith(key)) * 1024
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")  # reset the peak (VmHWM) to the current RSS
    before = status("VmRSS:")
    mesh = spinal.tube(x, 0.2, 8, lengths=lengths, dtype=np.float32)
    peak = status("VmHWM:") - before
    out = sum(a.nbytes for a in (mesh.vertices, mesh.faces, mesh.normals, mesh.uv))
    print(json.dumps({"peak": peak, "output": out, "rows": len(x)}))
""")


def test_bundle_peak_memory_is_its_output():
    # frames of the whole bundle (72 bytes a row) or its curve ids (4 bytes a face) would add
    # 16% and 14% of this output
    r = subprocess.run([sys.executable, "-c", PEAK, "5000", "48"], capture_output=True,
                       text=True, check=True, timeout=300)
    got = json.loads(r.stdout)
    assert got["peak"] <= 1.05 * got["output"], got
