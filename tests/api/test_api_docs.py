"""The public API is documented and its inline type annotations are complete.

* Every public function and class, and every public method, property, classmethod and
  staticmethod of a public class, has a docstring (``help()`` shows something real).
* The public modules (``spinal``, ``spinal.curves``, ``spinal.fields``, ``spinal.ph``,
  ``spinal.quaternions``, ``spinal.io``) are typed inline (PEP 561, ``py.typed``): every public
  function and method annotates all its parameters and its return value, every property its
  value, every public attribute a class assigns to ``self`` is declared with a type in the
  class body, and every annotation resolves (a misspelt or stale name fails here). No ``.pyi``
  beside a public module: a type checker that finds one ignores the ``.py`` beside it.
  ``tests/api/test_types.py`` runs ``mypy --strict`` on the package.
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import sys
import textwrap
import types
import typing
from pathlib import Path

import pytest

import spinal

PKG = Path(spinal.__file__).parent
# the public modules: documented and typed inline
DOCUMENTED = [spinal, spinal.curves, spinal.fields, spinal.ph, spinal.quaternions, spinal.io]
# dunder methods that are part of the API when a class defines them
API_DUNDERS = {"__init__", "__call__", "__len__", "__add__", "__radd__", "__iter__",
               "__getitem__", "__contains__"}


def public(mod):
    names = getattr(mod, "__all__", None) or [n for n in dir(mod) if not n.startswith("_")]
    for n in names:
        obj = getattr(mod, n)
        if inspect.isfunction(obj) or inspect.isclass(obj) or inspect.isbuiltin(obj):
            yield f"{mod.__name__}.{n}", obj


def public_classes(mod):
    return [(n, o) for n, o in public(mod) if inspect.isclass(o)]


def _ids(v):
    return v if isinstance(v, str) else ""


# ---------------------------------------------------------------------------- docstrings


@pytest.mark.parametrize("name, obj", [p for m in DOCUMENTED for p in public(m)], ids=_ids)
def test_public_objects_have_docstrings(name, obj):
    doc = inspect.getdoc(obj)
    assert doc and len(doc) > 40, f"{name} has no real docstring"
    if inspect.isclass(obj):
        missing = []
        for attr, member in vars(obj).items():
            if attr.startswith("_"):
                continue
            if isinstance(member, (classmethod, staticmethod)):
                member = member.__func__
            documented = (member.__doc__ or "").strip()
            if (isinstance(member, property) or inspect.isfunction(member)) and not documented:
                missing.append(attr)
        assert not missing, f"{name}: no docstring on {missing}"


def test_the_docstring_check_sees_properties():
    """A property without a docstring is caught (the check is not vacuous)."""

    class Probe:
        """A class with an undocumented property, for the check above to catch."""

        @property
        def bare(self):
            return 1

    with pytest.raises(AssertionError, match="bare"):
        test_public_objects_have_docstrings("Probe", Probe)


def test_help_of_frames_tells_the_conventions():
    doc = inspect.getdoc(spinal.frames)
    for word in ("columns ``(r, s, t)``", "s_i = t_i × r_i", "unit tangent", "ValueError",
                 "closed", "double_reflection"):
        assert word in doc


# ---------------------------------------------------------------------------- annotations


def _type_namespace() -> dict:
    """Names the annotations may use that their modules import only for type checkers."""
    from spinal import _core

    return {"Mesh": spinal.Mesh, "Curve": spinal.curves.Curve, "Field": _core.Field,
            "PHSpline": spinal.ph.PHSpline}


def _home(obj) -> dict:
    """The globals of the module that defines ``obj``: a public submodule's names live in
    its private twin ``spinal._<name>`` (see ``spinal._public.publish``)."""
    package, _, name = obj.__module__.rpartition(".")
    private = sys.modules.get(f"{package}._{name}")
    if private is not None and getattr(private, obj.__name__, None) is obj:
        return vars(private)
    return vars(sys.modules[obj.__module__])


def _unresolved(fn, where: str) -> list[str]:
    try:
        namespace = fn.__globals__ if inspect.isfunction(fn) else _home(fn)
        typing.get_type_hints(fn, globalns=namespace, localns=_type_namespace())
    except (NameError, TypeError, AttributeError) as e:  # a stale annotation
        return [f"{where}: an annotation does not resolve ({type(e).__name__}: {e})"]
    return []


def _check_function(where: str, fn, *, method: bool = False) -> list[str]:
    """Missing or unresolvable annotations of a Python function (``self``/``cls`` exempt)."""
    if not inspect.isfunction(fn):
        return []  # compiled (spinal._core): typed by _core.pyi, see test_core_stub.py
    sig = inspect.signature(fn)
    params = list(sig.parameters.values())
    if method and params and params[0].name in ("self", "cls"):
        params = params[1:]
    errors = [f"{where}: parameter {p.name} has no annotation" for p in params
              if p.annotation is inspect.Parameter.empty]
    if sig.return_annotation is inspect.Signature.empty:
        errors.append(f"{where}: no return annotation")
    return errors + _unresolved(fn, where)


def _declared(cls) -> set[str]:
    """Attributes declared with a type in the class body of ``cls`` or a base."""
    out = set()
    for base in cls.__mro__:
        out |= set(vars(base).get("__annotations__", {}))
        out |= {n for n, v in vars(base).items() if isinstance(v, property)}
    return out


def _self_attributes(cls) -> set[str]:
    """Public attributes the implementation assigns to ``self`` in the class's methods."""
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    except (OSError, TypeError):
        return set()
    out = set()
    for node in ast.walk(tree):
        targets = (node.targets if isinstance(node, ast.Assign)
                   else [node.target] if isinstance(node, ast.AnnAssign) else [])
        for t in targets:
            for e in (t.elts if isinstance(t, ast.Tuple) else [t]):
                if (isinstance(e, ast.Attribute) and isinstance(e.value, ast.Name)
                        and e.value.id == "self" and not e.attr.startswith("_")):
                    out.add(e.attr)
    return out


def _check_class(where: str, cls: type) -> list[str]:
    errors = []
    if dataclasses.is_dataclass(cls) or (issubclass(cls, tuple) and hasattr(cls, "_fields")):
        errors += _unresolved(cls, where)  # the fields' annotations
    for attr, member in vars(cls).items():
        if attr.startswith("_") and attr not in API_DUNDERS:
            continue
        w = f"{where}.{attr}"
        if isinstance(member, property):
            for acc in (member.fget, member.fset):
                if acc is not None:
                    errors += _check_function(w, acc, method=True)
        elif isinstance(member, (classmethod, staticmethod)):
            errors += _check_function(w, member.__func__, method=isinstance(member, classmethod))
        elif inspect.isfunction(member):
            errors += _check_function(w, member, method=True)
    declared = _declared(cls)
    for attr in sorted(_self_attributes(cls) - declared):
        if not any(attr in vars(b) for b in cls.__mro__):
            errors.append(f"{where}.{attr}: instance attribute not declared with a type in the "
                          f"class body")
    return errors


def check_module(mod) -> list[str]:
    """Every public name of ``mod`` whose annotations are missing or do not resolve."""
    errors = []
    for name in mod.__all__:
        obj = getattr(mod, name)
        where = f"{mod.__name__}.{name}"
        if inspect.isclass(obj):
            errors += _check_class(where, obj)
        elif callable(obj) and not inspect.ismodule(obj):
            errors += _check_function(where, inspect.unwrap(obj))
    return errors


@pytest.mark.parametrize("mod", DOCUMENTED, ids=lambda m: m.__name__)
def test_the_api_is_annotated(mod):
    errors = check_module(mod)
    assert not errors, "\n".join(errors)


def _probe(monkeypatch, source: str):
    """A throwaway public module made from ``source`` (for the checks to catch drift)."""
    mod = types.ModuleType("probe")
    monkeypatch.setitem(sys.modules, "probe", mod)
    # the source of a probe class is not on disk: read it from the probe text
    monkeypatch.setattr(inspect, "getsource", lambda obj: textwrap.dedent(source))
    exec(compile(textwrap.dedent(source), "<probe>", "exec"), vars(mod))  # noqa: S102
    return mod


@pytest.mark.parametrize("source, message", [
    # a parameter without a type
    ("""
     from __future__ import annotations
     def f(x: float, y) -> float:
         return x
     __all__ = ["f"]
     """, "probe.f: parameter y has no annotation"),
    # no return type
    ("""
     from __future__ import annotations
     def f(x: float):
         return x
     __all__ = ["f"]
     """, "probe.f: no return annotation"),
    # an annotation naming something that does not exist
    ("""
     from __future__ import annotations
     def f(x: Meshh) -> None:
         pass
     __all__ = ["f"]
     """, "probe.f: an annotation does not resolve"),
    # a property without a type
    ("""
     from __future__ import annotations
     class C:
         @property
         def area(self):
             return 1.0
     __all__ = ["C"]
     """, "probe.C.area: no return annotation"),
    # a method's parameter without a type
    ("""
     from __future__ import annotations
     class C:
         def scale(self, k) -> None:
             pass
     __all__ = ["C"]
     """, "probe.C.scale: parameter k has no annotation"),
    # an instance attribute not declared in the class body
    ("""
     from __future__ import annotations
     class C:
         def __init__(self) -> None:
             self.fold_over = 1
     __all__ = ["C"]
     """, "probe.C.fold_over: instance attribute not declared"),
    # a stale field type of a dataclass
    ("""
     from __future__ import annotations
     from dataclasses import dataclass
     @dataclass
     class R:
         volume: Flaot
     __all__ = ["R"]
     """, "probe.R: an annotation does not resolve"),
])
def test_the_annotation_check_catches_drift(monkeypatch, source, message):
    mod = _probe(monkeypatch, source)
    errors = check_module(mod)
    assert any(message in e for e in errors), errors


def test_the_annotation_check_passes_a_typed_probe(monkeypatch):
    source = """
        from __future__ import annotations
        class C:
            fold_over: int
            def __init__(self, k: int = 1) -> None:
                self.fold_over = k
            @property
            def area(self) -> float:
                return 1.0
        def f(x: float, *args: int, mesh: Mesh | None = None, **kw: str) -> C:
            return C()
        __all__ = ["C", "f"]
        """
    mod = _probe(monkeypatch, source)
    assert check_module(mod) == []


def test_typed_inline_and_packaged():
    """maturin ships everything under ``python-source`` (``python/``); ``py.typed`` tells type
    checkers to read the inline annotations (PEP 561). The compiled core is the one module
    with a stub; a ``.pyi`` beside a public module would shadow its annotations."""
    assert (PKG / "py.typed").exists()
    assert sorted(p.name for p in PKG.glob("*.pyi")) == ["_core.pyi"]


@pytest.mark.parametrize("mod", [spinal.curves, spinal.fields, spinal.io, spinal.ph,
                                 spinal.quaternions], ids=lambda m: m.__name__)
def test_submodules_show_only_their_public_names(mod):
    """The public submodules hold their public names and nothing else that looks public
    (no NumPy, helpers or typing names): the implementation lives in private modules."""
    shown = sorted(n for n in dir(mod) if not n.startswith("_"))
    assert shown == sorted(mod.__all__)
    for name in mod.__all__:
        obj = getattr(mod, name)
        if inspect.isclass(obj) or inspect.isfunction(obj):
            assert obj.__module__ == mod.__name__, name  # documented and pickled here
