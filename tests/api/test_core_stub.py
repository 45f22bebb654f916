"""The type stub of the compiled core (``python/spinal/_core.pyi``) matches the module: the
same public functions, each with the same parameter names in the same order (pyo3 functions
carry ``__text_signature__``, which ``inspect.signature`` reads)."""

import ast
import inspect
from pathlib import Path

import pytest

import spinal
from spinal import _core

STUB = Path(spinal.__file__).with_name("_core.pyi")


def stub_functions(text: str) -> dict[str, list[str]]:
    """Top-level ``def`` names of a stub and their parameter names in order."""
    tree = ast.parse(text)
    out = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            a = node.args
            out[node.name] = [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]
    return out


def core_functions() -> dict[str, list[str]]:
    out = {}
    for name in dir(_core):
        f = getattr(_core, name)
        if name.startswith("_") or not callable(f) or inspect.isclass(f):
            continue
        out[name] = list(inspect.signature(f).parameters)
    return out


def mismatches(stub: dict[str, list[str]], core: dict[str, list[str]]) -> list[str]:
    bad = [f"{n}: in the stub, not in _core" for n in sorted(stub.keys() - core.keys())]
    bad += [f"{n}: in _core, not in the stub" for n in sorted(core.keys() - stub.keys())]
    bad += [
        f"{n}: stub parameters {stub[n]} != _core parameters {core[n]}"
        for n in sorted(stub.keys() & core.keys())
        if stub[n] != core[n]
    ]
    return bad


def test_stub_matches_the_compiled_module():
    core = core_functions()
    assert len(core) > 20
    bad = mismatches(stub_functions(STUB.read_text(encoding="utf-8")), core)
    assert not bad, "_core.pyi is stale:\n" + "\n".join(bad)


def test_stub_check_catches_a_broken_stub():
    text = STUB.read_text(encoding="utf-8")
    core = core_functions()
    renamed = text.replace("def ph_eval(\n    control_points", "def ph_eval(\n    cp", 1)
    assert renamed != text
    want = (
        "ph_eval: stub parameters ['cp', 's', 'derivative'] != _core parameters "
        "['control_points', 's', 'derivative']"
    )
    assert mismatches(stub_functions(renamed), core) == [want]
    dropped = text.replace("def quat_continuous(", "def _quat_continuous(", 1)
    assert "quat_continuous: in _core, not in the stub" in mismatches(stub_functions(dropped), core)


def test_stub_classes_match_the_compiled_module():
    """The compiled classes (``Field``) and their public methods are in the stub (besides
    the types that exist for the checker only: ``TypedDict`` shapes of returned dicts)."""
    tree = ast.parse(STUB.read_text(encoding="utf-8"))
    stub = {n.name: {m.name for m in n.body if isinstance(m, ast.FunctionDef)}
            for n in tree.body if isinstance(n, ast.ClassDef)
            and not any(isinstance(b, ast.Name) and b.id == "TypedDict" for b in n.bases)}
    core = {n: getattr(_core, n) for n in dir(_core)
            if not n.startswith("_") and inspect.isclass(getattr(_core, n))}
    assert stub.keys() == core.keys()
    for name, cls in core.items():
        methods = {m for m in vars(cls) if not m.startswith("__") or m in (
            "__call__", "__add__", "__radd__", "__len__", "__reduce__")}
        assert methods <= stub[name], (name, methods - stub[name])


@pytest.mark.parametrize("name", sorted(core_functions()))
def test_every_core_function_has_a_doc(name):
    assert (getattr(_core, name).__doc__ or "").strip(), name
