"""Outputs are allocated uninitialised (``numpy.empty``) and filled by the Rust core: every
element must be written. Freed NaN-filled blocks of the same size make any unwritten element
show up as NaN (NumPy and malloc hand the freed memory back for the next allocation)."""

import numpy as np
import pytest

import spinal
from spinal.curves import Helix, TorusKnot


def poison(*shapes):
    for _ in range(3):
        blocks = [np.full(s, np.nan) for s in shapes]
        del blocks


@pytest.mark.parametrize("method", ["double_reflection", "rotation", "projection", "frenet"])
@pytest.mark.parametrize("closed", [False, True])
def test_frames_write_every_row(method, closed):
    x = TorusKnot().sample(257) if closed else Helix().sample(200)
    for _ in range(5):
        poison((len(x), 3, 3))
        f = spinal.frames(x, method=method, closed=closed)
        assert np.isfinite(f).all()


def test_frames_rk4_and_bundle_write_every_row():
    h = Helix()
    poison((65, 3, 3))
    assert np.isfinite(spinal.frames(h, method="rk4", u=65)).all()
    x = np.concatenate([Helix().sample(50), TorusKnot().sample(80)])
    for _ in range(5):
        poison((130, 3, 3))
        assert np.isfinite(spinal.frames(x, lengths=[50, 80])).all()


@pytest.mark.parametrize("kw", [{}, {"closed": True}, {"split_seams": True},
                                {"closed": True, "split_seams": True}, {"caps": False}])
def test_sweep_writes_every_element(kw):
    x = TorusKnot().sample(120)[:-1] if kw.get("closed") else Helix().sample(120)
    m0 = spinal.tube(x, 0.2, 12, **kw)
    for _ in range(5):
        poison(m0.vertices.shape, m0.normals.shape, m0.uv.shape, m0.faces.shape)
        m = spinal.tube(x, 0.2, 12, **kw)
        for a in (m.vertices, m.normals, m.uv):
            assert np.isfinite(a).all()
        np.testing.assert_array_equal(m.faces, m0.faces)
        np.testing.assert_array_equal(m.vertices, m0.vertices)
