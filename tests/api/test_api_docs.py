"""The public API is documented and its type stubs match the implementation.

* Every public function and class, and every public method, property, classmethod and
  staticmethod of a public class, has a docstring (``help()`` shows something real).
* For each public module with a stub (``spinal/__init__.pyi``, ``fields.pyi``,
  ``quaternions.pyi``, ``curves.pyi``, ``ph.pyi``), every name of ``__all__`` is declared in
  the stub, every public member of every public class too (including the attributes the
  implementation assigns to ``self``), and every function's parameters — names, kinds
  (positional / keyword-only / ``*args`` / ``**kwargs``) and defaults — equal
  ``inspect.signature`` of the implementation. The stub is read with :mod:`ast`, so a
  deleted or stale stub entry fails here (a type checker that finds a ``.pyi`` ignores the
  ``.py`` beside it, so a gap in a stub hides the name from users' type checking).
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import textwrap
from pathlib import Path

import pytest

import spinal

PKG = Path(spinal.__file__).parent
STUBS = {
    spinal: PKG / "__init__.pyi",
    spinal.curves: PKG / "curves.pyi",
    spinal.fields: PKG / "fields.pyi",
    spinal.ph: PKG / "ph.pyi",
    spinal.quaternions: PKG / "quaternions.pyi",
}
MODULES = list(STUBS)
# modules typed inline (no stub): their docstrings are checked too
DOCUMENTED = [*MODULES, spinal.io]
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


# ---------------------------------------------------------------------------- stubs


def _is_overload(fn: ast.FunctionDef) -> bool:
    return any((isinstance(d, ast.Name) and d.id == "overload")
               or (isinstance(d, ast.Attribute) and d.attr == "overload")
               for d in fn.decorator_list)


def _decorators(node) -> set[str]:
    out = set()
    for d in node.decorator_list:
        d = d.func if isinstance(d, ast.Call) else d
        out.add(d.id if isinstance(d, ast.Name) else d.attr if isinstance(d, ast.Attribute)
                else "")
    return out


def _declarations(body) -> dict[str, list]:
    """name -> the stub nodes declaring it (several for overloads)."""
    out: dict[str, list] = {}
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            out.setdefault(node.name, []).append(node)
        elif isinstance(node, ast.ImportFrom):
            for a in node.names:
                out.setdefault(a.asname or a.name, []).append(node)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            out.setdefault(node.target.id, []).append(node)
        elif isinstance(node, ast.Assign):
            for t in node.targets:
                if isinstance(t, ast.Name):
                    out.setdefault(t.id, []).append(node)
    return out


def _stub_tree(mod) -> ast.Module:
    path = STUBS[mod]
    assert path.exists(), f"no stub {path.name} for {mod.__name__}"
    return ast.parse(path.read_text(), filename=str(path))


_KIND = inspect.Parameter


def _stub_params(fn: ast.FunctionDef, drop_first: bool = False):
    """[(name, kind, default node or None)] of a stub function."""
    a = fn.args
    pos = a.posonlyargs + a.args
    defaults = [None] * (len(pos) - len(a.defaults)) + list(a.defaults)
    out = [(p.arg, _KIND.POSITIONAL_ONLY if i < len(a.posonlyargs) else
            _KIND.POSITIONAL_OR_KEYWORD, d) for i, (p, d) in enumerate(zip(pos, defaults))]
    if a.vararg:
        out.append((a.vararg.arg, _KIND.VAR_POSITIONAL, None))
    out += [(p.arg, _KIND.KEYWORD_ONLY, d) for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    if a.kwarg:
        out.append((a.kwarg.arg, _KIND.VAR_KEYWORD, None))
    return out[1:] if drop_first else out


def _dataclass_params(cls: ast.ClassDef):
    """The constructor of a stub ``@dataclass`` or ``NamedTuple``: its annotated fields."""
    return [(n.target.id, _KIND.POSITIONAL_OR_KEYWORD, n.value) for n in cls.body
            if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name)
            and not n.target.id.startswith("_")]


def _same_default(node, value) -> bool:
    try:
        stub_value = ast.literal_eval(node)
    except ValueError:
        return False
    return stub_value is not Ellipsis and repr(stub_value) == repr(value)


def _compare(where: str, sig: inspect.Signature, overloads: list[list]) -> list[str]:
    """Differences between the implementation's signature and the stub's (overloads)."""
    want = [(p.name, p.kind) for p in sig.parameters.values()]
    errors = []
    for params in overloads:
        got = [(n, k) for n, k, _ in params]
        if got != want:
            errors.append(f"{where}: stub parameters {[(n, k.name) for n, k in got]} != "
                          f"implementation {[(n, k.name) for n, k in want]}")
            return errors
    for p in sig.parameters.values():
        stub_defaults = [d for params in overloads for n, _, d in params if n == p.name]
        if p.default is _KIND.empty:
            if any(d is not None for d in stub_defaults):
                errors.append(f"{where}: {p.name} has no default in the implementation")
            continue
        present = [d for d in stub_defaults if d is not None]
        # an overload may leave a default out to narrow a flag (Literal[True]), not all
        if not present:
            errors.append(f"{where}: {p.name} has no default in the stub "
                          f"(implementation: {p.default!r})")
        for d in present:
            if not _same_default(d, p.default):
                errors.append(f"{where}: default of {p.name} is {ast.unparse(d)} in the stub, "
                              f"{p.default!r} in the implementation")
    return errors


def _functions(nodes) -> list[ast.FunctionDef]:
    fns = [n for n in nodes if isinstance(n, ast.FunctionDef)]
    overloads = [f for f in fns if _is_overload(f)]
    return overloads or fns[-1:]


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


def check_module(mod) -> list[str]:
    """Every way the stub of ``mod`` differs from the implementation (empty: in sync)."""
    tree = _stub_tree(mod)
    top = _declarations(tree.body)
    errors = []
    if "__all__" in top:
        stub_all = set(ast.literal_eval(top["__all__"][0].value))
        if stub_all != set(mod.__all__):
            errors.append(f"{mod.__name__}: stub __all__ differs by "
                          f"{sorted(stub_all ^ set(mod.__all__))}")
    for name in mod.__all__:
        obj = getattr(mod, name)
        where = f"{mod.__name__}.{name}"
        if name not in top:
            errors.append(f"{where}: not declared in {STUBS[mod].name}")
            continue
        if inspect.isfunction(obj):
            fns = _functions(top[name])
            if not fns:
                errors.append(f"{where}: not a function in the stub")
                continue
            errors += _compare(where, inspect.signature(obj), [_stub_params(f) for f in fns])
        elif inspect.isclass(obj):
            cls_nodes = [n for n in top[name] if isinstance(n, ast.ClassDef)]
            if not cls_nodes:
                errors.append(f"{where}: not a class in the stub")
                continue
            errors += _check_class(where, obj, cls_nodes[0], top)
    # no stale public entries: what the stub defines exists at runtime
    for name, nodes in top.items():
        if name.startswith("_"):
            continue
        if any(isinstance(n, (ast.FunctionDef, ast.ClassDef, ast.AnnAssign, ast.Assign))
               for n in nodes) and not hasattr(mod, name):
            errors.append(f"{mod.__name__}: the stub declares {name}, which does not exist")
    return errors


def _check_class(where: str, cls: type, node: ast.ClassDef, top: dict) -> list[str]:
    body = _declarations(node.body)
    # what the class and its bases declared in the same stub provide (inherited attributes)
    inherited = set()
    for base in cls.__mro__:
        for n in top.get(base.__name__, []):
            if isinstance(n, ast.ClassDef):
                inherited |= set(_declarations(n.body))
    errors = []
    is_record = dataclasses.is_dataclass(cls) or (issubclass(cls, tuple)
                                                  and hasattr(cls, "_fields"))
    # the constructor
    if is_record:
        if "__init__" in body:
            params = [_stub_params(f, True) for f in _functions(body["__init__"])]
        else:
            if dataclasses.is_dataclass(cls) and "dataclass" not in _decorators(node):
                errors.append(f"{where}: a dataclass; decorate the stub with @dataclass")
            params = [_dataclass_params(node)]
        errors += _compare(f"{where}()", inspect.signature(cls), params)
    elif "__init__" in vars(cls):
        if "__init__" not in body:
            errors.append(f"{where}.__init__: not declared in the stub")
        else:
            errors += _compare(f"{where}.__init__", inspect.signature(cls.__init__),
                               [_stub_params(f) for f in _functions(body["__init__"])])
    # methods, properties, class attributes
    fields = set(getattr(cls, "_fields", ()))
    if dataclasses.is_dataclass(cls):
        fields |= {f.name for f in dataclasses.fields(cls)}
    for attr, member in vars(cls).items():
        if attr == "__init__" or attr in fields or (attr.startswith("_")
                                                   and attr not in API_DUNDERS):
            continue
        w = f"{where}.{attr}"
        if attr not in body:
            errors.append(f"{w}: not declared in the stub")
            continue
        fns = _functions(body[attr])
        if isinstance(member, property):
            if not fns or "property" not in _decorators(fns[0]):
                errors.append(f"{w}: a property; declare it with @property in the stub")
        elif isinstance(member, (classmethod, staticmethod)):
            kind = type(member).__name__
            if not fns or kind not in _decorators(fns[0]):
                errors.append(f"{w}: a {kind}; declare it with @{kind} in the stub")
                continue
            errors += _compare(w, inspect.signature(getattr(cls, attr)),
                               [_stub_params(f, kind == "classmethod") for f in fns])
        elif inspect.isfunction(member):
            if not fns:
                errors.append(f"{w}: a method, not a function in the stub")
                continue
            errors += _compare(w, inspect.signature(member), [_stub_params(f) for f in fns])
        elif not any(isinstance(n, (ast.AnnAssign, ast.Assign, ast.FunctionDef))
                     for n in body[attr]):
            errors.append(f"{w}: an attribute; declare it as `{attr}: type` in the stub")
    for field in sorted(fields):
        if field not in body:
            errors.append(f"{where}.{field}: field not declared in the stub")
    for attr in sorted(_self_attributes(cls) - set(vars(cls))):
        if attr not in inherited:
            errors.append(f"{where}.{attr}: instance attribute not declared in the stub")
    return errors


@pytest.mark.parametrize("mod", MODULES, ids=lambda m: m.__name__)
def test_stub_matches_the_implementation(mod):
    errors = check_module(mod)
    assert not errors, "\n".join(errors)


def _mutated_stub(tmp_path, mod, old: str, new: str):
    """A copy of ``mod``'s stub with one edit, installed in place of the real one."""
    text = STUBS[mod].read_text()
    assert old in text, old
    path = tmp_path / STUBS[mod].name
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize("old, new, message", [
    # a function deleted from the stub
    ("def tube(", "def _tube(", "spinal.tube: not declared"),
    # a default that drifted
    ("miter_limit: float = 4.0,\n    split_seams", "miter_limit: float = 3.0,\n    split_seams",
     "default of miter_limit"),
    # a renamed parameter
    ("def closing_angle(\n    points:", "def closing_angle(\n    pts:", "closing_angle"),
    # a property deleted from a class
    ("    def is_watertight(self)", "    def _is_watertight(self)", "Mesh.is_watertight"),
    # an instance attribute deleted
    ("    fold_over: ", "    _fold_over: ", "Mesh.fold_over"),
    # a dataclass field deleted
    ("    vertices_added: int\n", "", "DeformReport"),
])
def test_the_stub_check_catches_drift(tmp_path, monkeypatch, old, new, message):
    monkeypatch.setitem(STUBS, spinal, _mutated_stub(tmp_path, spinal, old, new))
    errors = check_module(spinal)
    assert any(message in e for e in errors), errors


def test_the_stub_check_reads_the_other_stubs(tmp_path, monkeypatch):
    cases = [
        (spinal.fields, "def twist(", "def _twist(", "spinal.fields.twist"),
        (spinal.quaternions, "def spin(", "def _spin(", "spinal.quaternions.spin"),
        (spinal.curves, "    def rmf(", "    def _rmf(", "Helix.rmf"),
        (spinal.ph, "    def segments(self)", "    def _segments(self)", "PHSpline.segments"),
    ]
    for mod, old, new, message in cases:
        monkeypatch.setitem(STUBS, mod, _mutated_stub(tmp_path, mod, old, new))
        errors = check_module(mod)
        assert any(message in e for e in errors), (mod.__name__, errors)


def test_stubs_are_packaged():
    """maturin ships everything under ``python-source`` (``python/``); the marker tells type
    checkers to use the stubs (PEP 561)."""
    assert (PKG / "py.typed").exists()
    for path in STUBS.values():
        assert path.parent == PKG


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
