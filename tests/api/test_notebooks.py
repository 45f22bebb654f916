"""The committed gallery notebooks are what tools/make_notebooks.py writes, executed: the same
cells (type and source, in order) and stored outputs, so that they show their pictures without
being run. (The suite also executes them through nbmake.) Regenerate with
``python tools/make_notebooks.py``."""

import importlib.util
import pathlib

import pytest

nbformat = pytest.importorskip("nbformat")

ROOT = pathlib.Path(__file__).parents[2]


def generator():
    found = importlib.util.spec_from_file_location("make_notebooks",
                                                   ROOT / "tools" / "make_notebooks.py")
    module = importlib.util.module_from_spec(found)
    found.loader.exec_module(module)
    return module


BOOKS = generator().BOOKS


def test_every_committed_notebook_has_a_generator():
    committed = {p.stem for p in (ROOT / "notebooks").glob("*.ipynb")}
    assert committed == set(BOOKS)


@pytest.mark.parametrize("name", sorted(BOOKS))
def test_notebook_matches_generator_and_has_outputs(name):
    path = ROOT / "notebooks" / f"{name}.ipynb"
    book = nbformat.read(path, as_version=4)
    expected = BOOKS[name].cells
    got = [(c.cell_type, c.source) for c in book.cells]
    want = [(c.cell_type, c.source) for c in expected]
    assert got == want, (f"{path.name} differs from tools/make_notebooks.py: "
                         f"run `python tools/make_notebooks.py {name}`")
    code = [c for c in book.cells if c.cell_type == "code"]
    assert all(c.execution_count is not None for c in code), f"{path.name} was not executed"
    outputs = [o for c in code for o in c.outputs]
    assert outputs, f"{path.name} has no outputs"
    assert not [o for o in outputs if o.output_type == "error"], f"{path.name} stored an error"
    # progress lines and warnings are not stored
    assert not [o for o in outputs if o.output_type == "stream" and o.name == "stderr"], path.name
    # at least one picture, and every picture small
    images = [o.data["image/png"] for o in outputs if "image/png" in o.get("data", {})]
    assert images, f"{path.name} stores no picture"
    assert max(len(i) for i in images) < 300_000, f"{path.name}: a picture over ~220 kB"
