"""Every public function and class has a docstring, and every top-level name is declared in
the type stubs (``python/spinal/__init__.pyi``) — so ``help()`` and type checkers see the
whole API."""

import ast
import inspect
from pathlib import Path

import pytest

import spinal

MODULES = [spinal, spinal.curves, spinal.fields, spinal.ph, spinal.quaternions]
STUB = Path(spinal.__file__).with_name("__init__.pyi")


def public(mod):
    names = getattr(mod, "__all__", None) or [n for n in dir(mod) if not n.startswith("_")]
    for n in names:
        obj = getattr(mod, n)
        if inspect.isfunction(obj) or inspect.isclass(obj) or inspect.isbuiltin(obj):
            yield f"{mod.__name__}.{n}", obj


@pytest.mark.parametrize("name, obj", [p for m in MODULES for p in public(m)],
                         ids=lambda v: v if isinstance(v, str) else "")
def test_public_objects_have_docstrings(name, obj):
    doc = inspect.getdoc(obj)
    assert doc and len(doc) > 40, f"{name} has no real docstring"
    if inspect.isclass(obj):
        for attr, member in vars(obj).items():
            if attr.startswith("_") or not callable(member):
                continue
            assert inspect.getdoc(member), f"{name}.{attr} has no docstring"


def test_top_level_names_are_in_the_stub():
    tree = ast.parse(STUB.read_text())
    declared = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            declared.add(node.name)
        elif isinstance(node, ast.ImportFrom):
            declared.update(a.asname or a.name for a in node.names)
        elif isinstance(node, (ast.AnnAssign, ast.Assign)):
            targets = [node.target] if isinstance(node, ast.AnnAssign) else node.targets
            declared.update(t.id for t in targets if isinstance(t, ast.Name))
    missing = [n for n in spinal.__all__ if n not in declared]
    assert not missing, f"not declared in __init__.pyi: {missing}"


def test_help_of_frames_tells_the_conventions():
    doc = inspect.getdoc(spinal.frames)
    for word in ("columns ``(r, s, t)``", "s_i = t_i × r_i", "unit tangent", "ValueError",
                 "closed", "double_reflection"):
        assert word in doc
