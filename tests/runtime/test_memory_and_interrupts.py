"""Running out of memory raises ``MemoryError`` instead of aborting the interpreter, Ctrl-C
stops a long call promptly, and ``ph.fit`` bounds ``segments`` (each test's docstring names
its row of the robustness review: D16, D17, D22).

The memory tests run each case in a child process whose address space is limited
(``RLIMIT_AS``) to what it already holds plus a small headroom, with inputs whose outputs
or working buffers need several times that headroom: the child must catch ``MemoryError``
and exit normally (without the checks several of them died of SIGABRT, 'memory allocation
of N bytes failed'). The Ctrl-C tests send SIGINT from a timer thread inside the child and
measure, in the child, the CPU time from the signal to the ``KeyboardInterrupt``.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from typing import NamedTuple

import numpy as np
import pytest
from conftest import late_after_sigint

import spinal
from spinal import ph

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_AS and SIGINT: Linux")
# the subprocess cases (memory limits, Ctrl-C) are marked slow one by one

# address space the child may still map after building its inputs
HEADROOM = 100 << 20

PRELUDE = """
import resource, sys, numpy as np, trimesh, spinal
from spinal import ph, quaternions as Q, fields as fl
spinal.set_num_threads(2)
u = np.linspace(0, 4 * np.pi, 60); H = np.c_[np.cos(u), np.sin(u), .2 * u]
spinal.frames(H); spinal.tube(H, .1, 8)  # the worker pool and its arenas exist
"""

LIMIT = """
def vm_size():
    for line in open('/proc/self/status'):
        if line.startswith('VmSize:'):
            return int(line.split()[1]) * 1024
lim = vm_size() + {headroom}
resource.setrlimit(resource.RLIMIT_AS, (lim, lim))
try:
    {call}
except MemoryError as e:
    print('MemoryError:', e)
    sys.exit(0)
print('no MemoryError')
sys.exit(3)
"""


def run_limited(setup: str, call: str) -> subprocess.CompletedProcess:
    code = PRELUDE + textwrap.dedent(setup) + LIMIT.format(headroom=HEADROOM, call=call)
    return subprocess.run([sys.executable, "-c", code], check=False, capture_output=True,
                          text=True, timeout=300)


# name: (inputs built before the limit, the call, the words of the MemoryError)
D16_CASES = {
    "estimate_tangents": (
        ("n = 10_000_000; s = np.linspace(0, 2000, n)\n"
        "X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"),
        "spinal.estimate_tangents(X)", "estimate_tangents: out of memory"),
    "to_quaternions": (
        "F = np.ascontiguousarray(np.broadcast_to(np.eye(3), (4_000_000, 3, 3)))\n",
        "Q.to_quaternions(F)", "to_quaternions: out of memory"),
    "quaternion_frames": (
        ("n = 4_000_000; s = np.linspace(0, 800, n)\n"
        "X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"),
        "Q.quaternion_frames(X)", "quaternion_frames: out of memory"),
    "walk_mesh": (
        "b = trimesh.creation.box()\n",
        "Q.walk_mesh(b.vertices, b.faces, 0, b.vertices[b.faces[0]].mean(0), [[3e7, .1234]])",
        "walk_mesh: out of memory: moves: a walk of total length 3.000e7"),
    # moves each short enough, together too long: refused before the walk starts
    "walk_mesh many moves": (
        "b = trimesh.creation.box(); M = np.tile([[1e6, .1234]], (30, 1))\n",
        "Q.walk_mesh(b.vertices, b.faces, 0, b.vertices[b.faces[0]].mean(0), M)",
        "walk_mesh: out of memory: moves: a walk of total length 3.000e7"),
    "deform": (
        ("s = np.linspace(0, 400, 300_000); m = spinal.tube(np.c_[np.cos(s), np.sin(s), .2 * s], .01, 8)\n"
         "f = fl.translation([0, 0, 1.6], .5, [0, 0, -.5])\n"),
        "spinal.deform(m, f, 1.0, 2)", "deform: out of memory"),
    # a profile of 2**22 vertices on a two-point spine (the profile's copies and, for the
    # star, the working memory of its self-intersection test and cap triangulation)
    "sweep huge profile": (
        ("m = 2**22; a = np.linspace(0, 2 * np.pi, m, endpoint=False)\n"
         "P = np.c_[np.cos(a), np.sin(a)]; X = np.array([[0, 0, 0], [0, .1, 1.]])\n"),
        "spinal.sweep(X, P)", "sweep: out of memory"),
    "sweep huge star profile": (
        ("m = 2**22; a = np.linspace(0, 2 * np.pi, m, endpoint=False)\n"
         "P = np.c_[np.cos(a), np.sin(a)]; P[::2] *= .9; X = np.array([[0, 0, 0], [0, .1, 1.]])\n"),
        "spinal.sweep(X, P, normals=False, uv=False, dtype='float32')", "sweep: out of memory"),
    "slerp": (
        ("q = np.tile([.1, .2, .3, .9], (5_000_000, 1)); q /= np.linalg.norm(q[0])\n"
         "q1 = q[::-1].copy(); u = np.linspace(0, 1, len(q))\n"),
        "Q.slerp(q, q1, u)", "slerp: out of memory"),
    "walk_mesh_many": (
        ("b = trimesh.creation.box(); w, k = 100_000, 60\n"
        "P = np.repeat(b.vertices[b.faces[0]].mean(0)[None], w, 0)\n"
        "M = np.tile([[.01, .1]], (w, k, 1))\n"),
        "Q.walk_mesh_many(b.vertices, b.faces, np.zeros(w, int), P, M)",
        "walk_mesh_many: out of memory"),
    "stamp": (
        ("s = trimesh.creation.icosphere(2)\n"
        "V = np.vstack([s.vertices, np.random.default_rng(0).normal(size=(6_000_000, 3))])\n"),
        "spinal.stamp((V, s.faces), [0, 0, 1.32], [0, 0, 1.1], .3)", "stamp: out of memory"),
    "SpineBinding": (
        "V = np.random.default_rng(0).normal(size=(5_000_000, 3))\n",
        "spinal.SpineBinding(V, H)", "SpineBinding: out of memory"),
    "flesh": (
        "V = np.random.default_rng(0).normal(size=(5_000_000, 3))\n",
        "spinal.flesh(V, H, H * 1.1)", "flesh: SpineBinding: out of memory"),
    "SurfaceBinding": (
        ("g = np.stack(np.meshgrid(np.linspace(0, 1, 8), np.linspace(0, 1, 9), indexing='ij'), -1)\n"
        "S = np.concatenate([g, np.zeros(g.shape[:2] + (1,))], -1)\n"
        "V = np.random.default_rng(0).uniform(size=(5_000_000, 3))\n"),
        "spinal.SurfaceBinding(V, S)", "SurfaceBinding: out of memory"),
    "ph.hermite": (
        "m = 1_000_000; P0 = np.zeros((m, 3)); P1 = np.ones((m, 3)); T = np.ones((m, 3))\n",
        "ph.hermite(P0, T, P1, T)", "ph.hermite: out of memory"),
    "frames guided": (
        ("n = 10_000_000; s = np.linspace(0, 2000, n)\n"
        "X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"),
        "spinal.frames(X, guide=[0, 0, 1])", "frames: out of memory"),
    # the output fits in the headroom, the Frenet frames' working vectors do not
    "frames frenet": (
        ("n = 1_200_000; s = np.linspace(0, 1000 * np.pi, n, endpoint=False)\n"
        "X = np.c_[np.cos(s), np.sin(s), .3 * np.sin(3 * s)]\n"),
        "spinal.frames(X, method='frenet')", "frames: out of memory"),
    # the frames' copy, the samples and the per-segment rotations of a path tool
    "along_path": (
        ("n = 1_000_000; s = np.linspace(0, 2000, n)\n"
        "X = np.c_[np.cos(s), np.sin(s), .2 * s]; F = spinal.frames(X)\n"),
        "spinal.fields.along_path(X, .1, 1.0, frames=F)", "along_path: out of memory"),
    "Mesh.is_watertight": (
        ("m = 30_000_000; F = np.arange(3 * m, dtype=np.int64).reshape(m, 3) % 1000\n"
        "mesh = spinal.Mesh(np.zeros((1000, 3)), F)\n"),
        "mesh.is_watertight", "mesh edges: out of memory"),
    "mesh_closed_centroid": (
        ("m = 5_000_000; F = np.arange(3 * m, dtype=np.int64).reshape(m, 3) % 1000\n"
        "V = np.random.default_rng(0).normal(size=(1000, 3))\n"),
        "spinal._core.mesh_closed_centroid(V, F)", "closed tool: out of memory"),
    "walk_mesh big mesh": (
        ("m = 5_000_000; F = np.arange(3 * m, dtype=np.int64).reshape(m, 3) % 1000\n"
        "V = np.random.default_rng(0).normal(size=(1000, 3))\n"),
        "Q.walk_mesh(V, F, 0, V[F[0]].mean(0), [[.01, .1]])", "walk_mesh: out of memory"),
    "strip_curve": (
        ("n = 2_000_000; s = np.linspace(0, 2000, n)\n"
        "X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"),
        "spinal.fields.strip_curve(X, .1, 1.0)", "strip_curve/rod axis: out of memory"),
    "SpineBinding at 1e200": (
        "V = np.random.default_rng(0).normal(size=(5_000_000, 3)) * 1e200\n",
        "spinal.SpineBinding(V, H * 1e200)", "SpineBinding: out of memory"),
    "ph.from_quaternions": (
        ("rng = np.random.default_rng(0); A0 = rng.normal(size=(12_000_000, 4))\n"
         "A1 = rng.normal(size=(12_000_000, 4))\n"),
        "ph.from_quaternions(A0, A1)", "ph.from_quaternions: out of memory for an output array"),
    "PHSpline.evaluate": (
        ("sp = ph.fit(spinal.curves.Helix(), segments=8)\n"
        "s = np.linspace(0, 1, 10_000_000)\n"),
        "sp.evaluate(s)", "PHSpline.evaluate: out of memory"),
    "keyframed": (
        ("n = 10_000_000; T = np.arange(n, dtype=float); P = np.c_[T, T, T] * 1e-6\n"
        "tool = spinal.fields.translation([0, 0, 0], .5, [0, 0, 1])\n"),
        "spinal.fields.keyframed(tool, T, P)", "keyframed: out of memory"),
    "spin": (
        "F = np.ascontiguousarray(np.broadcast_to(np.eye(3), (16_000_000, 3, 3)))\n",
        "Q.spin(F, np.eye(3))", "quaternions.spin: out of memory for an output array"),
    "ph.invariants": (
        ("m = 2_000_000; c = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1.]])\n"
        "C = np.ascontiguousarray(np.broadcast_to(c, (m, 4, 3)))\n"),
        "ph.invariants(C)", "ph.invariants: out of memory"),
    # the working data fit in the headroom, the NumPy output arrays do not
    "sweep output": (
        ("m = 1 << 20; a = np.linspace(0, 2 * np.pi, m, endpoint=False)\n"
         "P = np.c_[np.cos(a), np.sin(a)]; X = np.array([[0, 0, 0], [0, 0, 1.]])\n"),
        "spinal.sweep(X, P, caps=False)", "sweep: out of memory for an output array"),
    "PHSpline.rmf output": (
        ("sp = ph.fit(spinal.curves.Helix(), segments=8)\n"
         "s = np.linspace(0, 1, 10_000_000)\n"),
        "sp.rmf(s)", "PHSpline frames: out of memory for an output array"),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(D16_CASES))
def test_out_of_memory_raises_memory_error(name):
    """D16: running out of memory raises MemoryError in the child, which exits normally."""
    setup, call, words = D16_CASES[name]
    r = run_limited(setup, call)
    assert r.returncode == 0, (r.returncode, r.stdout, r.stderr[-3000:])
    # the message starts with the call's name
    assert f"MemoryError: {words}" in r.stdout, r.stdout


@pytest.mark.slow
def test_memory_error_comes_from_the_core_not_an_abort():
    """D16: The review's reproducer: a 3e7-long move asks for a 2.4 GB crossing path; the walk
    grows its path fallibly and says which call ran out."""
    r = run_limited("b = trimesh.creation.box()\n",
                    "Q.walk_mesh(b.vertices, b.faces, 0, b.vertices[b.faces[0]].mean(0), "
                    "[[3e7, .1234]])")
    assert r.returncode == 0 and "walk_mesh: out of memory" in r.stdout, (r.stdout, r.stderr)


@pytest.mark.slow
def test_small_calls_unchanged_under_a_limit():
    """D16: small calls run unchanged under the memory limit."""
    r = run_limited("", "print(spinal.estimate_tangents(H).shape); raise MemoryError('fine')")
    assert r.returncode == 0 and "(60, 3)" in r.stdout, (r.stdout, r.stderr)


def test_fit_segments_is_bounded():
    """D22: ph.fit bounds its segments."""
    with pytest.raises(ValueError, match=r"^segments: must be <= 100000"):
        ph.fit(spinal.curves.Helix(), segments=10**7)
    assert ph.fit(spinal.curves.Helix(), segments=4).segments == 4


# ------------------------------------------------------------------------------ Ctrl-C

D17_CASES = {
    "advect": (
        ("P = np.random.default_rng(0).normal(size=(2_000_000, 3))\n"
        "f = fl.translation([0, 0, 1.32], .3, [0, 0, -1])\n"),
        "spinal.advect(P, f, .3, 200)"),
    "advect_many_steps": (
        "f = fl.translation([0, 0, 1.32], .3, [0, 0, -1])\n",
        "spinal.advect(np.zeros((10, 3)), f, .3, 10**8)"),
    "deform": (
        "s = trimesh.creation.icosphere(6); f = fl.translation([0, 0, 1.6], .5, [0, 0, -.5])\n",
        "spinal.deform(s, f, 1.0, 20000)"),
    # 4,000 poses of a 201-sample spine, ~2 ms each: the stop comes between poses
    "SpineBinding.animate": (
        ("x = np.linspace(0, 4, 201); rest = np.c_[x, 0 * x, 0 * x]\n"
         "V = np.random.default_rng(0).uniform([0, -.3, -.3], [4, .3, .3], (2_000, 3))\n"
         "b = spinal.SpineBinding(V, rest); a = np.linspace(0, 1, 4000)[:, None]\n"
         "P = np.stack([x + 0 * a, .05 * np.sin(3 * x * a), 0 * x + 0 * a], -1)\n"),
        "b.animate(P)"),
    "frames_bundle": (
        ("s = np.linspace(0, 40, 5000); C = np.c_[np.cos(s), np.sin(s), .2 * s]\n"
         "X = np.concatenate([C + i for i in range(2000)])\n"),
        "spinal.frames(X, lengths=[5000] * 2000)"),
    "flesh": (
        ("u = np.linspace(0, 4 * np.pi, 60); H = np.c_[np.cos(u), np.sin(u), .2 * u]\n"
         "V = np.random.default_rng(0).normal(size=(3_000_000, 3))\n"),
        "spinal.flesh(V, H, H * 1.1)"),
    "walk_mesh_many": (
        ("b = trimesh.creation.icosphere(4); w, k = 1000, 2000\n"
         "P = b.vertices[b.faces[:w]].mean(1); M = np.tile([[2.0, .1]], (w, k, 1))\n"),
        "Q.walk_mesh_many(b.vertices, b.faces, np.arange(w), P, M)"),
    "SurfaceBinding": (
        ("g = np.stack(np.meshgrid(np.linspace(0, 1, 40), np.linspace(0, 1, 40),\n"
         "                         indexing='ij'), -1)\n"
         "S = np.concatenate([g, np.zeros(g.shape[:2] + (1,))], -1)\n"
         "V = np.random.default_rng(0).uniform(size=(2_000_000, 3))\n"),
        "spinal.SurfaceBinding(V, S)"),
    "stamp": (
        "s = trimesh.creation.icosphere(5)\n",
        "spinal.stamp(s, [0, 0, 1.32], [0, 0, 0.2], .5, frames=100_000)"),
    "frames_one_curve": (
        ("n = 20_000_000; s = np.linspace(0, 4000, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"),
        "spinal.frames(X)"),
    "estimate_tangents": (
        ("n = 20_000_000; s = np.linspace(0, 4000, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"),
        "spinal.estimate_tangents(X)"),
    "to_quaternions": (
        "F = np.ascontiguousarray(np.broadcast_to(np.eye(3), (20_000_000, 3, 3)))\n",
        "Q.to_quaternions(F)"),
    "from_quaternions": (
        "q = np.tile([.1, .2, .3, .9], (10_000_000, 1))\n",
        "Q.from_quaternions(q)"),
    "Mesh.volume": (
        ("rng = np.random.default_rng(0); V = rng.normal(size=(2_000_000, 3))\n"
         "mesh = spinal.Mesh(V, rng.integers(0, len(V), size=(8_000_000, 3)))\n"),
        "mesh.volume"),
    "Mesh.area": (
        ("rng = np.random.default_rng(0); V = rng.normal(size=(2_000_000, 3))\n"
         "mesh = spinal.Mesh(V, rng.integers(0, len(V), size=(8_000_000, 3)))\n"),
        "mesh.area"),
    "Mesh.edge_stats": (
        ("rng = np.random.default_rng(0); V = rng.normal(size=(1_000_000, 3))\n"
         "mesh = spinal.Mesh(V, rng.integers(0, len(V), size=(3_000_000, 3)))\n"),
        "mesh.edge_stats()"),
    "SurfaceBinding.deform": (
        # binding is far slower than deforming: bind 100,000 vertices and repeat their
        # registration 30 times (the deformation maps each registered vertex on its own)
        ("g = np.stack(np.meshgrid(np.linspace(0, 1, 8), np.linspace(0, 1, 9),\n"
         "                         indexing='ij'), -1)\n"
         "S = np.concatenate([g, np.zeros(g.shape[:2] + (1,))], -1)\n"
         "V = np.random.default_rng(0).uniform(size=(100_000, 3)) * [1, 1, .2]\n"
         "b = spinal.SurfaceBinding(V, S)\n"
         "b._cell, b._coords = np.tile(b._cell, 30), np.tile(b._coords, (30, 1))\n"
         "P = S.copy(); P[..., 2] += .2 * S[..., 0] ** 2\n"),
        "b.deform(P)"),
    "frames_closed": (
        ("n = 3_000_000; s = np.linspace(0, 1000 * np.pi, n, endpoint=False)\n"
         "X = np.c_[np.cos(s), np.sin(s), .3 * np.sin(3 * s)]\n"),
        "spinal.frames(X, closed=True)"),
    "frames_given_tangents": (
        ("n = 3_000_000; s = np.linspace(0, 1000 * np.pi, n, endpoint=False)\n"
         "X = np.c_[np.cos(s), np.sin(s), .3 * np.sin(3 * s)]\n"
         "T = np.c_[-np.sin(s), np.cos(s), .9 * np.cos(3 * s)]\n"),
        "spinal.frames(X, T, closed=True)"),
    "frames_frenet": (
        ("n = 3_000_000; s = np.linspace(0, 1000 * np.pi, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .3 * np.sin(3 * s)]\n"),
        "spinal.frames(X, method='frenet')"),
    "frames_constraints": (
        ("n = 3_000_000; s = np.linspace(0, 1000 * np.pi, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .3 * np.sin(3 * s)]\n"),
        "spinal.frames(X, constraints={n // 2: [0, 0, 1]})"),
    "frames_guide": (
        ("n = 3_000_000; s = np.linspace(0, 1000 * np.pi, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .3 * np.sin(3 * s)]\n"),
        "spinal.frames(X, guide=[0, 0, 1])"),
    "camera_frames": (
        ("n = 3_000_000; s = np.linspace(0, 1000 * np.pi, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .3 * np.sin(3 * s)]\n"),
        "Q.camera_frames(X)"),
    "ph.fit": (
        ("n = 2_000_000; s = np.linspace(0, 200 * np.pi, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .3 * s]\n"),
        "ph.fit(X)"),
    "tube": (
        ("n = 2_000_000; s = np.linspace(0, 1000 * np.pi, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .3 * np.sin(3 * s)]\n"),
        "spinal.tube(X, .01)"),
    # frames given and a three-sided profile without normals or texture coordinates: the
    # set-up (input checks and layout) is a large share of the call
    "sweep_setup": (
        ("n = 2_000_000; s = np.linspace(0, 1000 * np.pi, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .3 * np.sin(3 * s)] * 1e200\n"
         "F = spinal.frames(X)\n"),
        ("spinal.sweep(X, [[1e198, 0], [0, 1e198], [-1e198, 0]], frames=F, normals=False, "
         "uv=False)")),
    "sweep_setup_bundle": (
        ("s = np.linspace(0, 40, 1000); C = np.c_[np.cos(s), np.sin(s), .2 * s]\n"
         "X = np.concatenate([C + i for i in range(2000)])\n"
         "F = spinal.frames(X, lengths=[1000] * 2000)\n"),
        ("spinal.sweep(X, [[.01, 0], [0, .01], [-.01, 0]], frames=F, lengths=[1000] * 2000, "
         "normals=False, uv=False)")),
    "frames_in_time": (
        ("n, T = 240_000, 50; s = np.linspace(0, 100, n); C = np.c_[np.cos(s), np.sin(s), .2 * s]\n"
         "P = np.stack([C * (1 + .01 * k) for k in range(T)])\n"),
        "spinal.frames_in_time(P, previous_twist=False)"),
    "estimate_tangents_offsets": (
        ("n = 20_000_000; s = np.linspace(0, 4000, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"),
        "spinal.estimate_tangents(X, lengths=[1000] * (n // 1000))"),
    # the check, volume and centroid of a closed tool (fields.mesh_tool, fields.mesh_curl),
    # called alone: 32 million faces of a closed tube
    "closed_tool_centroid": (
        ("s = np.linspace(0, 4000, 2_000_000); m = spinal.tube(np.c_[np.cos(s), np.sin(s), .2 * s], .01)\n"
         "V, F = np.asarray(m.vertices), np.asarray(m.faces)\n"),
        "spinal._core.mesh_closed_centroid(V, F)"),
    # the same tube without its first face: the search for the first edge in one face
    "closed_tool_not_watertight": (
        ("s = np.linspace(0, 4000, 2_000_000); m = spinal.tube(np.c_[np.cos(s), np.sin(s), .2 * s], .01)\n"
         "V, F = np.asarray(m.vertices), np.ascontiguousarray(np.asarray(m.faces)[1:])\n"
         "def refused():\n"
         "    try:\n"
         "        spinal._core.mesh_closed_centroid(V, F)\n"
         "    except ValueError:\n"
         "        pass\n"),
        "refused()"),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(D17_CASES))
def test_ctrl_c_within_half_a_second(name):
    """D17: Ctrl-C stops each long call within half a second of CPU time after the signal."""
    setup, call = D17_CASES[name]
    assert late_after_sigint(setup, call) < 0.5


SIGINT_ONCE_CHILD = """
import hashlib, os, signal, subprocess, sys, tempfile, time
import numpy as np, trimesh, spinal
from spinal import fields as fl, quaternions as Q, ph
spinal.set_num_threads(2)
signal.signal(signal.SIGINT, signal.default_int_handler)
{setup}
def run():
    return {call}
def digest(x, h):
    if isinstance(x, np.ndarray):
        h.update(repr((x.dtype, x.shape)).encode()); h.update(np.ascontiguousarray(x).tobytes())
    elif isinstance(x, dict):
        for k in sorted(x):
            h.update(repr(k).encode()); digest(x[k], h)
    elif isinstance(x, (tuple, list)):
        for v in x:
            digest(v, h)
    else:
        h.update(repr(x).encode())
    return h.hexdigest()
start, cpu = time.perf_counter(), time.process_time()
result = run()
full = time.perf_counter() - start  # the call alone: hashing a large result takes seconds
full_cpu = (time.process_time() - cpu) / 2
first = digest(result, hashlib.sha256())
del result
assert full >= {least}, f'the uninterrupted call takes only {{full:.2f}} s'
# the signal comes from a shell started now, as Ctrl-C comes from the terminal: a timer
# thread of this process would need the GIL to send it, and could send it only after a call
# that holds the GIL (or keeps taking it back) has returned. The shell first records this
# process's CPU time (from /proc), so the work done after the signal is measured in CPU
# time, which a machine loaded by other work does not stretch as it stretches wall time.
stat = tempfile.NamedTemporaryFile(delete=False).name
pid = os.getpid()
sender = subprocess.Popen(["sh", "-c", f"sleep {{{after}:.4f}}; cat /proc/{{pid}}/stat > {{stat}}; "
                           f"kill -INT {{pid}}"])
planned = time.perf_counter() + {after}
try:
    run()
except KeyboardInterrupt:
    late_wall = time.perf_counter() - planned
    cpu_now = time.process_time()
else:
    print(f'finished, no KeyboardInterrupt'); sys.exit(3)
sender.wait()
fields = open(stat).read().rsplit(")", 1)[1].split()
os.unlink(stat)
cpu_sent = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
# per thread of the pool (2); the clock ticks' resolution is 1/CLK_TCK s
late = max(0.0, cpu_now - cpu_sent) / 2
# no worker left running: the process stays idle after the interrupt
cpu = time.process_time(); time.sleep(0.3); busy = time.process_time() - cpu
same = digest(run(), hashlib.sha256()) == first
print(f'late={{late:.3f}} full={{full_cpu:.3f}} busy={{busy:.3f}} same={{same}} '
      f'wall_late={{late_wall:.3f}} wall_full={{full:.2f}}')
"""


class Interrupted(NamedTuple):
    late: float  # CPU seconds per pool thread from the signal to the KeyboardInterrupt
    full: float  # CPU seconds per pool thread of the uninterrupted call
    busy: float  # CPU seconds used in 0.3 s of sleep after the interrupt
    same: bool  # whether the run after the interrupt gave the first run's bits
    report: str  # the child's line, for assertion messages


def interrupt_once(setup: str, call: str, after: float | str = 0.3,
                   least: float = 1.5) -> Interrupted:
    """Run `call` once uninterrupted (it must take at least `least` seconds, so the case
    cannot pass by returning before the signal), once with SIGINT `after` seconds in (a
    number, or an expression of the uninterrupted wall time `full`), then again. Times are
    CPU time per thread of the pool, which other load on the machine does not stretch."""
    code = SIGINT_ONCE_CHILD.format(setup=textwrap.dedent(setup), call=call, after=after,
                                    least=least)
    r = subprocess.run([sys.executable, "-c", code], check=False, capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, (r.returncode, r.stdout, r.stderr[-3000:])
    w = dict(kv.split("=") for kv in r.stdout.split())
    return Interrupted(float(w["late"]), float(w["full"]), float(w["busy"]),
                       w["same"] == "True", r.stdout)


# a PH spline of m cubics: the Hermite interpolants of a helix sampled at m + 1 points
PH_CHAIN = ("u = np.linspace(0, 0.4 * {m}, {m} + 1)\n"
            "X = np.c_[np.cos(u), np.sin(u), .3 * u]; T = np.c_[-np.sin(u), np.cos(u), .3 + 0 * u]\n"
            "sp = ph.PHSpline(ph.hermite(X[:-1], T[:-1], X[1:], T[1:]))\n")

# the calls stopped inside one run (each takes 1.5 s or more uninterrupted)
D17_ONCE_CASES = {
    "walk_mesh": (
        "b = trimesh.creation.box(); p = b.vertices[b.faces[0]].mean(0)\n",
        "Q.walk_mesh(b.vertices, b.faces, 0, p, [[7e6, .1234]])"),
    "quaternion_frames": (
        ("n = 24_000_000; s = np.linspace(0, 8000, n)\n"
         "X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"),
        "Q.quaternion_frames(X)"),
    "ph.invariants": (
        ("c = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1.]])\n"
         "C = np.ascontiguousarray(np.broadcast_to(c, (7_000_000, 4, 3)))\n"),
        "ph.invariants(C)"),
    "ph.preimage": (
        ("c = ph.from_quaternions([[.3, -1.2, .7, .4]], [[-.5, .2, 1.1, -.9]])[0]\n"
         "C = np.ascontiguousarray(np.broadcast_to(c, (8_500_000, 4, 3)))\n"),
        "ph.preimage(C)"),
    # the fields' builds, each evaluated at a few points (their bits compared)
    "keyframed": (
        ("T = np.arange(16_000_000.0); P = np.c_[T, T, T] * 1e-6\n"
         "tool = fl.translation([0, 0, 0], .5, [0, 0, 1]); Z = np.linspace(-1, 1, 30).reshape(10, 3)\n"),
        "fl.keyframed(tool, T, P)(Z, 1.0)"),
    "along_path": (
        ("s = np.linspace(0, 3600, 9_000_000); X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"
         "F = spinal.frames(X); Z = X[::900_000] + .05\n"),
        "fl.along_path(X, .1, 1.0, frames=F)(Z, .5)"),
    "strip_curve": (
        ("s = np.linspace(0, 3200, 1_600_000); X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"
         "Z = X[::160_000] + .05\n"),
        "fl.strip_curve(X, .1, 1.0)(Z)"),
    "rod": (
        ("s = np.linspace(0, 3000, 1_000_000); X = np.c_[np.cos(s), np.sin(s), .2 * s]\n"
         "Z = X[::100_000] + .05\n"),
        "fl.rod(X, .1, velocity=[1, 0, 0])(Z)"),
    # a G¹ spline of 150,000 PH cubics through a long helix: its frame set-up carries the
    # reference vector cubic to cubic, then fits each cubic's rational angle (~30 µs each)
    "PHSpline.angle_fit": (
        PH_CHAIN.format(m=150_000),
        "sp.angle_fit()"),
    # a spine of 6M samples: its model (edge checks, curvatures, Hermite pieces) is built
    # before the vertices are registered
    "SpineBinding (spine set-up)": (
        ("n = 6_000_000; rest = np.c_[np.linspace(0, 1, n), np.zeros(n), np.zeros(n)]\n"
         "V = np.random.default_rng(0).normal(size=(10, 3)) * .01\n"),
        "spinal.SpineBinding(V, rest).offset"),
    "PHSpline.rmf (set-up)": (
        PH_CHAIN.format(m=150_000) + "s = np.linspace(0, 150_000, 200_000)\n",
        "sp.rmf(s, exact=True)"),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(D17_ONCE_CASES))
def test_ctrl_c_within_half_a_second_inside_one_call(name):
    """D17: Ctrl-C stops each call within half a second even inside one long core call."""
    r = interrupt_once(*D17_ONCE_CASES[name])
    assert r.late < 0.5, r.report
    assert r.busy < 0.05, r.report  # no worker thread still running
    assert r.same, r.report


# calls that pass a second only on inputs of gigabytes: each is run at a size that takes
# about half a second and signalled a sixth of the way in; a call that did not poll would
# finish the remaining five sixths before raising
D17_FRACTION_CASES = {
    "ph.is_ph": (
        ("c = ph.from_quaternions([[.3, -1.2, .7, .4]], [[-.5, .2, 1.1, -.9]])[0]\n"
         "C = np.ascontiguousarray(np.broadcast_to(c, (8_000_000, 4, 3)))\n"),
        "ph.is_ph(C)"),
    "PHSpline.rmf": (
        ("sp = ph.fit(spinal.curves.Helix(), segments=8); s = np.linspace(0, 1, 16_000_000)\n"),
        "sp.rmf(s)"),
    "slerp": (
        ("q = np.tile([.1, .2, .3, .9], (8_000_000, 1)); q /= np.linalg.norm(q[0])\n"
         "q1 = q[::-1].copy(); u = np.linspace(0, 1, len(q))\n"),
        "Q.slerp(q, q1, u)"),
    # the first ~0.4 s of this sweep check its convex profile of 2**23 vertices (copy,
    # scaling, convexity, arc lengths): signalled there, not only while the rings are written
    "sweep (profile checks)": (
        ("m = 2**23; a = np.linspace(0, 2 * np.pi, m, endpoint=False)\n"
         "P = np.c_[np.cos(a), np.sin(a)]; X = np.array([[0, 0, 0], [0, .1, 1.]])\n"),
        "spinal.sweep(X, P, caps=False, normals=False, uv=False, dtype='float32')"),
    "slerp_frames": (
        "K = Q.from_quaternions(np.random.default_rng(0).normal(size=(1000, 4))); u = np.linspace(0, 999, 8_000_000)\n",
        "Q.slerp_frames(K, u)"),
    "quaternion_length": (
        "q = np.random.default_rng(0).normal(size=(16_000_000, 4))\n",
        "Q.quaternion_length(q)"),
    "make_continuous": (
        "q = np.random.default_rng(0).normal(size=(24_000_000, 4))\n",
        "Q.make_continuous(q)"),
    "spin": (
        ("F = spinal.frames(np.c_[np.cos(np.linspace(0, 900, 9_000_000)), np.sin(np.linspace(0, 900, 9_000_000)), np.linspace(0, 200, 9_000_000)])\n"
         "G = F @ Q.from_quaternions([0, 0, np.sin(.3), np.cos(.3)])\n"),
        "Q.spin(F, G)"),
    "ph.hermite": (
        ("m = 2_000_000; u = np.linspace(0, 0.1 * m, m + 1)\n"
         "X = np.c_[np.cos(u), np.sin(u), .3 * u]; T = np.c_[-np.sin(u), np.cos(u), .3 + 0 * u]\n"
         "P0, T0, P1, T1 = X[:-1].copy(), T[:-1].copy(), X[1:].copy(), T[1:].copy()\n"),
        "ph.hermite(P0, T0, P1, T1)"),
    "ph.from_quaternions": (
        ("rng = np.random.default_rng(0); A0 = rng.normal(size=(12_000_000, 4))\n"
         "A1 = rng.normal(size=(12_000_000, 4))\n"),
        "ph.from_quaternions(A0, A1)"),
    "PHSpline.evaluate": (
        "sp = ph.fit(spinal.curves.Helix(), segments=8); s = np.linspace(0, 8, 32_000_000)\n",
        "sp.evaluate(s)"),
    "Field": (
        ("f = fl.sum([fl.translation([0, 0, z], .3, [0, 0, -1]) for z in np.linspace(-1, 1, 12)])\n"
         "P = np.random.default_rng(0).normal(size=(12_000_000, 3)) * [.2, .2, 1]\n"),
        "f(P, .1)"),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(D17_FRACTION_CASES))
def test_ctrl_c_within_a_fraction_of_a_short_call(name):
    """D17: Ctrl-C stops a short call within a fraction of its duration."""
    r = interrupt_once(*D17_FRACTION_CASES[name], after="full / 6", least=0.3)
    assert r.late < 0.2 * r.full, r.report
    assert r.busy < 0.05, r.report  # no worker thread still running
    assert r.same, r.report


SDF_GRID = ("n = 300; x = np.linspace(-1, 1, n); X, Y, Z = np.meshgrid(x, x, x, indexing='ij')\n"
            "D = np.sqrt(X**2 + Y**2 + Z**2) - .5; del X, Y, Z\n")


@pytest.mark.slow
@pytest.mark.parametrize("tool", ["sdf_tool(D, [-1, -1, -1], 2 / (n - 1), [1, 0, 0]",
                                  "sdf_curl(D, [-1, -1, -1], 2 / (n - 1), velocity=[1, 0, 0]"])
def test_distance_grid_tools_stop_within_half_a_second(tool):
    """D17: A tool from the largest distance grid accepted (300³ nodes): the B-spline coefficients
    and the tool's cell minima are computed in Rust, polling Ctrl-C; what stays in NumPy
    (the default centre and reach) are single operations of well under half a second.
    Signalled halfway through."""
    call = f"fl.{tool}, center=[0, 0, 0], reach=.3)([[0, 0, .6]])"
    r = interrupt_once(SDF_GRID, call, after="full / 2", least=0.5)
    assert r.late < 0.5, r.report
    assert r.busy < 0.05, r.report
    assert r.same, r.report


@pytest.mark.slow
def test_cold_sweep_stops_promptly():
    """D17: The first sweep of a fresh process writes into output pages never touched before
    (each write may fault one in); Ctrl-C in its writing phase (the set-up of these 2000
    curves takes about 0.2 s, the writing seconds) stops it within a quarter second,
    including the caps, which a stopped sweep no longer writes, and the curve ids of the
    faces."""
    setup = ("s = np.linspace(0, 40, 1000); C = np.c_[np.cos(s), np.sin(s), .2 * s]\n"
             "X = np.concatenate([C + i for i in range(2000)])\n"
             "F = spinal.frames(X, lengths=[1000] * 2000)\n")
    assert late_after_sigint(setup, "spinal.tube(X, .01, 8, frames=F, lengths=[1000] * 2000)",
                             after=0.5) < 0.25


def test_threads_setting_keeps_results():
    """D17: The calls stay bit-identical with the signal-watching pool (review: threads
    bit-identical)."""
    u = np.linspace(0, 4 * np.pi, 60)
    h = np.c_[np.cos(u), np.sin(u), 0.2 * u]
    with spinal.threads(1):
        a = spinal.frames(h)
    with spinal.threads(2):
        b = spinal.frames(h)
    np.testing.assert_array_equal(a, b)


@pytest.mark.slow
def test_sweep_of_a_huge_non_convex_profile_stops_in_its_checks():
    """D17: A star profile of 2**22 vertices is not convex: the sweep first tests it for
    self-intersection (a sweep line over its 2**23 edge ends, about 4 s here) and then
    triangulates its caps (about 3 s), each in O(m log m) and each polling Ctrl-C every
    few thousand events; before, neither polled, and a stop waited for both."""
    setup = ("m = 2**22; a = np.linspace(0, 2 * np.pi, m, endpoint=False)\n"
             "r = 1 + .3 * (np.arange(m) % 2); P = np.c_[r * np.cos(a), r * np.sin(a)]\n"
             "X = np.array([[0, 0, 0], [0, .1, 1.]])\n")
    call = "spinal.sweep(X, P, normals=False, uv=False, dtype='float32')"
    for after in (1.0, 3.0, 5.5):
        assert late_after_sigint(setup, call, after=after) < 0.5


@pytest.mark.slow
def test_sweep_of_a_huge_profile_stops_inside_a_ring():
    """D17: A profile of 2**23 vertices on a two-point spine: two rings of 96 MiB of float32
    vertices and 192 MiB of int32 faces. The writer polls Ctrl-C between pieces of at most
    1 MiB of a ring's columns, not only between rings, and builds the profile's columns per
    piece (0.8 GB peak); before, each ring was written whole after the columns and face
    pattern of the whole profile were built (2.6 GB peak), and a stop waited up to seconds.
    Signalled at two moments of the repeated call."""
    setup = ("m = 2**23; a = np.linspace(0, 2 * np.pi, m, endpoint=False)\n"
             "P = np.c_[np.cos(a), np.sin(a)]\n"
             "X = np.array([[0, 0, 0], [0, .1, 1.]])\n")
    call = "spinal.sweep(X, P, caps=False, normals=False, uv=False, dtype='float32')"
    for after in (0.5, 1.0):
        assert late_after_sigint(setup, call, after=after) < 0.5
