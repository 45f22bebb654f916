"""spinal.deform behind tools with sharp features: the refined mesh keeps healthy faces.

A `fields.mesh_curl` tool made from a CAD part (the fandisk: sharp creases and corners) or a
generated cube presses into a closed mesh. Checks are independent of the core's own counts:
face areas and coincident vertices recounted in NumPy, crossing faces from libigl's exact
predicates (``igl.predicates.find_self_intersections``), volumes from trimesh and libigl.
The shared meshes are read from ``../shared/data/meshes`` and skipped when absent.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
from test_deform import volumes

import spinal
from spinal import fields

igl = pytest.importorskip("igl")
pytest.importorskip("igl.predicates")

MESHES = Path(__file__).resolve().parents[2] / "shared" / "data" / "meshes"


def shared(*names):
    return pytest.mark.skipif(not all((MESHES / n).exists() for n in names),
                              reason="shared test meshes not available")


def pressing(target, tool, frac=0.25, gap=0.005, depth=0.06, reach=0.1):
    """A mesh curl tool of `tool`'s shape, scaled to `frac` of `target`'s diagonal, placed
    `gap`·diag off `target`'s +x extreme along its vertex normal and moving `depth`·diag
    into it over unit time, with reach `reach`·diag."""
    diag = float(np.linalg.norm(target.extents))
    t = tool.copy()
    t.apply_translation(-t.bounds.mean(0))
    t.apply_scale(frac * diag / np.linalg.norm(t.extents))
    i = int(np.argmax(target.vertices[:, 0]))
    n, p = target.vertex_normals[i], target.vertices[i]
    t.apply_translation(p + (gap * diag + np.max(-t.vertices @ n)) * n)
    return fields.mesh_curl(t, velocity=-n * depth * diag, reach=reach * diag)


def crossing_pairs(V, F):
    import igl.predicates

    r = igl.predicates.find_self_intersections(np.ascontiguousarray(V, dtype=np.float64),
                                               np.ascontiguousarray(F, dtype=np.int64))
    return int(r[0])


def assert_healthy(mesh, rep, rest_volume):
    V, F = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    tri = V[F]
    area2 = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    assert np.count_nonzero(area2 == 0) == 0
    assert len(np.unique(V, axis=0)) == len(V), "two vertices at one position"
    assert crossing_pairs(V, F) == 0
    assert rep.degenerate_faces == 0 and rep.crossing_pairs == 0 and rep.converged
    m = trimesh.Trimesh(V, F, process=False)
    assert m.is_watertight and m.is_winding_consistent
    vt, vi = volumes(V, F)
    assert abs(vt - vi) <= 1e-12 * abs(vt)
    assert vt / rest_volume - 1 == pytest.approx(rep.relative_change, abs=1e-12)
    return vt / rest_volume - 1


@shared("rocker-arm.obj", "fandisk.obj")
def test_rocker_arm_pressed_by_the_fandisk_keeps_healthy_faces():
    """The rocker arm's long CAD triangles: splitting a shorter over-long edge of a triangle
    whose longest edge is not over the threshold cycles towards a fixed point and stacked 39
    copies of one vertex (150 zero-area faces, 98 crossing pairs). Longest-edge propagation
    splits only longest edges."""
    m = trimesh.load(MESHES / "rocker-arm.obj", force="mesh")
    f = pressing(m, trimesh.load(MESHES / "fandisk.obj", force="mesh"))
    out, rep = spinal.deform(m, f, 1.0, check="intersections")
    change = assert_healthy(out, rep, m.volume)
    assert abs(change) <= 5e-4
