"""Sphinx configuration of spinal's documentation: the API reference from the docstrings
(autodoc + numpydoc), the pages in docs/ (MyST Markdown) and the gallery notebooks rendered
from their stored outputs (myst-nb, never executed here). Build:
``python -m sphinx -W -b html docs docs/_build/html``."""

import pathlib
import shutil

import spinal

HERE = pathlib.Path(__file__).parent

project = "spinal"
author = "spinal contributors"
release = version = spinal.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_nb",
]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "images/README*"]
nb_execution_mode = "off"          # the notebooks are shown with their stored outputs
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]

autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
autodoc_typehints = "none"         # the signatures are in the docstrings' Parameters
numpydoc_show_class_members = False
numpydoc_validation_checks = set()
numpydoc_xref_param_type = False

html_theme = "alabaster"
html_static_path = []

# The gallery: the committed notebooks, copied next to the pages (docs/gallery/ is generated
# and not committed).
gallery = HERE / "gallery"
gallery.mkdir(exist_ok=True)
for nb in sorted((HERE.parent / "notebooks").glob("*.ipynb")):
    target = gallery / nb.name
    if not target.exists() or target.read_bytes() != nb.read_bytes():
        shutil.copyfile(nb, target)
for old in gallery.glob("*.ipynb"):
    if not (HERE.parent / "notebooks" / old.name).exists():
        old.unlink()
