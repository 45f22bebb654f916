"""Streamlines and polylines from the files users hold them in.

:func:`read_streamlines` reads

* ``.trk`` (TrackVis) and ``.tck`` (MRtrix) through nibabel's ``streamlines.load``, with the
  points in RAS+ millimetres ("world" coordinates: nibabel applies the file's voxel-to-RAS
  affine, so the points are those of nibabel's ``Tractogram``);
* ``.trx`` (the TRX format, Rheault et al. 2023) through trx-python, also in RAS+ mm;
* ``.vtp`` and ``.vtk`` polylines (every line cell of a PolyData is one streamline; ParaView,
  VTK and many tractography tools write them) through pyvista.

The streamlines come back as a list of ``(n_i, 3)`` float64 arrays, which every spinal
function taking a bundle accepts (``spinal.tube(s.points, 0.2)``), with the per-point and
per-streamline data of the file. Each reader's package is optional: ``pip install
'spinal[io]'`` (from the package index once published; from a clone ``pip install -e
'.[io]'``) installs nibabel, trx-python and pyvista.

:func:`tube_file` sweeps tubes around the streamlines of a file (or of any iterable of
arrays) chunk by chunk into a ``.ply`` or ``.vtp`` file in memory bounded by the chunk, so a
whole-brain tractogram of millions of streamlines becomes one mesh file on a laptop.

Meshes are read by :meth:`spinal.Mesh.load` and written by :meth:`spinal.Mesh.save`.
"""


import os as _os
import pathlib as _pathlib
import warnings as _warnings
from collections.abc import Callable as _Callable
from collections.abc import Iterable as _Iterable
from collections.abc import Iterator as _Iterator
from typing import Any as _Any
from typing import Literal as _Literal
from typing import NamedTuple as _NamedTuple

import numpy as _np
import numpy.typing as _npt

__all__ = ["STREAMLINE_SUFFIXES", "Streamlines", "read_streamlines", "tube_file"]

#: The file suffixes :func:`read_streamlines` reads.
STREAMLINE_SUFFIXES = (".trk", ".tck", ".trx", ".vtp", ".vtk")


class Streamlines(_NamedTuple):
    """Streamlines read from a file (unpacks as ``points, point_data, streamline_data``).

    Attributes
    ----------
    points : list of ndarray (n_i, 3) float64
        One array per streamline, in the file's world coordinates (RAS+ mm for
        ``.trk``/``.tck``/``.trx``).
    point_data : dict of str to list of ndarray
        Per-point values: for every name one array per streamline, ``(n_i,)`` for a scalar,
        ``(n_i, k)`` otherwise (``.trk`` scalars, ``.trx`` ``dpv``, VTK point data).
    streamline_data : dict of str to ndarray
        Per-streamline values, ``(S,)`` or ``(S, k)`` (``.trk`` properties, ``.trx``
        ``dps``, VTK cell data).
    """

    points: list[_np.ndarray]
    point_data: dict[str, list[_np.ndarray]]
    streamline_data: dict[str, _np.ndarray]

    @property
    def lengths(self) -> _np.ndarray:
        """The number of points of every streamline, ``(S,)`` int64."""
        return _np.array([len(p) for p in self.points], dtype=_np.int64)


def _need(module: str, extra: str = "io") -> _Any:
    """Import ``module`` or say which extra installs it."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(
            f"reading this format needs {module.split('.')[0]}: pip install 'spinal[{extra}]' "
            f"(from the package index once published; from a clone: pip install -e "
            f"'.[{extra}]')") from None


def _split(data: _np.ndarray, lengths: _np.ndarray, squeeze: bool = True
           ) -> list[_np.ndarray]:
    """``data`` (the rows of all streamlines back to back) cut into one array per streamline
    (views); ``(n, 1)`` columns become ``(n,)``."""
    data = _np.asarray(data)
    if squeeze and data.ndim == 2 and data.shape[1] == 1:
        data = data[:, 0]
    ends = _np.cumsum(lengths)
    return _np.split(data, ends[:-1]) if len(lengths) else []


def _from_sequence(seq: _Any) -> tuple[_np.ndarray, _np.ndarray]:
    """The rows and lengths of a nibabel ``ArraySequence`` (copied into one block when its
    pieces are not back to back)."""
    lengths = _np.asarray(seq._lengths, dtype=_np.int64)
    offsets = _np.asarray(seq._offsets, dtype=_np.int64)
    data = _np.asarray(seq._data)
    total = int(lengths.sum())
    if len(lengths) and (offsets[0] != 0 or _np.any(offsets[1:] != _np.cumsum(lengths)[:-1])):
        data = _np.concatenate([data[o:o + n] for o, n in zip(offsets, lengths, strict=True)])
    return data[:total], lengths


def _sequences(points: _Any, per_point: dict[str, _Any], per_streamline: dict[str, _Any]
               ) -> Streamlines:
    data, lengths = _from_sequence(points)
    pts = _split(_np.asarray(data, dtype=_np.float64), lengths, squeeze=False)
    pd: dict[str, list[_np.ndarray]] = {}
    for k, v in per_point.items():
        d, _ = _from_sequence(v)
        pd[k] = _split(d, lengths)
    sd: dict[str, _np.ndarray] = {}
    for k, v in per_streamline.items():
        a = _np.asarray(v)
        sd[k] = a[:, 0] if a.ndim == 2 and a.shape[1] == 1 else a
    return Streamlines(pts, pd, sd)


def _read_nibabel(path: _pathlib.Path) -> Streamlines:
    nib = _need("nibabel")
    t = nib.streamlines.load(_os.fspath(path), lazy_load=False).tractogram  # RAS+ mm
    return _sequences(t.streamlines, dict(t.data_per_point), dict(t.data_per_streamline))


def _read_trx(path: _pathlib.Path) -> Streamlines:
    trx = _need("trx.trx_file_memmap")
    f = trx.load(_os.fspath(path))
    try:
        out = _sequences(f.streamlines, dict(f.data_per_vertex), dict(f.data_per_streamline))
        # the memory maps close with the file: keep copies
        return Streamlines([p.copy() for p in out.points],
                           {k: [a.copy() for a in v] for k, v in out.point_data.items()},
                           {k: _np.array(v) for k, v in out.streamline_data.items()})
    finally:
        f.close()


def _read_vtk(path: _pathlib.Path) -> Streamlines:
    pv = _need("pyvista")
    from vtkmodules.util.numpy_support import vtk_to_numpy

    poly = pv.read(_os.fspath(path))
    if not isinstance(poly, pv.PolyData):
        poly = poly.extract_surface()
    if poly.n_lines == 0:
        raise ValueError(f"path: {path.name} holds no polylines (line cells), only "
                         f"{poly.n_cells} other cells")
    lines = poly.GetLines()
    offsets = vtk_to_numpy(lines.GetOffsetsArray()).astype(_np.int64)
    ids = vtk_to_numpy(lines.GetConnectivityArray()).astype(_np.int64)
    lengths = _np.diff(offsets)
    pts = _np.asarray(poly.points, dtype=_np.float64)[ids]
    pd = {k: _split(_np.asarray(poly.point_data[k])[ids], lengths)
          for k in poly.point_data}
    # cell data of the line cells, which VTK numbers after the vertex cells
    first = poly.n_verts
    sd = {k: _np.asarray(poly.cell_data[k])[first:first + len(lengths)]
          for k in poly.cell_data}
    return Streamlines(_split(pts, lengths, squeeze=False), pd, sd)


def read_streamlines(path: str | _os.PathLike[str]) -> Streamlines:
    """Read the streamlines (polylines) of a ``.trk``, ``.tck``, ``.trx``, ``.vtp`` or
    ``.vtk`` file.

    Parameters
    ----------
    path : str or os.PathLike
        The file; its suffix picks the reader (see the module documentation).

    Returns
    -------
    Streamlines
        ``(points, point_data, streamline_data)``: one ``(n_i, 3)`` float64 array per
        streamline (RAS+ mm for the tractography formats), and their data.

    Examples
    --------
    >>> s = spinal.io.read_streamlines("bundle.trk")              # doctest: +SKIP
    >>> mesh = spinal.tube(s.points, 0.2, 8, dtype="float32")   # doctest: +SKIP
    """
    from ._files import _path

    path, suffix = _path(path, STREAMLINE_SUFFIXES, "streamline ")
    if not path.exists():
        raise FileNotFoundError(f"path: no such file: {_os.fspath(path)!r}")
    if suffix in (".trk", ".tck"):
        return _read_nibabel(path)
    if suffix == ".trx":
        return _read_trx(path)
    return _read_vtk(path)


def _lazy_items(path: _pathlib.Path
                ) -> _Iterator[tuple[_np.ndarray, dict[str, _np.ndarray]]]:
    """``(points (n, 3) float64, {name: per-point values})`` of every streamline of the file,
    read lazily where the format allows (nibabel's lazy loading of ``.trk``/``.tck``, the
    memory maps of ``.trx``)."""
    suffix = path.suffix.lower()
    if suffix in (".trk", ".tck"):
        nib = _need("nibabel")
        lazy = nib.streamlines.load(_os.fspath(path), lazy_load=True).tractogram
        # `lazy.streamlines` applies the file's affine (RAS+ mm, as the eager loading
        # gives); the items of iterating `lazy` itself do not all do so
        keys = list(lazy.data_per_point)
        for p, *values in zip(lazy.streamlines, *(lazy.data_per_point[k] for k in keys),
                              strict=False):
            data = {}
            for k, v in zip(keys, values, strict=True):
                v = _np.asarray(v)
                data[k] = v[:, 0] if v.ndim == 2 and v.shape[1] == 1 else v
            yield _np.asarray(p, dtype=_np.float64), data
    elif suffix == ".trx":
        trx = _need("trx.trx_file_memmap")
        f = trx.load(_os.fspath(path))
        try:
            seq, dpv = f.streamlines, dict(f.data_per_vertex)
            for i in range(len(seq)):
                data = {}
                for k, v in dpv.items():
                    a = _np.array(v[i])
                    data[k] = a[:, 0] if a.ndim == 2 and a.shape[1] == 1 else a
                yield _np.array(seq[i], dtype=_np.float64), data
        finally:
            f.close()
    else:
        s = read_streamlines(path)
        for i, p in enumerate(s.points):
            yield p, {k: v[i] for k, v in s.point_data.items()}


def _is_pair(x: object) -> bool:
    """Whether an item of ``tube_file``'s ``src`` is a ``(points, data)`` pair."""
    return isinstance(x, tuple) and len(x) == 2 and isinstance(x[1], dict)


def _orientation(p: _np.ndarray) -> _np.ndarray:
    """``|unit tangent|`` as RGB in [0, 1] (x red, y green, z blue), the tractography
    convention; zeros where a curve has fewer than two distinct points."""
    from ._frames import estimate_tangents

    try:
        return _np.abs(estimate_tangents(p))
    except ValueError:
        return _np.zeros((len(p), 3))


def _summarise(folds: list[tuple[int, int, _Any]], skipped: list[_np.ndarray],
               other: dict[str, _warnings.WarningMessage]) -> None:
    """One warning per kind for the whole file, naming streamlines by their index in
    ``src``."""
    from ._mesh import FoldOverWarning, SkippedCurvesWarning

    if folds:
        # streamline index in src, row within it, row of all streamlines back to back
        curves = _np.concatenate([w.curves + first for first, _, w in folds])
        rows = _np.concatenate([w.rows for _, _, w in folds])
        indices = _np.concatenate([w.indices + before for _, before, w in folds])
        firsts = ", ".join(f"streamline {c} row {r}" for c, r in zip(curves[:5], rows[:5],
                                                                      strict=True))
        _warnings.warn(FoldOverWarning(
            f"the profile reaches past the spine's centre of curvature (the surface folds "
            f"over itself) on {len(rows):,} segments of {len(_np.unique(curves)):,} "
            f"streamlines ({firsts}{', …' if len(rows) > 5 else ''}); reduce the radius or "
            f"smooth the streamlines", indices, curves, rows), stacklevel=3)
    if skipped:
        ids = _np.concatenate(skipped)
        _warnings.warn(SkippedCurvesWarning(
            f"{len(ids):,} streamlines with fewer than two distinct points or with NaN were "
            f"skipped (the first: {', '.join(map(str, ids[:8]))})", ids), stacklevel=3)
    for w in other.values():
        _warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def tube_file(
    src: str | _os.PathLike[str] | _Iterable[object],
    dst: str | _os.PathLike[str],
    radius: float | str = 0.25,
    sides: int = 8,
    *,
    chunk_points: int = 1 << 20,
    dtype: _npt.DTypeLike = "float32",
    colors: str | None = None,
    join: _Literal["round", "bevel", "miter"] = "round",
    progress: bool | _Callable[[int], object] = False,
) -> _pathlib.Path:
    """Sweep a tube around every streamline of ``src`` into the mesh file ``dst``, a chunk
    of streamlines at a time.

    Each chunk of about ``chunk_points`` spine points is read (lazily where the format
    allows), swept by :func:`spinal.tube` and appended to temporary files beside ``dst``;
    at the end the header and the spooled blocks are written to a temporary name that
    then replaces ``dst``. Peak memory is that of one chunk (its points and its mesh), not
    of the tractogram; the file has the bytes that :meth:`spinal.Mesh.save` writes for one
    :func:`spinal.tube` call on all streamlines. Ctrl-C (or an error) leaves no file under
    ``dst``. Streamlines with fewer than two distinct points or with NaN are skipped (their
    ``curve_id`` is kept free), as ``on_short="skip"`` and ``on_invalid="skip"`` do.

    Parameters
    ----------
    src : str, os.PathLike or iterable of array_like (n_i, 3)
        A streamline file (see :func:`read_streamlines`) or the streamlines themselves (a
        list, a generator, nibabel's ``ArraySequence``); an item may also be a pair
        ``(points, data)`` with ``data`` a dict of per-point arrays that ``radius`` and
        ``colors`` can name.
    dst : str or os.PathLike
        The mesh file: ``.ply`` (binary) or ``.vtp`` (appended binary).
    radius : float or str
        The tube radius in the file's units, or the name of per-point data of ``src`` that
        holds it.
    sides : int
        Sides of the tube (3 … 2**20).
    chunk_points : int
        Spine points per chunk (at least 1; a streamline is never split).
    dtype : "float32" or "float64"
        Of the vertices and normals.
    colors : None, "orientation" or str
        Vertex colours: ``"orientation"`` (``|tangent|`` as RGB) or the name of per-point data
        of ``src`` holding RGB (uint8, or floats in [0, 1]).
    join : "round", "bevel" or "miter"
        As in :func:`spinal.tube`.
    progress : bool or callable
        ``True``: a bar counting streamlines (tqdm when installed, in a terminal or a
        notebook), else a line on stderr after every chunk; a callable is called as
        ``progress(streamlines_done)`` after every chunk.

    Returns
    -------
    pathlib.Path
        ``dst``.
    """
    from ._files import Spool, vertex_colors
    from ._mesh import FoldOverWarning, SkippedCurvesWarning
    from ._progress import Progress
    from ._sweep import tube
    from ._validate import as_int

    if not isinstance(dst, (str, _os.PathLike)):
        raise TypeError(f"dst: expected a str or os.PathLike, got {type(dst).__name__}")
    chunk_points = as_int(chunk_points, "chunk_points", 1, 1 << 40)
    if not (isinstance(progress, bool) or callable(progress)):
        raise TypeError(f"progress: expected a bool or a callable, got "
                        f"{type(progress).__name__}")
    items: _Iterable[tuple[_Any, dict[str, _Any]]]
    if isinstance(src, (str, _os.PathLike)):
        path = _pathlib.Path(src)
        if not path.exists():
            raise FileNotFoundError(f"src: no such file: {_os.fspath(path)!r}")
        if path.suffix.lower() not in STREAMLINE_SUFFIXES:
            raise ValueError(f"src: unknown streamline format {path.suffix!r}; use one of "
                             f"{', '.join(STREAMLINE_SUFFIXES)}")
        items = _lazy_items(path)
    else:
        items = (x if isinstance(x, tuple) and _is_pair(x) else (x, {}) for x in src)
    named = [x for x in (radius, colors) if isinstance(x, str) and x != "orientation"]
    spool = Spool(_pathlib.Path(dst))
    bar = Progress(progress is True, None, "tube_file", "streamline")

    def flush(chunk: list[_np.ndarray], data: dict[str, list[_np.ndarray]], first: int) -> None:
        r = _np.concatenate(data[radius]) if isinstance(radius, str) else radius
        point_data: dict[str, _npt.ArrayLike] | None = None
        if colors == "orientation":
            point_data = {"colors": _np.concatenate([_orientation(p) for p in chunk])}
        elif colors is not None:
            point_data = {"colors": _np.concatenate(data[colors])}
        with _warnings.catch_warnings(record=True) as caught:
            _warnings.simplefilter("always")
            m = tube(chunk, r, sides, dtype=dtype, join=join, point_data=point_data,
                     on_short="skip", on_invalid="skip")
        for w in caught:
            if isinstance(w.message, FoldOverWarning):
                folds.append((first, rows_before[0], w.message))
            elif isinstance(w.message, SkippedCurvesWarning):
                skipped.append(_np.asarray(w.message.curves) + first)
            elif str(w.message) not in other:
                other[str(w.message)] = w
        if first and "curve_id" in m.cell_data:
            m.cell_data["curve_id"] = m.cell_data["curve_id"] + first
        rgb, rest = vertex_colors(m, None)
        spool.add(m, rgb, rest)
        rows_before[0] += sum(len(p) for p in chunk)

    done = 0
    # the chunks' warnings, given once at the end for the whole file
    folds: list[tuple[int, int, _Any]] = []
    skipped: list[_np.ndarray] = []
    other: dict[str, _warnings.WarningMessage] = {}
    rows_before = [0]  # spine rows of the chunks written
    try:
        chunk: list[_np.ndarray] = []
        data: dict[str, list[_np.ndarray]] = {k: [] for k in named}
        size = 0
        for i, (p, d) in enumerate(items):
            p = _np.asarray(p, dtype=_np.float64)
            for k in named:
                if k not in d:
                    what = "radius" if k == radius else "colors"
                    raise ValueError(f"{what}: src has no per-point data named {k!r} (it has "
                                     f"{', '.join(sorted(d)) or 'none'})")
                v = _np.asarray(d[k])
                if v.ndim == 0 or len(v) != len(p):
                    raise ValueError(f"src: streamline {i}: its {k!r} data has "
                                     f"{v.shape[0] if v.ndim else 'no'} rows for {len(p)} "
                                     f"points")
                data[k].append(v)
            chunk.append(p)
            size += len(p)
            if size >= chunk_points:
                flush(chunk, data, done)
                done += len(chunk)
                chunk, data, size = [], {k: [] for k in named}, 0
                bar.update(done)
                if callable(progress):
                    progress(done)
        if chunk:
            flush(chunk, data, done)
            done += len(chunk)
            bar.update(done)
        if callable(progress):
            progress(done)
        if spool.nv == 0:
            raise ValueError(f"src: no streamline could be swept ({done:,} read; each needs "
                             f"two distinct finite points)")
        out = spool.finish()
        _summarise(folds, skipped, other)
        return out
    finally:
        spool.close()
        bar.close()
