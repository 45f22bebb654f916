"""The number of worker threads of spinal's parallel calls.

The heavy calls (frames of many curves, sweeps, advection, deformation, fleshing, mesh
walks, …) run in a rayon thread pool with the GIL released. By default the pool has
``RAYON_NUM_THREADS`` threads when that environment variable holds a positive integer, else
one per logical CPU. Process pools (Dask, joblib, ``concurrent.futures``) that run several
spinal calls side by side should give each worker one thread to avoid oversubscription:
``spinal.set_num_threads(1)`` in the worker initializer, or ``with spinal.threads(1): ...``.
The setting is process-wide (shared by all Python threads); one pool per thread count is
built on first use and kept, so switching back and forth costs nothing. Results do not
depend on the number of threads (the parallel loops write disjoint rows).
"""

from __future__ import annotations

import contextlib
import numbers
from collections.abc import Iterator

from . import _core

#: Largest thread count accepted.
MAX_THREADS = 1024


def _as_count(n: object) -> int | None:
    if n is None:
        return None
    if isinstance(n, bool) or not isinstance(n, numbers.Integral):
        raise TypeError(f"n: must be a positive int or None, got {type(n).__name__}")
    count = int(n)
    if not 1 <= count <= MAX_THREADS:
        raise ValueError(f"n: must be a positive int (at most {MAX_THREADS}), got {count}")
    return count


def set_num_threads(n: int | None) -> None:
    """Use ``n`` worker threads in spinal's parallel calls (``None``: back to the default).

    ``n`` must be a positive int (at most 1024). The default is ``RAYON_NUM_THREADS`` when it
    is set to a positive integer, else the number of logical CPUs. The setting applies to
    the whole process; see :func:`threads` for a temporary setting and
    :func:`get_num_threads` for the current count.

    >>> import spinal
    >>> spinal.set_num_threads(1)
    >>> spinal.get_num_threads()
    1
    >>> spinal.set_num_threads(None)
    """
    _core.set_num_threads(_as_count(n))


def get_num_threads() -> int:
    """The number of worker threads the next parallel call of spinal will use: the value of
    :func:`set_num_threads` (or :func:`threads`), else the default (``RAYON_NUM_THREADS`` when
    it is a positive integer, else the number of logical CPUs)."""
    return int(_core.get_num_threads())


@contextlib.contextmanager
def threads(n: int | None) -> Iterator[None]:
    """Context manager: spinal's parallel calls use ``n`` worker threads inside the block,
    and the previous setting (a count or the default) comes back when the block ends, also
    on an exception. ``n`` as in :func:`set_num_threads`; the setting is process-wide.

    >>> import spinal
    >>> with spinal.threads(1):
    ...     spinal.get_num_threads()
    1
    """
    count = _as_count(n)
    previous = _core.num_threads_setting()
    _core.set_num_threads(count)
    try:
        yield
    finally:
        _core.set_num_threads(previous)
