"""``out=`` of ``spinal.frames``, ``spinal.tube``/``spinal.sweep`` and ``spinal.advect``: the
result written into the caller's buffer is the result of the call without it, bit for bit;
the returned array is that buffer; buffers of the wrong shape, dtype or order, read-only or
sharing memory with an input are refused naming ``out``; one buffer serves many calls."""

from __future__ import annotations

import numpy as np
import pytest

import spinal
from spinal import _core, fields
from spinal.curves import Helix


def same_bits(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def curve(n, phase=0.0, dtype=np.float64):
    u = np.linspace(0, 6 * np.pi, n) + phase
    x = np.c_[np.cos(u), np.sin(u), 0.1 * u] + 0.05 * np.sin(7 * u)[:, None]
    return x.astype(dtype)


def garbage(shape, dtype=np.float64):
    """A buffer full of NaN: every value of a result written into it must be written."""
    return np.full(shape, np.nan, dtype=dtype)


# ---- frames ----------------------------------------------------------------------------------

FRAME_CASES = {
    "float64": lambda: ((curve(500),), {}),
    "float32 points": lambda: ((curve(500, dtype=np.float32),), {}),
    "given tangents": lambda: ((curve(500), np.gradient(curve(500), axis=0)), {}),
    "rotation, end": lambda: ((curve(500),), {"method": "rotation", "end": [0, 0, 1]}),
    "closed": lambda: ((curve(400)[:-1],), {"closed": True, "turns": 1}),
    "bundle": lambda: ((curve(500),), {"lengths": [100, 250, 150]}),
    # a chunked scan (more than 2 * 2**15 rows)
    "long": lambda: ((curve(70_001),), {}),
    # the paths that copy into out: repeated samples, a guide, an analytic curve
    "repeats": lambda: ((np.repeat(curve(100), 2, axis=0),), {}),
    "guide": lambda: ((curve(300),), {"guide": np.tile([0.0, 0.0, 1.0], (300, 1))}),
    "analytic": lambda: ((Helix(1.0, 0.3),), {"u": 200}),
}


@pytest.mark.parametrize("case", sorted(FRAME_CASES))
def test_frames_into_out_are_the_frames_without_it(case):
    args, kw = FRAME_CASES[case]()
    want = spinal.frames(*args, **kw)
    out = garbage(want.shape)
    got = spinal.frames(*args, **kw, out=out)
    assert got is out
    assert same_bits(out, want)


def test_frames_core_writes_into_out_without_a_copy():
    x = curve(300)
    offs = np.array([0, len(x)], dtype=np.int64)
    options = {"method": "double_reflection", "tangent_rule": "five_point_bounded",
               "closed": False, "turns": 0.0}
    args = (x, None, offs, options)
    want, _ = _core.frames_sampled(*args)
    out = garbage(want.shape)
    got, _ = _core.frames_sampled(*args, out=out)
    assert got is out and same_bits(out, want)


def test_frames_out_reused_across_curves_of_the_same_size():
    out = garbage((1000, 3, 3))
    for phase in (0.0, 0.7, 2.1):
        x = curve(1000, phase)
        assert spinal.frames(x, out=out) is out
        assert same_bits(out, spinal.frames(x))


def bad_outs(shape, dtype=np.float64):
    """Buffers that must be refused: wrong shape, wrong dtype, not C-contiguous, read-only."""
    wrong_shape = np.empty((shape[0] + 1, *shape[1:]), dtype)
    other = np.float32 if dtype == np.float64 else np.float64
    wrong_dtype = np.empty(shape, other)
    strided = np.empty((shape[0] * 2, *shape[1:]), dtype)[::2]
    fortran = np.asfortranarray(np.empty(shape, dtype))
    ro = np.empty(shape, dtype)
    ro.flags.writeable = False
    return {"shape": wrong_shape, "dtype": wrong_dtype, "strided": strided,
            "fortran": fortran, "read-only": ro}


@pytest.mark.parametrize("kind", ["shape", "dtype", "strided", "fortran", "read-only"])
@pytest.mark.parametrize("case", ["float64", "repeats", "analytic"])
def test_frames_refuse_a_wrong_out(case, kind):
    args, kw = FRAME_CASES[case]()
    n = len(spinal.frames(*args, **kw))
    with pytest.raises(ValueError, match="^out: "):
        spinal.frames(*args, **kw, out=bad_outs((n, 3, 3))[kind])


def test_frames_refuse_an_out_sharing_memory_with_an_input():
    n = 200
    buf = np.empty(9 * n)
    x = buf[: 3 * n].reshape(n, 3)
    x[:] = curve(n)
    with pytest.raises(ValueError, match="^out: shares memory with points"):
        spinal.frames(x, out=buf.reshape(n, 3, 3))
    t = np.gradient(curve(n), axis=0)
    buf[3 * n: 6 * n] = t.ravel()
    with pytest.raises(ValueError, match="^out: shares memory with tangents"):
        spinal.frames(curve(n), buf[3 * n: 6 * n].reshape(n, 3), out=buf.reshape(n, 3, 3))
    with pytest.raises(TypeError, match="^out: expected a NumPy array"):
        spinal.frames(curve(n), out=[[0.0] * 9] * n)


# ---- tubes and sweeps ------------------------------------------------------------------------

def tube(x, dtype="float64", out=None, **kw):
    return spinal.tube(x, 0.1, 8, dtype=dtype, out=out, **kw)


def sweep(x, out=None, **kw):
    profile = np.array([[0.1, 0.0], [0.0, 0.05], [-0.1, 0.0], [0.0, -0.05]])
    return spinal.sweep(x, profile, scale=np.linspace(1, 2, len(x)), out=out, **kw)


def fresh_garbage(mesh):
    """A mesh of the same sizes whose vertices, normals and uv are NaN."""
    m = spinal.Mesh(mesh.vertices.copy(), mesh.faces.copy())
    for name in ("vertices", "normals", "uv"):
        a = getattr(mesh, name)
        setattr(m, name, None if a is None else garbage(a.shape, a.dtype))
    return m


@pytest.mark.parametrize("make", [
    lambda x, out=None: tube(x, out=out),
    lambda x, out=None: tube(x, np.float32, out=out),
    lambda x, out=None: tube(x, out=out, normals=False, uv=False),
    lambda x, out=None: tube(x, np.float32, out=out, join="miter", closed=True),
    lambda x, out=None: sweep(x, out=out),
    lambda x, out=None: sweep(np.repeat(x, 2, axis=0), out=out),
])
def test_meshes_into_out_are_the_meshes_without_it(make):
    x = curve(300)
    want = make(x)
    out = fresh_garbage(want)
    got = make(x, out=out)
    assert got.vertices is out.vertices
    assert same_bits(got.vertices, want.vertices)
    assert same_bits(got.faces, want.faces)
    for name in ("normals", "uv"):
        a, b = getattr(got, name), getattr(want, name)
        assert (a is None) == (b is None)
        if a is not None:
            assert a is getattr(out, name) and same_bits(a, b)


def test_mesh_out_reused_across_spines_of_the_same_size():
    out = fresh_garbage(tube(curve(400), np.float32))
    for phase in (0.0, 0.4, 1.3):
        x = curve(400, phase)
        got = tube(x, np.float32, out=out)
        want = tube(x, np.float32)
        assert got.vertices is out.vertices and got.normals is out.normals
        assert same_bits(got.vertices, want.vertices) and same_bits(got.uv, want.uv)


@pytest.mark.parametrize("kind", ["shape", "dtype", "strided", "fortran", "read-only"])
@pytest.mark.parametrize("name", ["vertices", "normals", "uv"])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_meshes_refuse_a_wrong_out(kind, name, dtype):
    x = curve(200)
    out = fresh_garbage(tube(x, dtype))
    setattr(out, name, bad_outs(getattr(out, name).shape, dtype)[kind])
    with pytest.raises(ValueError, match=f"^out.{name}: "):
        tube(x, dtype, out=out)


def test_meshes_refuse_an_out_sharing_memory_with_an_input_or_of_another_kind():
    x = curve(200)
    out = fresh_garbage(tube(x))
    pts = out.vertices[: len(x)]
    pts[:] = x
    with pytest.raises(ValueError, match="^out.vertices: shares memory with points"):
        tube(pts, out=out)
    out = fresh_garbage(tube(x))
    out.normals = out.vertices
    with pytest.raises(ValueError, match="^out.normals: "):
        tube(x, out=out)
    out.normals = None
    with pytest.raises(ValueError, match="^out.normals: None"):
        tube(x, out=out)
    with pytest.raises(TypeError, match="^out: expected a spinal.Mesh"):
        tube(x, out=out.vertices)


# ---- advection -------------------------------------------------------------------------------

def field():
    return fields.twist([0, 0, 0], [0, 0, 1], 2.0, 3.0)


ADVECT_CASES = {
    "float64": lambda: (curve(500), {}),
    "float32": lambda: (curve(500, dtype=np.float32), {}),
    "euler": lambda: (curve(500), {"method": "euler", "steps": 7}),
    "no time": lambda: (curve(50), {"steps": 1, "duration": 0.0}),
    # a path tool: runs of steps between its breakpoints
    "path tool": lambda: (curve(300), {"field": fields.along_path(curve(20), 0.5, 1.0),
                                       "steps": 12}),
}


@pytest.mark.parametrize("case", sorted(ADVECT_CASES))
def test_advect_into_out_is_the_advection_without_it(case):
    x, kw = ADVECT_CASES[case]()
    f = kw.pop("field", field())
    duration = kw.pop("duration", 0.5)
    want = spinal.advect(x, f, duration, **kw)
    out = garbage(want.shape)
    got = spinal.advect(x, f, duration, **kw, out=out)
    assert got is out and same_bits(out, want)
    assert same_bits(spinal.advect(x, f, duration, **kw, progress=lambda d, t: None,
                                   out=out), want)


def test_advect_out_reused_and_refused():
    f = field()
    out = garbage((300, 3))
    for phase in (0.0, 1.0):
        x = curve(300, phase)
        assert spinal.advect(x, f, 0.3, 8, out=out) is out
        assert same_bits(out, spinal.advect(x, f, 0.3, 8))
    x = curve(300)
    for bad in bad_outs((300, 3)).values():
        with pytest.raises(ValueError, match="^out: "):
            spinal.advect(x, f, 0.3, 8, out=bad)
    with pytest.raises(ValueError, match="^out: shares memory with vertices"):
        spinal.advect(x, f, 0.3, 8, out=x)
    with pytest.raises(ValueError, match="^out: shares memory with vertices"):
        spinal.advect(out[:, :], f, 0.3, 8, out=out)
