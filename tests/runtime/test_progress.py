"""``progress=`` on the long calls: reports between blocks, the same results bit for bit,
errors numbered as without it, a bar or a plain line, Ctrl-C between the blocks."""

import pickle
import warnings

import numpy as np
import pytest

import spinal
from spinal import _fields_grid, fields


def walks(count=1200, seed=3):
    rng = np.random.default_rng(seed)
    return [np.cumsum(rng.normal(size=(int(k), 3)), 0) for k in rng.integers(3, 40, count)]


class Calls(list):
    def __call__(self, done, total):
        self.append((done, total))


def assert_reports(calls, total, at_least=1):
    """Reports rise to ``total``, where they end."""
    done = [d for d, _ in calls]
    assert len(calls) >= at_least
    assert all(t == total for _, t in calls)
    assert done == sorted(done) and done[-1] == total and done[0] > 0


def assert_same_mesh(a, b):
    for k in ("vertices", "faces", "normals", "uv", "sample_of", "curve_of", "fold_over",
              "skipped_curves"):
        x, y = getattr(a, k), getattr(b, k)
        assert x.dtype == y.dtype and x.shape == y.shape and np.array_equal(x, y), k
    assert a.point_data.keys() == b.point_data.keys()
    for k in a.point_data:
        assert np.array_equal(a.point_data[k], b.point_data[k]), k
    assert np.array_equal(a.cell_data["curve_id"], b.cell_data["curve_id"])


def test_tube_of_a_bundle_with_progress_is_the_one_call():
    w = walks()
    # a repeated point (merged), a NaN curve and a one-point curve (skipped), per-row radius,
    # per-point colours, round joins at the walks' corners
    w[5] = np.insert(w[5], 2, w[5][2], axis=0)
    w[700] = w[700].copy()
    w[700][1] = np.nan
    w[900] = w[900][:1]
    rows = sum(len(p) for p in w)
    radius = 0.05 + 0.01 * np.sin(np.arange(rows))
    colors = np.random.default_rng(0).integers(0, 255, (rows, 3)).astype(np.uint8)
    kw = {"point_data": {"colors": colors}, "on_invalid": "skip", "on_short": "skip"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for dtype in (np.float64, np.float32):
            one = spinal.tube(w, radius, 8, dtype=dtype, **kw)
            calls = Calls()
            blocks = spinal.tube(w, radius, 8, dtype=dtype, progress=calls, **kw)
            assert_same_mesh(one, blocks)
            # the rows swept: not the skipped curves, nor the repeated row
            assert_reports(calls, rows - len(w[700]) - 1 - 1)


def test_sweep_of_a_bundle_with_progress_is_the_one_call():
    w = walks(600, seed=5)
    square = [[1, 1], [-1, 1], [-1, -1], [1, -1]]
    rows = sum(len(p) for p in w)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        one = spinal.sweep(w, np.multiply(square, 0.05), twist=np.arange(rows) * 0.01,
                           tangent_rule="circle")
        calls = Calls()
        blocks = spinal.sweep(w, np.multiply(square, 0.05), twist=np.arange(rows) * 0.01,
                              tangent_rule="circle", progress=calls)
    assert_same_mesh(one, blocks)
    assert_reports(calls, rows)


def test_a_refused_curve_is_named_as_without_progress():
    w = walks()
    w[1100] = w[1100].copy()
    w[1100][4] = np.inf
    for call in (lambda **k: spinal.tube(w, 0.1, 6, **k),
                 lambda **k: spinal.frames(w, **k)):
        messages = []
        for kw in ({}, {"progress": Calls()}):
            with pytest.raises(ValueError) as e:
                call(**kw)
            messages.append(str(e.value))
        assert messages[0] == messages[1]
        assert "curve 1100" in messages[0] and "row 4" in messages[0]


def test_frames_of_a_bundle_with_progress_are_the_one_call():
    w = walks(1500, seed=7)
    rows = sum(len(p) for p in w)
    rng = np.random.default_rng(1)
    initial = rng.normal(size=(len(w), 3))
    guide = rng.normal(size=(rows, 3))
    for kw in ({}, {"initial": initial, "method": "rotation"},
               {"guide": guide, "guide_weight": 10.0}, {"closed": True, "turns": 1}):
        one = spinal.frames(w, **kw)
        calls = Calls()
        blocks = spinal.frames(w, progress=calls, **kw)
        assert np.array_equal(one, blocks), kw
        assert_reports(calls, rows)
    # one short curve: reported once, at the end
    calls = Calls()
    F = spinal.frames(w[0], progress=calls)
    assert np.array_equal(F, spinal.frames(w[0])) and calls == [(len(w[0]), len(w[0]))]


def test_frames_in_time_report_every_step_with_the_same_frames():
    rng = np.random.default_rng(2)
    base = np.c_[np.cos(np.linspace(0, 6, 400)), np.sin(np.linspace(0, 6, 400)),
                 np.linspace(0, 3, 400)]
    pts = base + np.cumsum(rng.normal(scale=0.003, size=(30, 400, 3)), 0)
    for kw in ({}, {"previous_twist": False}):
        one = spinal.frames_in_time(pts, **kw)
        calls = Calls()
        steps = spinal.frames_in_time(pts, progress=calls, **kw)
        assert np.array_equal(one, steps), kw
        assert_reports(calls, 30, 30 if not kw else 1)


def test_stamp_reports_every_frame():
    import trimesh

    s = trimesh.creation.icosphere(3)
    calls = Calls()
    kw = {"frames": 6, "reach": 0.8}
    a, ra = spinal.stamp(s, [0, 0, 1.5], [0, 0, 0.8], 0.4, **kw)
    b, rb = spinal.stamp(s, [0, 0, 1.5], [0, 0, 0.8], 0.4, progress=calls, **kw)
    assert np.array_equal(a.vertices, b.vertices) and ra.volume == rb.volume
    assert calls == [(k, 6) for k in range(1, 7)]


def test_mesh_tool_samples_in_slabs_with_the_same_field(monkeypatch):
    pytest.importorskip("igl")
    import trimesh

    box = trimesh.creation.box((1.0, 0.6, 0.4))
    x = np.random.default_rng(4).uniform(-1, 1, (200, 3))
    one = fields.mesh_tool(box, [0, 0, 1], resolution=24)
    monkeypatch.setattr(_fields_grid, "SLAB_NODES", 1000)  # a few planes per slab
    monkeypatch.setattr(_fields_grid, "SLAB_PER_FACE", 0)
    calls = Calls()
    slabs = fields.mesh_tool(box, [0, 0, 1], resolution=24, progress=calls)
    assert np.array_equal(one(x), slabs(x))
    nodes = calls[-1][1]
    assert_reports(calls, nodes, 10)
    # the field pickles without its progress callback (it is not part of the field)
    assert np.array_equal(pickle.loads(pickle.dumps(slabs))(x), one(x))
    curl = fields.mesh_curl(box, velocity=[0, 0, 1], resolution=24, progress=Calls())
    assert np.array_equal(curl(x), fields.mesh_curl(box, velocity=[0, 0, 1],
                                                    resolution=24)(x))


def test_an_error_in_the_callback_stops_the_call():
    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop

    import trimesh

    with pytest.raises(Stop):
        spinal.stamp(trimesh.creation.icosphere(2), [0, 0, 1.5], [0, 0, 0.8], 0.4,
                     frames=4, reach=0.8, progress=stop)
    with pytest.raises(Stop):
        spinal.tube(walks(20), 0.1, 6, progress=stop)
    with pytest.raises(Stop):
        spinal.frames_in_time(np.zeros((3, 1, 3)) + np.c_[np.arange(5.0), np.zeros((5, 2))]
                              [None], progress=stop)


@pytest.mark.parametrize("call", [
    lambda p: spinal.tube(np.eye(3), 0.1, progress=p),
    lambda p: spinal.sweep(np.eye(3), [[0, 0], [1, 0], [0, 1]], progress=p),
    lambda p: spinal.frames(np.eye(3), progress=p),
    lambda p: spinal.frames_in_time(np.eye(3)[None], progress=p),
    lambda p: spinal.stamp((np.eye(3), [[0, 1, 2]]), [0, 0, 0], [1, 1, 1], 1.0, progress=p),
    lambda p: fields.mesh_tool((np.eye(3), [[0, 1, 2]]), [0, 0, 1], progress=p),
])
def test_progress_other_than_a_bool_or_a_callable_is_refused(call):
    with pytest.raises(TypeError, match="^progress: expected a bool or a callable, got str"):
        call("yes")


def test_progress_true_off_a_terminal_writes_a_line_at_every_tenth(capsys):
    w = walks(800)
    rows = sum(len(p) for p in w)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        spinal.tube(w, 0.05, 6, progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert 1 <= len(lines) <= 11
    assert all(line.startswith("tube: ") and line.endswith(" rows") for line in lines)
    assert lines[-1] == f"tube: {rows:,}/{rows:,} rows"


def test_reports_come_while_a_long_sweep_runs():
    """The calling thread reports the count while the work runs (about every 20 ms): a call
    that lasts several intervals reports more than its end, with the same mesh."""
    import time

    rng = np.random.default_rng(8)
    w = [np.cumsum(rng.normal(size=(200, 3)) + [1.0, 0, 0], 0) for _ in range(1500)]
    calls = Calls()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        m = spinal.tube(w, 0.05, 8, dtype=np.float32, progress=calls)
        took = time.perf_counter() - t0
        assert_same_mesh(m, spinal.tube(w, 0.05, 8, dtype=np.float32))
    assert_reports(calls, 300_000)
    if took > 0.2:  # ten intervals at least
        assert len(calls) >= 2 and calls[0][0] < 300_000
    F = spinal.frames(np.concatenate(w), lengths=[200] * 1500, progress=calls)
    assert calls[-1] == (300_000, 300_000) and np.isfinite(F).all()


def test_frames_in_time_without_previous_twist_reports_steps_with_the_same_frames():
    rng = np.random.default_rng(5)
    u = np.linspace(0, 6, 300)
    base = np.c_[np.cos(u), np.sin(u), 0.3 * u]
    pts = base + np.cumsum(rng.normal(scale=0.002, size=(40, 300, 3)), 0)
    for kw in ({}, {"initial": [0.3, -1, 0.7]}, {"closed": True}):
        one = spinal.frames_in_time(pts, previous_twist=False, **kw)
        calls = Calls()
        got = spinal.frames_in_time(pts, previous_twist=False, progress=calls, **kw)
        assert np.array_equal(one, got), kw
        assert_reports(calls, 40)

    def fails(done, total):
        raise ValueError("stop here")

    with pytest.raises(ValueError, match="stop here"):
        spinal.frames_in_time(pts, previous_twist=False, progress=fails)


def test_a_numpy_bool_is_a_bool():
    assert spinal.frames(np.eye(3), progress=np.True_).shape == (3, 3, 3)
    assert spinal.tube(np.eye(3), 0.1, progress=np.False_).is_watertight
