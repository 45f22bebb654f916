"""Packaging: the release workflow passes its linters, and the wheel installs and runs where
there is no Rust toolchain.

* The workflow (``.github/workflows/release.yml``) is audited by zizmor (pedantic persona,
  offline) and, where actionlint is installed, linted by it. Neither can run the workflow
  itself: that happens on the public repository's CI.
* The wheel test builds the abi3 wheel with maturin (reusing ``target/``), checks its
  metadata and that auditwheel calls it manylinux and abi3audit finds only stable-ABI
  symbols, installs it into a fresh virtual environment with no cargo on ``PATH`` and runs
  ``python -m spinal demo`` and the README's first example there.
"""

from __future__ import annotations

import os
import pathlib
import shutil
import subprocess
import sys
import zipfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
WORKFLOW = ROOT / ".github" / "workflows" / "release.yml"


def _tool(name: str) -> str | None:
    """The executable ``name`` beside this interpreter or on PATH."""
    here = pathlib.Path(sys.executable).parent / name
    return str(here) if here.exists() else shutil.which(name)


def test_release_workflow_passes_zizmor():
    zizmor = _tool("zizmor")
    if zizmor is None:
        pytest.skip("zizmor is not installed (the test extra installs it)")
    r = subprocess.run([zizmor, "--offline", "--persona", "pedantic", str(WORKFLOW)],
                       capture_output=True, text=True, timeout=120, check=False)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "No findings" in r.stdout + r.stderr


def test_release_workflow_passes_actionlint():
    actionlint = _tool("actionlint")
    if actionlint is None:
        pytest.skip("actionlint is not installed (a Go binary; see docs/release.md)")
    r = subprocess.run([actionlint, str(WORKFLOW)], capture_output=True, text=True,
                       timeout=120, check=False)
    assert r.returncode == 0, r.stdout + r.stderr


def test_release_workflow_builds_every_platform_and_publishes_by_trusted_publishing():
    """What the workflow promises, read from the file: the five wheels, the sdist, and a
    publish job that needs them all and holds only the OIDC permission."""
    text = WORKFLOW.read_text()
    for needle in ("target: [x86_64, aarch64]", "manylinux:", "macos-14", "macos-13",
                   "windows-latest", "command: sdist", "needs: [linux, macos, windows, sdist]",
                   "id-token: write", "pypa/gh-action-pypi-publish@", "tags: [\"v*\"]"):
        assert needle in text, needle
    assert "password" not in text and "secrets." not in text  # no token: trusted publishing


@pytest.mark.slow
def test_wheel_installs_and_runs_without_rust(tmp_path):
    maturin = _tool("maturin")
    if maturin is None:
        pytest.skip("maturin is not installed (the test extra installs it)")
    out = tmp_path / "dist"
    r = subprocess.run([maturin, "build", "--release", "--out", str(out)], cwd=ROOT,
                       capture_output=True, text=True, timeout=1800, check=False)
    assert r.returncode == 0, r.stderr[-3000:]
    (wheel,) = out.glob("*.whl")
    # one wheel for every CPython >= 3.10 on this platform, manylinux-compliant
    assert "-cp310-abi3-" in wheel.name, wheel.name
    if sys.platform == "linux":
        assert "manylinux" in wheel.name, wheel.name
        for tool, args, words in (("auditwheel", ["show"], "manylinux"),
                                  ("abi3audit", ["--strict", "--report"], "")):
            exe = _tool(tool)
            if exe is None:
                continue
            a = subprocess.run([exe, *args, str(wheel)], capture_output=True, text=True,
                               timeout=300, check=False)
            assert a.returncode == 0, a.stdout + a.stderr
            assert words in a.stdout + a.stderr
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
        meta = z.read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    assert "spinal/py.typed" in names and "spinal/_core.abi3.so" in names or any(
        n.startswith("spinal/_core") for n in names)
    for field in ("Requires-Python: >=3.10", "License: MIT", "Classifier: Typing :: Typed",
                  "Description-Content-Type: text/markdown", "Requires-Dist: numpy",
                  "Provides-Extra: io"):
        assert field in meta, field
    assert any(n.endswith("LICENSE") for n in names)
    # a fresh environment with no Rust toolchain on PATH
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep)
                                  if not (pathlib.Path(p) / "cargo").exists())
    assert shutil.which("cargo", path=env["PATH"]) is None
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=300)
    py = str(venv / ("Scripts" if os.name == "nt" else "bin") / "python")
    r = subprocess.run([py, "-m", "pip", "install", "-q", str(wheel)], env=env,
                       capture_output=True, text=True, timeout=900, check=False)
    assert r.returncode == 0, r.stderr[-3000:]
    r = subprocess.run([py, "-m", "spinal", "demo", "--out", str(tmp_path / "demo")],
                       env=env, cwd=tmp_path, capture_output=True, text=True, timeout=600,
                       check=False)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    readme = (ROOT / "README.md").read_text()
    block = readme.split("```python\n")[1].split("```", 1)[0]
    r = subprocess.run([py, "-c", block], env=env, cwd=tmp_path, capture_output=True,
                       text=True, timeout=600, check=False)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
