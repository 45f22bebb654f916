"""A bound shape moving along its spine: sliding by arc length and animation over poses
(Zhuo 2014 §5.2.2, Fig. 2; the implementation of ``SpineBinding.deform(slide=)`` and
``SpineBinding.animate``).

**Sliding.** The shape's sections are carried to the posed spine by a compass walk from its
first point (see :meth:`spinal.SpineBinding.deform`). Sliding by ``Δs`` starts the walk at
the point at arc length ``Δs`` along the posed polyline instead (past either end, on the
straight extension of the end edge; round a loop, modulo its length): every section moves
``Δs`` along the spine, unbent at its rest place and bent at the new one, so the map keeps
the volume exactly as a bend does (the speed ratio is taken at the corresponding
parameters, as without sliding). On a straight spine it is the translation by ``Δs`` along
it; on a circular arc, the rotation about the arc's centre by ``Δs/ρ``.

**Animation.** The posed spines of consecutive poses get frames that follow each other:
the first pose's frames are those of :meth:`deform`, every later pose's the frames of
:func:`spinal.frames` with ``previous=`` the pose before and ``previous_twist=True``, so
each section turns between poses by about as much as its tangent does (Hanson & Ma's
parallel transport carried in time, as :func:`spinal.frames_in_time` does).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ._mesh import FoldOverWarning
from ._progress import Progress, checked
from ._validate import as_finite

if TYPE_CHECKING:
    from ._flesh import SpineBinding


def _arc(points: np.ndarray) -> np.ndarray:
    d = np.diff(points, axis=0)
    return np.concatenate([[0.0], np.cumsum(np.hypot(np.hypot(d[:, 0], d[:, 1]), d[:, 2]))])


def _point_at(points: np.ndarray, s: np.ndarray, arc: np.ndarray) -> np.ndarray:
    """Points at arc lengths ``s`` along the open polyline (its end edges extended)."""
    k = np.clip(np.searchsorted(arc, s, side="right") - 1, 0, len(points) - 2)
    u = (s - arc[k]) / (arc[k + 1] - arc[k])
    out: np.ndarray = points[k] + u[:, None] * (points[k + 1] - points[k])
    return out


def slid(posed: np.ndarray, ds: float, closed: bool
         ) -> tuple[np.ndarray, Callable[[np.ndarray], np.ndarray]]:
    """The polyline whose compass walk is that of ``posed`` slid by ``ds``: it starts at the
    point at arc length ``ds`` (rows after it follow; a loop wraps round), and a map of
    positions on it (arc lengths) back to arc lengths on ``posed``."""
    arc = _arc(np.concatenate([posed, posed[:1]]) if closed else posed)
    total = arc[-1]
    if closed:
        s0 = ds % total
        ring = np.concatenate([posed, posed[:1]])
        x = _point_at(ring, np.array([s0]), arc)
        after = np.flatnonzero(arc[:-1] > s0)
        before = np.flatnonzero(arc[:-1] < s0)
        keep = ring[np.concatenate([after, before])]
        return np.concatenate([x, keep]), (lambda s: (s + s0) % total)
    x = _point_at(posed, np.array([ds]), arc)
    keep = posed[arc > ds]
    if len(keep) == 0:  # past the end: the walk goes on along the last edge
        d = posed[-1] - posed[-2]
        keep = x + d[None] / np.linalg.norm(d)
    return np.concatenate([x, keep]), (lambda s: s + ds)


def as_slide(slide: object) -> float:
    """``slide`` as a finite float (``ValueError``/``TypeError`` naming it)."""
    return as_finite(slide, "slide")


def positions(at_q: np.ndarray, q: np.ndarray, back: Callable[[np.ndarray], np.ndarray],
              posed: np.ndarray, closed: bool) -> np.ndarray:
    """Positions ``k + u`` on the slid polyline ``q`` as positions on ``posed`` (clamped to
    its rows, for blending the caller's per-row frames)."""
    ring_q = np.concatenate([q, q[:1]]) if closed else q
    arc_q = _arc(ring_q)
    k = np.clip(np.floor(at_q).astype(np.int64), 0, len(ring_q) - 2)
    s = arc_q[k] + (at_q - k) * (arc_q[k + 1] - arc_q[k])
    s = back(s)
    ring = np.concatenate([posed, posed[:1]]) if closed else posed
    arc = _arc(ring)
    s = np.clip(s, 0.0, arc[-1])
    j = np.clip(np.searchsorted(arc, s, side="right") - 1, 0, len(ring) - 2)
    out: np.ndarray = j + (s - arc[j]) / (arc[j + 1] - arc[j])
    return out


def animate(binding: SpineBinding, posed_spines_t: ArrayLike, solution: str,
            stretchable: bool, twist: float | ArrayLike | None, slide: ArrayLike, previous_weight: object,
            progress: object, blend: float | None = None) -> np.ndarray:
    """:meth:`spinal.SpineBinding.animate` (see there)."""
    from ._frames import frames
    from ._validate import as_float_array, as_real

    report = checked(progress)
    weight = as_real(previous_weight, "previous_weight")
    if not 0.0 < weight < np.inf:
        raise ValueError(f"previous_weight: must be a positive finite number, got {weight}")
    P = as_float_array(posed_spines_t, "posed_spines_t")
    if P.ndim != 3 or P.shape[0] < 1:
        raise ValueError(f"posed_spines_t: expected shape (T, m, {binding._dim}) — one posed "
                         f"spine per pose —, got {P.shape}")
    steps = P.shape[0]
    if np.ndim(slide) == 0:
        sl = np.full(steps, as_slide(slide))
    else:
        sl = as_float_array(slide, "slide")
        if sl.shape != (steps,):
            raise ValueError(f"slide: expected a number or one per pose ({steps}), got shape "
                             f"{sl.shape}")
        bad = np.flatnonzero(~np.isfinite(sl))
        if bad.size:
            raise ValueError(f"slide: the slide of pose {bad[0]} is not finite ({sl[bad[0]]})")
    out = np.empty((steps, len(binding), binding._dim))
    prev = None
    clamped: list[tuple[int, np.ndarray]] = []
    with Progress(report, steps, "animate", "pose") as bar:
        for t in range(steps):
            try:
                posed, _, _ = binding._posed(P[t], stretchable, float(sl[t]))
            except ValueError as e:
                raise ValueError(f"posed_spines_t: pose {t}: {str(e).split(': ', 1)[-1]}") \
                    from None
            if binding._dim == 2 or prev is None:
                fr = None
            else:
                fr = frames(posed, previous=prev, previous_twist=True,
                            guide_weight=weight, closed=binding._closed)
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                out[t], prev = binding._apply(posed, fr, solution, twist, False, level=5,
                                              blend=blend)
            for w in caught:
                if isinstance(w.message, FoldOverWarning):
                    clamped.append((t, w.message.indices))
                else:
                    warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            bar.update(t + 1)
    if clamped:
        # one warning for the call, not one per pose
        worst_t, worst = max(clamped, key=lambda c: (len(c[1]), -c[0]))
        first_t, first = clamped[0]
        every = np.unique(np.concatenate([c for _, c in clamped])).astype(np.int64)
        warnings.warn(FoldOverWarning(
            f"posed_spines_t: {every.size} vertices have no fold-free offset (bent past the "
            f"existence limit) in {len(clamped)} of {steps} poses and were clamped, e.g. "
            f"vertex {first[0]} in pose {first_t}; most in pose {worst_t} ({worst.size} "
            f"vertices)", every), stacklevel=3)
    return out
