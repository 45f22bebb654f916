"""spinal.deform's edge collapses and vertex moves along the strip a curl tool's slip tears
open (src/deform/refine/collapse.rs).

The strip of the tool's surface between the torn sides is filled by vertices of a few rest
points each; where the torn curve runs along the slip the strip narrows to a line and its
triangles are slivers and folds (the "teeth" of the lip). After a converged refinement they
are collapsed (link condition, volume-preserving survivor on the tool's surface) or their
vertices moved on the surface. Every check here is independent of the Rust core: angles and
dihedral angles in NumPy, closure and winding by trimesh and libigl, volumes by trimesh and
libigl, the edge threshold recounted in NumPy.
"""

from __future__ import annotations

import igl
import numpy as np
import pytest
import trimesh
from test_deform import icosphere, volumes
from test_deform_refine import DRAG, PRESS, band_quality, check_report

import spinal


@pytest.fixture(scope="module")
def drag10k():
    s = trimesh.creation.icosphere(5)
    V, F = icosphere(5)
    M, rep = spinal.deform(s, DRAG, 1.0)
    return V, F, M, rep


def test_the_10k_drag_band_has_few_slivers_and_few_folds(drag10k):
    """Measured on icosphere(5): 1.26% of the band's 15,672 faces with a smallest angle under
    1° and 907 band faces folded back against a neighbour (dihedral angle over 120°). Before
    the collapses (flips only): 32.3% of 24,563 and 6,179; without flips 48.5% and 10,752.
    The bounds leave about twice the measured values for a different order of the greedy
    passes (the counts move by tens when a test is changed), and are far below the flips
    alone. The folds left are mostly at the lip, between faces with vertices of a side's
    material, which the collapses (whose survivor lies on the tool's surface) do not move."""
    _, _, M, rep = drag10k
    count, slivers, folded = band_quality(M)
    assert count > 10000, count
    assert slivers < 0.03, (count, slivers)
    assert folded < 1800, folded
    assert rep.collapses > 1000 and rep.moves > 0 and rep.flips > 1000, str(rep)


def test_the_strip_interior_is_not_folded(drag10k):
    """Faces whose three vertices lie on the tool's surface (the strip itself) folded against
    another such face (dihedral angle over 120°): measured 80 of the strip's 20,448 interior
    edges (flips only: 3,558 of 31,870, 11%); the bound is 1%."""
    _, _, M, _ = drag10k
    V, F = np.asarray(M.vertices), np.asarray(M.faces)
    on = np.abs(np.linalg.norm(V - [0.5, 0.0, 0.9], axis=1) - 0.9) < 1e-12
    strip = on[F].all(axis=1)
    T = V[F]
    n = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
    pairs = trimesh.Trimesh(V, F, process=False).face_adjacency
    both = strip[pairs[:, 0]] & strip[pairs[:, 1]]
    folded = np.einsum("ij,ij->i", n[pairs[:, 0]], n[pairs[:, 1]]) < np.cos(np.radians(120))
    assert both.sum() > 10000
    assert (both & folded).sum() < 0.01 * both.sum(), ((both & folded).sum(), both.sum())


def test_the_collapsed_mesh_is_closed_manifold_and_consistently_wound(drag10k):
    V0, F0, M, rep = drag10k
    W, F = np.asarray(M.vertices), np.asarray(M.faces)
    tm = check_report(M, rep, V0, F0)  # trimesh watertight and winding, threshold recount
    assert tm.is_watertight and tm.is_winding_consistent and tm.is_volume
    assert igl.is_edge_manifold(F)[0]
    assert np.all(igl.is_vertex_manifold(F))
    oriented, components = igl.bfs_orient(F)
    assert components.max() == 0 and np.array_equal(oriented, F)
    # no vertex left unused by the collapses, no repeated or degenerate face
    assert np.array_equal(np.unique(F), np.arange(len(W)))
    assert len(np.unique(np.sort(F, axis=1), axis=0)) == len(F)
    assert np.all((F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0]))


def test_the_collapses_keep_the_volume(drag10k):
    """Each collapse places its survivor where the enclosed volume is kept, within 1e-3 of the
    mean rest edge cubed: measured −4.22e-5 (before the collapses −4.18e-5), the collapses and
    moves adding −1.75e-6 in all (−4.2e-7 of the volume); the rest mesh keeps its volume to
    1e-13 (check_report)."""
    V0, F0, M, rep = drag10k
    W, F = np.asarray(M.vertices), np.asarray(M.faces)
    vt, vi = volumes(W, F)
    assert abs(vt / vi - 1) < 1e-12 and abs(rep.volume / vt - 1) < 1e-12
    assert abs(rep.relative_change) <= 5e-5, str(rep)
    assert len(W) <= 10 * len(V0) and rep.converged
    lbar = np.linalg.norm(V0[F0[:, 0]] - V0[F0[:, 1]], axis=1).mean()
    assert abs(rep.collapse_volume) <= (rep.collapses + rep.moves) * 1e-3 * lbar**3
    assert abs(rep.collapse_volume) < 1e-6 * rep.rest_volume, rep.collapse_volume


def test_the_counts_agree_with_the_mesh(drag10k):
    V0, _, M, rep = drag10k
    W = np.asarray(M.vertices)
    assert rep.vertices_added == len(W) - len(V0)
    assert rep.step_vertices[-1] == len(W)
    # every vertex the collapses removed was a new one
    assert rep.torn_vertices <= rep.vertices_added + rep.collapses
    on = np.abs(np.linalg.norm(W - [0.5, 0.0, 0.9], axis=1) - 0.9) < 1e-12
    assert on.sum() == rep.slip_vertices


def test_a_press_flips_and_collapses_nothing():
    """No slip surface through the mesh: no strip, nothing to flip or collapse."""
    s = trimesh.creation.icosphere(3)
    _, rep = spinal.deform(s, PRESS, 1.0)
    assert rep.converged and rep.vertices_added > 0
    assert (rep.flips, rep.collapses, rep.moves) == (0, 0, 0)
    assert rep.flip_volume == 0.0 and rep.collapse_volume == 0.0


def test_a_bounded_refinement_is_not_collapsed():
    """A refinement the vertex bound stopped keeps every vertex it got (the bound is met
    exactly) and nothing is collapsed."""
    s = trimesh.creation.icosphere(3)
    with pytest.warns(spinal.RefinementWarning):
        M, rep = spinal.deform(s, DRAG, 1.0, max_vertices=1000)
    assert len(M.vertices) == 1000 and not rep.converged
    assert rep.collapses == 0 and rep.moves == 0
