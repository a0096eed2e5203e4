"""Kind names come from the kinds and descriptor names from the descriptor registry.

A kind's keyword (``retreat``) or a descriptor's name (``retreat_distance``) spelt as a
string literal anywhere in ``aou_dsl/`` outside ``lang/primitives/`` (where the kinds
spell their own names) and ``lang/descriptors.py`` (the descriptor registry) is one more
place to edit when a kind is added or renamed, and one a plugin kind never reaches. So is
a descriptor name assembled from a kind (``f"{ep.kind}_acceleration"``). This test walks
every module with :mod:`ast` and fails on either. Docstrings are prose and are left
alone, as are messages that hold a kind word inside a longer sentence.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterable
from pathlib import Path

from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.lang.primitives import BUILTIN_KINDS

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "aou_dsl"
#: Where the names are defined, and may be spelt.
ALLOWED = (PACKAGE / "lang" / "primitives", PACKAGE / "lang" / "descriptors.py")
#: The names no other module may spell.
NAMES = frozenset(BUILTIN_KINDS) | frozenset(REGISTRY)


def _docstrings(tree: ast.AST) -> set[int]:
    """The ids of the docstring nodes of a module, its classes and functions."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef,
                             ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and \
                    isinstance(first.value.value, str):
                out.add(id(first.value))
    return out


def _assembled(node: ast.JoinedStr, names: Iterable[str]) -> str | None:
    """The name an f-string could build, when its literal parts with any words in the
    gaps spell one of ``names`` (``f"{ep.kind}_acceleration"``); else None. An f-string
    whose literal parts are only separators (``f"{a}_{b}"``) builds no name of its own."""
    parts, literal = [], ""
    for v in node.values:
        if isinstance(v, ast.Constant) and isinstance(v.value, str):
            parts.append(re.escape(v.value))
            literal += v.value
        else:
            parts.append("[a-z_]+")
    if not re.search(r"[a-z]{2}", literal) or len(node.values) < 2:
        return None
    pattern = re.compile("".join(parts))
    return next((n for n in sorted(names) if pattern.fullmatch(n)), None)


def offenders_in(source: str, where: str, names: Iterable[str] = NAMES) -> list[str]:
    """Each kind or descriptor name spelt (or assembled) in ``source``, as
    ``where:line: what``."""
    names = frozenset(names)
    tree = ast.parse(source)
    skip = _docstrings(tree)
    inside_fstrings = {id(c) for n in ast.walk(tree) if isinstance(n, ast.JoinedStr)
                       for c in n.values}
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and \
                id(node) not in skip and id(node) not in inside_fstrings and \
                node.value in names:
            out.append(f"{where}:{node.lineno}: {node.value!r}")
        elif isinstance(node, ast.JoinedStr):
            built = _assembled(node, names)
            if built is not None:
                out.append(f"{where}:{node.lineno}: an f-string builds {built!r}")
    return out


def modules() -> list[Path]:
    """Every module the rule covers."""
    return sorted(p for p in PACKAGE.rglob("*.py")
                  if not any(p == a or a in p.parents for a in ALLOWED))


def offenders(paths: Iterable[Path] | None = None) -> list[str]:
    """Every offence in ``paths`` (every module the rule covers, by default)."""
    out = []
    for p in modules() if paths is None else paths:
        out += offenders_in(p.read_text(encoding="utf-8"), str(p.relative_to(ROOT)))
    return out


def test_no_kind_or_descriptor_name_is_spelt_outside_its_registry():
    found = offenders()
    assert not found, ("name a kind by its constant (`from aou_dsl.lang.primitives import "
                       "RETREAT`) or kind object, a descriptor through the registry:\n"
                       + "\n".join(found))


def test_the_rule_covers_the_kinds_and_the_descriptors():
    assert {"approach", "pause", "retreat", "gaze", "tilt", "shiver"} <= NAMES
    assert {"approach_acceleration", "horizontal_gaze", "shiver_amplitude"} <= NAMES
    assert PACKAGE / "compiler" / "pipeline.py" in modules()
    assert PACKAGE / "lang" / "descriptors.py" not in modules()
    assert PACKAGE / "lang" / "primitives" / "gaze.py" not in modules()


PLANTED = '''
"""A module that names the retreat kind in its docstring: prose, allowed."""

def f(ep, plane):
    """pause is fine here too."""
    message = "a retreat must start at a pause"  # a sentence: allowed
    if ep.kind == "retreat":  # planted
        return ep.values[f"{ep.kind}_acceleration"]  # planted
    return {"tilt_velocity": 1.0}, f"{plane}_gaze", f"{plane}_{ep}", f"{ep} done"  # 2 planted
'''


def test_the_checker_finds_planted_literals_and_spares_prose():
    found = sorted(offenders_in(PLANTED, "planted.py"))
    assert found == ["planted.py:7: 'retreat'",
                     "planted.py:8: an f-string builds 'approach_acceleration'",
                     "planted.py:9: 'tilt_velocity'",
                     "planted.py:9: an f-string builds 'horizontal_gaze'"], found


def test_the_checker_fails_on_a_literal_planted_in_a_copy_of_a_module(tmp_path):
    module = PACKAGE / "compiler" / "pipeline.py"
    copy = tmp_path / "aou_dsl" / "compiler" / "pipeline.py"
    copy.parent.mkdir(parents=True)
    text = module.read_text(encoding="utf-8")
    copy.write_text(text + '\nSHOWN = {"shiver": "pause_duration"}\n', encoding="utf-8")
    clean = offenders_in(text, "pipeline.py")
    planted = offenders_in(copy.read_text(encoding="utf-8"), "pipeline.py")
    added = [o for o in planted if o not in clean]
    last = text.count("\n") + 2
    assert added == [f"pipeline.py:{last}: 'shiver'", f"pipeline.py:{last}: 'pause_duration'"]
