"""Messages of the compiled core for inputs the Python layer normally screens out: each
names the argument the user can act on and lists the choices of an option."""

import numpy as np
import pytest

import spinal
from spinal import _core

PTS = np.ascontiguousarray(np.c_[np.arange(4.0), np.zeros(4), np.zeros(4)])
ANALYTIC = {"method": "rotation", "closed": False, "turns": 0}


def sampled(method="double_reflection", rule="five_point", offsets=(0, 4), end_frames=None):
    options = {"method": method, "tangent_rule": rule, "closed": False,
               "end_frames": end_frames, "turns": 0}
    return _core.frames_sampled(PTS, None, np.array(offsets, dtype=np.int64), options)


def test_option_strings_name_the_argument_and_list_the_choices():
    with pytest.raises(ValueError, match=r"^method: unknown method \"dr\"; expected "
                       r"'double_reflection', 'projection', 'rotation', 'frenet', 'rk4', "
                       r"'rk4_phi', 'torsion' or 'bisector'"):
        sampled(method="dr")
    with pytest.raises(ValueError, match=r"^method: unknown tangent estimate \"x\"; expected "
                       r"'five_point', 'five_point_uniform' or 'circle'"):
        _core.estimate_tangents(PTS, False, "x")
    with pytest.raises(ValueError, match=r"^mode: unknown frame \"x\"; expected 'frenet', "
                       r"'exact' or 'rational'"):
        _core.ph_frames(np.random.rand(1, 4, 3), np.zeros(1), "x", None, 0.0, None)
    with pytest.raises(ValueError, match=r"^method: unknown method \"x\"; expected 'rk4', "
                       r"'euler' or 'split'"):
        _core.advect(PTS, spinal.fields.translation([0, 0, 0], 1, [1, 0, 0]), 0.0, 0.1, 1, "x")
    with pytest.raises(ValueError, match=r"^solution: unknown value \"x\"; expected 'none', "
                       r"'normal', 'binormal', 'radial' or 'blend'"):
        _core.flesh_deform(PTS, np.zeros((4, 3, 3)), np.zeros(0, dtype=np.int64),
                           np.zeros((0, 3)), {"solution": "x", "twist": None})
    with pytest.raises(TypeError):
        sampled(method=3)


def test_array_messages_name_the_argument():
    with pytest.raises(ValueError, match="^offsets: must be non-negative$"):
        sampled(offsets=(0, -1))
    frames = np.tile(np.eye(3), (1, 1, 1))[:, :, ::-1]
    with pytest.raises(ValueError, match="^end: array must be C-contiguous$"):
        sampled(end_frames=frames)
    u = np.linspace(0.0, 1.0, 4)
    with pytest.raises(ValueError, match=r"^points\.d1: expected shape \(n, 3\)"):
        _core.frames_analytic(PTS, u, np.zeros((7, 2)), np.zeros((7, 3)), ANALYTIC)
    with pytest.raises(ValueError, match=r"^points\.d2: expected shape \(n, 3\)"):
        _core.frames_analytic(PTS, u, np.zeros((7, 3)), np.zeros((7, 2)), ANALYTIC)


def test_ph_frame_setup_rows_are_34_wide():
    cp = np.array([[[1.0, 0, 0], [1, 0.5858183513, 0.2929091757],
                    [0.5858183513, 1, 0.4924889878], [0, 1, np.pi / 4]]])
    assert _core.ph_frame_setup(cp, None, 0.0, None).shape == (1, 34)
