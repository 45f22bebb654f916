"""Whole-file commands of ``python -m spinal``: ``tube``, ``frames`` and ``info``.

Inputs are streamlines (``.trk``, ``.tck``, ``.trx``, ``.vtp``, ``.vtk``; see
:mod:`spinal.io`) or one curve as an ``(n, 3)`` array (``.npy``, or ``.csv``/``.txt`` with
three numbers per line); meshes are written by :meth:`spinal.Mesh.save`. Errors of the
input end the command with exit status 1 and one line on stderr; Ctrl-C with status 130.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, TextIO

import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:  # Python 3.11+ at run time
    from typing import Self

    from .io import Streamlines

#: Spine rows per chunk of a bundle streamed to a file (a progress step; Ctrl-C stops
#: between chunks).
BLOCK_ROWS = 1 << 18

#: Mesh formats written chunk by chunk (the others are written from one mesh in memory).
STREAMED = (".ply", ".vtp")

TUBE_EXAMPLES = """examples:
  python -m spinal tube fornix.trk fornix.vtp --radius 0.3 --color orientation
  python -m spinal tube bundle.tck bundle.glb --sides 6 --float32
  python -m spinal tube tracts.trk tracts.ply --radius-from fa --color fa
  python -m spinal tube path.npy path.stl --radius 2 --join miter
"""


class _Progress:
    """A bar (tqdm, when installed and stderr is a terminal) showing a count of ``total``
    (None: not known), else nothing; ``--quiet`` silences the summary lines too."""

    def __init__(self, total: int | None, what: str, quiet: bool):
        self.bar = None
        if not quiet and sys.stderr.isatty():
            try:
                from tqdm import tqdm

                self.bar = tqdm(total=total, desc=what, unit="pt" if total else " curves",
                                unit_scale=True, file=sys.stderr, leave=False)
            except ImportError:
                pass

    def step(self, done: int) -> None:
        """Show ``done`` so far."""
        if self.bar is not None:
            self.bar.update(done - self.bar.n)

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.close()


def _say(quiet: bool, text: str) -> None:
    if not quiet:
        print(text, file=sys.stderr)


def read_curves(path: pathlib.Path) -> Streamlines:
    """``Streamlines`` of a streamline file, or of one curve given as an array file."""
    from . import io

    suffix = path.suffix.lower()
    if suffix in io.STREAMLINE_SUFFIXES:
        return io.read_streamlines(path)
    if suffix == ".npy":
        x = np.load(path, allow_pickle=False)
    elif suffix in (".csv", ".txt", ".xyz"):
        x = np.loadtxt(path, delimiter="," if suffix == ".csv" else None, ndmin=2)
    else:
        raise ValueError(f"IN: unknown input format {suffix!r}; use a streamline file "
                         f"({', '.join(io.STREAMLINE_SUFFIXES)}) or an (n, 3) array "
                         f"(.npy, .csv, .txt)")
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"IN: expected an (n, 3) array of points, got shape {x.shape}")
    return io.Streamlines([np.asarray(x, dtype=np.float64)], {}, {})


def _per_point(s: Streamlines, name: str, what: str) -> list[np.ndarray]:
    """The per-point arrays of ``name`` (per-streamline values repeated along each)."""
    if name in s.point_data:
        return [np.asarray(a) for a in s.point_data[name]]
    if name in s.streamline_data:
        v = np.asarray(s.streamline_data[name])
        return [np.repeat(v[i:i + 1], len(p), axis=0) for i, p in enumerate(s.points)]
    names = sorted(s.point_data) + sorted(s.streamline_data)
    raise ValueError(f"{what}: the input has no data named {name!r} (it has "
                     f"{', '.join(names) if names else 'none'})")


def _colormap(t: np.ndarray) -> np.ndarray:
    """RGB in [0, 1] of values in [0, 1]: matplotlib's viridis when installed, else a
    blue-to-yellow ramp."""
    try:
        from matplotlib import colormaps

        out: np.ndarray = colormaps["viridis"](t)[:, :3]
        return out
    except ImportError:
        out = np.c_[t, t, 1 - t]
        return out


def _colors(s: Streamlines, spec: str) -> list[np.ndarray]:
    """One ``(n_i, 3)`` array of colours in [0, 1] per streamline."""
    import spinal

    if spec == "orientation":
        # the absolute unit tangent as RGB (the tractography convention: x red, y green,
        # z blue)
        out = []
        for p in s.points:
            t = spinal.estimate_tangents(p) if len(p) > 1 else np.zeros((len(p), 3))
            out.append(np.abs(t))
        return out
    values = _per_point(s, spec, "--color")
    v: np.ndarray = np.concatenate(values) if values else np.zeros(0)
    if v.ndim == 2 and v.shape[1] in (3, 4):
        rgb = v[:, :3].astype(np.float64)
        if v.dtype == np.uint8 or rgb.max(initial=0) > 1:
            rgb = rgb / 255.0
    else:
        v = v.reshape(len(v), -1)[:, 0].astype(np.float64)
        lo, hi = np.nanmin(v, initial=np.inf), np.nanmax(v, initial=-np.inf)
        t = (v - lo) / (hi - lo) if hi > lo else np.zeros_like(v)
        rgb = _colormap(np.nan_to_num(t))
    ends = np.cumsum([len(p) for p in s.points])[:-1]
    return np.split(np.clip(rgb, 0, 1), ends)


def _check_paths(a: argparse.Namespace, output_suffixes: Sequence[str] | None = None) -> None:
    """Refuse a missing input and an unknown output format before any work."""
    src = pathlib.Path(getattr(a, "input", None) or a.file)
    if not src.exists():
        raise FileNotFoundError(f"IN: no such file: {str(src)!r}")
    if output_suffixes is not None:
        suffix = pathlib.Path(a.output).suffix.lower()
        if suffix not in output_suffixes:
            raise ValueError(f"OUT: unknown format {suffix!r}; use one of "
                             f"{', '.join(output_suffixes)}")


def tube(a: argparse.Namespace) -> int:
    import spinal

    from . import io
    from ._files import WRITES

    _check_paths(a, WRITES)
    if a.radius_from is None and not a.radius > 0:
        raise ValueError(f"--radius: must be positive, got {a.radius}")
    dtype = np.float32 if a.float32 else np.float64
    out = pathlib.Path(a.output)
    t0 = time.perf_counter()
    if out.suffix.lower() in STREAMED and a.radius_from is None and a.color in (None,
                                                                                "orientation"):
        # nothing needs the whole bundle: read and tubed a block at a time, written as
        # it goes (memory of one block)
        path = pathlib.Path(a.input)
        src: pathlib.Path | list[np.ndarray] = path
        if path.suffix.lower() not in io.STREAMLINE_SUFFIXES:
            src = read_curves(path).points
        with _Progress(None, "tube", a.quiet) as bar:
            io.tube_file(src, out, a.radius, a.sides, chunk_points=BLOCK_ROWS, dtype=dtype,
                         colors=a.color, join=a.join,
                         progress=(lambda done: bar.step(done)) if bar.bar else False)
        _say(a.quiet, f"wrote {a.output} ({out.stat().st_size / 1e6:,.1f} MB, "
                      f"{time.perf_counter() - t0:.2f} s)")
        return 0
    s = read_curves(pathlib.Path(a.input))
    rows = sum(len(p) for p in s.points)
    _say(a.quiet, f"read {len(s.points):,} curve(s), {rows:,} points from {a.input} "
                  f"({time.perf_counter() - t0:.2f} s)")
    radius = _per_point(s, a.radius_from, "--radius-from") if a.radius_from else None
    colors = _colors(s, a.color) if a.color else None
    t1 = time.perf_counter()
    if out.suffix.lower() in STREAMED:
        # per-point radius and colours computed over the whole bundle, then streamed out
        per_curve: list[dict[str, np.ndarray]] = [{} for _ in s.points]
        for name, values in (("radius", radius), ("colors", colors)):
            for d, v in zip(per_curve, values or ()):
                d[name] = v
        with _Progress(None, "tube", a.quiet) as bar:
            io.tube_file(zip(s.points, per_curve), out, "radius" if radius else a.radius,
                         a.sides, chunk_points=BLOCK_ROWS, dtype=dtype,
                         colors="colors" if colors else None, join=a.join,
                         progress=(lambda done: bar.step(done)) if bar.bar else False)
        _say(a.quiet, f"wrote {a.output} ({out.stat().st_size / 1e6:,.1f} MB, "
                      f"{time.perf_counter() - t1:.2f} s)")
        return 0
    r = a.radius if radius is None else np.concatenate(radius).astype(float)
    data: dict[str, npt.ArrayLike] | None = (
        None if colors is None else {"colors": np.concatenate(colors)})
    with _Progress(rows, "tube", a.quiet) as bar:
        mesh = spinal.tube(s.points, r, a.sides, dtype=dtype, join=a.join, point_data=data,
                           on_short="skip", on_invalid="skip",
                           progress=(lambda done, total: bar.step(done)) if bar.bar else False)
    _say(a.quiet, f"tube: {len(mesh.vertices):,} vertices, {len(mesh.faces):,} faces "
                  f"({time.perf_counter() - t1:.2f} s)")
    mesh.save(a.output)
    _say(a.quiet, f"wrote {a.output}")
    return 0


def frames(a: argparse.Namespace) -> int:
    import spinal

    _check_paths(a, (".npz",))
    s = read_curves(pathlib.Path(a.input))
    lengths = s.lengths
    pts = np.concatenate(s.points) if s.points else np.zeros((0, 3))
    out = pathlib.Path(a.output)
    if out.suffix.lower() != ".npz":
        raise ValueError(f"OUT: expected a .npz file, got {out.name!r}")
    F = spinal.frames(pts, lengths=lengths, method=a.method, on_invalid="skip")
    np.savez_compressed(out, points=pts, lengths=lengths, frames=F)
    _say(a.quiet, f"frames of {len(lengths):,} curve(s), {len(pts):,} points → {out} "
                  f"(arrays points (N, 3), lengths (C,), frames (N, 3, 3) with columns "
                  f"r, s = t × r and the unit tangent t)")
    return 0


def info(a: argparse.Namespace) -> int:
    import spinal

    _check_paths(a)
    path = pathlib.Path(a.file)
    suffix = path.suffix.lower()
    lines = [f"{path}"]
    if suffix in (".trk", ".tck", ".trx", ".npy", ".csv", ".txt", ".xyz") or (
            suffix in (".vtp", ".vtk") and path.exists() and _only_lines(path)):
        s = read_curves(path)
        n = s.lengths
        pts = np.concatenate(s.points) if s.points else np.zeros((0, 3))
        arc = np.array([np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in s.points])
        lines += [f"  curves         {len(n):,}", f"  points         {len(pts):,}"]
        if len(n):
            lines += [(f"  points/curve   {n.min():,} … {n.max():,} (median "
                      f"{int(np.median(n)):,})"),
                      (f"  length         {arc.min():.4g} … {arc.max():.4g} (median "
                      f"{np.median(arc):.4g})"),
                      f"  bounding box   {_box(pts)}"]
        for k in sorted(s.point_data):
            lines.append(f"  point data     {k}")
        for k in sorted(s.streamline_data):
            lines.append(f"  curve data     {k}")
    else:
        m = spinal.Mesh.load(path)
        st = m.edge_stats()
        lines += [f"  vertices       {len(m.vertices):,}", f"  faces          {len(m.faces):,}",
                  f"  bounding box   {_box(m.vertices)}",
                  f"  watertight     {m.is_watertight}"
                  + ("" if m.is_watertight else f" ({st['boundary']:,} boundary, "
                                                 f"{st['non_manifold']:,} non-manifold, "
                                                 f"{st['inconsistent']:,} inconsistent edges)"),
                  f"  area           {m.area:.6g}"]
        if m.is_watertight:
            lines.append(f"  volume         {m.volume:.6g}")
        for k in sorted(m.point_data):
            lines.append(f"  point data     {k} {np.asarray(m.point_data[k]).shape[1:]}")
    print("\n".join(lines))
    return 0


def _only_lines(path: pathlib.Path) -> bool:
    """Whether the VTK file holds polylines and no polygons (streamlines, not a mesh)."""
    from .io import _need

    d = _need("pyvista").read(str(path))
    return getattr(d, "n_lines", 0) > 0 and getattr(d, "n_faces_strict", 0) == 0


def _box(x: np.ndarray) -> str:
    if len(x) == 0:
        return "empty"
    lo, hi = x.min(0), x.max(0)
    return " × ".join(f"[{a:.4g}, {b:.4g}]" for a, b in zip(lo, hi, strict=True))


def add_commands(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """The ``tube``, ``frames`` and ``info`` sub-commands on an argparse sub-parser set."""
    t = sub.add_parser(
        "tube", help="tube every streamline of a file and write the mesh",
        description="Sweep a tube around every curve of IN (streamlines or one (n, 3) "
                    "curve) and write the mesh to OUT (.ply, .vtp, .obj, .stl, .glb; "
                    "colours are written as vertex colours). Curves with fewer than two "
                    "distinct points or with NaN are skipped with a warning.",
        epilog=TUBE_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    t.add_argument("input", metavar="IN")
    t.add_argument("output", metavar="OUT")
    r = t.add_mutually_exclusive_group()
    r.add_argument("--radius", type=float, default=0.25,
                   help="tube radius in the file's units (default 0.25)")
    r.add_argument("--radius-from", metavar="FIELD",
                   help="per-point (or per-streamline) data of IN to use as the radius")
    t.add_argument("--sides", type=int, default=8, help="sides of the tube (default 8)")
    t.add_argument("--color", metavar="orientation|FIELD",
                   help="vertex colours: 'orientation' (|tangent| as RGB) or data of IN "
                        "(RGB, or a scalar through the viridis colour map)")
    t.add_argument("--float32", action="store_true", help="float32 vertices (half the size)")
    t.add_argument("--join", choices=["round", "bevel", "miter"], default="round",
                   help="joins at sharp corners (default round)")
    t.add_argument("--quiet", "-q", action="store_true", help="no progress or summary")
    t.set_defaults(run=tube)
    f = sub.add_parser(
        "frames", help="rotation-minimising frames of every curve of a file",
        description="Compute rotation-minimising frames of every curve of IN and write "
                    "OUT.npz with the arrays points (N, 3), lengths (C,) and frames (N, 3, 3) "
                    "(columns: the reference vector r, s = t × r and the unit tangent t; see "
                    "spinal.frames). Curves with NaN are skipped (their rows are NaN).",
        epilog="example:\n  python -m spinal frames fornix.trk fornix_frames.npz",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    f.add_argument("input", metavar="IN")
    f.add_argument("output", metavar="OUT.npz")
    f.add_argument("--method", default="double_reflection",
                   help="frame method (default double_reflection)")
    f.add_argument("--quiet", "-q", action="store_true")
    f.set_defaults(run=frames)
    i = sub.add_parser(
        "info", help="counts, bounding box, watertightness and volume of a file",
        description="Print what FILE holds: for streamlines the counts, lengths and bounding "
                    "box; for a mesh the counts, bounding box, whether it is watertight, its "
                    "area and volume.",
        epilog="examples:\n  python -m spinal info fornix.trk\n  python -m spinal info "
               "fornix.vtp", formatter_class=argparse.RawDescriptionHelpFormatter)
    i.add_argument("file", metavar="FILE")
    i.set_defaults(run=info)


def run(a: argparse.Namespace) -> int:
    """Run the sub-command of the parsed arguments ``a``: its status, 1 after an error of
    the input (one line on stderr), 130 after Ctrl-C."""
    import warnings

    def one_line(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                 file: TextIO | None = None, line: str | None = None) -> None:
        print(f"spinal {a.command}: warning: {message}", file=sys.stderr)

    try:
        with warnings.catch_warnings():
            warnings.showwarning = one_line
            out: int = a.run(a)
            return out
    except KeyboardInterrupt:
        print("spinal: interrupted", file=sys.stderr)
        return 130
    except (ValueError, TypeError, FileNotFoundError, ImportError, MemoryError,
            OSError) as exc:
        print(f"spinal {a.command}: error: {exc}", file=sys.stderr)
        return 1
