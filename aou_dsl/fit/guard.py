"""Nothing the fit or a hint offers is refused by the language.

Every text the fit writes and every edit a diagnostic offers (its ``fix``, its hint's
``write `...``` edit, the changes and text edits of its :class:`~.refusals.Answer`) is
linted before it is offered: :func:`refusal` gives the first error of a text, and
:func:`guarded` withholds each edit of a build's diagnostics that would not lint clean of
errors. A withheld edit is no longer offered (no ``fix``, no ``edits``) and the
diagnostic's hint says so, with the language's code, line and message. Edits are judged
on a file that lints clean (what the compiler builds), so any error is the edit's own.
Pure Python (the linter, no numeric imports).
"""

from __future__ import annotations

import re
from dataclasses import replace
from typing import Any

from ..core.codes import C308, C309
from ..core.diagnostics import Diagnostic, Span
from ..lang.linter import FileResult, lint_source
from .refusals import answer_of, first_error
from .text_edits import Change, apply, apply_edit, splice

__all__ = ["guarded", "offered_text", "own_edit", "refusal"]

#: The start distance a start pose refusal's hint gives.
_START = re.compile(r"`(start \d+cm)`")
#: A hint that is an edit of keyed values (``write `f=1.3Hz for 2.31s```).
SAID = re.compile(r"write `([^`]+)`")
#: The refusals whose edit sets keyed values of their statement.
KEYED = frozenset({C308, C309})


def refusal(text: str, path: str) -> tuple[FileResult, str | None]:
    """``text`` linted, and its first error in words (None: it lints clean)."""
    lint = lint_source(text, path)
    return lint, None if lint.ok else first_error(lint.diagnostics)


def own_edit(lint: FileResult, d: Diagnostic) -> str | None:
    """The file's text with ``d``'s own hint applied (None: the hint is no edit)."""
    text = lint.source
    assert text is not None
    if d.span.path != lint.path or d.span.line < 1:
        return None
    if d.fix is not None and d.fix.key is not None and (d.hint or "").startswith("write `"):
        return apply_edit(text, d.fix.span, d.fix.text)
    said = SAID.match(d.hint or "")
    if d.fix is None and said and d.code in KEYED:  # `f=1.3Hz for 2.31s`: two keys
        return apply_edit(text, d.span, said[1])
    offered = answer_of(d).offered
    if offered:
        return apply(text, [Change(Span(d.span.path, r["line"], r["col"], r["line"],
                                        r["end_col"]), r["key"], r["declared"], r["fitted"],
                                   r["unit"]) for r in offered])
    start = _START.search(d.hint or "")
    spans = lint.behaviour.settings.spans if lint.behaviour is not None else {}
    if not (start and d.span in spans.values() and d.span.line == d.span.end_line):
        return None
    # the `start` line changed, or, in a file without one, written after the setting
    # the refusal points at (`goal (0.3, 0, 0.6); start 21cm`)
    if spans.get("start") == d.span:
        now = start[1]
    elif "start" not in spans:
        now = f"{_text(text, d.span)}; {start[1]}"
    else:
        return None
    return splice(text, d.span.line, d.span.col, d.span.end_col - 1, now)


def _text(text: str, s: Span) -> str:
    """The source a one-line span covers."""
    return text.split("\n")[s.line - 1][s.col - 1:s.end_col - 1]


def _replaced(text: str, line: int, col: int, end_line: int, end_col: int, new: str) -> str:
    """``text`` with the span (1-based, ``end_col`` exclusive) replaced by ``new``."""
    rows = text.split("\n")

    def at(n: int, c: int) -> int:
        return sum(len(r) + 1 for r in rows[:n - 1]) + c - 1

    return text[:at(line, col)] + new + text[at(end_line, end_col):]


def offered_text(lint: FileResult, d: Diagnostic) -> str | None:
    """The file's text with every edit ``d`` offers made (None: it offers none): its
    hint's text edits, else its ``fix``, else its hint's own edit."""
    text = lint.source
    assert text is not None
    edits = [e for e in answer_of(d).edits if e.get("text") is not None]
    if edits:
        for e in sorted(edits, key=lambda e: (e["line"], e["col"]), reverse=True):
            text = _replaced(text, e["line"], e["col"], e["end_line"], e["end_col"],
                             e["text"])
        return text
    f = d.fix
    if f is not None and f.span.path == lint.path and f.span.line >= 1:
        if f.key is not None:
            return apply_edit(text, f.span, f.text)
        return _replaced(text, f.span.line, f.span.col, f.span.end_line, f.span.end_col,
                         f.text)
    return own_edit(lint, d)


def _withheld(d: Diagnostic, why: str) -> Diagnostic:
    """``d`` without its edit, its hint saying why."""
    rest = "; or " + d.hint.split("; or ", 1)[1] if d.hint and "; or " in d.hint else ""
    hint = f"no edit offered: the one found would not lint: {why}{rest}"
    fields = {**d.fields, "withheld": why}
    if "edits" in fields:
        fields |= {"edits": [], "edits_complete": False}
    answer = d.answer if d.answer is None else replace(
        answer_of(d), offered=(), edits=(), edits_complete=False)
    return replace(d, hint=hint, fix=None, answer=answer, fields=fields)


def guarded(res: Any) -> Any:
    """``res`` (a build result) with every edit its diagnostics offer linted: one that
    would not lint clean of errors is withheld (see the module)."""
    lint = getattr(res, "lint", None)
    if lint is None or lint.source is None or not lint.ok:
        return res  # the compiler built nothing: the lint's own fixes are its own
    out = []
    for d in res.diagnostics:
        text = offered_text(lint, d)
        why = None if text is None or text == lint.source else refusal(text, lint.path)[1]
        out.append(d if why is None else _withheld(d, why))
    res.diagnostics = out
    return res
