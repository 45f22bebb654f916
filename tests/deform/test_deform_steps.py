"""The default step count of advect and deform, measured on the points: the first of 8, 16,
32, … RK4 steps whose run agrees with the run at half as many to 1e-5 of the field's length
scale (Richardson), with no point and no tool moving more than ℓ/8 in a step, never more
than the a priori bound ``field.steps(duration)``.

The references are independent runs: the a priori count (each step moving a point by at
most ℓ/8 of the speed bound) and runs with many more steps.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import spinal
from spinal import fields

trimesh = pytest.importorskip("trimesh")
pytest.importorskip("igl")

TOL = 1e-5  # the rule's tolerance, a fraction of the length scale

MESHES = Path(__file__).resolve().parents[3] / "shared" / "data" / "meshes"


def hair_tool():
    """A mesh curl tool pressing a unit icosphere at its +x pole with a blunt cube, a hair
    (a thin cylinder, thinner than the distance grid's spacing) pointing away from the
    sphere: its sampled distance's coefficient differences make the a priori speed bound
    many times the speed any vertex reaches."""
    cube = trimesh.creation.box((0.3, 0.3, 0.3))
    hair = trimesh.creation.cylinder(0.004, 0.6, sections=8)
    hair.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    hair.apply_translation((0.46, 0, 0))
    tool = trimesh.util.concatenate([cube, hair])
    tool.apply_translation([1.005 - tool.bounds[0, 0], 0, 0])
    return fields.mesh_curl(tool, velocity=[-0.2, 0, 0], reach=0.2, resolution=64)


def test_a_thin_feature_away_from_the_contact_does_not_multiply_the_steps():
    s = trimesh.creation.icosphere(3)
    V = np.asarray(s.vertices)
    f = hair_tool()
    bound = f.steps(1.0)
    n = f.steps(1.0, V)
    assert 8 <= n and 3 * n < bound, (n, bound)
    # the default is that count, bit for bit
    W = spinal.advect(V, f, 1.0)
    assert np.array_equal(W, spinal.advect(V, f, 1.0, n))
    # within the tolerance of the run at the a priori count, and of a run at 4x it
    ref = spinal.advect(V, f, 1.0, 4 * bound)
    assert np.abs(W - spinal.advect(V, f, 1.0, bound)).max() <= TOL * f.length_scale
    assert np.abs(W - ref).max() <= TOL * f.length_scale
    # deform takes the same count on the rest mesh
    _, rep = spinal.deform(s, f, 1.0)
    assert rep.steps == n
    # the count before it would not have met the tolerance: the rule stops at the first
    q, h = spinal.advect(V, f, 1.0, n // 4), spinal.advect(V, f, 1.0, n // 2)
    assert np.abs(q - h).max() > TOL * f.length_scale


def test_a_tool_moving_past_the_points_is_not_stepped_over():
    """A small tool passing a cluster of points at t ≈ 10.3, where no stage time of 4, 8 or
    16 steps over 20 falls: those runs never see it and agree exactly. The count must let
    the tool move at most ℓ/8 per step, and the result must carry the points as a run at
    the a priori count does."""
    rng = np.random.default_rng(3)
    x = rng.normal(size=(40, 3)) * 0.01
    f = fields.translation([-10.3, 0, 0], 0.1, [1, 0, 0], reach=0.1)
    n = f.steps(20.0, x)
    assert n >= 8 * 20 / 0.1
    W = spinal.advect(x, f, 20.0)
    assert np.abs(W - x).max() > 0.05  # the tool did move them
    assert np.abs(W - spinal.advect(x, f, 20.0, f.steps(20.0))).max() <= TOL * 0.1


def test_points_the_field_leaves_alone_take_the_fewest_steps():
    f = fields.rotation([5, 0, 0], 0.5, [0, 0, 1], 3.0)
    x = trimesh.creation.icosphere(2).vertices
    assert f.steps(1.0) > 8
    assert f.steps(1.0, x) == 8


def test_path_tools_keep_the_a_priori_count():
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1.0]])
    f = fields.along_path(pts, 0.3, 1.0)
    x = trimesh.creation.icosphere(2).vertices * 0.5
    assert len(f.breakpoints()) and f.steps(1.0, x) == f.steps(1.0)


def test_measuring_checks_its_arguments():
    f = fields.rotation([0, 0, 0], 0.5, [0, 0, 1], 3.0)
    with pytest.raises(ValueError, match="^points"):
        f.steps(1.0, np.full((4, 3), np.nan))
    with pytest.raises(ValueError, match="^points"):
        f.steps(1.0, np.zeros((4, 2)))
    with pytest.raises(ValueError, match="^t0"):
        f.steps(1.0, np.zeros((4, 3)), np.inf)
    x = np.zeros((4, 3))
    x.setflags(write=False)
    assert f.steps(1.0, x) >= 4  # a read-only array is fine, and not modified


@pytest.mark.skipif(not (MESHES / "cow.obj").exists() or not (MESHES / "fandisk.obj").exists(),
                    reason="shared test meshes not available")
def test_a_cow_shaped_tool_on_the_fandisk():
    """The fandisk pressed by a cow-shaped mesh curl tool (a quarter of the fandisk's
    diagonal, 0.005·diag off its +x extreme along the vertex normal, moving 0.06·diag into
    it, reach 0.1·diag): the a priori bound asks for thousands of steps (the cow's thin legs
    and ears in the distance grid), the measured count for at most 200, with the volume kept
    to 1e-4 and the vertices where 4x the steps put them."""
    m = trimesh.load(MESHES / "fandisk.obj", force="mesh")
    diag = float(np.linalg.norm(m.extents))
    cow = trimesh.load(MESHES / "cow.obj", force="mesh")
    cow.apply_translation(-cow.bounds.mean(0))
    cow.apply_scale(0.25 * diag / np.linalg.norm(cow.extents))
    i = int(np.argmax(m.vertices[:, 0]))
    nrm, p = m.vertex_normals[i], m.vertices[i]
    cow.apply_translation(p + (0.005 * diag + np.max(-cow.vertices @ nrm)) * nrm)
    f = fields.mesh_curl(cow, velocity=-nrm * 0.06 * diag, reach=0.1 * diag)
    assert f.steps(1.0) > 1000
    _, rep = spinal.deform(m, f, 1.0)
    assert rep.steps <= 200
    assert abs(rep.relative_change) <= 1e-4
    V = np.asarray(m.vertices)
    W = spinal.advect(V, f, 1.0)
    assert np.abs(W - spinal.advect(V, f, 1.0, 4 * rep.steps)).max() <= TOL * f.length_scale
