"""Reproducers of the robustness review (sweeps and meshes, part b), one test per row of
../shared/reviews/robustness-defects.md, each named after its row."""

from __future__ import annotations

import numpy as np
import pytest

import spinal


def test_D10_mesh_validates_its_arrays():
    """Mesh used to validate nothing: a negative index wrapped (volume from the wrong vertex),
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
