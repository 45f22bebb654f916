"""Work limits of spinal.fields.strip_curve: the axis checks (curvature, no distant parts
within 2(radius + reach) of each other) run in the Rust core, the second on a uniform grid, so
the cost grows about linearly with the number of samples (it was quadratic: a 2,000-sample
straight axis took about a minute).
"""

from __future__ import annotations

import subprocess
import sys
import time

import numpy as np
import pytest

from spinal import fields

# ---- strip_curve: the axis checks ------------------------------------------------------------


def line(n, length=20.0):
    return np.c_[np.linspace(0, length, n), np.zeros(n), np.zeros(n)]


def test_a_2000_sample_axis_builds_and_flows_along_it():
    f = fields.strip_curve(line(2000), 0.1, 1.0)
    x = np.array([[5.0, 0.05, 0.0], [13.3, 0.0, -0.07], [19.0, 0.0, 0.0]])
    np.testing.assert_allclose(f(x), [[1, 0, 0]] * 3, atol=1e-12)
    assert np.abs(f([[5.0, 0.5, 0.0]])).max() == 0  # beyond radius + reach


CPU_LIMITED_CHILD = """
import resource, time, numpy as np
from spinal import fields
n = 20_000
axis = np.c_[np.linspace(0, 20, n), np.zeros(n), np.zeros(n)]
fields.strip_curve(axis[:100], 0.1, 1.0)  # imports and first-call set-up are not counted
resource.setrlimit(resource.RLIMIT_CPU, ({limit}, {limit}))
t = time.process_time()
fields.strip_curve(axis, 0.1, 1.0)
print(time.process_time() - t)
"""


@pytest.mark.skipif(sys.platform == "win32", reason="RLIMIT_CPU: POSIX")
def test_construction_is_not_quadratic():
    """20,000 samples build within 20 s of CPU time (measured about 0.1 s). The old
    all-pairs check took about a minute for 2,000 samples, so 20,000 would take about 100×
    that (an O(n^1.5) check about 30×). CPU time, not wall-clock time: waiting for a core
    that another process holds is not counted, so load cannot fail a linear construction;
    and the child is killed (SIGXCPU) when it uses up the bound, so a quadratic one fails
    after 20 s instead of running for hours."""
    limit = 20
    r = subprocess.run([sys.executable, "-c", CPU_LIMITED_CHILD.format(limit=limit)],
                       check=False, capture_output=True, text=True, timeout=3600)
    assert r.returncode == 0, (r.returncode, r.stdout, r.stderr[-2000:])
    assert float(r.stdout) < limit


def test_a_finely_sampled_axis_coming_back_is_still_refused():
    th = np.linspace(0, 5.5, 4000)
    axis = np.c_[np.cos(th), np.sin(th), np.zeros_like(th)]
    t = time.process_time()  # CPU time: a loaded machine does not stretch it
    with pytest.raises(ValueError, match=r"^points: the axis comes within 0\.\d+ < "
                       r"2·\(radius \+ reach\) = 0\.8 of itself \(segments 0 and \d+\); the "
                       r"closest point would be ambiguous$"):
        fields.strip_curve(axis, 0.2, 1.0)
    assert time.process_time() - t < 30  # once about 3 minutes
    fields.strip_curve(axis, 0.15, 1.0)  # a narrower tube: the ends are 0.76 > 0.6 apart


def test_a_helix_is_refused_only_when_its_turns_are_within_twice_the_reach():
    """Three turns of pitch 0.5 in 3,000 samples: the turns are 0.5 apart along the axis."""
    u = np.linspace(0, 6 * np.pi, 3000)
    axis = np.c_[np.cos(u), np.sin(u), 0.5 * u / (2 * np.pi)]
    fields.strip_curve(axis, 0.12, 1.0)  # 2 · 0.24 < 0.5
    with pytest.raises(ValueError, match=r"^points: the axis comes within 0\.\d+ < 2·\(radius "
                       r"\+ reach\) = 0\.52 of itself \(segments 0 and \d+\)"):
        fields.strip_curve(axis, 0.13, 1.0)


def test_the_curvature_check_names_points_and_the_worst_segment():
    th = np.r_[np.linspace(0, 1, 10), 1 + np.linspace(0, 1, 6)[1:] ** 2 * 0.8]
    axis = np.c_[np.cos(th), np.sin(th), np.zeros_like(th)] * np.r_[np.ones(10), 1 - 0.6 * (
        np.linspace(0, 1, 6)[1:])][:, None]
    with pytest.raises(ValueError, match=r"^points: the axis bends too sharply in segment "
                       r"(\d+): curvature [\d.]+ × \(radius \+ reach \+ segment length\) = "
                       r"[\d.]+ must stay below 1") as e:
        fields.strip_curve(axis, 0.2, 1.0)
    k = int(str(e.value).split("segment ")[1].split(":")[0])
    assert k >= 9  # the sharp end, not the gentle arc
