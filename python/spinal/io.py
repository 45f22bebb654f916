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

Meshes are read by :meth:`spinal.Mesh.load` and written by :meth:`spinal.Mesh.save`.
"""

from __future__ import annotations

import os as _os
import pathlib as _pathlib
from typing import NamedTuple as _NamedTuple

import numpy as _np

__all__ = ["STREAMLINE_SUFFIXES", "Streamlines", "read_streamlines"]

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

    points: list
    point_data: dict
    streamline_data: dict

    @property
    def lengths(self) -> _np.ndarray:
        """The number of points of every streamline, ``(S,)`` int64."""
        return _np.array([len(p) for p in self.points], dtype=_np.int64)


def _need(module: str, extra: str = "io"):
    """Import ``module`` or say which extra installs it."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(
            f"reading this format needs {module.split('.')[0]}: pip install 'spinal[{extra}]' "
            f"(from the package index once published; from a clone: pip install -e "
            f"'.[{extra}]')") from None


def _split(data: _np.ndarray, lengths: _np.ndarray, squeeze: bool = True) -> list:
    """``data`` (the rows of all streamlines back to back) cut into one array per streamline
    (views); ``(n, 1)`` columns become ``(n,)``."""
    data = _np.asarray(data)
    if squeeze and data.ndim == 2 and data.shape[1] == 1:
        data = data[:, 0]
    ends = _np.cumsum(lengths)
    return _np.split(data, ends[:-1]) if len(lengths) else []


def _from_sequence(seq) -> tuple[_np.ndarray, _np.ndarray]:
    """The rows and lengths of a nibabel ``ArraySequence`` (copied into one block when its
    pieces are not back to back)."""
    lengths = _np.asarray(seq._lengths, dtype=_np.int64)
    offsets = _np.asarray(seq._offsets, dtype=_np.int64)
    data = _np.asarray(seq._data)
    total = int(lengths.sum())
    if len(lengths) and (offsets[0] != 0 or _np.any(offsets[1:] != _np.cumsum(lengths)[:-1])):
        data = _np.concatenate([data[o:o + n] for o, n in zip(offsets, lengths, strict=True)])
    return data[:total], lengths


def _sequences(points, per_point: dict, per_streamline: dict) -> Streamlines:
    data, lengths = _from_sequence(points)
    pts = _split(_np.asarray(data, dtype=_np.float64), lengths, squeeze=False)
    pd = {}
    for k, v in per_point.items():
        d, _ = _from_sequence(v)
        pd[k] = _split(d, lengths)
    sd = {}
    for k, v in per_streamline.items():
        v = _np.asarray(v)
        sd[k] = v[:, 0] if v.ndim == 2 and v.shape[1] == 1 else v
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


def read_streamlines(path: str | _os.PathLike) -> Streamlines:
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
    if not isinstance(path, (str, _os.PathLike)):
        raise TypeError(f"path: expected a str or os.PathLike, got {type(path).__name__}")
    path = _pathlib.Path(path)
    suffix = path.suffix.lower()
    if suffix not in STREAMLINE_SUFFIXES:
        raise ValueError(f"path: unknown streamline format {suffix!r}; use one of "
                         f"{', '.join(STREAMLINE_SUFFIXES)}")
    if not path.exists():
        raise FileNotFoundError(f"path: no such file: {_os.fspath(path)!r}")
    if suffix in (".trk", ".tck"):
        return _read_nibabel(path)
    if suffix == ".trx":
        return _read_trx(path)
    return _read_vtk(path)
