"""Measures of spinal.Mesh: area and volume at any scale of the coordinates."""

import numpy as np
import pytest

import spinal

TETRA_F = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]]  # wound outwards


def _helix(n=60):
    t = np.linspace(0.0, 6.0, n)
    return np.c_[np.cos(t), np.sin(t), 0.2 * t]


@pytest.mark.parametrize("scale", [1e-150, 1e-100, 1e-80, 1e-40, 1.0, 1e40, 1e77, 1e80,
                                   1e102, 1e103, 1e150])
def test_area_and_volume_scale_with_the_coordinates(scale):
    """T3-01: the area of the corner tetrahedron scaled by s is (3 + √3)/2 · s² and its
    volume s³/6 wherever those are representable (the plain sums were NaN from 1e77 (area)
    and 1e103 (volume) and 0 below 1e-80); beyond the range of float64 they are ±inf or 0,
    never NaN."""
    V = np.eye(4)[:, :3] * scale
    m = spinal.Mesh(V, TETRA_F)
    area = (3 + np.sqrt(3)) / 2 * scale * scale  # nan-free: numpy's scalar product
    with np.errstate(over="ignore", under="ignore"):
        volume = np.float64(scale) * scale * (scale / 6)
    assert not np.isnan(m.area) and not np.isnan(m.volume)
    if np.isfinite(area) and area > 1e-300:
        assert m.area == pytest.approx(area, rel=1e-14)
    if np.isfinite(volume) and volume > 1e-300:
        assert m.volume == pytest.approx(volume, rel=1e-14)
    elif volume == np.inf:
        assert m.volume == np.inf


def test_power_of_two_scaling_changes_no_bit():
    """T3-01: the measures are taken on coordinates scaled by a power of two, which is exact:
    a mesh scaled by 2**k has the area × 4**k and volume × 8**k bit for bit."""
    m = spinal.tube(_helix(), 0.1)
    for k in (-300, -40, -1, 3, 60, 300):
        w = spinal.Mesh(np.ldexp(m.vertices, k), m.faces)
        assert w.area == np.ldexp(m.area, 2 * k)
        assert w.volume == np.ldexp(m.volume, 3 * k)


def test_sweeps_far_from_unit_scale_have_finite_measures():
    """T3-01: a tube around a helix scaled by 1e100 (radius 1e99) has area and volume
    100²⁰⁰ and 100³⁰⁰ times those of the unit one; it used to report area NaN."""
    unit = spinal.tube(_helix(), 0.1)
    big = spinal.tube(_helix() * 1e100, 1e99)
    small = spinal.tube(_helix() * 1e-100, 1e-101)
    assert big.area == pytest.approx(unit.area * 1e200, rel=1e-12)
    assert big.volume == pytest.approx(unit.volume * 1e300, rel=1e-12)
    assert small.area == pytest.approx(unit.area * 1e-200, rel=1e-12)
    assert small.volume / 1e-300 == pytest.approx(unit.volume, rel=1e-12)
