"""Scale-out with Dask (docs/scale-out.md, notebooks/07_scale_out.ipynb): a small bundle of
tubes and a short animation mapped over chunks on a LocalCluster of 2 worker processes (one
thread each) equal the single call bit for bit. Also: arrays as pickle protocol 5 delivers
them (unaligned buffers) are accepted."""

import pathlib
import pickle
import sys

import numpy as np
import pytest

import spinal

pytestmark = pytest.mark.slow  # starts Dask workers

ROOT = pathlib.Path(__file__).parents[2]


def unaligned(a):
    """A C-contiguous copy of ``a`` whose data starts 4 bytes off an 8-byte boundary."""
    raw = np.zeros(a.nbytes + 8, dtype=np.uint8)
    start = (-raw.ctypes.data) % 8 + 4
    out = raw[start:start + a.nbytes].view(a.dtype).reshape(a.shape)
    out[...] = a
    assert not out.flags.aligned and out.flags.c_contiguous
    return out


def test_unaligned_arrays_are_accepted():
    t = 2 * np.pi * np.arange(64) / 64
    points = np.c_[np.cos(t), np.sin(t), 0.1 * t]
    ring = spinal.tube(points, 0.2, sides=8)
    tool = spinal.fields.translation([1.3, 0, 0], 0.3, [-0.5, 0, 0])
    np.testing.assert_array_equal(spinal.frames(unaligned(points)), spinal.frames(points))
    np.testing.assert_array_equal(spinal.advect(unaligned(ring.vertices), tool, 0.1),
                                  spinal.advect(ring.vertices, tool, 0.1))
    a, _ = spinal.deform((unaligned(ring.vertices), unaligned(ring.faces)), tool, 0.1)
    b, _ = spinal.deform(ring, tool, 0.1)
    np.testing.assert_array_equal(a.vertices, b.vertices)
    # out-of-band pickle buffers
    buffers = []
    data = pickle.dumps(ring.vertices, protocol=5, buffer_callback=buffers.append)
    raw = bytearray(len(buffers[0].raw()) + 4)
    raw[4:] = buffers[0].raw()
    copy = pickle.loads(data, buffers=[memoryview(raw)[4:]])
    np.testing.assert_array_equal(spinal.advect(copy, tool, 0.1),
                                  spinal.advect(ring.vertices, tool, 0.1))


def test_chunks_on_a_local_cluster_equal_the_single_call():
    pytest.importorskip("dask")
    distributed = pytest.importorskip("distributed")
    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        import scale_out
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None, silence_logs=50) as cluster, \
            distributed.Client(cluster) as client:
        client.upload_file(str(ROOT / "benchmarks" / "scale_out.py"))  # the workers import it
        out = scale_out.run(client, n_curves=2000, n_frames=6, chunks=3)  # asserts equality
    assert out["workers"] == 2
    assert [r["threads"] for r in out["tube_chunks"]] == [1, 1, 1]  # spinal.threads(1)
    assert sum(r["curves"] for r in out["tube_chunks"]) == 2000
    assert len(out["anim_chunks"]) == 3 and abs(out["volume_change"]) < 1e-3
