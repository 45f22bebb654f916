"""Analytic space curves with exact derivatives.

Each curve maps a parameter ``u`` (a float or an array) to points ``(k, 3)``; ``d1``, ``d2``
and ``d3`` are the exact first, second and third derivatives with respect to ``u``. They feed
``spinal.frames(curve, u=..., method="rk4")`` (which needs ``x′`` and ``x″``), give exact
tangents to the other methods, and serve as references in tests:

* :class:`Helix` – ``(a cos u, a sin u, b u)``; constant curvature ``a/(a²+b²)`` and torsion
  ``b/(a²+b²)``; its rotation-minimising frame is known in closed form (:meth:`Helix.rmf`).
* :class:`TorusKnot` – ``((R + r cos qu) cos pu, (R + r cos qu) sin pu, r sin qu)``; the
  default ``p = 2, q = 7, R = 0.6, r = 0.3`` is Example 1 of Wang et al. (ACM TOG 2008).
* :class:`Viviani` – ``a (1 + cos u, sin u, 2 sin(u/2))`` on the sphere of radius ``2a``
  about the origin (a spherical curve: double reflection is exact on it).
* :class:`Polynomial` – ``Σ c_j u^j``; :class:`Bezier` – Bernstein form on ``[0, 1]``.
* :class:`Spline` – a piecewise cubic spine through control points: the C¹ non-uniform
  Catmull–Rom spline or the C² natural/periodic cubic spline at chord-length knots, or the
  clamped/periodic uniform cubic B-spline; exact derivatives, arc length and samples equally
  spaced in arc length (:meth:`Spline.sample_arc_length`).

Lengths are in the units of the coordinates, angles in radians.
"""

from ._curves import (
    Bezier,
    Curve,
    Helix,
    Polynomial,
    Spline,
    TorusKnot,
    Viviani,
)
from ._public import publish as _publish

__all__ = [
    "Bezier",
    "Curve",
    "Helix",
    "Polynomial",
    "Spline",
    "TorusKnot",
    "Viviani",
]

_publish(globals())  # documented, pickled and shown under this module's name
