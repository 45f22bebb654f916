"""Command line: ``python -m spinal`` (help), ``python -m spinal --version``, the whole-file
commands ``tube IN OUT``, ``frames IN OUT.npz`` and ``info FILE`` (see ``spinal._cli``), and
``python -m spinal demo [--out DIR]``, a small end-to-end run on built-in curves.

The demo computes rotation-minimising frames on the torus knot of Wang et al. (2008) and on a
helix, measures their accuracy against an independent closed form (the helix RMF) and the
published closing angle; sweeps a closed tube around the knot and tubes around a circle,
measuring their volumes against Pappus' theorem; pushes a dent into a tube with a
divergence-free field and reports the volume change; bends a bar that sits off its spine with
and without Zhuo's volume correction and compares the uncorrected change with its closed form.
It writes the frames, a convergence table and the meshes (PLY with float64 positions, normals
and texture coordinates, and OBJ with 17 digits, by :meth:`spinal.Mesh.save`) to DIR and, when
pyvista is installed (``pip install 'spinal[viz]'``), one labelled picture per part; it prints
every path and volume error. Needs only NumPy; takes a few seconds.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
from collections.abc import Sequence
from typing import Any

import numpy as np

import spinal
from spinal import _cli
from spinal.curves import Helix, TorusKnot


def save_mesh(mesh: spinal.Mesh, path: pathlib.Path) -> pathlib.Path:
    """Write ``mesh`` as PLY or OBJ (by the suffix) with :meth:`spinal.Mesh.save`: float64
    positions, the normals and the texture coordinates are kept (trimesh's PLY writer would
    store float32 and drop the texture coordinates)."""
    return mesh.save(path)


def mesh_writer() -> str:
    return ("spinal's built-in writer (PLY float64 with normals and uv, OBJ 17 digits with "
            "vn and vt)")


def ribbon(x: np.ndarray, F: np.ndarray, width: float) -> spinal.Mesh:
    """The developable ribbon x ± width·r as a triangle strip (an open surface)."""
    v = np.empty((2 * len(x), 3))
    v[0::2], v[1::2] = x - width * F[:, :, 0], x + width * F[:, :, 0]
    a = 2 * np.arange(len(x) - 1)
    faces = np.concatenate([np.c_[a, a + 1, a + 3], np.c_[a, a + 3, a + 2]])
    return spinal.Mesh(v, faces)


def square_profile(y0: float, y1: float, z0: float, z1: float, k: int) -> np.ndarray:
    """The rectangle [y0, y1] × [z0, z1] as a polygon with k vertices per side."""
    e = np.linspace(0, 1, k, endpoint=False)
    out: np.ndarray = np.r_[np.c_[y0 + (y1 - y0) * e, z0 + 0 * e], np.c_[y1 + 0 * e, z0 + (z1 - z0) * e],
                 np.c_[y1 - (y1 - y0) * e, z1 + 0 * e], np.c_[y0 + 0 * e, z1 - (z1 - z0) * e]]
    return out


def demo(out: pathlib.Path) -> int:
    out.mkdir(parents=True, exist_ok=True)
    written = []

    knot = TorusKnot()
    x = knot.sample(2049)
    F = spinal.frames(x, closed=True)
    np.save(out / "torus_knot_frames.npy", F)
    written.append(out / "torus_knot_frames.npy")
    written.append(save_mesh(ribbon(x, F, 0.04), out / "torus_knot_ribbon.ply"))
    alpha = spinal.closing_angle(x)
    seam = np.abs(F[-1] - F[0]).max()

    helix = Helix(1.0, 0.5)
    c = np.hypot(1.0, 0.5)
    lines = ["n,method,max_error_rad"]
    rows = []
    for n in (64, 128, 256, 512, 1024):
        u = np.linspace(0, 20 / c, n + 1)
        exact = helix.rmf(u)
        for method in ("double_reflection", "rotation", "projection"):
            G = spinal.frames(helix.point(u), method=method, initial=exact[0][:, 0])
            err = np.arctan2(np.linalg.norm(np.cross(G[:, :, 0], exact[:, :, 0]), axis=1),
                             np.einsum("ij,ij->i", G[:, :, 0], exact[:, :, 0])).max()
            lines.append(f"{n},{method},{err:.6e}")
            rows.append((n, method, err))
    (out / "helix_convergence.csv").write_text("\n".join(lines) + "\n")
    written.append(out / "helix_convergence.csv")

    # A closed tube around the knot, written as PLY and OBJ.
    tube = spinal.tube(x, 0.12, sides=24, closed=True)
    for ext in ("ply", "obj"):
        written.append(save_mesh(tube, out / f"torus_knot_tube.{ext}"))
    # Tubes around a circle of radius R: the volume tends to Pappus' 2πR·A (A the polygon's
    # area) at 2nd order in the spine spacing.
    R, r, sides = 1.0, 0.25, 24
    area = 0.5 * sides * r**2 * np.sin(2 * np.pi / sides)
    pappus = 2 * np.pi * R * area
    ring_rows = []
    for n in (32, 64, 128, 256):
        t = 2 * np.pi * np.arange(n) / n
        ring = spinal.tube(np.c_[R * np.cos(t), R * np.sin(t), 0 * t], r, sides, closed=True)
        ring_rows.append((n, ring.volume, abs(ring.volume / pappus - 1)))
    # A tool pushes a dent into the circle tube (divergence-free field, RK4, refinement).
    ring = spinal.tube(np.c_[R * np.cos(t), R * np.sin(t), 0 * t], r, sides, closed=True)
    tool = spinal.fields.translation([R + r + 0.25, 0, 0], 0.2, [-0.5, 0, 0])
    dented, report = spinal.deform(ring, tool, 0.4, estimate=True)
    tool_end = np.array([R + r + 0.25 - 0.5 * 0.4, 0, 0])  # the tool's centre at the end
    written.append(save_mesh(dented, out / "dented_ring.ply"))

    # Fleshing: a bar beside its spine (cross-section [0.15, 0.35] × [-0.1, 0.1], centroid
    # ȳ = 0.25 off the spine, towards the centre of curvature) bent with the spine into an
    # arc of radius Rb. The uncorrected map (rigid in every normal plane) scales volume by
    # 1 − y/Rb at distance y towards that centre, in all by 1 − ȳ/Rb; the
    # radial correction keeps every piece's volume (what is left is the mesh's error).
    Rb, ybar = 1.0, 0.25
    xs = np.linspace(-0.5, 0.5, 81)
    axes = np.tile(np.array([[0.0, 0, 1], [1, 0, 0], [0, 1, 0]]), (len(xs), 1, 1))  # r=y, s=z
    bar = spinal.sweep(np.c_[xs, 0 * xs, 0 * xs], square_profile(0.15, 0.35, -0.1, 0.1, 8),
                       frames=axes)
    arc = np.linspace(-1.5, 1.5, 301)  # arc length along the spine
    rest_spine = np.c_[arc, 0 * arc, 0 * arc]
    posed_spine = np.c_[Rb * np.sin(arc / Rb), Rb * (1 - np.cos(arc / Rb)), 0 * arc]
    bar_change, bent_bars = {}, {}
    for solution in ("none", "radial"):
        V = spinal.flesh(bar.vertices, rest_spine, posed_spine, solution=solution)
        bent = spinal.Mesh(V, bar.faces, uv=bar.uv)  # texture coordinates ride along
        bent_bars[solution] = bent
        bar_change[solution] = bent.volume / bar.volume - 1
        written.append(save_mesh(bent, out / f"bent_bar_{solution}.ply"))

    try:
        pictures = render_pictures(out, x, F, alpha, tube, ring, dented, report, tool_end,
                                   bar, bent_bars, bar_change, posed_spine)
        written += pictures
        picture = None
    except ImportError as e:  # pyvista missing: the demo runs without pictures
        picture = (f"skipped ({e}; pip install 'spinal[viz]' from the package index once "
                   "published, or pip install -e '.[viz]' from a clone, for the pictures: "
                   "frames ribbon, knot tube, dent, bent bar)")
    except Exception as e:  # noqa: BLE001 - no OpenGL: say so and go on
        picture = f"skipped (could not render off-screen: {type(e).__name__}: {e})"

    print(f"spinal {spinal.__version__} demo")
    print(f"  torus knot, 2048 segments, closed: RMF closing angle {alpha:+.9f} rad "
          f"(published −2.875711998), seam mismatch {seam:.1e}")
    print("  helix (a=1, b=0.5, length 20) vs closed-form RMF, max angle error (rad):")
    print("      n  double_reflection   rotation   projection")
    for n in (64, 128, 256, 512, 1024):
        errs = {m: err for (k, m, err) in rows if k == n}
        print(f"  {n:5d}  {errs['double_reflection']:17.3e}  {errs['rotation']:9.3e}  "
              f"{errs['projection']:11.3e}")
    print(f"  closed knot tube: {len(tube.vertices)} vertices, watertight {tube.is_watertight}, "
          f"volume {tube.volume:.6f}")
    print(f"  tube (ρ = {r}, {sides} sides) round a circle (R = {R}) vs Pappus 2πR·A = "
          f"{pappus:.9f}:")
    for n, vol, err in ring_rows:
        print(f"    {n:4d} spine points: volume {vol:.9f}, relative error {err:.2e}")
    print(f"  tool pushing a dent into that tube (RK4, {report.steps} steps, "
          f"+{report.vertices_added} vertices by refinement): volume {report.volume:.9f}, "
          f"relative volume change {report.relative_change:+.2e} (integration "
          f"{report.integration_error:+.1e}, mesh {report.mesh_error:+.1e})")
    print(f"  bar beside its spine (centroid {ybar} off it, volume {bar.volume:.9f}, "
          f"{len(bar.vertices)} vertices) bent to radius {Rb}: relative volume change")
    print(f"    uncorrected (solution='none') {bar_change['none']:+.6e}, closed form "
          f"−ȳ/R = {-ybar / Rb:+.6e}, difference "
          f"{bar_change['none'] + ybar / Rb:+.1e}")
    print(f"    corrected (solution='radial') {bar_change['radial']:+.1e}")
    print(f"  meshes written by {mesh_writer()}")
    if picture is not None:
        print(f"  picture: {picture}")
    print("wrote:")
    for p in written:
        print(f"  {p}")
    return 0


def _pyvista() -> Any:
    """pyvista set up to render off-screen without a window and without warnings: on a Linux
    machine with no display VTK renders through EGL instead of trying X first."""
    import os

    os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY")
                                                 or os.environ.get("WAYLAND_DISPLAY")):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv

    pv.OFF_SCREEN = True
    return pv


def render_pictures(out: pathlib.Path, x: np.ndarray, F: np.ndarray, alpha: float | np.ndarray,
                    tube: spinal.Mesh, ring: spinal.Mesh, dented: spinal.Mesh,
                    report: spinal.DeformReport, tool_end: np.ndarray, bar: spinal.Mesh,
                    bent_bars: dict[str, spinal.Mesh], bar_change: dict[str, float],
                    posed_spine: np.ndarray) -> list[pathlib.Path]:
    """One labelled PNG per part of the demo (needs pyvista): the frames as a ribbon, the
    closed knot tube, the dent with its volume report and the bar bent without and with the
    volume correction, side by side."""
    pv = _pyvista()
    written: list[pathlib.Path] = []

    def finish(pl: Any, name: str) -> None:
        path = out / name
        pl.screenshot(str(path))
        pl.close()
        written.append(path)

    # 1. frames: a ribbon x ± w·r along the closed RMF, coloured by arc length
    w = 0.05
    pts = np.empty((2 * len(x), 3))
    pts[0::2], pts[1::2] = x - w * F[:, :, 0], x + w * F[:, :, 0]
    a = 2 * np.arange(len(x) - 1)
    faces = np.concatenate([np.c_[a, a + 1, a + 3], np.c_[a, a + 3, a + 2]])
    poly = spinal.Mesh(pts, faces).to_pyvista()
    poly["arc length"] = np.repeat(np.r_[0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))], 2)
    pl = pv.Plotter(off_screen=True, window_size=(640, 480))
    pl.add_mesh(poly, scalars="arc length", cmap="viridis", show_scalar_bar=False,
                smooth_shading=True)
    pl.add_text(f"Rotation-minimising frames on a torus knot ({len(x) - 1} segments)\n"
                f"ribbon along r; closing angle {alpha:+.6f} rad spread over the loop",
                position="upper_left", font_size=10)
    pl.view_isometric()
    finish(pl, "frames_ribbon.png")

    # 2. the closed knot tube
    pl = pv.Plotter(off_screen=True, window_size=(640, 480))
    pl.add_mesh(tube.to_pyvista(), color="#c9a227", smooth_shading=True)
    pl.add_text(f"Closed torus-knot tube: {len(tube.vertices):,} vertices,\n"
                f"watertight {tube.is_watertight}, volume {tube.volume:.6f}",
                position="upper_left", font_size=10)
    pl.view_isometric()
    finish(pl, "torus_knot_tube.png")

    # 3. the dent, with the tool where it stopped and the volume report
    pl = pv.Plotter(off_screen=True, window_size=(640, 480))
    pl.add_mesh(dented.to_pyvista(), color="#d9a066", smooth_shading=True)
    pl.add_mesh(pv.Sphere(radius=0.2, center=tool_end), color="#4060a0", opacity=0.35)
    pl.add_text(f"A divergence-free tool pushes a dent into a tube\n"
                f"volume change {report.relative_change:+.1e} (integration "
                f"{report.integration_error:+.0e}, mesh {report.mesh_error:+.0e})\n"
                f"{report.steps} RK4 steps, +{report.vertices_added} vertices by refinement",
                position="upper_left", font_size=10)
    # the view direction of the dent, then the camera moved until the whole ring and the
    # tool fit below the caption
    pl.camera_position = [(3.2, -2.2, 1.9), (0.6, 0.0, 0.0), (0, 0, 1)]
    pl.reset_camera()  # fits the bounding sphere: generous for a flat ring
    pl.camera.zoom(1.5)
    finish(pl, "dented_ring.png")

    # 4. the bar bent with its spine: uncorrected and radial correction, side by side
    pl = pv.Plotter(off_screen=True, shape=(1, 2), window_size=(960, 420))
    near = np.abs(posed_spine[:, 0]) < 0.75
    for k, (solution, label) in enumerate((("none", "no correction (solution='none')"),
                                           ("radial", "volume correction ('radial')"))):
        pl.subplot(0, k)
        pl.add_mesh(bar.to_pyvista(), color="grey", opacity=0.25)
        pl.add_mesh(bent_bars[solution].to_pyvista(), color="#c8a27a", smooth_shading=True)
        pl.add_mesh(pv.lines_from_points(posed_spine[near]), color="#3060a0", line_width=3)
        pl.add_text(f"{label}\nvolume change {bar_change[solution]:+.4%}",
                    position="upper_left", font_size=10)
        pl.camera_position = "xy"
    pl.link_views()
    finish(pl, "bent_bar.png")
    return written


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m spinal",
        description="spinal: moving frames, sweeps and volume-preserving deformations along "
                    "3D curves. Run `python -m spinal demo` for a tour that writes its results "
                    "(and, with spinal[viz], pictures) to a folder.")
    ap.add_argument("--version", action="version", version=f"spinal {spinal.__version__}")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND")
    d = sub.add_parser("demo", help="run the built-in example and write results to a folder")
    d.add_argument("--out", default="spinal-demo", help="output folder (default: spinal-demo)")
    _cli.add_commands(sub)
    a = ap.parse_args(argv)
    if a.command == "demo":
        return demo(pathlib.Path(a.out))
    if a.command is not None:
        return _cli.run(a)
    ap.print_help()
    return 0


if __name__ == "__main__":
    sys.exit(main())
