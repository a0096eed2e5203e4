"""A shiver's `for`: given once, and the C308 fix that changes it writes one.

A repeated `for` was accepted (the last one won) where a repeated `a=` or a second count
is an error; the C308 hint on `shiver 5deg f=12Hz for 0.5s` (Panda) sets `f=` and `for`
together, and an editor's quick fix that set `f=` alone wrote a second `for`.
"""

from __future__ import annotations

import pytest

from aou_dsl.core.diagnostics import Span
from aou_dsl.driver.builder import build_source
from aou_dsl.fit.text_edits import apply_edit
from aou_dsl.lang.linter import lint_source

REFUSED = "behaviour f : fearful\nrobot panda\nshiver 5deg f=12Hz for 0.5s\n"


@pytest.mark.parametrize("stmt", ["shiver 30deg f=1.3Hz for 2.31s for 1s",
                                  "shiver 5deg for 2s for 2s", "shiver 5deg for 1s x2 for 3s",
                                  "sequence {\n  shiver 5deg for 1s for 2s\n}"])
def test_a_repeated_for_is_an_error_like_a_repeated_key(stmt):
    r = lint_source(f"behaviour f : fearful\nrobot panda\n{stmt}\n", "t.aou")
    (d,) = [d for d in r.diagnostics if d.severity == "error"]
    assert d.code == "V111" and "`for` is given twice" in d.message
    line = r.source.split("\n")[d.span.line - 1]
    assert line[d.span.col - 1:d.span.end_col - 1].startswith("for ")
    assert not r.ok


def test_one_for_is_no_error():
    assert lint_source("behaviour f : fearful\nrobot panda\nshiver 5deg f=12Hz for 1s\n",
                       "t.aou").ok


def _apply(text: str, span: Span, new: str) -> str:
    lines = text.split("\n")
    row = lines[span.line - 1]
    assert span.line == span.end_line
    lines[span.line - 1] = row[:span.col - 1] + new + row[span.end_col - 1:]
    return "\n".join(lines)


def test_the_c308_fix_replaces_the_whole_clause_and_compiles():
    """Every form the fix takes (the statement edit, the structured fix an editor
    resolves, the hint's own edit) gives one `for`, and the file then compiles without
    V126 (a shiver lengthened past its `for`)."""
    from aou_dsl.editor.actions import resolve

    res = build_source(REFUSED, "f.aou")
    (d,) = [x for x in res.diagnostics if x.code == "C308"]
    (edit,) = d.fields["edits"]
    span, text = resolve(d.fix, REFUSED.split("\n"))
    fixed = [
        _apply(REFUSED, Span("f.aou", edit["line"], edit["col"], edit["end_line"],
                             edit["end_col"]), edit["text"]),
        _apply(REFUSED, span, text),
        apply_edit(REFUSED, d.span, d.hint.split("`")[1]),
    ]
    for f in fixed:
        assert f.count(" for ") == 1, f
        again = build_source(f, "f.aou")
        codes = [x.code for x in again.diagnostics]
        assert again.ok and "V126" not in codes and "V111" not in codes, (f, codes)


def test_the_compiler_alone_gives_no_fix_that_sets_half_the_edit():
    """Before the whole build completes the edit, the compiler's refusal has no
    structured fix where its edit sets two keys (a fix sets one)."""
    from aou_dsl.compiler.pipeline import compile_behaviour

    lint = lint_source(REFUSED, "f.aou")
    (d,) = [x for x in compile_behaviour(lint.behaviour, timeline=lint.timeline).diagnostics
            if x.code == "C308"]
    assert "for" in d.hint and (d.fix is None or " for " not in d.fix.text)
