"""Curves as users hold them: consecutive repeated samples merged, and invalid curves found.

A polyline from a tracker, a GPS log or a simulation often repeats a sample (a pause, a
rounding). Consecutive samples closer than ``2⁻⁴⁰ ≈ 9.1e-13`` times their curve's size are one
point: the core refuses them (``RepeatedPointsError``, a ValueError); the functions that take
curves then merge them (the core's ``distinct_rows`` decides which rows stay) and compute
again on the rows kept, so clean input pays nothing for this.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _core

#: ``status`` values of :func:`plan`.
VALID, NON_FINITE, TOO_FEW = 0, 1, 2


@dataclass(frozen=True)
class Plan:
    """Which rows of curves stored back to back remain when repeats are merged.

    ``into[j]``: the row that row ``j`` is merged into (``j`` where it is kept; a closed
    curve's last row that repeats its first goes into the first); ``keep``: the rows kept;
    ``status[c]``: ``VALID``, ``NON_FINITE`` or ``TOO_FEW`` (fewer distinct samples than a
    curve needs); ``offsets``: the kept rows' curve offsets."""

    into: np.ndarray
    keep: np.ndarray
    status: np.ndarray
    offsets: np.ndarray

    @property
    def rows(self) -> np.ndarray:
        """For every given row, its row among the kept rows (the kept row it merged into)."""
        rows: np.ndarray = (np.cumsum(self.keep) - 1)[self.into]
        return rows

    @property
    def merged(self) -> bool:
        return not bool(self.keep.all())


def plan(pts: np.ndarray, offs: np.ndarray, closed: bool) -> Plan:
    """The :class:`Plan` of the curves ``pts`` (rows ``offs[c]:offs[c+1]``)."""
    into, status = _core.distinct_rows(pts, np.ascontiguousarray(offs, dtype=np.int64), closed)
    keep = into == np.arange(len(into))
    kept = np.concatenate([[0], np.cumsum(keep)])
    return Plan(into, keep, status, kept[offs].astype(np.int64))


def too_few_error(p: Plan, offs: np.ndarray, closed: bool, bundle: bool,
                  arg: str = "points") -> ValueError | None:
    """The ValueError for the first curve left with too few distinct samples, or None."""
    bad = np.flatnonzero(p.status == TOO_FEW)
    if not bad.size:
        return None
    c = int(bad[0])
    where = f"curve {c} (rows {offs[c]} to {max(offs[c + 1], 1) - 1}): " if bundle else ""
    need = 3 if closed else 2
    return ValueError(f"{arg}: {where}a{' closed' if closed else 'n open'} curve needs at "
                      f"least {need} distinct points, got "
                      f"{int(p.keep[offs[c]:offs[c + 1]].sum())} (consecutive repeats merged)")


_CURVE = re.compile(r"curve (\d+) \(rows (\d+) to (\d+)\)")
_ROWS = re.compile(r"\b(rows? )(\d+)(,? (?:and|to) (?:row )?)?(\d+)?")


def as_given(msg: str, p: Plan, offs: np.ndarray) -> str:
    """The message of an error of a call on the rows kept, with its curve's rows and the
    rows within it (``row 7``, ``rows 4 and 5``, ``from row 4 to row 5``) numbered as given
    (``offs``: the given curves' offsets)."""
    m = _CURVE.search(msg)
    c = int(m.group(1)) if m else 0
    if m:
        given = f"curve {c} (rows {offs[c]} to {max(int(offs[c + 1]), 1) - 1})"
        head, tail = msg[:m.start()] + given, msg[m.end():]
    else:
        head, tail = "", msg
    row_of = np.flatnonzero(p.keep)

    def local(k: str) -> str:
        j = int(p.offsets[c]) + int(k)
        return str(int(row_of[j] - offs[c])) if 0 <= j < len(row_of) else k

    def rows(mm: re.Match[str]) -> str:
        out = mm.group(1) + local(mm.group(2))
        if mm.group(3) and mm.group(4):
            out += mm.group(3) + local(mm.group(4))
        elif mm.group(3):
            out += mm.group(3)
        return out

    return head + _ROWS.sub(rows, tail)


def on_rows(call: Callable[..., Any], pts: np.ndarray, offs: np.ndarray, closed: bool,
            bundle: bool, per_row: Sequence[np.ndarray | None] = (), arg: str = "points") -> Any:
    """``call(pts, offs, *per_row)``, or, where the core finds repeated samples, the same
    call on the rows kept (``per_row``: other ``(n, …)`` arrays, cut alike, None passed
    through) with its first result spread back over the rows as given: ``(out, rest…)``.
    Errors of the second call name the rows as given."""
    try:
        return call(pts, offs, *per_row)
    except _core.RepeatedPointsError:
        p = plan(pts, offs, closed)
    err = too_few_error(p, offs, closed, bundle, arg)
    if err is not None:
        raise err
    cut = [None if a is None else np.ascontiguousarray(a[p.keep]) for a in per_row]
    try:
        res = call(np.ascontiguousarray(pts[p.keep]), p.offsets, *cut)
    except ValueError as exc:
        raise ValueError(as_given(str(exc), p, offs)) from None
    out, rest = (res[0], res[1:]) if isinstance(res, tuple) else (res, ())
    out = out[p.rows]
    return (out, *rest) if isinstance(res, tuple) else out


def invalid_curves(points: object, lengths: object, offsets: object, closed: bool
                   ) -> tuple[np.ndarray, ...] | None:
    """The curves of ``points`` (one curve, or a bundle as :func:`spinal.frames` takes it)
    that hold a NaN or an infinity or have too few distinct samples (2; 3 closed), for
    ``on_invalid="skip"``: ``None`` when there are none, else ``(pts, offs, keep_rows,
    kept_offsets, bad, nan, few)`` with the rows ``pts`` and curve offsets ``offs`` as given,
    the rows kept, the kept curves' offsets among them, and the ids of the curves left out
    (all, with NaN or inf, with too few points)."""
    from ._validate import as_curves

    pts, offs, _ = as_curves(points, lengths, offsets)
    status = plan(pts, offs, closed).status
    bad = np.flatnonzero(status != VALID)
    if not bad.size:
        return None
    keep_curve = status == VALID
    keep = np.repeat(keep_curve, np.diff(offs))
    kept = np.concatenate([[0], np.cumsum(np.diff(offs)[keep_curve])]).astype(np.int64)
    return (pts, offs, keep, kept, bad, np.flatnonzero(status == NON_FINITE),
            np.flatnonzero(status == TOO_FEW))


def skipped_message(arg: str, nan: np.ndarray, few: np.ndarray, closed: bool, what: str) -> str:
    """The SkippedCurvesWarning message of ``on_invalid="skip"``."""
    need = 3 if closed else 2
    parts = [f"with NaN or inf: {_listed(nan)}"] if nan.size else []
    if few.size:
        parts.append(f"with fewer than {need} distinct points: {_listed(few)}")
    return (f"{arg}: left out {nan.size + few.size} invalid curve(s) (on_invalid='skip'), "
            f"{what}: {'; '.join(parts)}")


def _listed(ids: np.ndarray, most: int = 20) -> str:
    shown = ", ".join(str(int(i)) for i in ids[:most])
    return shown + (f" and {ids.size - most} more" if ids.size > most else "")
