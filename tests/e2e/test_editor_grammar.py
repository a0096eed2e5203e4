"""The TextMate grammar of editors/vscode: it knows every keyword, state, plane and unit
of the language, and it scopes the sample files as their assertions say
(`vscode-tmgrammar-test`, from npm, where node is available)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from aou_dsl.core.units import UNITS
from aou_dsl.lang.ir import State
from aou_dsl.lang.validate import KEYWORDS

VSCODE = Path(__file__).resolve().parents[2] / "editors" / "vscode"
GRAMMAR = json.loads((VSCODE / "syntaxes" / "aou.tmLanguage.json").read_text())
TOOL = "vscode-tmgrammar-test@0.1.3"


def _patterns(name: str) -> list[str]:
    node = GRAMMAR["repository"][name]
    return [p["match"] for p in node.get("patterns", [node]) if "match" in p]


def test_grammar_knows_the_language() -> None:
    words = " ".join(_patterns("keyword") + _patterns("header"))
    for kw in KEYWORDS:
        assert re.search(rf"\b{kw}\b", words), kw
    header = re.compile(GRAMMAR["repository"]["header"]["match"])
    for s in State:
        m = header.match(f"behaviour b : {s.value}")
        assert m and m.group(4) == s.value
    quantity = re.compile(GRAMMAR["repository"]["quantity"]["match"])
    for unit in UNITS:
        m = quantity.fullmatch(f"-1.5e-2{unit}")
        assert m and m.group(1) == "-1.5e-2" and m.group(2) == unit, unit


def test_extension_points_at_the_grammar_and_the_server() -> None:
    pkg = json.loads((VSCODE / "package.json").read_text())
    (grammar,) = pkg["contributes"]["grammars"]
    assert (VSCODE / grammar["path"]).is_file() and grammar["scopeName"] == "source.aou"
    assert pkg["contributes"]["languages"][0]["extensions"] == [".aou"]
    assert pkg["contributes"]["configuration"]["properties"]["aou.server.command"][
        "default"] == ["aouc", "server"]
    assert "server.command" in (VSCODE / "extension.js").read_text()


def _tool() -> Path:
    """vscode-tmgrammar-test, installed once into editors/vscode/node_modules (ignored
    by git); the test skips where node or npm is missing or npm cannot install it."""
    if shutil.which("node") is None or shutil.which("npm") is None:
        pytest.skip("node and npm are not installed: the grammar's samples are not run")
    prefix = VSCODE / "node_modules" / ".aou-test"  # the tool alone, not the extension's
    exe = prefix / "node_modules" / ".bin" / "vscode-tmgrammar-test"
    if not exe.exists():
        prefix.mkdir(parents=True, exist_ok=True)
        out = subprocess.run(["npm", "install", "--prefix", str(prefix), "--no-save",
                              "--no-package-lock", "--no-audit", "--no-fund", TOOL],
                             cwd=prefix, capture_output=True, text=True, timeout=300)
        if out.returncode != 0 or not exe.exists():
            pytest.skip(f"npm could not install {TOOL}: {out.stderr.strip()[-300:]}")
    return exe


def test_samples_are_scoped_as_asserted() -> None:
    exe = _tool()
    samples = sorted(str(p.relative_to(VSCODE)) for p in (VSCODE / "test").glob("*.aou"))
    assert len(samples) >= 2
    out = subprocess.run([str(exe), "-g", "syntaxes/aou.tmLanguage.json", *samples],
                         cwd=VSCODE, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    assert out.stdout.count("run successfuly") == len(samples)
