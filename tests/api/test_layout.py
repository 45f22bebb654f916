"""Layout of the code: the Python package and the Rust crate import in one direction (no
cycle among their modules)."""

from __future__ import annotations

import ast
import os
import re
from pathlib import Path

import spinal

SRC = Path(__file__).resolve().parents[2] / "src"


def find_cycle(graph):
    """One cycle of the directed graph {node: set of nodes} as a list [a, b, ..., a], or None
    (depth-first search: an edge to a node still open closes a cycle)."""
    state = {}

    def visit(m, stack):
        state[m] = "open"
        for d in sorted(graph.get(m, ())):
            if state.get(d) == "open":
                return stack[stack.index(d):] + [d]
            if d not in state:
                found = visit(d, stack + [d])
                if found:
                    return found
        state[m] = "done"
        return None

    for m in sorted(graph):
        if m not in state:
            found = visit(m, [m])
            if found:
                return found
    return None


def test_the_package_imports_in_one_direction():
    """No import cycle among spinal's modules (module-level and function-level imports; the
    imports for type checkers only, under ``if TYPE_CHECKING:``, never run and are left out:
    annotations may name a class of a module that imports this one)."""
    pkg = Path(spinal.__file__).parent
    graph = {}
    for path in pkg.glob("*.py"):
        mod = path.stem
        deps = set()
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.If) and ast.unparse(node.test) in (
                    "TYPE_CHECKING", "typing.TYPE_CHECKING"):
                node.body = []  # (the walk below does not see them)
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                if node.module:
                    deps.add(node.module.split(".")[0])
                else:
                    deps.update(a.name for a in node.names)
        graph[mod] = {d for d in deps if (pkg / f"{d}.py").exists() and d != mod}
    graph.pop("__init__", None)
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)
    assert os.path.basename(str(pkg)) == "spinal"


# ----------------------------------------------------------------------------- Rust crate

def _strip(text):
    """The source without comments, string and char literals (kept as empty \"\")."""
    out, i = [], 0
    while i < len(text):
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = len(text) if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            i = len(text) if j < 0 else j + 2
        elif c == "r" and re.match(r"r#*\"", text[i:]) and (i == 0 or not text[i - 1].isalnum()):
            hashes = re.match(r"r(#*)\"", text[i:]).group(1)
            j = text.find('"' + hashes, i + 2 + len(hashes))
            out.append('""')
            i = len(text) if j < 0 else j + 1 + len(hashes)
        elif c == '"':
            j = i + 1
            while j < len(text) and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append('""')
            i = j + 1
        elif c == "'" and re.match(r"'(\\.|[^'\\])'", text[i:i + 4]):
            m = re.match(r"'(\\.|[^'\\])'", text[i:i + 4])
            out.append("' '")
            i += len(m.group(0))
        else:
            out.append(c)
            i += 1
    return "".join(out)


def _skip_item(code, i):
    """The index just past the item starting at code[i] (ends at `;` or a balanced `{}`)."""
    depth = 0
    while i < len(code):
        c = code[i]
        if c in "([":
            depth += 1
        elif c in ")]":
            depth -= 1
        elif c == ";" and depth == 0:
            return i + 1
        elif c == "{" and depth == 0:
            level = 0
            while i < len(code):
                if code[i] == "{":
                    level += 1
                elif code[i] == "}":
                    level -= 1
                    if level == 0:
                        return i + 1
                i += 1
        i += 1
    return i


_CFG_TEST = re.compile(r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*")


def _without_tests(code):
    """The code without `#[cfg(test)]` items, and the names of out-of-line test modules."""
    test_mods, out, i = set(), [], 0
    for m in _CFG_TEST.finditer(code):
        if m.start() < i:
            continue
        out.append(code[i:m.start()])
        end = _skip_item(code, m.end())
        decl = re.match(r"(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;", code[m.end():end])
        if decl:
            test_mods.add(decl.group(1))
        i = end
    out.append(code[i:])
    return "".join(out), test_mods


def _expand_use(tree):
    """The paths of a use tree: `a::{b, c::{d, e}}` -> [a::b, a::c::d, a::c::e]."""
    tree = re.sub(r"\s+", "", tree)
    tree = re.sub(r"\bas\w+", "", tree)  # `x as y` became `xasy`: drop the alias
    brace = tree.find("{")
    if brace < 0:
        return [tree]
    prefix, inner = tree[:brace], tree[brace + 1:tree.rfind("}")]
    parts, depth, start = [], 0, 0
    for k, c in enumerate(inner):
        if c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(inner[start:k])
            start = k + 1
    parts.append(inner[start:])
    return [prefix + q for p in parts if p for q in _expand_use(p)]


def rust_modules():
    """{module path (tuple of names): its file} for the crate's non-test modules."""
    mods, tests = {}, set()
    for path in sorted(SRC.rglob("*.rs")):
        rel = path.relative_to(SRC).with_suffix("").parts
        if rel == ("lib",):
            name = ()
        elif rel[-1] == "mod":
            name = rel[:-1]
        else:
            name = rel
        if name and name[-1] == "tests":
            continue
        mods[name] = path
    for name, path in list(mods.items()):
        _, test_mods = _without_tests(_strip(path.read_text(encoding="utf-8")))
        tests.update(name + (t,) for t in test_mods)
    return {n: p for n, p in mods.items() if not any(n[:len(t)] == t for t in tests)}


_USE = re.compile(r"\buse\s+([^;]+);")
_INLINE = re.compile(r"(?<![\w:])(\w+(?:\s*::\s*\w+)+)")


def rust_use_graph():
    """{module: set of modules it names in a `use` or a path `crate::…`, `super::…`, `self::…`
    or `child::…`}.

    A path `a::b::Item` is an edge to the longest prefix that is a module of the crate (a
    file; `mod.rs` is its folder's module), and a path to an item a module re-exports
    (`pub use x::Item`) is an edge to the module `x` that defines it. `mod` declarations are
    not edges, and neither are a parent's paths to its own descendants: a folder's `mod.rs`
    declares its children, re-exports them, holds what they share (the folder's trait and
    checks, which they use as `super::Tool`) and dispatches to them. So cycles are sought
    among siblings and across folders: a child reaching a sibling through the parent's
    re-export is an edge to that sibling."""
    mods = rust_modules()
    reexports = {}  # (module, name) -> module that defines it
    graph = {}
    code_of = {n: _without_tests(_strip(p.read_text(encoding="utf-8")))[0] for n, p in mods.items()}

    def absolute(here, path, inline=False):
        segs = [s for s in re.sub(r"\s+", "", path).split("::") if s]
        if not segs:
            return None
        if segs[0] == "crate":
            base, segs = (), segs[1:]
        elif segs[0] in ("super", "self"):
            base = here
            while segs and segs[0] in ("super", "self"):
                if segs[0] == "super":
                    base = base[:-1]
                segs = segs[1:]
        elif here + (segs[0],) in mods:
            base = here
        else:
            return None  # an external crate or a name in scope
        return base + tuple(segs)

    def module_of(full):
        for k in range(len(full), -1, -1):
            if full[:k] in mods:
                return full[:k], full[k:]
        return None, ()

    uses = {}
    for name, code in code_of.items():
        found = []
        for m in _USE.finditer(code):
            public = re.search(r"\bpub(?:\([^)]*\))?\s*$", code[max(0, m.start() - 20):m.start()])
            for p in _expand_use(m.group(1)):
                full = absolute(name, p)
                if full is not None:
                    found.append((full, bool(public)))
        rest = _USE.sub(";", code)
        for m in _INLINE.finditer(rest):
            full = absolute(name, m.group(1), inline=True)
            if full is not None:
                found.append((full, False))
        uses[name] = found
        for full, public in found:
            target, tail = module_of(full)
            if public and target is not None and len(tail) == 1 and tail[0] not in ("*", "self"):
                reexports[(name, tail[0])] = target

    def resolve(full):
        target, tail = module_of(full)
        seen = set()
        while target is not None and len(tail) == 1 and (target, tail[0]) in reexports:
            if (target, tail[0]) in seen:
                break
            seen.add((target, tail[0]))
            target = reexports[(target, tail[0])]
        return target

    for name, found in uses.items():
        deps = set()
        for full, public in found:
            target = resolve(full)
            if target is None or target == name:
                continue
            if target[:len(name)] == name:
                continue  # a parent naming its own descendant
            deps.add(target)
        graph[name] = deps
    return graph


def _label(mod):
    return "crate::" + "::".join(mod) if mod else "crate"


def test_the_rust_modules_use_each_other_in_one_direction():
    """No cycle among the crate's modules (files) through `use` and `crate::`/`super::`
    paths, `#[cfg(test)]` modules and `tests.rs` files left out."""
    graph = rust_use_graph()
    assert ("deform", "tube") in graph and ("frames",) in graph
    assert ("deform", "shape") in graph[("deform", "tube")]
    cycle = find_cycle(graph)
    assert cycle is None, "use cycle: " + " -> ".join(map(_label, cycle))
