"""Divergence-free velocity fields for volume-preserving deformation.

A field is a small immutable object describing a closed-form velocity field ``v(X, t)`` with
``div v = 0`` exactly; evaluate it with ``field(points, t=0.0) -> (n, 3)``, add fields with
``+`` or :func:`sum`, and move points along it with :func:`spinal.advect`. Everything is
float64 and evaluated in Rust (in parallel) at the points themselves: no grid sampling.

Units: lengths in the mesh's units, time in the caller's units; a velocity is length/time,
an angular speed rad/time (right-handed about the axis), a twist rate rad/(length·time), a
bend rate rad/(length²·time).

**Curl fields** (Zheng's thesis Ch. 12, with the printed fields' sign and scale corrected so
that the tool's surface moves with the tool, see ``src/deform/fields.rs``): ``V = c·curl(φ(d) B)`` with ``d`` the signed distance to a spherical tool,
``φ = (R − |d|)^p`` zero beyond the reach ``R`` (``p = 2`` as in the thesis: the field is C⁰
at ``|d| = R``; ``falloff_power=4`` makes it C²):

* :func:`translation` — ``V = (e^{p−1}/R^p)[e u + (p/2) sgn(d)((n·u)Y − (n·Y)u)]``,
  ``e = R − |d|``: on the tool surface the normal velocity is exactly ``u·n``;
* :func:`rotation` — ``V = (e^{p−1}/(3R^p))[p sgn(d) n × (|Y|²Ω − (Ω·Y)Y) + 3e Ω × Y]``;
* :func:`twist`, :func:`bend` — swirls ``v = h(z, r) a × Y`` about an axis, ``h = κ z W(r)``
  and ``β r² W(r)`` with ``W = (1 − r/R)²`` (or the thesis's curl form).

**Cross-product fields** ``v = ∇p × ∇q`` (von Funck et al. 2006, thesis Ch. 11) with the
region function ``D = b(clamp(d/R_f, 0, 1))``, ``b = 4σ³ − 3σ⁴`` (C¹) or ``σ`` (linear):

* :func:`sphere`, :func:`capsule` (the exact distance-field extension to a free-form tool)
  — ``v = (1 − D)² u + (1 − D)D′[(n·u)Y − (n·Y)u]``, rigid inside the tool;
* :func:`strip` — along the axis (type I) or across it (type II);
* :func:`strip_curve` — type I along a curved axis (the C² spline through samples):
  ``v = s (1 − D)(1 − D − r D′) T``, ``r`` the distance to the axis, ``T`` its tangent at the
  closest point;
* :func:`torus` — a torus moving along its axis;
* :func:`sdf_tool`, :func:`mesh_tool` — a free-form tool given by a sampled signed distance
  (or a closed triangle mesh): the sphere field with the tool's distance ``d``, interpolated
  by a C² tricubic B-spline whose exact gradient gives ``n = ∇d``.

**Curl tools of any shape** (thesis §11.2.5–11.2.6 with the curl fields of Ch. 12): the
translation and rotation above with the signed distance ``d`` of any shape and its exact
gradient ``g = ∇d`` in place of the sphere's, divergence-free for any C¹ ``d`` —
:func:`sdf_curl` (a sampled distance), :func:`mesh_curl` (a closed mesh), :func:`rod` (a tube
about a spline axis, the thesis's strip along a curve — §11.2.2's region about an inner axis —
in curl form; two points give a capsule).

**Keyframed tools** — :func:`keyframed` moves any field rigidly through keys
``(t_k, c_k, Q_k)``: a tool with a shape (the curl tools, and the sphere, capsule, strip,
torus, strip_curve and grid tools by their shapes) as the curl tool of the moving shape; any
other field (twist, bend, along_path, sums) carried whole, ``v = Q v₀(C + Qᵀ(X − c), t)``.

**Tools along a path** — :func:`along_path`: a sphere tool travels along a spine curve at
constant speed, posed by Hermite positions and the interpolated rotation-minimizing frames
of :func:`spinal.frames`; it translates (pushes or carries), and optionally rotates with the
frames, twists or bends the material around it.
"""

from ._core import Field
from ._fields import (  # noqa: F401
    _rebuild,
    along_path,
    bend,
    capsule,
    keyframed,
    mesh_curl,
    mesh_tool,
    rod,
    rotation,
    sdf_curl,
    sdf_tool,
    sphere,
    strip,
    strip_curve,
    sum,
    torus,
    translation,
    twist,
)
from ._public import publish as _publish

__all__ = [
    "Field",
    "along_path",
    "bend",
    "capsule",
    "keyframed",
    "mesh_curl",
    "mesh_tool",
    "rod",
    "rotation",
    "sdf_curl",
    "sdf_tool",
    "sphere",
    "strip",
    "strip_curve",
    "sum",
    "torus",
    "translation",
    "twist",
]

_publish(globals())  # documented, pickled and shown under this module's name
