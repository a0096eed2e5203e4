"""Quick fixes: every hint that is an edit carries it as a structured fix; applied, the
diagnostic it came with is gone. Hover's descriptor text is docs/model.md's."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from aou_dsl.lang.descriptors import DEFINITIONS, REGISTRY
from aou_dsl.lang.linter import lint_source

pytest.importorskip("lsprotocol", reason="the lsp extra is not installed")
from aou_dsl.editor.actions import resolve
from aou_dsl.editor.convert import Text

ROOT = Path(__file__).resolve().parents[3]

SLIPS = [
    ("pause 1,5s\n", "S001", "pause 1.5s\n"),
    ("tilt 20°\npause 1s x2\n", "S003", "tilt 20deg\npause 1s x2\n"),
    ("tilt 20 °\npause 1s x2\n", "S003", "tilt 20deg\npause 1s x2\n"),
    ("pause 2sec\n", "V104", "pause 2s\n"),
    ("shiver 6deg for=1.2s\n", "V112", "shiver 6deg for 1.2s\n"),
    ("approach qqq=0.1\n", None, None),
    ("approach aa=0.1\npause 1s\n", "V112", "approach a=0.1\npause 1s\n"),
    ("pauze 1s\n", "V101", "pause 1s\n"),
    ("sequence {\n  pauze 1s\n}\n", "V101", "sequence {\n  pause 1s\n}\n"),
    ("behaviour h : hesitnt\npause 1s\n", "V114", "behaviour h : hesitant\npause 1s\n"),
    ("robot pandaa\npause 1s\n", "V109", "robot panda\npause 1s\n"),
    ("pause 1.25 s\n", "V103", "pause 1.25s\n"),
    ("shiver 6deg f=3 Hz\n", "V113", "shiver 6deg f=3Hz\n"),
    ("pause 1s x 3\n", "V113", "pause 1s x3\n"),
    ("pause 1s x+2\n", "V116", "pause 1s x2\n"),
]


def _apply(text: str, d) -> str:
    span, new = resolve(d.fix, text.split("\n"))
    lines = text.split("\n")
    start = sum(len(ln) + 1 for ln in lines[:span.line - 1]) + span.col - 1
    end = sum(len(ln) + 1 for ln in lines[:span.end_line - 1]) + span.end_col - 1
    return text[:start] + new + text[end:]


@pytest.mark.parametrize(("text", "code", "fixed"), SLIPS)
def test_fix_applied_clears_the_diagnostic(text, code, fixed):
    diags = lint_source(text).diagnostics
    if code is None:  # nothing close enough to suggest: no fix either
        assert all(d.fix is None for d in diags), diags
        return
    (d,) = [d for d in diags if d.code == code]
    assert d.fix is not None and d.hint and d.fix.text.strip() in d.hint
    out = _apply(text, d)
    assert out == fixed
    assert code not in {x.code for x in lint_source(out).diagnostics}


def test_key_fix_replaces_or_adds_the_key():
    from aou_dsl.core.diagnostics import Fix, Span

    lines = ["tilt 90deg v=500deg/s x2  # fast"]
    stmt = Span("x", 1, 1, 1, 27)
    span, text = resolve(Fix(stmt, "v=44deg/s", "v"), lines)
    assert (span.col, span.end_col, text) == (12, 22, "v=44deg/s")
    span, text = resolve(Fix(Span("x", 1, 1, 1, 11), "v=44deg/s", "v"), ["tilt 90deg"])
    assert (span.col, span.end_col, text) == (11, 11, " v=44deg/s")


def test_printed_output_has_no_fix():
    """The fix is for editors: lint's JSON records are what they were."""
    (d,) = [d for d in lint_source("pause 2sec\n").diagnostics if d.code == "V104"]
    assert "fix" not in d.to_json()


@pytest.mark.parametrize("name", list(REGISTRY))
def test_hover_definitions_are_the_docs_words(name):
    rows = [ln for ln in (ROOT / "docs" / "model.md").read_text().splitlines()
            if re.match(rf"\| \d+ \| `{name}` \|", ln)]
    assert len(rows) == 1 and DEFINITIONS[name] in rows[0]


def test_ranges_count_utf16_and_skip_a_byte_order_mark():
    from lsprotocol import types

    from aou_dsl.core.diagnostics import Span, diag
    from aou_dsl.editor.convert import to_lsp

    text = "\ufeffpause 3m\n"
    (d,) = [d for d in lint_source(text, "x.aou").diagnostics if d.code == "V102"]
    rng = to_lsp(d, Text(text), "x.aou").range
    assert (rng.start, rng.end) == (types.Position(0, 7), types.Position(0, 9))
    text = 'robot "😀x"; pause 3m\n'  # the emoji is two UTF-16 code units
    (d,) = [d for d in lint_source(text, "x.aou").diagnostics if d.code == "V102"]
    assert to_lsp(d, Text(text), "x.aou").range.start == types.Position(0, 19)
    other = diag("V102", "in the robot file", Span("arm.toml", 7, 3, 7, 9))
    shown = to_lsp(other, Text(text), "x.aou")
    assert shown.range.start == shown.range.end == types.Position(0, 0)
    assert shown.message.startswith("arm.toml:7:3: ")


def test_a_comment_names_any_registered_code_for_hover():
    """Hover explains a code a comment names, whatever its category: DMP, study and
    plugin codes too, not only the front end's and the compiler's."""
    from aou_dsl.core.rules import RULES
    from aou_dsl.editor.hover import _CODE, rule_text

    for code in RULES:
        assert _CODE.findall(f"pause 1s  # {code} is expected here") == [code]
        assert rule_text(code)
