"""Frames of a curve moving in time (:func:`spinal.frames_in_time`)."""


from __future__ import annotations

from typing import Any, Literal

import numpy as np

from . import _core
from ._frames import frames
from ._frames_args import (
    METHODS,
    REFLECTIONS,
    _guide_options,
    _orientation,
    _previous_weight,
    _shape,
    _time_steps,
)
from ._progress import Progress, Reported, checked
from ._steer import previous_frames
from ._types import (
    Array,
    Float64Array,
    FrameMethod,
    Ints,
    ProgressArg,
    Reflection,
)
from ._validate import (
    as_bool,
    as_choice,
    as_float_array,
    as_turns,
)

__all__ = ["frames_in_time"]


def frames_in_time(
    points_t: Array | None,
    tangents_t: Array | None = None,
    *,
    method: FrameMethod = "double_reflection",
    initial: Array | None = None,
    closed: bool = False,
    turns: float = 0,
    reflection: Reflection = "chord",
    previous: Array | None = None,
    previous_twist: bool = True,
    previous_weight: float | None = None,
    guide: Array | None = None,
    guide_weight: float = 1.0,
    guide_tolerance: float = 1e-3,
    guide_sign: Literal["follow", "free"] = "follow",
    lengths: Ints | None = None,
    offsets: Ints | None = None,
    progress: ProgressArg = False,
) -> Float64Array:
    r"""Frames of a curve moving in time that do not flicker: ``(T, n, 3, 3)``.

    ``points_t`` holds ``T`` time steps of the same curve (or bundle, with ``lengths`` /
    ``offsets``), ``(T, n, 3)`` (same sample count at every step). The first step gets its
    rotation-minimising frame (from ``initial``, or turned closest to ``previous``); then:

    * ``previous_twist=True`` (default): every step follows the frames of the step before
      sample by sample: they are :func:`frames` with ``previous=`` the step before and
      ``previous_twist=True``, i.e. the guide ``previous[:, :, 0]`` (the previous ``r``
      columns projected on the new normal planes) with the weight ``previous_weight``, so
      each sample's frame turns between steps by about as much as its tangent does, however
      the curve's own twist changes (an MD trajectory of a protein backbone, a swimming
      tail). With the default weight 1000 the frame of a sample is the one closest to its
      previous frame up to a smoothing bias of about ``φ″/1000`` (see ``guide_weight`` of
      :func:`frames`). The steps are computed in order.
    * ``previous_twist=False``: every step gets its rotation-minimising frame (computed in
      parallel over ``T``), turned about the tangents by the one angle ``c`` that brings it
      closest to the frames of the step before: ``c`` minimises ``Σ_i ‖R_t(c) U_i − P_i‖²``
      (Frobenius; every sample counts the same), in closed form
      ``c = atan2(Σ s·P_r − r·P_s, Σ r·P_r + s·P_s)``. All RMFs of a curve differ only by such
      a constant turn (Zheng 2008, Cor. 4.1.3), so the frames stay rotation minimising along
      the curve and change in time only as much as the RMF does (Ma 1996, §3.5.3, aligns the
      frames of similar curves by one rotation); where the curve's total torsion changes
      between steps, frames far from the middle turn by that much more than their tangents.
      Equivalent to calling :func:`frames` with ``previous=`` step by step.
    * ``guide`` given: every step follows its guide (``(3,)``, ``(n, 3)`` for all steps or
      ``(T, n, 3)`` one per step; ``guide_weight``, ``guide_tolerance``, ``guide_sign`` as in
      :func:`frames`) and, from the second step on (or from the first with ``previous``),
      the frames of the step before: they are :func:`frames` with ``guide=`` and
      ``previous=`` the step before, the guide and the previous ``r`` columns two targets of
      one twist solve weighted by ``guide_weight`` and ``previous_weight`` (by default the
      same weight, so a guide that jitters in time moves the frames about half as much);
      ``previous_twist`` does not apply then. With ``guide_sign="free"`` (axes, such as raw
      carbonyl bonds) each step's rows take the sign that agrees with the step before and
      the signed guide is followed alone, so the frames do not flip between steps.

    Parameters
    ----------
    points_t : array_like (T, n, 3)
        The curve (bundle) at ``T`` time steps.
    tangents_t : array_like (T, n, 3), optional
        Tangents at every step (else estimated as in :func:`frames`).
    method, closed, turns, reflection, lengths, offsets
        As in :func:`frames` (a closed curve keeps its closing twist at every step).
    initial : array_like (3,) or (3, 3), optional
        The start of the first step (as in :func:`frames`); not with ``previous``.
    previous : array_like (n, 3, 3), optional
        Frames of the step before the first one (to continue a sequence).
    previous_twist : bool
        Follow the previous step sample by sample (default) or by one turn per step.
    previous_weight : float, optional
        The weight of the previous step's ``r`` against the twist rate, per sample (> 0).
        Default: 1000 with ``previous_twist`` and no guide, ``guide_weight`` with a guide.
    guide, guide_weight, guide_tolerance, guide_sign
        A guide followed at every step (see above and :func:`frames`).
    progress : bool or callable
        Report the time steps done: ``True`` shows a bar (tqdm when installed, in a
        terminal or a notebook) or a line on stderr at every tenth; a callable is called as
        ``progress(steps_done, T)``. The same frames, bit for bit.

    Returns
    -------
    ndarray (T, n, 3, 3) float64

    Raises
    ------
    ValueError
        As :func:`frames` (the message names the time step), a ``previous`` of another shape
        than ``(n, 3, 3)`` or not made of rotations, a ``guide`` of another shape.
    """
    previous_twist = as_bool(previous_twist, "previous_twist")
    guide_weight, guide_tolerance = _guide_options(guide_weight, guide_tolerance)
    guide_sign = as_choice(guide_sign, "guide_sign", ("follow", "free"))
    progress = checked(progress)
    chained = previous_twist or guide is not None or lengths is not None or offsets is not None
    if chained:
        return _frames_in_time_chained(points_t, tangents_t, method, initial, closed, turns,
                                       reflection, previous, previous_twist, previous_weight,
                                       guide, guide_weight, guide_tolerance, guide_sign,
                                       lengths, offsets, progress)
    method = as_choice(method, "method", METHODS)
    reflection = as_choice(reflection, "reflection", REFLECTIONS)
    closed = as_bool(closed, "closed")
    turns = as_turns(turns, "turns")
    p, tg, steps, n = _time_steps(points_t, tangents_t)
    iv, if_ = _orientation(initial, "initial", 1, False)
    prev = previous_frames(previous, n, "the frames of the step before")

    def flat(a: np.ndarray | None) -> np.ndarray | None:
        return None if a is None else np.ascontiguousarray(a.reshape(-1, 3))

    try:
        with Reported(progress, "frames_in_time", "step") as report:
            options = _shape(method, closed, iv, if_, tangent_chords=reflection == "tangents",
                             turns=turns)
            out = _core.frames_in_time(flat(p), flat(tg), steps, options, prev, report.callback)
    except _core.RepeatedPointsError:
        if reflection == "tangents":
            raise
        # repeated samples: step by step through frames(previous=), which merges them
        return _frames_in_time_chained(points_t, tangents_t, method, initial, closed, turns,
                                       reflection, previous, False, 1.0, None, 1.0, 1e-3,
                                       "follow", None, None, progress)
    return out.reshape(steps, n, 3, 3)


def _frames_in_time_chained(points_t: object, tangents_t: object, method: object,
                            initial: object, closed: object, turns: object, reflection: object,
                            previous: object, previous_twist: bool, previous_weight: object,
                            guide: object, guide_weight: float, guide_tolerance: float,
                            guide_sign: Literal["follow", "free"], lengths: object,
                            offsets: object,
                            progress: object = False) -> np.ndarray:
    """:func:`frames_in_time` step by step through :func:`frames` (``previous_twist``, a
    guide, or a bundle), with a ``progress`` report after every step."""
    p, tg, steps, n = _time_steps(points_t, tangents_t)
    # by default the previous step weighs 1000 alone, as much as the guide with a guide
    weight = _previous_weight(previous_weight, 1000.0 if guide is None else guide_weight)
    g = None
    if guide is not None:
        g = as_float_array(guide, "guide")
        if g.shape not in ((3,), (n, 3), (steps, n, 3)):
            raise ValueError(f"guide: expected shape (3,), ({n}, 3) or ({steps}, {n}, 3), "
                             f"got {g.shape}")
    if previous is not None:
        previous = previous_frames(previous, n, "the frames of the step before")
        if initial is not None:
            raise ValueError("previous: cannot be combined with initial (the previous frames "
                             "fix the start)")
    out = np.empty((steps, n, 3, 3))
    common = {"method": method, "closed": closed, "turns": turns, "reflection": reflection,
              "lengths": lengths, "offsets": offsets}
    with Progress(progress, steps, "frames_in_time", "step") as bar:
        for k in range(steps):
            _frames_step(k, p, tg, g, out, previous, guide_sign, initial, guide_weight,
                         guide_tolerance, previous_twist, weight, common)
            bar.update(k + 1)
    return out


def _frames_step(k: int, p: np.ndarray | None, tg: np.ndarray | None, g: np.ndarray | None,
                 out: np.ndarray, previous: Any, guide_sign: Literal["follow", "free"],
                 initial: Any,
                 guide_weight: float, guide_tolerance: float, previous_twist: bool,
                 previous_weight: float, common: dict[str, Any]) -> None:
    """Step ``k`` of :func:`_frames_in_time_chained` into ``out[k]``."""
    pts = p[k] if p is not None else None
    tgk = tg[k] if tg is not None else None
    before = out[k - 1] if k else previous
    try:
        if g is not None:
            # the guide and the step before (from the second step on): axes take their signs
            # from it, directions are followed together with it
            gk = g[k] if g.ndim == 3 else g
            out[k] = frames(pts, tgk, initial=None if before is not None else initial,
                            guide=gk, guide_weight=guide_weight,
                            guide_tolerance=guide_tolerance, guide_sign=guide_sign,
                            previous=before, previous_weight=previous_weight, **common)
        elif before is None:
            out[k] = frames(pts, tgk, initial=initial, **common)
        else:
            out[k] = frames(pts, tgk, previous=before, previous_twist=previous_twist,
                            guide_weight=previous_weight, **common)
    except ValueError as exc:
        msg = str(exc)
        for arg, name in (("points: ", "points_t"), ("tangents: ", "tangents_t")):
            if msg.startswith(arg):
                raise ValueError(f"{name}: time step {k}: {msg[len(arg):]}") from None
        raise
