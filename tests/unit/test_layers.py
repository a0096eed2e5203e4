"""The package's layers: each imports only from the layers below it, no import cycle, a
small package root and no two modules with one name.

Every import counts: at the top of a module, inside a function, and under
``TYPE_CHECKING`` (a type that needs a higher layer is a design that does too).
"""

from __future__ import annotations

import ast
import re
from collections import defaultdict
from pathlib import Path

import pytest

from tests.conftest import ROOT

PACKAGE = ROOT / "aou_dsl"

#: Each layer, lowest first. A module may import from its own layer and any layer before it.
#: The package root's modules are placed where they sit: ``version`` at the bottom, the API
#: facade just under the command line.
LAYERS = [
    ("version", "core"),
    ("lang",),
    ("robot",),
    ("compiler", "fit"),
    ("measuring",),
    ("safety",),
    ("driver",),
    ("synth",),
    ("dmp",),
    ("live",),
    ("media", "editor"),
    ("studio",),
    ("study",),
    ("api",),
    ("cli",),
    ("__main__", ""),
]
RANK = {name: i for i, names in enumerate(LAYERS) for name in names}
ROOT_MODULES_MAX = 6


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


MODULES = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _targets(module: str, path: Path) -> set[str]:
    """The package's modules that ``module`` imports, anywhere in its text."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".") if package else []
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            elif node.module and (node.module + ".").startswith("aou_dsl."):
                target = node.module.removeprefix("aou_dsl").lstrip(".")
            else:
                continue
            names = [f"{target}.{a.name}".lstrip(".") for a in node.names]
            found.update(n for n in names if n in MODULES)
            if not all(n in MODULES for n in names):  # names of the module itself
                found.add(target)
        elif isinstance(node, ast.Import):
            for a in node.names:
                if (a.name + ".").startswith("aou_dsl."):
                    found.add(a.name.removeprefix("aou_dsl").lstrip("."))
    found.discard(module)
    # importing a.b.c runs a/__init__ and a/b/__init__ first
    return {t for t in found if t in MODULES or t == ""}


GRAPH = {m: _targets(m, p) for m, p in MODULES.items()}


def _layer(module: str) -> str:
    return module.split(".")[0]


def test_every_module_belongs_to_a_layer():
    """Each top-level module or subpackage of aou_dsl has a place in the table of layers."""
    assert {_layer(m) for m in MODULES} <= set(RANK), {_layer(m) for m in MODULES} - set(RANK)


@pytest.mark.parametrize("module", sorted(m for m in MODULES if m))
def test_no_upward_import(module):
    """A module imports nothing from a layer above its own (the package facade, which
    imports its names on first use by name only, is above everything)."""
    mine = RANK[_layer(module)]
    upward = [t for t in GRAPH[module] if RANK[_layer(t)] > mine]
    assert not upward, (f"{MODULES[module].relative_to(ROOT)} imports "
                        + ", ".join(str(MODULES[t].relative_to(ROOT)) for t in upward))


def _cycles() -> list[list[str]]:
    """Every strongly connected component with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in GRAPH[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(GRAPH):
        if v not in index:
            visit(v)
    return out


def test_no_import_cycle():
    """No set of modules imports itself round, counting imports inside functions."""
    assert _cycles() == [], [[str(MODULES[m].relative_to(ROOT)) for m in c] for c in _cycles()]


def test_cycle_finder_finds_a_planted_cycle(monkeypatch):
    """The cycle check is not vacuous: an edge from the lowest module back up to one that
    imports it is reported."""
    planted = {m: set(t) for m, t in GRAPH.items()}
    planted["core.diagnostics"] = planted["core.diagnostics"] | {"lang.parse"}
    monkeypatch.setattr(__import__(__name__, fromlist=["GRAPH"]), "GRAPH", planted)
    assert any({"core.diagnostics", "lang.parse"} <= set(c) for c in _cycles())


def test_package_root_is_small():
    """The package root holds the facade, the API, ``__main__`` and the version only."""
    root = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert len(root) <= ROOT_MODULES_MAX, root


def test_no_two_modules_share_a_name():
    """A module's file name says what it holds, once in the package (``__init__`` aside)."""
    by_name = defaultdict(list)
    for p in PACKAGE.rglob("*.py"):
        if p.name != "__init__.py":
            by_name[p.name].append(str(p.relative_to(ROOT)))
    assert not {n: ps for n, ps in by_name.items() if len(ps) > 1}


def test_each_layer_states_its_public_face():
    """Each layer's ``__init__`` has a docstring saying what it holds."""
    for init in sorted(PACKAGE.glob("*/__init__.py")):
        tree = ast.parse(init.read_text())
        assert ast.get_docstring(tree), init.relative_to(ROOT)


def test_no_module_level_mutable_state():
    """No ``global`` statement, and no module-level dict, list or set that the module then
    changes (caches belong to the registry of ``aou_dsl.core.memo`` or to a session
    object)."""
    offenders = []
    for p in PACKAGE.rglob("*.py"):
        text = p.read_text()
        tree = ast.parse(text)
        for node in ast.walk(tree):
            if isinstance(node, ast.Global):
                offenders.append(f"{p.relative_to(ROOT)}:{node.lineno}: global")
        module_level = set()
        for node in tree.body:
            targets = [node.target] if isinstance(node, ast.AnnAssign) else (
                node.targets if isinstance(node, ast.Assign) else [])
            value = getattr(node, "value", None)
            if isinstance(value, (ast.Dict, ast.List, ast.Set)) or (
                    isinstance(value, ast.Call) and getattr(value.func, "id", "") in
                    ("dict", "list", "set", "defaultdict", "OrderedDict")):
                module_level.update(t.id for t in targets if isinstance(t, ast.Name))
        for name in module_level:
            mutated = re.search(rf"\b{name}\s*\[[^\]]*\]\s*=(?!=)|\b{name}\.(append|add|update|"
                                rf"setdefault|pop|clear|extend|insert|remove)\(", text)
            if mutated:
                line = text[: mutated.start()].count("\n") + 1
                offenders.append(f"{p.relative_to(ROOT)}:{line}: {name} is changed")
    assert not offenders, offenders


#: What makes a process-wide cache outside the registry of ``core/memo.py``.
_UNREGISTERED = ("cache", "lru_cache")


def _unregistered_caches(text: str, where: str) -> list[str]:
    """Each use of ``functools.cache`` or ``functools.lru_cache`` in ``text`` (as a
    decorator, called, or imported by name). ``functools.cached_property`` is a value
    kept on one object, not process-wide, and is allowed."""
    offenders = []
    tree = ast.parse(text)
    names = {"functools"} | {a.asname for node in ast.walk(tree)
                             if isinstance(node, ast.Import)
                             for a in node.names if a.name == "functools" and a.asname}
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr in _UNREGISTERED and \
                isinstance(node.value, ast.Name) and node.value.id in names:
            offenders.append(f"{where}:{node.lineno}: functools.{node.attr}")
        elif isinstance(node, ast.ImportFrom) and node.module == "functools":
            offenders += [f"{where}:{node.lineno}: from functools import {a.name}"
                          for a in node.names if a.name in _UNREGISTERED]
    return sorted(offenders, key=lambda o: int(o.split(":")[1]))


def test_every_cache_is_made_by_the_registry():
    """No module keeps a ``functools`` cache: each cache is made by
    ``aou_dsl.core.memo`` (``cached``, ``table``), where every one is registered, so
    a session reaches, measures and clears it (``core/memo.py`` itself aside)."""
    offenders = []
    for p in sorted(PACKAGE.rglob("*.py")):
        if p != PACKAGE / "core" / "memo.py":
            offenders += _unregistered_caches(p.read_text(), str(p.relative_to(ROOT)))
    assert not offenders, offenders


def test_a_planted_functools_cache_is_found():
    """The registry check is not vacuous: each way of writing a functools cache fails."""
    planted = ("import functools\n\n@functools.cache\ndef f(x):\n    return x\n\n"
               "@functools.lru_cache(maxsize=8)\ndef g(x):\n    return x\n\n"
               "h = functools.lru_cache(None)(len)\n"
               "from functools import cache as kept\n\n"
               "class A:\n    @functools.cached_property\n    def a(self):\n        return 1\n"
               "import functools as ft\n\n@ft.lru_cache\ndef k(x):\n    return x\n")
    assert [o.split(": ", 1)[1] for o in _unregistered_caches(planted, "x.py")] == [
        "functools.cache", "functools.lru_cache", "functools.lru_cache",
        "from functools import cache", "functools.lru_cache"]


def _class_memos(text: str, where: str) -> list[str]:
    """Each dict, list or set made in a class body that the module then changes through
    the class or one of its objects (one value shared by every object of the process: a
    cache no session reaches)."""
    offenders = []
    for cls in ast.walk(ast.parse(text)):
        if not isinstance(cls, ast.ClassDef):
            continue
        for node in cls.body:
            targets = [node.target] if isinstance(node, ast.AnnAssign) else (
                node.targets if isinstance(node, ast.Assign) else [])
            value = getattr(node, "value", None)
            if not (isinstance(value, (ast.Dict, ast.List, ast.Set)) or (
                    isinstance(value, ast.Call) and getattr(value.func, "id", "") in
                    ("dict", "list", "set", "defaultdict", "OrderedDict"))):
                continue
            for name in (t.id for t in targets if isinstance(t, ast.Name)):
                owner = rf"\b(self|cls|{cls.name})\.{name}"
                if not re.search(rf"\bself\.{name}\s*(:[^=]*)?=(?!=)", text) and re.search(
                        rf"{owner}\s*\[[^\]]*\]\s*=(?!=)|{owner}\.(append|add|update|"
                        rf"setdefault|pop|clear|extend|insert|remove)\(", text):
                    offenders.append(f"{where}:{node.lineno}: {cls.name}.{name} is changed")
    return offenders


def test_no_class_keeps_a_memo_of_its_own():
    """No class holds a container in its body that its objects fill: a memo that way is
    the process's, out of the registry's and a session's reach."""
    offenders = []
    for p in sorted(PACKAGE.rglob("*.py")):
        offenders += _class_memos(p.read_text(), str(p.relative_to(ROOT)))
    assert not offenders, offenders


def test_a_planted_class_memo_is_found():
    """The class check is not vacuous: a class-level dict filled through ``self`` or
    through the class fails; one each object sets for itself, or that is only read,
    does not."""
    planted = ("class A:\n    seen = {}\n    def f(self, x):\n        self.seen[x] = 1\n"
               "class B:\n    kept: dict = dict()\n    def f(self, x):\n"
               "        B.kept.setdefault(x, 1)\n"
               "class C:\n    names = {1: 2}\n    def f(self, x):\n        return self.names[x]\n"
               "class D:\n    own = {}\n    def __init__(self):\n        self.own = {}\n"
               "    def f(self, x):\n        self.own[x] = 1\n")
    assert [o.split(": ", 1)[1] for o in _class_memos(planted, "x.py")] == [
        "A.seen is changed", "B.kept is changed"]


def test_architecture_page_names_only_modules_that_exist():
    """docs/architecture.md names modules by path; each exists, and each layer of the
    table of layers is one."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    named = set(re.findall(r"aou_dsl/[\w/]+\.py", text))
    assert len(named) > 20
    assert [p for p in sorted(named) if not (ROOT / p).is_file()] == []
    table = re.findall(r"^\| `(\w+)`", text, re.M)
    assert set(table) - {"api"} <= set(RANK), table


def test_every_public_name_of_the_package_resolves():
    """Each name in ``aou_dsl.__all__`` imports from the module the facade names."""
    import aou_dsl

    for name in aou_dsl.__all__:
        assert getattr(aou_dsl, name) is not None, name


def test_every_code_is_a_constant_and_no_code_is_spelt_out():
    """aou_dsl.core.codes holds one constant per registered code (a misspelt one fails at
    import), and no module writes a code as a string literal."""
    from aou_dsl.core import codes
    from aou_dsl.core.rules import RULES

    assert set(codes.__all__) == set(RULES)
    assert all(getattr(codes, c) == c for c in RULES)
    letters = "".join(sorted({c[0] for c in RULES}))  # every family, a new one too
    literal = re.compile(rf'''(?<![\w'"])"[{letters}]\d{{3}}"(?![\w"])''')
    spelt = []
    for p in PACKAGE.rglob("*.py"):
        if p.name in ("rules.py", "codes.py"):
            continue
        tree = ast.parse(p.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and \
                    literal.fullmatch(f'"{node.value}"'):
                spelt.append(f"{p.relative_to(ROOT)}:{node.lineno}: {node.value}")
    assert not spelt, spelt


def test_the_exit_status_comes_from_the_rule_category():
    """Usage codes (I) exit 2, every other category 1, by the registry's category."""
    from aou_dsl.cli.args import exit_for
    from aou_dsl.core.diagnostics import Span, diag
    from aou_dsl.core.rules import RULES, Category

    where = Span.whole_file("x.aou")
    for code, rule in RULES.items():
        want = 2 if rule.category is Category.USAGE else 1
        assert exit_for([diag(code, "m", where)]) == want, code


def test_every_subpackage_ships_in_the_wheel():
    """pyproject.toml lists every subpackage of aou_dsl (a missing one installs without
    it, and only an installed aou finds out)."""
    import tomllib

    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"][
        "packages"])
    here = {".".join(p.parent.relative_to(ROOT).parts) for p in PACKAGE.rglob("__init__.py")}
    assert here - listed == set()
