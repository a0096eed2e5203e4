"""What the docs name exists: every ``aou_dsl/...`` path and ``aou_dsl.x.y`` name in the
pages, the README and the grammar's comments is a file, folder, module or a name a module
defines; every ``tests/...`` path and ``python -m tests.x`` command is one of the tests;
and the README's layout names every script under ``tools/``. A module moved or renamed
leaves its old name behind in prose, where nothing imports it to fail."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from tests.conftest import ROOT

#: The texts a reader follows: the pages, the README and the grammar's comments (not the
#: pages of the npm packages a test installs under editors/).
TEXTS = sorted([*ROOT.glob("docs/**/*.md"), ROOT / "README.md", ROOT / "grammar" / "aou.lark",
                *(p for p in ROOT.glob("editors/**/*.md") if "node_modules" not in p.parts)])
PATH = re.compile(r"\b(?:aou_dsl|tests)(?:/[\w.*-]+)+/?")
DOTTED = re.compile(r"(?<![\w/.])aou_dsl(?:\.\w+)+")
MODULE_RUN = re.compile(r"python -m (tests(?:\.\w+)+)")


def _line(text: str, at: int) -> int:
    return text.count("\n", 0, at) + 1


def _module_names(path: Path) -> set[str]:
    """The names ``path`` defines at its top level, and those its ``__all__`` lists (the
    facade's names are loaded on first use)."""
    names: set[str] = set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names.update(t.id for t in targets if isinstance(t, ast.Name))
            if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets) and \
                    isinstance(node.value, (ast.List, ast.Tuple)):
                names.update(e.value for e in node.value.elts if isinstance(e, ast.Constant))
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
    return names


def _module_file(parts: list[str]) -> Path | None:
    base = ROOT.joinpath(*parts)
    if base.with_suffix(".py").is_file():
        return base.with_suffix(".py")
    if (base / "__init__.py").is_file():
        return base / "__init__.py"
    return None


def dotted_exists(name: str) -> bool:
    """``aou_dsl.a.b.c``: its longest prefix that is a module, then a name that module
    defines (an attribute of that name may go on: ``Regulator.replan``). The grammar is
    shipped as the package ``aou_dsl.grammar`` from ``grammar/``."""
    parts = name.split(".")
    if parts[:2] == ["aou_dsl", "grammar"]:
        return len(parts) == 2
    for k in range(len(parts), 0, -1):
        found = _module_file(parts[:k])
        if found is not None:
            return k == len(parts) or parts[k] in _module_names(found) or \
                (ROOT.joinpath(*parts[:k], parts[k])).exists()
    return False


def path_exists(named: str) -> bool:
    """A path as a page writes it: a file, a folder, or a pattern some file matches."""
    named = named.rstrip(".")
    if "*" in named:
        return any(ROOT.glob(named))
    return (ROOT / named).exists()


def drifted(text: str, where: str) -> list[str]:
    """Each name in ``text`` that names nothing there is, as ``where:line: name``."""
    found = [(m.start(), m.group(0)) for m in PATH.finditer(text) if not path_exists(m.group(0))]
    found += [(m.start(), m.group(0)) for m in DOTTED.finditer(text)
              if not dotted_exists(m.group(0))]
    found += [(m.start(), m.group(1)) for m in MODULE_RUN.finditer(text)
              if _module_file(m.group(1).split(".")) is None]
    return [f"{where}:{_line(text, at)}: {name}" for at, name in sorted(found)]


def test_there_is_something_to_check():
    """The patterns find the names the pages do write (a pattern that matched nothing
    would pass every page)."""
    text = "\n".join(p.read_text(encoding="utf-8") for p in TEXTS)
    assert len(set(PATH.findall(text))) > 50 and len(set(DOTTED.findall(text))) > 10
    assert MODULE_RUN.search(text)


@pytest.mark.parametrize("page", TEXTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_named_path_and_module_exists(page: Path):
    assert drifted(page.read_text(encoding="utf-8"), str(page.relative_to(ROOT))) == []


def test_a_drifted_name_is_found():
    """The check is not vacuous: names of the package's old shape fail, their current
    spelling passes."""
    old = ("the kinds in `aou_dsl/primitives/`, checked by aou_dsl.validate and by\n"
           "aou_dsl.lang.validate.no_such_name; `tests/test_cv.py`, "
           "`python -m tests.test_recordings`, `aou_dsl/lang/nothing.py`")
    assert [d.split(": ", 1)[1] for d in drifted(old, "x.md")] == [
        "aou_dsl/primitives/", "aou_dsl.validate", "aou_dsl.lang.validate.no_such_name",
        "tests/test_cv.py", "tests.test_recordings", "aou_dsl/lang/nothing.py"]
    new = ("the kinds in `aou_dsl/lang/primitives/`, checked by aou_dsl.lang.validate "
           "(aou_dsl.lang.validate.validate_tree), `aou_dsl.compile`; `tests/unit/lang/`")
    assert drifted(new, "x.md") == []


def test_the_readme_names_every_tool():
    """The README's layout names each script under ``tools/`` (a new one too)."""
    layout = (ROOT / "README.md").read_text(encoding="utf-8").split("## Layout", 1)[1]
    tools = sorted(p.name for p in (ROOT / "tools").glob("*.py"))
    assert len(tools) >= 3
    assert [t for t in tools if t not in layout] == []
