"""Tubes of the polylines users have: every random walk, hairpin and exact reversal is
tubed, watertight and wound outwards, alone or in one bundle call."""

import re
import warnings

import numpy as np
import pytest

import spinal

trimesh = pytest.importorskip("trimesh")


def _walks(count, seed, lo=3, hi=61):
    """Gaussian random walks of lo…hi−1 points (turns of every size)."""
    rng = np.random.default_rng(seed)
    return [np.cumsum(rng.normal(size=(rng.integers(lo, hi), 3)), axis=0) for _ in range(count)]


def _polygon_area(sides, r):
    return 0.5 * sides * r * r * np.sin(2 * np.pi / sides)


def test_every_random_walk_is_tubed_watertight_and_outward():
    walks = _walks(300, 10)
    r, sides = 0.05, 8
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        mesh = spinal.tube(walks, r, sides)
        singles = [spinal.tube(x, r, sides) for x in walks[:60]]
    assert set(mesh.curve_of) == set(range(len(walks)))
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert tm.is_watertight and tm.is_winding_consistent
    # each curve's part: its own tube (the bundle changes nothing), outwards
    v0 = 0
    for c, one in enumerate(singles):
        part = mesh.vertices[v0:v0 + len(one.vertices)]
        np.testing.assert_array_equal(part, one.vertices)
        v0 += len(one.vertices)
        assert one.is_watertight and one.volume > 0, c


def test_hairpins_and_exact_reversals_are_tubed_watertight():
    for turn in (150, 170, 179, 179.999):
        a = np.radians(turn)
        d = np.array([np.cos(a), np.sin(a), 0])  # the outgoing chords, turned by `turn`
        x = np.array([[-2, 0, 0], [-1, 0, 0], [0, 0, 0], d, 2 * d])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", spinal.FoldOverWarning)
            mesh = spinal.tube(x, 0.05, 12)
        tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
        assert tm.is_watertight and tm.is_winding_consistent and mesh.volume > 0, turn
    x = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 0, 0], [0, 0, 0]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        mesh = spinal.tube(x, 0.05, 12)
    assert mesh.is_watertight and mesh.volume > 0


def test_tube_ends_lean_at_most_45_degrees_from_their_chords():
    rng = np.random.default_rng(11)
    walks = [np.cumsum(rng.normal(size=(12, 3)) + [1.5, 0, 0], axis=0) for _ in range(200)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        mesh = spinal.tube(walks, 0.1, 16)
    F = spinal.frames(walks)
    starts = np.r_[0, np.cumsum([len(w) for w in walks])]
    for c, x in enumerate(walks):
        for row, chord in ((0, x[1] - x[0]), (len(x) - 1, x[-1] - x[-2])):
            t = F[starts[c] + row, :, 2]
            lean = np.degrees(np.arccos(np.clip(t @ chord / np.linalg.norm(chord), -1, 1)))
            assert lean <= 45 + 1e-9, (c, row, lean)
            # the tube's end ring lies in the plane normal to that tangent, or where the
            # next sample is a corner with a join, square to the end chord (the ring next
            # to a join lies square to its own run)
            ring = mesh.vertices[(mesh.sample_of == starts[c] + row)]
            nxt = starts[c] + (1 if row == 0 else len(x) - 2)
            if (mesh.sample_of == nxt).sum() > 16:
                t = chord / np.linalg.norm(chord)
            np.testing.assert_allclose((ring - x[row]) @ t, 0, atol=1e-12)


def _zigzag(rng, n, planar):
    """A polyline of n points with chords 0.5…2 long turning by 61°…149° at every sample."""
    d, x = np.array([1.0, 0, 0]), [np.zeros(3)]
    for _ in range(n - 1):
        x.append(x[-1] + rng.uniform(0.5, 2) * d)
        phi = np.radians(rng.uniform(61, 149))
        ax = np.array([0, 0, rng.choice([-1.0, 1.0])]) if planar else np.cross(d, rng.normal(size=3))
        ax /= np.linalg.norm(ax)
        K = np.array([[0, -ax[2], ax[1]], [ax[2], 0, -ax[0]], [-ax[1], ax[0], 0]])
        d = (np.eye(3) + np.sin(phi) * K + (1 - np.cos(phi)) * K @ K) @ d
    return np.array(x)


def test_planar_polyline_with_sharp_corners_has_the_exact_volume():
    """With mitre joins, turns of 60° or more are corners whose rings lie in the bisector
    planes (the exact cut of the straight tubes about both chords) and the ends are square
    to the end chords, so a thin planar tube is the union of its prisms: area × length, to
    rounding (under the mitre limit's 151° turn)."""
    rng = np.random.default_rng(1)
    sides, r = 12, 0.01
    for n in (3, 4, 5, 9, 30):
        for _ in range(4):
            x = _zigzag(rng, n, planar=True)
            length = np.linalg.norm(np.diff(x, axis=0), axis=1).sum()
            mesh = spinal.tube(x, r, sides, join="miter")
            assert mesh.is_watertight
            assert abs(mesh.volume / (_polygon_area(sides, r) * length) - 1) < 1e-13, n


def test_repeated_samples_are_merged_into_the_first():
    """Consecutive samples closer than 2⁻⁴⁰ of the curve's size are one point: the tube of
    the curve with them is the tube without them; the ring's point_data and sample_of are
    those of the first row of each group."""
    rng = np.random.default_rng(7)
    x = np.cumsum(rng.normal(size=(12, 3)), axis=0)
    size = np.ptp(x, axis=0).max()
    dup = np.insert(x, [3, 3, 7, 12], [x[2], x[2] + 1e-13 * size, x[6], x[11]], axis=0)
    given = np.insert(np.arange(12), [3, 3, 7, 12], [2, 2, 6, 11])  # the row each repeats
    value = np.arange(len(dup), dtype=float)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        clean = spinal.tube(x, 0.1, 8)
        merged = spinal.tube(dup, 0.1, 8, point_data={"v": value})
    np.testing.assert_array_equal(merged.vertices, clean.vertices)
    np.testing.assert_array_equal(merged.faces, clean.faces)
    kept = np.flatnonzero(np.r_[True, given[1:] != given[:-1]])
    np.testing.assert_array_equal(np.unique(merged.sample_of), kept)
    np.testing.assert_array_equal(merged.point_data["v"], value[merged.sample_of])
    # frames and tangents: one row per given row, the repeats get their group's
    F, Fc = spinal.frames(dup), spinal.frames(x)
    np.testing.assert_array_equal(F, Fc[given])
    np.testing.assert_array_equal(spinal.estimate_tangents(dup), spinal.estimate_tangents(x)[given])
    # in a bundle, the other curves are untouched and the rows map back as given
    other = np.cumsum(rng.normal(size=(9, 3)), axis=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        both = spinal.tube([other, dup, other], 0.1, 8)
        ref = spinal.tube([other, x, other], 0.1, 8)
    np.testing.assert_array_equal(both.vertices, ref.vertices)
    np.testing.assert_array_equal(np.unique(both.sample_of[both.curve_of == 1]), 9 + kept)
    np.testing.assert_array_equal(spinal.frames([other, dup])[9:], Fc[given])
    # a closed curve whose last sample repeats its first (to rounding)
    u = 2 * np.pi * np.arange(30) / 30
    loop = np.c_[np.cos(u), np.sin(u), 0.3 * np.sin(2 * u)]
    near = np.r_[loop, loop[:1] + 1e-14, ]
    np.testing.assert_array_equal(spinal.tube(np.insert(near, 5, loop[4], axis=0), 0.1, 8,
                                              closed=True).vertices,
                                  spinal.tube(loop, 0.1, 8, closed=True).vertices)


def test_curves_with_nan_or_too_few_distinct_points_are_refused_or_skipped():
    rng = np.random.default_rng(8)
    good = [np.cumsum(rng.normal(size=(m, 3)), axis=0) for m in (6, 9, 5)]
    nan = good[0].copy()
    nan[2, 1] = np.nan
    flat = np.repeat(good[1][:1], 4, axis=0)  # one point four times
    curves = [good[0], nan, good[1], flat, good[2], good[2][:1]]
    with pytest.raises(ValueError, match=r"points: curve 1 \(rows 6 to 11\): non-finite"):
        spinal.tube(curves, 0.1, 8, on_short="skip")
    with pytest.raises(ValueError, match=r"points: curve 3 \(rows 20 to 23\): an open curve "
                                         r"needs at least 2 distinct points, got 1"):
        spinal.tube([good[0], good[1], good[2], flat], 0.1, 8)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        mesh = spinal.tube(curves, 0.1, 8, on_invalid="skip",
                           point_data={"c": np.arange(6.0)})
    skipped = [w.message for w in rec if issubclass(w.category, spinal.SkippedCurvesWarning)]
    assert len(skipped) == 1
    assert "with NaN or inf: 1; with fewer than 2 distinct points: 3, 5" in str(skipped[0])
    np.testing.assert_array_equal(skipped[0].curves, [1, 3, 5])
    np.testing.assert_array_equal(mesh.skipped_curves, [1, 3, 5])
    assert set(mesh.curve_of) == {0, 2, 4}
    np.testing.assert_array_equal(mesh.point_data["c"], mesh.curve_of)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        ref = spinal.tube([good[0], good[1], good[2]], 0.1, 8)
    np.testing.assert_array_equal(mesh.vertices, ref.vertices)
    # one curve alone: an empty mesh and the warning
    with pytest.warns(spinal.SkippedCurvesWarning, match="with NaN or inf: 0"):
        empty = spinal.tube(nan, 0.1, on_invalid="skip")
    assert len(empty.vertices) == 0 and list(empty.skipped_curves) == [0]
    with pytest.raises(ValueError, match="on_invalid: unknown value .drop.; expected one of"):
        spinal.tube(good[0], 0.1, on_invalid="drop")


def test_dipy_bundled_tracts_are_tubed_in_one_call_each():
    """dipy's bundled tracts (when dipy is installed): every streamline tubed, watertight and
    wound outwards, no end tilted more than 45° from its end chord."""
    dipy = pytest.importorskip("dipy")
    nib = pytest.importorskip("nibabel")
    import os

    files = os.path.join(os.path.dirname(dipy.__file__), "data", "files")
    for name in ("tracks300.trk", "EuDX_small_25.trk"):
        path = os.path.join(files, name)
        if not os.path.exists(path):
            pytest.skip(f"{name} not in this dipy")
        lines = [np.asarray(s, dtype=float) for s in nib.streamlines.load(path).streamlines]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", spinal.FoldOverWarning)
            mesh = spinal.tube(lines, 0.1, 8)
        tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
        assert tm.is_watertight and tm.is_winding_consistent and mesh.volume > 0, name
        assert set(mesh.curve_of) == set(range(len(lines)))
        F = spinal.frames(lines)
        start = 0
        for x in lines:
            for row, chord in ((0, x[1] - x[0]), (len(x) - 1, x[-1] - x[-2])):
                t = F[start + row, :, 2]
                assert t @ chord / np.linalg.norm(chord) >= np.cos(np.pi / 4) - 1e-12
            start += len(x)


def test_fold_warning_stays_readable_on_a_long_rough_curve():
    """A tube around a 40,000-step random walk warns about its folds naming the first 20
    ranges of rows and how many more; the warning still carries every row."""
    walk = np.cumsum(np.random.default_rng(7).normal(size=(40_000, 3)), 0)
    with pytest.warns(spinal.FoldOverWarning) as rec:
        spinal.tube(walk, 0.3, 8)
    w = rec[0].message
    assert len(str(w)) < 1000, len(str(w))
    assert re.search(r"… and [\d,]+ more \([\d,]+ rows in all\)", str(w))
    total = int(re.search(r"\(([\d,]+) rows in all\)", str(w)).group(1).replace(",", ""))
    assert total == len(w.indices) > 20
