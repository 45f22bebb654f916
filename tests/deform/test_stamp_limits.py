"""Validity and work limits of spinal.stamp: it refuses a tool that swallows the mesh,
touches every triangle, or dents with nothing in reach to protrude (it used to snap the whole
mesh onto the tool, volume ×23.8, silently); it bounds its frames and iterations and stops on
Ctrl-C between frames.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import late_after_sigint
from test_deform import icosphere, volumes

import spinal

# ---- stamp: a tool that cannot give the dent back ---------------------------------------------

def octahedron():
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1.0]])
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return v, f


def test_a_tool_larger_than_the_mesh_is_refused():
    V, F = icosphere(2)
    with pytest.raises(ValueError, match=r"^radius: the tool \(radius 10\) swallows the whole "
                       r"mesh at frame 1"):
        spinal.stamp((V, F), [0, 0, 1.32], [0, 0, 1.1], 10.0)
    # the same press with a tool of radius 0.3 is fine
    r = spinal.stamp((V, F), [0, 0, 1.32], [0, 0, 1.1], 0.3)[1]
    assert abs(r.relative_change) < 1e-5 and (r.contact > 0).any()


def test_a_tool_touching_every_triangle_is_refused():
    # from (0, 0, 1.5) to (0, 0, 0.3) with radius 1.1: +Z and the equator inside, −Z not
    with pytest.raises(ValueError, match=r"^radius: the tool \(radius 1\.1\) leaves no "
                       r"triangle free of contact at frame 1"):
        spinal.stamp(octahedron(), [0, 0, 1.5], [0, 0, 0.3], 1.1, frames=1)


def test_a_dent_with_nothing_in_reach_to_protrude_is_refused():
    # +Z is pushed in by 0.05; the free (bottom) triangles are far beyond a reach of 0.2
    with pytest.raises(ValueError, match=r"^reach: no triangle free of contact within reach "
                       r"\(0\.2\) of the tool faces its field at frame 1"):
        spinal.stamp(octahedron(), [0, 0, 1.5], [0, 0, 1.05], 0.1, reach=0.2, frames=1)
    # with the whole mesh in reach the dent is given back
    m, r = spinal.stamp(octahedron(), [0, 0, 1.5], [0, 0, 1.05], 0.1, reach=3.0, frames=1)
    assert r.dent[0] > 0 and r.time[0] > 0
    v0, _ = volumes(*octahedron())
    v1, _ = volumes(np.asarray(m.vertices), octahedron()[1])
    assert abs(v1 / v0 - 1) < 1e-6


# ---- stamp: bounded and interruptible ---------------------------------------------------------

@pytest.mark.parametrize("kw, match", [
    ({"frames": 2**64 - 1}, r"^frames: must be at least 1 and at most 1,000,000, got 1844"),
    ({"frames": 1_000_001}, r"^frames: .* at most 1,000,000"),
    ({"frames": 0}, r"^frames: must be at least 1"),
    ({"iterations": 2**64}, r"^iterations: .* at most 1000"),
])
def test_stamp_work_is_bounded(kw, match):
    V, F = icosphere(1)
    with pytest.raises(ValueError, match=match):
        spinal.stamp((V, F), [0, 0, 1.32], [0, 0, 1.1], 0.3, **kw)


@pytest.mark.slow
def test_ctrl_c_stops_a_long_stamp_between_frames():
    """SIGINT one second into a ~25-minute stamp raises KeyboardInterrupt at the next frame:
    the child's CPU time per pool thread after the signal stays below 0.5 s."""
    call = "spinal.stamp(m, [0, 0, 1.32], [0, 0, 1.1], 0.3, frames=1_000_000)"
    assert late_after_sigint("m = trimesh.creation.icosphere(5)\n", call, after=1.0) < 0.5
