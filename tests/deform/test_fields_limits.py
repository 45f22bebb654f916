"""Limits of the compiled fields and of advection: speed bounds that overflow, step counts
that no call could finish, Ctrl-C during a long advection, and the package's import graph."""

from __future__ import annotations

import ast
import os
from pathlib import Path

import numpy as np
import pytest
from conftest import late_after_sigint

import spinal
from spinal import fields as fl


def test_an_overflowing_speed_bound_is_refused_at_construction():
    """A finite velocity of 1e200 would make max_speed inf (and the step rule fall back to
    4 steps): the constructor refuses it, naming the argument."""
    with pytest.raises(ValueError, match="^velocity: is too large"):
        fl.translation([0, 0, 1], 0.3, [1e200, 0, 0])
    with pytest.raises(ValueError, match="^angular_speed: is too large"):
        fl.rotation([0, 0, 0], 1e150, [0, 0, 1], 1e200)
    f = fl.translation([0, 0, 1], 0.3, [1e100, 0, 0])  # large but representable
    assert np.isfinite(f.max_speed)
    with pytest.raises(ValueError, match="^steps: the default step rule needs 5.333e101"):
        f.steps(1.0)  # no call could take that many steps: the message says to choose them
    assert f.steps(1e-103) == 4


def test_step_counts_are_bounded():
    """An absurd step count is refused up front, and so is a default step rule that would
    need more than 1e8 steps."""
    x = np.zeros((10, 3))
    f = fl.translation([0, 0, 1.32], 0.3, [0, 0, -1])
    for steps in (2**63, 10**8 + 1, 0):
        with pytest.raises(ValueError, match="^steps"):
            spinal.advect(x, f, 0.3, steps)
    with pytest.raises(ValueError, match="^steps: the default step rule needs"):
        f.steps(1e300)
    with pytest.raises(ValueError, match="^steps"):
        spinal.advect(x, f, 1e300)
    tiny = fl.translation([0, 0, 1], 1e-9, [0, 0, -1])
    with pytest.raises(ValueError, match="^steps"):
        spinal.deform((np.eye(3), np.array([[0, 1, 2]])), tiny, 1.0)


@pytest.mark.slow
def test_ctrl_c_stops_a_long_advection():
    """SIGINT during one long advect call raises KeyboardInterrupt between blocks of steps
    (a block is sized to take about 20 ms): the child's CPU time per pool thread after the
    signal stays below 0.5 s."""
    setup = ("x = np.random.default_rng(0).normal(size=(200_000, 3))\n"
             "f = fl.translation([0, 0, 1.32], 0.3, [0, 0, -1])\n")
    assert late_after_sigint(setup, "spinal.advect(x, f, 0.3, 20_000)", after=1.0) < 0.5


def test_the_package_imports_in_one_direction():
    """No import cycle among spinal's modules (module-level and function-level imports; the
    imports for type checkers only, under ``if TYPE_CHECKING:``, never run and are left out:
    annotations may name a class of a module that imports this one)."""
    pkg = Path(spinal.__file__).parent
    graph = {}
    for path in pkg.glob("*.py"):
        mod = path.stem
        deps = set()
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.If) and ast.unparse(node.test) in (
                    "TYPE_CHECKING", "typing.TYPE_CHECKING"):
                node.body = []  # (the walk below does not see them)
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                if node.module:
                    deps.add(node.module.split(".")[0])
                else:
                    deps.update(a.name for a in node.names)
        graph[mod] = {d for d in deps if (pkg / f"{d}.py").exists() and d != mod}
    state = {}

    def visit(m, stack):
        state[m] = "open"
        for d in graph.get(m, ()):
            if state.get(d) == "open":
                raise AssertionError("import cycle: " + " -> ".join(stack + [m, d]))
            if d not in state:
                visit(d, stack + [m])
        state[m] = "done"

    for m in graph:
        if m not in state and m != "__init__":
            visit(m, [])
    assert os.path.basename(str(pkg)) == "spinal"
