"""Limits of the sweeps: frames that run against the spine are refused by name (not an
inside-out mesh) while frames of tight turns are swept, the cost is linear in the profile's
vertices, and ``sides`` and the profile's size are bounded with named errors (row ids D11,
D12, D23 of the robustness review in the docstrings)."""

from __future__ import annotations

import time
import warnings

import numpy as np
import pytest

import spinal

u = np.linspace(0, 4 * np.pi, 60)
H = np.c_[np.cos(u), np.sin(u), 0.2 * u]
SQ = np.array([(0.1, 0.1), (-0.1, 0.1), (-0.1, -0.1), (0.1, -0.1)])
TWO = np.array([[0, 0, 0], [1, 0, 0.0]])


def test_frames_against_the_spine_are_refused():
    """D11: Frames of the reversed helix, reversed back: every tangent points backwards."""
    with pytest.raises(ValueError, match=r"frames: the tangent column t of row 0 "
                                         r"points against the spine"):
        spinal.sweep(H, SQ, frames=spinal.frames(H[::-1])[::-1])
    # the same frames in the curve's direction sweep an outward mesh
    assert spinal.sweep(H, SQ, frames=spinal.frames(H)).volume > 0
    # one reversed frame in the middle is refused by its row (its t opposes both chords),
    # not swept into a local inside-out ring reported as a fold
    F = spinal.frames(H)
    F[30] = F[30] @ np.diag([-1.0, 1.0, -1.0])
    with pytest.raises(ValueError, match=r"frames: the tangent column t of row 30 points "
                                         r"against the spine \(negative dot product with "
                                         r"the chords at point 30\)"):
        spinal.sweep(H, SQ, frames=F)
    # at an open end there is one chord to oppose
    for row in (0, len(H) - 1):
        F = spinal.frames(H)
        F[row] = F[row] @ np.diag([-1.0, 1.0, -1.0])
        with pytest.raises(ValueError, match=rf"frames: the tangent column t of row {row} "
                                             rf"points against the spine \(negative dot "
                                             rf"product with the chord at point {row}\)"):
            spinal.tube(H, 0.1, 4, frames=F)
    # in a bundle the message names the curve and the row within it
    F = spinal.frames([H, H + 5.0])
    F[len(H) + 7] = F[len(H) + 7] @ np.diag([-1.0, 1.0, -1.0])
    with pytest.raises(ValueError, match=r"frames: curve 1 \(rows 60 to 119\): the tangent "
                                         r"column t of row 7 points against the spine"):
        spinal.sweep([H, H + 5.0], SQ, frames=F)
    # a closed loop checks its closing segment too
    c = np.c_[np.cos(u[:-1]), np.sin(u[:-1]), np.zeros(59)]
    Fc = spinal.frames(c, closed=True)
    with pytest.raises(ValueError, match="frames: the tangent column"):
        spinal.sweep(c, SQ, closed=True, frames=Fc[::-1].copy() @ np.diag([-1.0, 1.0, -1.0]))


def _chord_dots(points, frames, closed=False):
    """t_k · (x_k − x_{k−1}) and t_k · (x_{k+1} − x_k) per row (NaN where there is none)."""
    c = np.diff(np.vstack([points, points[:1]]) if closed else points, axis=0)
    none = np.full((1, 3), np.nan)
    cin = np.vstack([c[-1:] if closed else none, c])[: len(points)]
    cout = np.vstack([c, none])[: len(points)]
    t = frames[:, :, 2]
    return np.einsum("ij,ij->i", t, cin), np.einsum("ij,ij->i", t, cout)


def test_frames_of_tight_turns_are_accepted():
    """D11: Frames from spinal.frames on tight turns are swept: a coarse helix (6 samples a turn),
    a hairpin of 2 samples round its bend, a closed loop, and a 150° corner between a long
    and a short chord, with a given tangent leaning onto the short chord so that it opposes
    the long one (one negative dot product: not a reversed frame)."""
    v = np.linspace(0, 6 * np.pi, 19)
    helix = np.c_[np.cos(v), np.sin(v), 0.1 * v]
    th = np.linspace(0, np.pi, 4)[1:-1]
    line = np.linspace(0, -3, 7)
    hairpin = np.vstack([np.c_[line[::-1], np.ones(7), np.zeros(7)],
                         np.c_[np.sin(th), np.cos(th), np.zeros(2)],
                         np.c_[line, -np.ones(7), np.zeros(7)]])
    w = 2 * np.pi * np.arange(7) / 7
    loop = np.c_[np.cos(w), np.sin(w), 0.3 * np.sin(2 * w)]
    ph = np.radians(150)
    d2 = np.array([np.cos(2 * ph), np.sin(2 * ph), 0.3]) / np.hypot(1, 0.3)
    corner = np.vstack([np.c_[-10.0 * np.arange(5, 0, -1), np.zeros((5, 2))], np.zeros(3)])
    corner = np.vstack([corner, [np.cos(ph), np.sin(ph), 0]])
    corner = np.vstack([corner, corner[-1] + 10 * np.arange(1, 6)[:, None] * d2])
    small = SQ / 100
    one_sided = 0
    # the corner's tangent leaning onto the short chord (estimated tangents no longer do:
    # their chord guard turns them to the corner's bisector), given
    lean = spinal.estimate_tangents(corner)
    lean[5] = corner[6] - corner[5]
    for name, P, closed in (("helix", helix, False), ("hairpin", hairpin, False),
                            ("loop", loop, True), ("corner", corner, False)):
        for rule in ("five_point_bounded", "circle", "given"):
            if rule == "given" and name != "corner":
                continue
            t = lean if rule == "given" else spinal.estimate_tangents(P, method=rule,
                                                                       closed=closed)
            F = spinal.frames(P, t, closed=closed)
            a, b = _chord_dots(P, F, closed)
            one_sided += int(np.sum((a < 0) ^ (b < 0)))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", spinal.FoldOverWarning)
                mesh = spinal.sweep(P, small, frames=F, closed=closed, caps=not closed)
            assert mesh.is_watertight and mesh.volume > 0, (name, rule)
    # the given corner tangent opposes one of its chords: the test covers that case
    assert one_sided >= 1
    # a bundle of such curves, with its frames, too
    bundle = [helix, hairpin, corner]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        assert spinal.sweep(bundle, small, frames=spinal.frames(bundle)).volume > 0


@pytest.mark.parametrize("caps", [False, True])
def test_cost_is_linear_in_the_profile(caps):
    """D12: 64,000 sides on a 2-point spine took 30–48 s (an O(m²) simplicity test): now a
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


def _star(m, inner=0.5):
    """A star of m vertices (m/2 points), alternately on radius 1 and ``inner``: non-convex
    at every other vertex, so no convex shortcut applies."""
    a = 2 * np.pi * np.arange(m) / m
    rho = np.where(np.arange(m) % 2, inner, 1.0)
    return np.c_[rho * np.cos(a), rho * np.sin(a)]


def _cpu_seconds(f, repeats=3):
    """Best of ``repeats`` process CPU times of ``f()`` (all threads; unlike the wall clock
    it does not grow when other processes share the cores)."""
    best = np.inf
    for _ in range(repeats):
        t0 = time.process_time()
        f()
        best = min(best, time.process_time() - t0)
    return best


def test_non_convex_profiles_of_many_vertices():
    """D12: A capped sweep of a non-convex profile is linear in its vertices: 8× the vertices of a
    star cost at most 16× (an O(m²) check or ear clipping costs 64×, linear ~8×), and
    64,000 vertices (30–48 s when the profile check was O(m²)) take at most 2 s of CPU.
    The caps are right: the volume is the star's area times the spine's length."""
    spine = TWO[:, [2, 1, 0]]
    small, large = _star(16_000), _star(128_000)
    t_small = _cpu_seconds(lambda: spinal.sweep(spine, small, caps=True))
    t_large = _cpu_seconds(lambda: spinal.sweep(spine, large, caps=True))
    assert t_large <= 16 * t_small + 0.05, (t_small, t_large)
    mid = _star(64_000)
    t_mid = _cpu_seconds(lambda: spinal.sweep(spine, mid, caps=True), repeats=1)
    assert t_mid < 2.0, t_mid
    mesh = spinal.sweep(spine, large, caps=True)
    assert mesh.is_watertight
    exact = 0.5 * abs(np.sum(large[:, 0] * np.roll(large[:, 1], -1)
                             - np.roll(large[:, 0], -1) * large[:, 1]))
    assert mesh.volume == pytest.approx(exact, rel=1e-9)


@pytest.mark.parametrize("sides", [2**31, 2**62, 2**70])
def test_sides_has_an_upper_bound(sides):
    """D23: 2**31 sides allocated 16 GiB; 2**62 and 2**70 gave numpy messages without the name."""
    with pytest.raises(ValueError, match=r"sides: at most 1,048,576 \(2\*\*20\) sides"):
        spinal.tube(TWO, 0.1, sides)


@pytest.mark.parametrize("closed", [False, True])
def test_profile_vertices_have_an_upper_bound(closed):
    """D23: A profile of more than 2**24 vertices is refused by name (after a closed profile's
    repeated first vertex is dropped: 2**24 + 2 rows then count 2**24 + 1)."""
    rows = 2**24 + 1 + int(closed)
    prof = np.zeros((rows, 2))
    with pytest.raises(ValueError, match=r"profile: at most 16777216 vertices \(2\*\*24\), "
                                         r"got 16777217"):
        spinal.sweep(TWO, prof, profile_closed=closed)
