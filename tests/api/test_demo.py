"""The README's first command: python -m spinal demo. Every file it prints exists and is not
empty, the meshes load in trimesh with the volumes it prints (and the knot tube's with an
independent one), and the volume errors it prints are small and behave as theory says."""

import re
import sys

import numpy as np
import pytest
import trimesh

from spinal.__main__ import main
from spinal.curves import TorusKnot

pytestmark = pytest.mark.slow  # runs the demo in a subprocess


def run_demo(out, capsys):
    assert main(["demo", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    head, _, tail = text.partition("\nwrote:\n")
    assert tail, text
    paths = [line.strip() for line in tail.splitlines() if line.strip()]
    return head, {p.rsplit("/", 1)[-1]: p for p in paths}


def number(pattern, text):
    m = re.search(pattern, text)
    assert m, f"{pattern!r} not in the demo's output"
    return float(m.group(1))


try:  # the demo makes its pictures only with pyvista
    import pyvista  # noqa: F401

    HAS_PYVISTA = True
except ImportError:
    HAS_PYVISTA = False

FLOAT = r"([-+]?\d+\.\d+(?:e[-+]\d+)?)"


def test_demo_writes_results(tmp_path, capsys):
    out, files = run_demo(tmp_path, capsys)
    assert "closing angle -2.8757120" in out
    for name, path in files.items():
        assert path.startswith(str(tmp_path)) and (tmp_path / name).stat().st_size > 0, name
    assert {"torus_knot_frames.npy", "torus_knot_ribbon.ply", "helix_convergence.csv",
            "torus_knot_tube.ply", "torus_knot_tube.obj", "dented_ring.ply",
            "bent_bar_none.ply", "bent_bar_radial.ply"} <= set(files)
    # meshes keep float64 positions, normals and texture coordinates (spinal's writer)
    assert "meshes written by spinal's built-in writer (PLY float64" in out
    for name, props in (("torus_knot_tube.ply", ("x", "nx", "s", "t")),
                        ("bent_bar_radial.ply", ("x", "s", "t"))):
        header = (tmp_path / name).read_bytes().split(b"end_header")[0].decode()
        for prop in props:
            assert f"property double {prop}\n" in header, (name, header)

    F = np.load(tmp_path / "torus_knot_frames.npy")
    assert F.shape == (2049, 3, 3) and np.array_equal(F[0], F[-1])
    mesh = trimesh.load(tmp_path / "torus_knot_ribbon.ply", process=False)
    assert len(mesh.faces) == 2 * 2048
    rows = np.genfromtxt(tmp_path / "helix_convergence.csv", delimiter=",", names=True,
                         dtype=None, encoding=None)
    dr = rows["max_error_rad"][rows["method"] == "double_reflection"]
    assert np.all(np.abs(dr[2:] / dr[1:-1] - 1 / 16) < 0.01)  # 4th order

    # The knot tube: the printed volume, and the volume of a tube of polygon area A along a
    # curve of length L, A·L (Pappus–Guldin for tubes), up to the O(h²) mesh error.
    vol = number(r"closed knot tube: .* volume " + FLOAT, out)
    x = TorusKnot().sample(2049)
    length = np.linalg.norm(np.diff(x, axis=0), axis=1).sum()
    area = 0.5 * 24 * 0.12**2 * np.sin(2 * np.pi / 24)
    for ext in ("ply", "obj"):
        tube = trimesh.load(tmp_path / f"torus_knot_tube.{ext}", process=False)
        assert len(tube.vertices) == 2048 * 24 and tube.is_watertight
        assert tube.volume == pytest.approx(vol, rel=2e-6)  # float32 PLY, 6 printed digits
        assert abs(tube.volume / (area * length) - 1) < 2e-3

    # Tubes round a circle vs Pappus: small errors, falling 4× per doubling (2nd order).
    pappus = [float(e) for e in re.findall(r"spine points: .* relative error " + FLOAT, out)]
    assert len(pappus) == 4 and pappus[0] < 2e-3
    assert np.allclose(np.array(pappus[:-1]) / pappus[1:], 4, rtol=0.02)

    # The dent: the printed volume is the file's, and the change is small.
    dent = number(r"relative volume change " + FLOAT + r" \(integration", out)
    assert abs(dent) < 1e-3
    ring = trimesh.load(tmp_path / "dented_ring.ply", process=False)
    assert ring.is_watertight
    assert ring.volume == pytest.approx(number(r"by refinement\): volume " + FLOAT, out),
                                        rel=1e-6)

    # The bent bar: uncorrected = closed form 1 − ȳ/R up to the mesh error; radial keeps it.
    bar = number(r"bar beside its spine .* volume " + FLOAT, out)
    none = number(r"uncorrected \(solution='none'\) " + FLOAT, out)
    radial = number(r"corrected \(solution='radial'\) " + FLOAT, out)
    assert bar == pytest.approx(0.2 * 0.2 * 1.0, rel=1e-12)
    assert abs(none + 0.25) < 1e-4
    assert abs(number(r"−ȳ/R = .*, difference " + FLOAT, out) - (none + 0.25)) < 1e-6
    assert abs(radial) < 1e-4
    for solution, change in (("none", none), ("radial", radial)):
        m = trimesh.load(tmp_path / f"bent_bar_{solution}.ply", process=False)
        assert m.is_watertight
        assert m.volume == pytest.approx(bar * (1 + change), rel=1e-6)

    # The picture, when pyvista can render.
    if HAS_PYVISTA:
        assert "torus_knot_tube.png" in files, out
        png = tmp_path / "torus_knot_tube.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        from PIL import Image

        image = np.asarray(Image.open(png).convert("RGB"))
        assert image.shape == (480, 640, 3) and len(np.unique(image.reshape(-1, 3), axis=0)) > 10
        # one labelled picture per part
        for name, shape in (("frames_ribbon.png", (480, 640)), ("dented_ring.png", (480, 640)),
                            ("bent_bar.png", (420, 960))):
            image = np.asarray(Image.open(tmp_path / name).convert("RGB"))
            assert image.shape[:2] == shape and len(np.unique(image.reshape(-1, 3), axis=0)) > 10


def test_demo_without_trimesh_uses_the_builtin_writer(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "trimesh", None)  # `import trimesh` raises ImportError
    monkeypatch.setitem(sys.modules, "pyvista", None)  # and no picture: quicker
    out, files = run_demo(tmp_path, capsys)
    monkeypatch.undo()
    assert "meshes written by spinal's built-in writer" in out
    assert "picture: skipped" in out and "torus_knot_tube.png" not in files
    assert "pip install 'spinal[viz]'" in out
    assert not any(name.endswith(".png") for name in files)
    for name in files:
        assert (tmp_path / name).stat().st_size > 0, name
    vol = number(r"closed knot tube: .* volume " + FLOAT, out)
    for ext in ("ply", "obj"):
        tube = trimesh.load(tmp_path / f"torus_knot_tube.{ext}", process=False)
        assert tube.is_watertight and tube.volume == pytest.approx(vol, rel=1e-6)
    assert "\nvt " in (tmp_path / "torus_knot_tube.obj").read_text()  # uv kept


def test_cli_help_and_version(capsys):
    import spinal

    assert main([]) == 0
    text = capsys.readouterr().out
    assert "usage: python -m spinal" in text and "demo" in text
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.strip() == f"spinal {spinal.__version__}"


def test_demo_prints_no_warning(tmp_path):
    """The demo renders off-screen without a word on stderr (no VTK/pyvista warnings)."""
    import os
    import subprocess

    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY",
                                                            "PYVISTA_OFF_SCREEN",
                                                            "VTK_DEFAULT_OPENGL_WINDOW")}
    run = subprocess.run([sys.executable, "-m", "spinal", "demo", "--out", str(tmp_path)],
                         check=False, capture_output=True, text=True, env=env,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stderr == ""
    if HAS_PYVISTA:
        assert "bent_bar.png" in run.stdout
