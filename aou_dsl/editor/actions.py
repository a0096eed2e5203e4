"""Quick fixes (a diagnostic's hint, where it is an edit) and whole-file formatting."""

from __future__ import annotations

from lsprotocol import types

from ..core.diagnostics import Diagnostic, Fix, Span
from ..fit.refusals import answer_of
from . import lsp_engine as engine
from .convert import to_lsp, to_range
from .state import Document
from .text import tokens_of

__all__ = ["code_actions", "format_edits", "resolve"]


def resolve(fix: Fix, lines: list[str]) -> tuple[Span, str]:
    """The span to replace and the text to write. A fix with a ``key`` sets that key
    in the statement at its span: over the written ``key=value``, else after the
    statement's last argument."""
    if fix.key is None:
        return fix.span, fix.text
    s = fix.span
    if s.line != s.end_line or not 1 <= s.line <= len(lines):
        return Span(s.path, s.end_line, s.end_col, s.end_line, s.end_col), " " + fix.text
    toks = [t for t in tokens_of(lines[s.line - 1]) if s.col - 1 <= t.start < s.end_col - 1]
    for i, t in enumerate(toks):
        if t.text == fix.key and i + 2 < len(toks) and toks[i + 1].text == "=":
            return Span(s.path, s.line, t.start + 1, s.line, toks[i + 2].end + 1), fix.text
    return Span(s.path, s.line, s.end_col, s.line, s.end_col), " " + fix.text


def _overlaps(a: types.Range, b: types.Range) -> bool:
    return (a.start.line, a.start.character) <= (b.end.line, b.end.character) and \
        (b.start.line, b.start.character) <= (a.end.line, a.end.character)


def _action(doc: Document, d: Diagnostic) -> types.CodeAction:
    """The quick fix of ``d``: every edit of its hint (a refusal's, which may change
    several statements: one workspace edit, applied at once), else its one ``fix``."""
    answer = answer_of(d)
    every, preferred = answer.edits, answer.edits_complete  # not when it leaves a refusal
    if every:
        edits = [types.TextEdit(range=to_range(Span(doc.path, e["line"], e["col"],
                                                     e["end_line"], e["end_col"]),
                                               doc.view), new_text=e["text"])
                 for e in every]
        said = "; ".join(f"`{e['text']}`" for e in every)
        title = f"{d.code}: write {said}"
    else:
        assert d.fix is not None
        span, text = resolve(d.fix, doc.lines)
        title = f"{d.code}: write `{text.strip()}`"
        edits = [types.TextEdit(range=to_range(span, doc.view), new_text=text)]
    return types.CodeAction(
        title=title, kind=types.CodeActionKind.QuickFix, is_preferred=preferred,
        diagnostics=[to_lsp(d, doc.view)],
        edit=types.WorkspaceEdit(changes={doc.uri: edits}))


def _fixable(doc: Document, d: Diagnostic) -> bool:
    """Whether ``d``'s hint is an edit of this document."""
    if answer_of(d).edits:
        return d.span.path == doc.path
    return d.fix is not None and d.fix.span.path == doc.path


def code_actions(doc: Document, rng: types.Range) -> list[types.CodeAction]:
    """A quick fix for each diagnostic at ``rng`` whose hint is an edit."""
    return [_action(doc, d) for d in doc.diagnostics
            if _fixable(doc, d) and _overlaps(to_range(d.span, doc.view), rng)]


def format_edits(doc: Document) -> list[types.TextEdit] | None:
    """``aouc fmt``'s output as one edit of the whole document; none when it is already
    formatted, None while it has a syntax error."""
    formatted = engine.format_text(doc.text, doc.path)
    if formatted is None:
        return None
    if formatted == doc.text:
        return []
    return [types.TextEdit(range=types.Range(types.Position(0, 0), doc.view.end()),
                           new_text=formatted)]
