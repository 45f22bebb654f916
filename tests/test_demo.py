"""The README's first command: python -m spinal demo."""

import numpy as np
import trimesh

from spinal.__main__ import main


def test_demo_writes_results(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "wrote:" in out and "closing angle -2.8757120" in out
    F = np.load(tmp_path / "torus_knot_frames.npy")
    assert F.shape == (2049, 3, 3) and np.array_equal(F[0], F[-1])
    mesh = trimesh.load(tmp_path / "torus_knot_ribbon.ply", process=False)
    assert len(mesh.faces) == 2 * 2048
    rows = np.genfromtxt(tmp_path / "helix_convergence.csv", delimiter=",", names=True,
                         dtype=None, encoding=None)
    dr = rows["max_error_rad"][rows["method"] == "double_reflection"]
    assert np.all(np.abs(dr[2:] / dr[1:-1] - 1 / 16) < 0.01)  # 4th order
