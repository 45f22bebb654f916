"""Limits of the deformation engine: speed bounds that overflow, strip curves of many
samples, a large drag bounded and reported, ``refine`` below one, a tool that swallows the
mesh, unbounded step counts (row ids of the robustness review in the docstrings). The deeper
tests of each behaviour live beside the feature (test_fields_limits, test_strip_limits,
test_deform_refine, test_stamp_limits)."""

import time
import warnings

import numpy as np
import pytest

import spinal
from spinal import fields as fl

trimesh = pytest.importorskip("trimesh")


def _d08_grid():
    g = np.linspace(-1, 1, 41)
    X, Y, Z = np.meshgrid(g, g, g, indexing="ij")
    return np.sqrt(X**2 + Y**2 + Z**2) - 0.4, [-1, -1, -1], 0.05


_D08_BIG = 1e308
_D08_U = [_D08_BIG, 0, 0]
_D08_LINE = np.c_[np.linspace(0, 1, 5), np.zeros(5), np.zeros(5)]

# every constructor taking a speed, velocity or rate, with a finite value whose field's
# speed bound overflows, and the argument its error names
_D08_CASES = {
    "translation": ("velocity", lambda: fl.translation([0, 0, 1], .3, [1e200, 0, 0])),
    "rotation": ("angular_speed", lambda: fl.rotation([0, 0, 0], .3, [0, 0, 1], _D08_BIG)),
    "sphere": ("velocity", lambda: fl.sphere([0, 0, 0], .3, _D08_U)),
    "capsule": ("velocity", lambda: fl.capsule([0, 0, 0], [1, 0, 0], .3, _D08_U)),
    "strip(along)": ("velocity", lambda: fl.strip([0, 0, 0], [1, 0, 0], .3, _D08_U)),
    "strip(across)": ("velocity", lambda: fl.strip([0, 0, 0], [1, 0, 0], .3,
                                                   [0, _D08_BIG, 0], kind="across")),
    "torus": ("speed", lambda: fl.torus([0, 0, 0], [0, 0, 1], 1, .2, _D08_BIG)),
    "strip_curve": ("speed", lambda: fl.strip_curve(_D08_LINE, .1, _D08_BIG)),
    "sdf_tool": ("velocity", lambda: fl.sdf_tool(*_d08_grid(), _D08_U, reach=.3)),
    "mesh_tool": ("velocity", lambda: fl.mesh_tool(trimesh.creation.icosphere(2, radius=.4),
                                                   _D08_U, reach=.3, resolution=32)),
    "sdf_curl": ("velocity", lambda: fl.sdf_curl(*_d08_grid(), velocity=_D08_U, reach=.3)),
    "sdf_curl(angular)": ("angular_velocity", lambda: fl.sdf_curl(
        *_d08_grid(), angular_velocity=_D08_U, reach=.3)),
    "mesh_curl": ("velocity", lambda: fl.mesh_curl(trimesh.creation.icosphere(2, radius=.4),
                                                   velocity=_D08_U, reach=.3, resolution=32)),
    "rod": ("velocity", lambda: fl.rod(_D08_LINE, .1, velocity=_D08_U)),
    "rod(angular)": ("angular_velocity", lambda: fl.rod(_D08_LINE, .1, angular_velocity=_D08_U)),
    "along_path": ("duration", lambda: fl.along_path(_D08_LINE, .1, 1e-308)),
    "keyframed": ("times", lambda: fl.keyframed(fl.translation([0, 0, 0], .3, [0, 0, 0]),
                                                [0, 1e-300], [[0, 0, 0], [1e300, 0, 0]])),
}


@pytest.mark.parametrize("case", sorted(_D08_CASES))
def test_an_overflowing_speed_bound_is_refused_not_stepped_four_times(case):
    # was: max_speed inf, steps(1.0) == 4 (translation; strip_curve and strip(across) too)
    """D08: a speed bound that overflows is refused instead of integrated in four steps."""
    arg, build = _D08_CASES[case]
    with pytest.raises(ValueError, match=f"^{arg}: .*(out of floating-point range|is inf)"):
        build()


def test_twist_bend_and_path_rates_stay_finite():
    """D08: The swirls' bound is ``|rate|·radius^k`` times a constant below 1: a finite rate
    gives a finite bound (no overflow to refuse), and steps() refuses the step count it asks."""
    for f in (fl.twist([0, 0, 0], [0, 0, 1], _D08_BIG, .3), fl.bend([0, 0, 0], [0, 0, 1],
                                                                   _D08_BIG, .3),
              fl.along_path(_D08_LINE, .1, 1.0, kind="twist", rate=_D08_BIG)):
        assert np.isfinite(f.max_speed) and f.max_speed > 1e300
        with pytest.raises(ValueError, match="^steps: the default step rule needs"):
            f.steps(1.0)


def test_strip_curve_builds_2000_samples_quickly():
    # was: about a minute (a per-row Python loop, O(n²)); now O(n) in Rust
    """D13: Strip curve builds 2000 samples quickly."""
    n = 2000
    t = time.process_time()  # CPU time: a loaded machine does not stretch it
    f = fl.strip_curve(np.c_[np.linspace(0, 20, n), np.zeros(n), np.zeros(n)], .1, 1.0)
    assert time.process_time() - t < 5.0  # generous: about 3 ms here
    assert np.isfinite(f.max_speed)


def test_a_large_drag_is_bounded_and_says_so():
    # was: 49,788 vertices added in 20 passes, no warning, nothing in the report
    """D14: a large drag stops at its vertex bound and says so."""
    sphere = trimesh.creation.icosphere(3)
    tool = fl.translation(center=[0, 0, .9], radius=.9, velocity=[.5, 0, 0])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh, report = spinal.deform(sphere, tool, 1.0, max_passes=20)
    # the refinement converges well inside the default bound (8× the input's vertices)
    assert len(mesh.vertices) <= 8 * len(sphere.vertices)
    assert report.converged and report.edges_over_threshold == 0
    assert not any(isinstance(w.message, spinal.RefinementWarning) for w in caught)
    # a bound that stops it is reported and warned about
    bound = len(sphere.vertices) + 100
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh, report = spinal.deform(sphere, tool, 1.0, max_passes=20, max_vertices=bound)
    assert len(mesh.vertices) <= bound and report.max_vertices == bound
    assert not report.converged and report.edges_over_threshold > 0
    assert any(isinstance(w.message, spinal.RefinementWarning) for w in caught)


def test_refine_below_one_is_refused():
    # was: refine=1e-300 doubled the mesh every pass
    """D15: refine below one is refused."""
    with pytest.raises(ValueError, match=r"^refine: must be at least 1 .* got 1e-300"):
        spinal.deform(trimesh.creation.icosphere(2), fl.translation([10, 0, 0], .3, [1, 0, 0]),
                      1.0, refine=1e-300, max_passes=8)


def test_a_tool_that_swallows_the_mesh_is_refused():
    # was: every vertex snapped to the tool, volume x23.8, no warning
    """D18: a tool that swallows the whole mesh is refused."""
    with pytest.raises(ValueError, match="^radius: the tool .* swallows the whole mesh"):
        spinal.stamp(trimesh.creation.icosphere(2), [0, 0, 1.32], [0, 0, 1.1], 10.0)


@pytest.mark.parametrize("steps", [2**63, 2**40])
def test_unbounded_step_counts_are_refused(steps):
    # was: 2**63 steps accepted (never returns)
    """D24: step counts beyond any bound are refused."""
    with pytest.raises(ValueError, match="^steps: "):
        spinal.advect(np.zeros((10, 3)), fl.translation([0, 0, 1.32], .3, [0, 0, -1]), .3, steps)
