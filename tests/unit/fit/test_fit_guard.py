"""The guard over what the fit and the hints offer: an edit that would not lint clean of
errors is never offered (no fix, no text edits), and its diagnostic says which rule of
the language refuses it; an edit that lints is left as it was.

The edits fed here are made by hand, so the guard is tested on a case that must fail:
`a=` written into a gaze (a gaze takes `v=` only) and a gaze's angle written without
its unit."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import pytest

from aou_dsl.core.codes import C304, C308
from aou_dsl.core.diagnostics import Diagnostic, Fix, Severity, Span, diag
from aou_dsl.fit.every_change import with_every_change
from aou_dsl.fit.refusals import Answer
from aou_dsl.fit.rounds import fit_loop
from aou_dsl.lang.linter import lint_source
from aou_dsl.lang.primitives import GAZE

TEXT = "behaviour c : curious\nrobot ur5\napproach a=0.09\npause 1.25s x3\n" \
    "gaze horizontal 20deg x2\n"
PATH = "c.aou"


def _gaze(lint) -> Span:
    return next(p.span for p in lint.behaviour.primitives if p.kind == GAZE)


def _with_fix(lint, text: str, key: str | None) -> Diagnostic:
    span = _gaze(lint)
    d = diag(C304, "gaze reaches less than it declares", span)
    return replace(d, hint=f"write `{text}`", fix=Fix(span, text, key))


def _with_edits(lint, text: str) -> Diagnostic:
    s = _gaze(lint)
    edit = {"line": s.line, "col": s.col, "end_line": s.end_line, "end_col": s.end_col,
            "text": text, "was": "gaze horizontal 20deg x2"}
    d = diag(C308, "too fast", s, edits=[edit], edits_complete=True)
    return replace(d, severity=Severity.WARNING, hint=f"write `{text}` at line {s.line}",
                   answer=Answer(edits=(edit,)))


def _run(entry, d: Diagnostic) -> Diagnostic:
    lint = lint_source(TEXT, PATH)
    assert lint.ok

    def build(linted):
        return SimpleNamespace(lint=linted, diagnostics=[d], header=None,
                               fitted_source=None)

    res = entry(lint, build) if entry is fit_loop else entry(build(lint), build)
    return next(x for x in res.diagnostics if x.code == d.code)


ENTRIES = [fit_loop, with_every_change]


@pytest.mark.parametrize("entry", ENTRIES)
def test_a_fix_that_writes_a_into_a_gaze_is_withheld(entry):
    lint = lint_source(TEXT, PATH)
    got = _run(entry, _with_fix(lint, "a=0.122", "a"))
    assert got.fix is None
    assert "V112" in got.hint and "write `a=" not in got.hint, got.hint
    assert "V112" in got.fields["withheld"]


@pytest.mark.parametrize("entry", ENTRIES)
def test_text_edits_that_do_not_lint_are_withheld(entry):
    lint = lint_source(TEXT, PATH)
    got = _run(entry, _with_edits(lint, "gaze horizontal 20 x2"))  # no unit
    assert got.fix is None and not got.answer.edits and not got.answer.edits_complete
    assert got.fields["edits"] == [] and got.fields["edits_complete"] is False
    bad = next(d for d in lint_source(TEXT.replace("20deg", "20"), PATH).diagnostics
               if d.severity is Severity.ERROR)
    assert bad.code in got.hint and f"line {bad.span.line}" in got.hint, got.hint


@pytest.mark.parametrize("entry", ENTRIES)
def test_edits_that_lint_are_offered_unchanged(entry):
    lint = lint_source(TEXT, PATH)
    fix = _with_fix(lint, "v=20deg/s", "v")
    assert _run(entry, fix) == fix
    edits = _with_edits(lint, "gaze horizontal 15deg x2")
    assert _run(entry, edits) == edits
