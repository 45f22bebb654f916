"""Spatial Pythagorean-hodograph (PH) cubics and their rational rotation-minimising frames.

After Mäurer & Jüttler, *Rational approximation of rotation minimizing frames using
Pythagorean-hodograph cubics* (Journal for Geometry and Graphics 3, 1999, §3; "MJ" below,
with its equation numbers; see docs/references.md), with four corrections to the printed
formulas: the Hermite equation of Table 1 is used with signed ``λ₁, λ₂`` instead of absolute
values, the torsion (18) and the angle (30) carry the sign of ``det[d₁, d₂, d₃]`` (the
printed ``ψ`` is an unsigned angle), the angle is written with ``Ω(0)`` rather than (30)'s
free constant ``Ω₀``, and the sweep formula (42) has ``(1 − W²) b̂ − 2W n̂`` (the printed
``+`` breaks orthonormality).

A cubic Bézier curve ``x(v) = Σ bᵢ Bᵢ³(v)``, ``v ∈ [0, 1]``, is *PH* when its speed
``σ(v) = |x′(v)|`` is a polynomial (here quadratic). Every spatial PH cubic is the integral of
``x′ = A i A*`` for a linear quaternion polynomial ``A(v) = A₀(1 − v) + A₁v``, so
``σ = |A|²``, the arc length is a cubic polynomial, and the Frenet frame ``(t, n, b)`` is
rational. With ``dᵢ = bᵢ − bᵢ₋₁``, ``Lᵢ = |dᵢ|``, ``cθ = d₁·d₂/(L₁L₂)``,
``Δ = det[d₁, d₂, d₃]``::

    σ(v) = 3(c v² − 2b v + L₁),  a = √(L₁L₃ − L₂²cθ²),  b = L₁ − L₂cθ,  c = L₁ − 2L₂cθ + L₃
    κ = 6 L₂ sθ / σ²,            τ = sgn(Δ) 6 √(L₁L₃ − L₂²) / σ²        (κ/τ is constant)

The rotation-minimising frame (RMF) turns the principal normal ``n`` towards the binormal
``b`` by the angle ``Ω`` with ``Ω′ = −τσ``; on a PH cubic it is elementary:
``Ω(v) = Ω(0) + 2k[arctan((cv − b)/a) + arctan(b/a)]``, ``k = −sgn(Δ)√(L₁L₃ − L₂²)/a``.
Replacing ``tan((Ω − φ)/2)`` by a rational quadratic ``W`` (Hermite data at both ends, one
free parameter chosen by least squares) gives a *rational* frame of degree 6 that agrees
with the RMF at the segment ends and deviates from it by ≤ √Î in angle. Sweeping a rational
cross-section with it gives a rational Bézier surface of degree (9, m).

Conventions (as everywhere in spinal): frames are ``(n, 3, 3)`` rotation matrices with
columns ``(r, s, t)``; ``r`` is the reference vector, ``s = t × r``. The Frenet frame is
``(n, b, t)``; the RMF's ``r`` is ``sin Ω b + cos Ω n`` (``Ω`` measured from ``n`` towards
``b``, like :meth:`spinal.curves.Helix.rmf`'s ``angle``). Quaternions are ``(x, y, z, w)``
by default and ``(w, x, y, z)`` with ``scalar_first=True`` (scipy's convention). A spline
of ``m`` cubics is parametrised by ``s ∈ [0, m]``: segment ``⌊s⌋``, local ``v = s − ⌊s⌋``
(each cubic has its own ``v``: the spline is G¹, not C¹).

Functions: :func:`hermite`, :func:`is_ph`, :func:`from_quaternions`, :func:`preimage`,
:func:`invariants`, :func:`evaluate`, :func:`angle_fit`, :func:`fit` and the class
:class:`PHSpline` (frames, rational frames, rational sweep surfaces, meshes).
"""

from ._ph import (
    PHSpline,
    angle_fit,
    evaluate,
    fit,
    from_quaternions,
    hermite,
    invariants,
    is_ph,
    preimage,
)
from ._public import publish as _publish

__all__ = [
    "PHSpline",
    "angle_fit",
    "evaluate",
    "fit",
    "from_quaternions",
    "hermite",
    "invariants",
    "is_ph",
    "preimage",
]

_publish(globals())  # documented, pickled and shown under this module's name
