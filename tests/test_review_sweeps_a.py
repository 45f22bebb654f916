"""Rows D11, D12 and D23 of the robustness review of the sweeps: frames of the reversed
curve are refused by name (not an inside-out mesh), the cost is linear in the profile's
vertices, and ``sides`` is bounded with a named error."""

from __future__ import annotations

import time

import numpy as np
import pytest

import spinal

u = np.linspace(0, 4 * np.pi, 60)
H = np.c_[np.cos(u), np.sin(u), 0.2 * u]
SQ = np.array([(0.1, 0.1), (-0.1, 0.1), (-0.1, -0.1), (0.1, -0.1)])
TWO = np.array([[0, 0, 0], [1, 0, 0.0]])


def test_D11_frames_against_the_spine_are_refused():
    """Frames of the reversed helix, reversed back: every tangent points backwards."""
    with pytest.raises(ValueError, match=r"frames: the tangent column t of rows 0 and 1 "
                                         r"points against the spine"):
        spinal.sweep(H, SQ, frames=spinal.frames(H[::-1])[::-1])
    # the same frames in the curve's direction sweep an outward mesh
    assert spinal.sweep(H, SQ, frames=spinal.frames(H)).volume > 0
    # one reversed frame in the middle is not refused (one tangent of each segment still
    # agrees): the fold there is reported as before
    F = spinal.frames(H)
    F[30] = F[30] @ np.diag([-1.0, 1.0, -1.0])
    with pytest.warns(spinal.FoldOverWarning, match="rows 29–30"):
        spinal.sweep(H, SQ, frames=F)
    # a closed loop checks its closing segment too
    c = np.c_[np.cos(u[:-1]), np.sin(u[:-1]), np.zeros(59)]
    Fc = spinal.frames(c, closed=True)
    with pytest.raises(ValueError, match="frames: the tangent column"):
        spinal.sweep(c, SQ, closed=True, frames=Fc[::-1].copy() @ np.diag([-1.0, 1.0, -1.0]))


@pytest.mark.parametrize("caps", [False, True])
def test_D12_cost_is_linear_in_the_profile(caps):
    """64,000 sides on a 2-point spine took 30–48 s (an O(m²) simplicity test): now a
    strictly convex profile is checked and fanned in O(m). Generous bounds for a loaded
    2-core machine; 4× the sides may cost at most ~12× (linear, with noise)."""
    t0 = time.perf_counter()
    small = spinal.tube(TWO, 0.1, 16_000, caps=caps)
    t1 = time.perf_counter()
    mesh = spinal.tube(TWO, 0.1, 64_000, caps=caps)
    t2 = time.perf_counter()
    assert t2 - t1 < 3.0, t2 - t1
    assert t2 - t1 < 12 * (t1 - t0) + 0.2
    assert len(mesh.vertices) == 128_000 and len(small.vertices) == 32_000
    if caps:
        assert mesh.is_watertight
        sides = 64_000
        exact = 0.5 * sides * 0.01 * np.sin(2 * np.pi / sides)
        assert mesh.volume == pytest.approx(exact, rel=1e-9)


def test_D12_non_convex_profiles_of_many_vertices():
    """An ordinary non-convex profile (a gear of 2,000 teeth, 8,000 vertices) is checked and
    capped in well under a second's worth of work per 10k vertices."""
    teeth = 2000
    a = 2 * np.pi * np.arange(4 * teeth) / (4 * teeth)
    rho = np.where((np.arange(4 * teeth) // 2) % 2, 0.9, 1.0)
    gear = np.c_[rho * np.cos(a), rho * np.sin(a)]
    t0 = time.perf_counter()
    mesh = spinal.sweep(TWO[:, [2, 1, 0]], gear)
    assert time.perf_counter() - t0 < 3.0
    assert mesh.is_watertight
    exact = 0.5 * abs(np.sum(gear[:, 0] * np.roll(gear[:, 1], -1)
                             - np.roll(gear[:, 0], -1) * gear[:, 1]))
    assert mesh.volume == pytest.approx(exact, rel=1e-9)


@pytest.mark.parametrize("sides", [2**31, 2**62, 2**70])
def test_D23_sides_has_an_upper_bound(sides):
    """2**31 sides allocated 16 GiB; 2**62 and 2**70 gave numpy messages without the name."""
    with pytest.raises(ValueError, match=r"sides: at most 1,048,576 \(2\*\*20\) sides"):
        spinal.tube(TWO, 0.1, sides)
