"""Progress reports of long calls: the ``progress=`` argument that they share.

``progress`` is ``False`` (silent, the default), ``True`` (a bar) or a callable called as
``progress(done, total)`` as the work goes, with the GIL held: from the calling thread
while it waits for the work (sweeps, frames, ``frames_in_time``; about every 20 ms while
the count moves and once at the end), or from the worker running a sequential loop between
its steps (``advect``, ``deform``, ``stamp``). The bar is
tqdm's (``tqdm.auto``: a widget in a notebook) where tqdm is installed and the output is a
terminal or a notebook; otherwise a plain line on stderr at every tenth of the work, which
reads well in a log file. The work itself only counts (an atomic add per curve or step), so
reports cost nothing beside it; an exception raised by a callable stops the call and
propagates.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # Python 3.11+ at run time
    from typing import Self

#: ``progress=`` once checked: a bool or the user's callable.
Report = bool | Callable[..., object]


def checked(progress: object, name: str = "progress") -> Report:
    """``progress`` as a bool (NumPy's too) or the callable, else ``TypeError`` naming it."""
    if isinstance(progress, (bool, np.bool_)):
        return bool(progress)
    if callable(progress):
        return progress
    raise TypeError(f"{name}: expected a bool or a callable, got {type(progress).__name__}")


def _interactive() -> bool:
    """Whether stderr is a terminal or the call runs in a Jupyter kernel."""
    if "ipykernel" in sys.modules:
        return True
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):  # replaced or closed stderr
        return False


class Progress:
    """The report of one call: ``update(done)`` after every block, ``close()`` at the end
    (also on errors). ``Progress(False, …)`` does nothing."""

    def __init__(self, progress: object, total: int | None, desc: str,
                 unit: str = "it") -> None:
        # total None: not known in advance (a stream), a plain line after every update
        self.total, self.desc, self.unit = None if total is None else int(total), desc, unit
        self.call: Callable[..., object] | None = progress if callable(progress) else None
        self.bar: Any = None  # a tqdm bar
        self.line = False
        self.shown = -1  # the tenth of the work that the plain line showed last
        self.done = 0
        if progress is True:
            if _interactive():
                try:
                    from tqdm.auto import tqdm

                    self.bar = tqdm(total=self.total, desc=desc, unit=unit,
                                    unit_scale=(self.total or 10_000) >= 10_000, leave=False)
                except ImportError:
                    self.line = True
            else:
                self.line = True

    def __bool__(self) -> bool:
        return self.call is not None or self.bar is not None or self.line

    def update(self, done: int) -> None:
        done = int(done)
        if self.call is not None:
            self.call(done, self.total)
        elif self.bar is not None:
            self.bar.update(done - self.done)
        elif self.line and self.total is None:
            sys.stderr.write(f"{self.desc}: {done:,} {self.unit}s\n")
            sys.stderr.flush()
        elif self.line:
            tenth = 10 * done // max(self.total or 0, 1)
            if tenth > self.shown:
                self.shown = tenth
                sys.stderr.write(f"{self.desc}: {done:,}/{self.total or 0:,} {self.unit}s\n")
                sys.stderr.flush()
        self.done = done

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class Reported:
    """The ``progress(done, total)`` callback handed to the core, whose first call gives
    the total (rows after merging repeats, steps of an adaptive rule): a :class:`Progress`
    made then. ``callback`` is None without ``progress`` (the core then skips the counts).
    Use as a context manager; ``close()`` ends the bar."""

    def __init__(self, progress: object, desc: str, unit: str = "it") -> None:
        self.progress, self.desc, self.unit = progress, desc, unit
        self.report: Progress | None = None

    @property
    def callback(self) -> Reported | None:
        return None if self.progress is False else self

    def __call__(self, done: int, total: int) -> None:
        if self.report is None or self.report.total != total:
            # (a second core call, on the rows left once repeated points are merged)
            self.close()
            self.report = Progress(self.progress, total, self.desc, self.unit)
        self.report.update(done)

    def close(self) -> None:
        if self.report is not None:
            self.report.close()
            self.report = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
