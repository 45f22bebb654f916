"""The package type-checks under ``mypy --strict`` (its inline annotations, ``_core.pyi`` and
the settings in ``pyproject.toml``): a signature that drifts from what the code does, an
untyped helper or a wrong annotation fails here."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def test_mypy_strict_passes(tmp_path):
    pytest.importorskip("mypy")
    cmd = [sys.executable, "-m", "mypy", "--strict", "--cache-dir", str(tmp_path / "cache"),
           "python/spinal"]
    res = subprocess.run(cmd, check=False, cwd=ROOT, capture_output=True, text=True,
                         timeout=600)
    assert res.returncode == 0, (
        f"{' '.join(cmd[2:])} failed ({res.returncode}):\n{res.stdout}{res.stderr}")
