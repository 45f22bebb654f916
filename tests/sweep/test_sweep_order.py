"""Order of convergence of the swept volume under twist: a straight tube twisted by one full
turn either way (exact: area × length, each cross-section is the profile turned), a closed
knot tube whose closing twist is spread along it (reference by Richardson extrapolation), a
star profile twisted along a line and a polygon twisted around a circle (Pappus: the profile
turns about its centroid, which runs along the spine). The twisted quads are split along
alternating diagonals, so all of them converge at second order; the meshes stay watertight,
consistently wound, with unit normals that the faces follow and uv by arc length."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import spinal
from spinal.curves import TorusKnot

RINGS = (100, 200, 400, 800)


def polygon(m, r=1.0):
    a = 2 * np.pi * np.arange(m) / m
    return r * np.c_[np.cos(a), np.sin(a)]


def star(k=5, outer=0.5, inner=0.2):
    a = np.pi * np.arange(2 * k) / k
    rho = np.where(np.arange(2 * k) % 2, inner, outer)
    return np.c_[rho * np.cos(a), rho * np.sin(a)]


def area(p):
    return 0.5 * abs(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


def orders(errors):
    e = np.abs(np.asarray(errors))
    return np.log2(e[:-1] / e[1:])


def assert_clean(mesh):
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert tm.is_watertight and tm.is_winding_consistent and mesh.is_watertight
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-12)
    # the side faces are wound with the vertex normals (outwards); cap faces (last) carry
    # the side's radial normals at their corners, so they are not counted
    V, F = mesh.vertices, mesh.faces
    nf = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    dots = np.einsum("ij,ij->i", nf, mesh.normals[F].sum(axis=1))
    assert (dots > 0).mean() > 0.99


def straight(n, length):
    x = np.c_[np.zeros(n), np.zeros(n), np.linspace(0, length, n)]
    return x, np.repeat(np.eye(3)[None], n, axis=0)


@pytest.mark.parametrize("turns", [1, -1])
def test_twisted_straight_tube_volume_is_second_order_both_ways(turns):
    """Radius 0.5, length 2, one full turn: the volume error against area × L falls by 4
    per doubling of the rings in both twist directions (one diagonal everywhere: 1st order,
    a loss one way and a gain the other)."""
    prof, L = polygon(12, 0.5), 2.0
    exact = area(prof) * L
    errors = []
    for n in RINGS:
        x, F = straight(n, L)
        mesh = spinal.sweep(x, prof, frames=F, twist=np.linspace(0, 2 * np.pi * turns, n))
        errors.append(mesh.volume / exact - 1)
        if n == RINGS[0]:
            assert_clean(mesh)
            # the twist sits in the vertices, uv by arc length and profile fraction
            np.testing.assert_allclose(mesh.uv[:12, 1], np.arange(12) / 12)
            np.testing.assert_allclose(mesh.uv[::12, 0], x[:, 2] - x[0, 2], atol=1e-14)
    assert np.all(orders(errors) >= 1.8), (errors, orders(errors))
    assert abs(errors[-1]) < 2e-5


def test_both_twist_directions_agree():
    """Mirror twists give volumes within 1e-5 of each other at 400 rings (2.1e-3 apart with
    one diagonal)."""
    prof, L, n = polygon(12, 0.5), 2.0, 400
    x, F = straight(n, L)
    v = [spinal.sweep(x, prof, frames=F, twist=np.linspace(0, s * 2 * np.pi, n)).volume
         for s in (1, -1)]
    assert abs(v[0] - v[1]) / (area(prof) * L) < 1e-5


def test_closed_knot_tube_volume_is_second_order():
    """The rotation-minimising frames of a closed knot close with a twist spread along the
    loop (spinal.frames(closed=True)): errors against the Richardson extrapolation of the
    two finest tubes fall at second order."""
    sizes = (200, 400, 800, 1600, 3200)
    vols = []
    for n in sizes:
        mesh = spinal.tube(TorusKnot().sample(n + 1), 0.1, 16, closed=True)
        if n == sizes[0]:
            assert_clean(mesh)
        vols.append(mesh.volume)
    ref = (4 * vols[-1] - vols[-2]) / 3
    errors = [v - ref for v in vols[:-2]]
    assert np.all(orders(errors) >= 1.8), (errors, orders(errors))


@pytest.mark.parametrize("turns", [2, -2])
def test_twisted_star_along_a_line_is_second_order(turns):
    """A non-convex (star) profile twisted twice along a line, capped by its
    triangulation."""
    prof, L = star(), 3.0
    exact = area(prof) * L
    errors = []
    for n in RINGS:
        x, F = straight(n, L)
        mesh = spinal.sweep(x, prof, frames=F, twist=np.linspace(0, 2 * np.pi * turns, n))
        errors.append(mesh.volume / exact - 1)
        if n == RINGS[0]:
            assert_clean(mesh)
    assert np.all(orders(errors) >= 1.8), (errors, orders(errors))


@pytest.mark.parametrize("turns", [3, -3])
def test_twisted_polygon_around_a_circle_is_second_order(turns):
    """A pentagon (odd: the quads of a ring do not pair up) twisted three times around a
    circle of radius 2: Pappus gives 2πR · area exactly for the smooth solid; the mesh
    carries the error of the spine polygon too, both at second order."""
    prof, R = polygon(5, 0.4), 2.0
    exact = 2 * np.pi * R * area(prof)
    errors = []
    for n in RINGS:
        u = 2 * np.pi * np.arange(n) / n
        x = np.c_[R * np.cos(u), R * np.sin(u), np.zeros(n)]
        mesh = spinal.sweep(x, prof, closed=True, twist=turns * u)
        errors.append(mesh.volume / exact - 1)
        if n == RINGS[0]:
            assert_clean(mesh)
    assert np.all(orders(errors) >= 1.8), (errors, orders(errors))


def test_untwisted_tubes_keep_one_diagonal():
    """Planar quads (a straight or circular spine without twist) keep the split a–c
    everywhere (the split does not change their volume; curvature operators like the
    regular mesh); twisted segments alternate."""
    x, F = straight(5, 1.0)
    mesh = spinal.sweep(x, polygon(4), frames=F)
    a, b, c, d = 0, 1, 5, 4  # first quad: ring 0 → 1
    np.testing.assert_array_equal(mesh.faces[:2], [[a, b, c], [a, c, d]])
    second = mesh.faces[8:10]  # ring 1 → 2, same split
    np.testing.assert_array_equal(second, [[4, 5, 9], [4, 9, 8]])
    tw = spinal.sweep(x, polygon(4), frames=F, twist=np.linspace(0, 1, 5))
    np.testing.assert_array_equal(tw.faces[:2], [[a, b, c], [a, c, d]])
    np.testing.assert_array_equal(tw.faces[8:10], [[4, 5, 8], [5, 9, 8]])
