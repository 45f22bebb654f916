"""The documentation site (docs/: the API reference from the docstrings, the gallery notebooks
from their stored outputs, the notes) builds with warnings as errors."""

import pathlib
import subprocess
import sys

import pytest

pytestmark = pytest.mark.slow  # builds the documentation

pytest.importorskip("sphinx")
pytest.importorskip("numpydoc")
pytest.importorskip("myst_nb")

ROOT = pathlib.Path(__file__).parents[2]


def test_docs_build_without_warnings(tmp_path):
    run = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         "-d", str(tmp_path / "doctrees"), str(ROOT / "docs"), str(tmp_path / "html")],
        check=False, capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-8000:]
    html = tmp_path / "html"
    api = (html / "api" / "frames.html").read_text()
    assert "closing_angle" in api and "Parameters" in api
    gallery = sorted((html / "gallery").glob("*.html"))
    assert len(gallery) == len(list((ROOT / "notebooks").glob("*.ipynb")))
    for page in gallery:  # every notebook shows its stored pictures
        assert "<img" in page.read_text(), page.name
