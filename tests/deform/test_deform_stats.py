"""The statistics of the compiled ``deform_mesh`` cross into Python as a frozen record class
(``spinal._core.DeformStats``): read-only named attributes, ``repr``, ``==`` and pickling."""

import pickle

import numpy as np
import pytest

import spinal
from spinal import _core

OCTAHEDRON = (
    np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]),
    np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
              [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]], dtype=np.int64),
)
NAMES = ["passes", "torn", "over_threshold", "bounded", "time_integrate", "time_refine",
         "slip_vertices", "fallback", "flips", "flip_volume", "collapses", "moves",
         "collapse_volume", "bent", "bend_splits"]


def stats():
    field = spinal.fields.translation([0.5, 0, 0], 0.8, [1, 0, 0])
    options = {"t0": 0.0, "duration": 0.2, "steps": 4, "refine": 1.5, "max_vertices": 200,
               "max_passes": 5}
    return _core.deform_mesh(*OCTAHEDRON, field, options)[4]


def test_stats_are_a_frozen_record():
    s = stats()
    assert type(s) is _core.DeformStats
    assert list(s._asdict()) == NAMES
    assert isinstance(s.bounded, bool) and isinstance(s.passes, int)
    assert isinstance(s.flip_volume, float)
    with pytest.raises(AttributeError):
        s.passes = 3
    assert repr(s).startswith(f"DeformStats(passes={s.passes!r}, torn={s.torn!r}, ")


def test_stats_compare_and_pickle_by_value():
    s = stats()
    back = pickle.loads(pickle.dumps(s))
    assert back == s and back is not s
    assert _core.DeformStats(s._asdict()) == s
    assert _core.DeformStats({**s._asdict(), "passes": s.passes + 1}) != s
    with pytest.raises(KeyError, match="options: missing 'bent'"):
        _core.DeformStats({k: v for k, v in s._asdict().items() if k != "bent"})
