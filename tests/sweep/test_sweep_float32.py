"""Lean output of the sweeps: ``dtype=float32`` (coordinates computed in float64, stored
rounded; int32 faces), ``normals=False`` and ``uv=False``. Same topology as float64,
vertices within float32 rounding, at most 60 bytes per vertex, and a peak memory of the
call within 1.2× its output (measured in a fresh process)."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

import spinal
from spinal.curves import Helix, TorusKnot


def nbytes(mesh):
    return sum(a.nbytes for a in (mesh.vertices, mesh.faces, mesh.normals, mesh.uv)
               if a is not None)


@pytest.mark.parametrize("closed", [False, True])
def test_float32_is_the_float64_mesh_rounded(closed):
    x = TorusKnot().sample(301) if closed else Helix(1, 0.3, turns=2).sample(300)
    r = np.linspace(0.05, 0.1, len(x))
    m64 = spinal.tube(x, r, 12, closed=closed)
    m32 = spinal.tube(x, r, 12, closed=closed, dtype=np.float32)
    assert m32.vertices.dtype == m32.normals.dtype == m32.uv.dtype == np.float32
    assert m32.faces.dtype == np.int32
    np.testing.assert_array_equal(m32.faces, m64.faces)
    for a32, a64 in ((m32.vertices, m64.vertices), (m32.normals, m64.normals),
                     (m32.uv, m64.uv)):
        np.testing.assert_array_equal(a32, a64.astype(np.float32))  # rounded, not recomputed
    assert m32.is_watertight == m64.is_watertight
    assert m32.volume == pytest.approx(m64.volume, rel=1e-5)
    assert nbytes(m32) / len(m32.vertices) <= 60
    assert nbytes(m64) / len(m64.vertices) > 100
    assert m32.to_trimesh().is_watertight == m64.is_watertight
    assert m32.to_pyvista().n_points == len(m32.vertices)
    # a sweep with twist, scale and an open profile, as a string dtype
    prof = [(-0.1, 0.0), (0.0, 0.05), (0.1, 0.0)]
    kw = {"twist": np.linspace(0, 3, len(x)), "scale": np.c_[r, 2 * r], "closed": closed,
          "profile_closed": False}
    a, b = spinal.sweep(x, prof, **kw), spinal.sweep(x, prof, dtype="float32", **kw)
    np.testing.assert_array_equal(b.faces, a.faces)
    np.testing.assert_array_equal(b.vertices, a.vertices.astype(np.float32))


def test_normals_and_uv_can_be_left_out():
    x = Helix(1, 0.3, turns=1).sample(100)
    full = spinal.tube(x, 0.1, 8)
    for kw in ({"normals": False}, {"uv": False}, {"normals": False, "uv": False}):
        for dtype in (np.float64, np.float32):
            m = spinal.tube(x, 0.1, 8, dtype=dtype, **kw)
            assert (m.normals is None) == (not kw.get("normals", True))
            assert (m.uv is None) == (not kw.get("uv", True))
            np.testing.assert_array_equal(m.faces, full.faces)
            np.testing.assert_array_equal(m.vertices, full.vertices.astype(dtype))
            if m.normals is not None:
                np.testing.assert_array_equal(m.normals, full.normals.astype(dtype))
            if m.uv is not None:
                np.testing.assert_array_equal(m.uv, full.uv.astype(dtype))
            assert m.is_watertight and m.volume == pytest.approx(full.volume, rel=1e-5)
    lean = spinal.tube(x, 0.1, 8, dtype=np.float32, normals=False, uv=False)
    assert nbytes(lean) / len(lean.vertices) <= 40  # 12 + 2 × 12


def test_bundle_in_float32():
    curves = [Helix(1.0, 0.2 + 0.1 * c, turns=1).sample(50 + 10 * c) + c for c in range(4)]
    x = np.concatenate(curves)
    kw = {"lengths": [len(c) for c in curves]}
    a, b = spinal.tube(x, 0.05, 7, **kw), spinal.tube(x, 0.05, 7, dtype=np.float32, **kw)
    np.testing.assert_array_equal(b.faces, a.faces)
    np.testing.assert_array_equal(b.vertices, a.vertices.astype(np.float32))


@pytest.mark.parametrize("bad", ["float16", np.int32, "abc", complex])
def test_bad_dtype_is_named(bad):
    with pytest.raises(ValueError, match="dtype: expected numpy.float64 or numpy.float32"):
        spinal.tube(Helix().sample(20), 0.1, dtype=bad)


def test_bad_flags_are_named():
    with pytest.raises(TypeError, match="normals"):
        spinal.tube(Helix().sample(20), 0.1, normals="no")
    with pytest.raises(TypeError, match="uv"):
        spinal.sweep(Helix().sample(20), [(0, 0), (1, 0), (0, 1)], uv=1)


def test_mesh_accepts_float32_and_missing_normals():
    m = spinal.Mesh(np.eye(3, dtype=np.float32), np.array([[0, 1, 2]], dtype=np.int32))
    assert m.vertices.dtype == np.float32 and m.faces.dtype == np.int32
    assert m.normals is None and m.uv is None
    assert m.area == pytest.approx(np.sqrt(3) / 2)
    m = spinal.Mesh(np.eye(3), [[0, 1, 2]])
    assert m.vertices.dtype == np.float64 and m.faces.dtype == np.int64


PEAK = textwrap.dedent("""
    import json, sys
    import numpy as np
    import spinal
    n, sides, dtype = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    u = np.linspace(0, 2 * np.pi * 50, n)
    x = np.c_[np.cos(u), np.sin(u), 0.05 * u]
    spinal.tube(x[:100], 0.01, sides, dtype=dtype)  # warm-up: imports, thread pool
    def status(key):  # kB
        with open("/proc/self/status") as f:
            return next(int(l.split()[1]) for l in f if l.startswith(key)) * 1024
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")  # reset the peak (VmHWM) to the current RSS
    before = status("VmRSS:")
    mesh = spinal.tube(x, 0.01, sides, dtype=dtype)
    peak = status("VmHWM:") - before
    out = sum(a.nbytes for a in (mesh.vertices, mesh.faces, mesh.normals, mesh.uv))
    print(json.dumps({"peak": peak, "output": out, "vertices": len(mesh.vertices)}))
""")


@pytest.mark.parametrize("sides", [8, 16])
def test_float32_peak_memory_is_within_1_2_times_the_output(sides):
    r = subprocess.run([sys.executable, "-c", PEAK, "400000", str(sides), "float32"],
                       capture_output=True, text=True, check=True, timeout=300)
    got = json.loads(r.stdout)
    assert got["output"] / got["vertices"] <= 60
    assert got["peak"] <= 1.2 * got["output"], got


MEASURES = textwrap.dedent("""
    import ctypes, json, sys, time
    import numpy as np
    import spinal
    n, sides, dtype = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    u = np.linspace(0, 2 * np.pi * 50, n)
    x = np.c_[np.cos(u), np.sin(u), 0.05 * u]
    w = spinal.tube(x[:100], 0.01, sides, dtype=dtype)  # warm-up: imports, thread pool
    w.volume, w.area, w.is_watertight
    trim = ctypes.CDLL("libc.so.6").malloc_trim
    def status(key):  # bytes
        with open("/proc/self/status") as f:
            return next(int(l.split()[1]) for l in f if l.startswith(key)) * 1024
    t0 = time.process_time()
    mesh = spinal.tube(x, 0.01, sides, dtype=dtype)
    out = {"build": time.process_time() - t0, "faces": len(mesh.faces),
           "own": sum(a.nbytes for a in (mesh.vertices, mesh.faces, mesh.normals, mesh.uv))}
    for name in ("volume", "area", "is_watertight"):
        trim(0)  # freed heap pages back to the system: a reused page would not raise VmHWM
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")  # reset the peak (VmHWM) to the current RSS
        before = status("VmRSS:")
        t0 = time.process_time()
        value = getattr(mesh, name)
        out[name] = {"peak": status("VmHWM:") - before, "cpu": time.process_time() - t0,
                     "value": float(value)}
    print(json.dumps(out))
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/status")
@pytest.mark.parametrize("dtype", ["float32", "float64"])
def test_mesh_measures_need_no_big_temporaries(dtype):
    """Mesh.volume, .area and .is_watertight on a tube of 3.2 M faces, in a fresh process:
    the peak memory of each grows by at most a quarter of the mesh's own arrays (measured:
    under 1 MB; gathering the corners V[F] alone takes 1.3x the mesh's bytes, sorting
    its edges as int64 pairs 0.9x). Time: each measure at most twice the CPU time of the
    build. Loose on purpose: both are a few tens of milliseconds of memory-bound work in
    parallel, timed once on a machine that other processes share; the check is there to
    catch a measure that is many times the build (a NumPy sort of the edges was 75-430x)."""
    r = subprocess.run([sys.executable, "-c", MEASURES, "200000", "8", dtype],
                       capture_output=True, text=True, check=True, timeout=300)
    got = json.loads(r.stdout)
    assert got["faces"] == 2 * 8 * (200_000 - 1) + 2 * (8 - 2)
    for name in ("volume", "area", "is_watertight"):
        m = got[name]
        assert m["peak"] <= 0.25 * got["own"], (name, got)
        assert m["cpu"] <= 2 * got["build"], (name, got)
    assert got["is_watertight"]["value"] == 1.0
    # Pappus: the octagon's area (perimeter) times the spine's length, to O(h²) (measured
    # 1.4e-7 at this spacing)
    length = 2 * np.pi * 50 * np.hypot(1, 0.05)
    octagon = 0.5 * 8 * 0.01**2 * np.sin(2 * np.pi / 8)
    assert got["volume"]["value"] == pytest.approx(octagon * length, rel=1e-6)
    perimeter = 8 * 2 * 0.01 * np.sin(np.pi / 8)
    assert got["area"]["value"] == pytest.approx(perimeter * length + 2 * octagon, rel=1e-6)


def test_float32_that_cannot_resolve_the_profile_warns():
    """T3-15: a tube of radius 1e-4 around a spine at offset 1e6 in float32 (all its vertices
    round to a few points) warns with a PrecisionWarning pointing at the call; a tube whose
    profile float32 resolves does not."""
    t = np.linspace(0, 4 * np.pi, 200)
    h = np.c_[np.cos(t), np.sin(t), 0.2 * t]
    with pytest.warns(spinal.PrecisionWarning, match="dtype=float32: the coordinates' rounding") as rec:
        m = spinal.tube(h * 0.001 + 1e6, 1e-4, dtype=np.float32)
    assert rec[0].filename == __file__
    assert rec[0].message.spacing == np.spacing(np.float32(1e6))
    assert len(np.unique(m.vertices, axis=0)) < len(m.vertices) / 10
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        spinal.tube(h * 1000 + 1e4, 5.0, dtype=np.float32)
        spinal.sweep(h, [[0, 0], [1, 0], [0, 1]], scale=0.05, dtype=np.float32)
