"""``Mesh`` checks its arrays: non-finite vertices, normals and uv, wrapped or out-of-range
indices, float faces and planar vertices are refused by name (row ids of the robustness
review in the docstrings)."""

from __future__ import annotations

import numpy as np
import pytest

import spinal


def test_mesh_refuses_non_finite_vertices_normals_and_uv():
    """T3-06: Mesh() refuses NaN/inf vertices (float64 and float32), normals and uv, naming
    the array and the row, instead of NaN volumes and areas."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    F = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    assert spinal.Mesh(V, F).volume > 0
    for dtype in (np.float64, np.float32):
        for bad in (np.nan, np.inf, -np.inf):
            W = V.astype(dtype)
            W[3, 0] = bad
            with pytest.raises(ValueError, match="vertices: non-finite value .* at row 3"):
                spinal.Mesh(W, F)
    nrm = V.copy()
    nrm[2, 1] = np.nan
    with pytest.raises(ValueError, match="normals: non-finite value .* at row 2"):
        spinal.Mesh(V, F, normals=nrm)
    uv = np.zeros((4, 2))
    uv[1, 0] = np.inf
    with pytest.raises(ValueError, match="uv: non-finite value .* at row 1"):
        spinal.Mesh(V, F, uv=uv)
    # a non-contiguous view is read as it is
    wide = np.c_[V, np.zeros(4)]
    assert spinal.Mesh(wide[:, :3], F).volume == spinal.Mesh(V, F).volume


def test_mesh_refuses_wrapped_indices_float_faces_and_planar_vertices():
    """D10: Mesh used to validate nothing: a negative index wrapped (volume from the wrong vertex),
    an out-of-range one raised IndexError from .volume, float faces were truncated and
    (V, 2) vertices gave an einsum error."""
    with pytest.raises(ValueError, match="faces: face 0 refers to vertex -1, but there are 3"):
        _ = spinal.Mesh(np.eye(3), [[0, 1, -1]]).volume  # the review's reproducer
    with pytest.raises(ValueError, match="faces: face 0 refers to vertex 7"):
        spinal.Mesh(np.eye(3), [[0, 1, 7]])
    with pytest.raises(TypeError, match="faces: expected integer vertex indices, got dtype float"):
        spinal.Mesh(np.eye(3), [[0.0, 1.0, 2.7]])
    with pytest.raises(ValueError, match=r"vertices: expected an array of shape \(V, 3\)"):
        spinal.Mesh(np.zeros((3, 2)), [[0, 1, 2]])
    with pytest.raises(ValueError, match=r"faces: expected an array of shape \(F, 3\)"):
        spinal.Mesh(np.eye(3), [0, 1, 2])
    # faces changed after construction are checked again by the measures
    m = spinal.Mesh(np.eye(3), [[0, 1, 2]])
    m.faces = np.array([[0, 1, 3]])
    for what in ("volume", "area", "is_watertight"):
        with pytest.raises(ValueError, match="faces: face 0 refers to vertex 3"):
            getattr(m, what)
