"""A refusal's hint with every change at once: the one place that turns a refused build
into the values that make the file compile, for the hint without ``--fit``.

The compiler stops at its first refusal, and a refusal's own hint answers that refusal
only (a slower shiver, a shorter retreat, a nearer ``start``). A file may be refused for
more than one reason (out of reach and too fast for the wrist; two shivers of a
``sequence`` each too fast): applying the first hint would only reveal the next. So the
hint's own edit is applied, and where the file is then still refused, the rest is found
by the machinery of ``--fit`` (:func:`~aou_dsl.fit.rounds.fit_loop`: the fewest
values changed by the least, the state and the order of values kept). The hint then
names every changed statement, and its field ``edits`` holds them as text edits
(``line``, ``col``, ``end_line``, ``end_col`` of the statement as written, ``text`` to
write there), so an editor applies them at once. When no set of changes is found, the
hint gives what it can and says what is then still refused (``edits_complete``
false).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from ..core.diagnostics import Diagnostic, Fix, Severity, Span, has_errors
from ..lang.linter import FileResult, lint_source
from .guard import KEYED as _KEYED
from .guard import guarded, own_edit
from .refusals import answered, first_error

__all__ = ["statement_edits", "with_every_change"]

def with_every_change(res: Any, build: Callable[[FileResult], Any]) -> Any:
    """``res`` (a build result) with the hint of its first refusal that has an edit
    completed by every other change the file needs to compile (see the module).
    ``build`` builds a linted file as ``res`` was built (the reach and amplitude hints
    included, not this completion). No edit that would not lint is offered
    (:func:`~aou_dsl.fit.guard.guarded`)."""
    return guarded(_with_every_change(res, build))


def _with_every_change(res: Any, build: Callable[[FileResult], Any]) -> Any:
    lint = res.lint
    if lint.source is None or lint.behaviour is None or not has_errors(res.diagnostics):
        return res
    for d in res.diagnostics:
        own = own_edit(lint, d) if d.severity is Severity.ERROR else None
        if own is not None:
            break
    else:
        return res
    final, left = _complete(lint, own, build)
    edits = statement_edits(lint, final)
    if not edits:
        return res
    hint = d.hint if final == own else _said(d, edits) + _otherwise(d.hint)
    if left is not None:
        hint = f"{hint}; not every refusal is answered: then {left}"
    fix = d.fix
    mine = [e for e in edits if (e["line"], e["col"]) == (d.span.line, d.span.col)]
    if fix is None and d.code in _KEYED and mine:  # the refused statement, whole
        e = mine[0]
        fix = Fix(Span(d.span.path, e["line"], e["col"], e["end_line"], e["end_col"]),
                  e["text"])
    res.diagnostics = [replace(answered(x, hint, edits=edits, edits_complete=left is None),
                               fix=fix) if x is d else x for x in res.diagnostics]
    return res


def _complete(lint: FileResult, own: str, build: Callable[[FileResult], Any]
              ) -> tuple[str, str | None]:
    """The text with every change the file needs, from ``own`` (the hint applied), and
    what is then still refused, in words (None: it compiles)."""
    from .rounds import fit_loop

    again = lint_source(own, lint.path)
    if not again.ok:
        return own, _left(again.diagnostics)
    first = [build(again)]
    if not has_errors(first[0].diagnostics):
        return own, None
    fit = fit_loop(again, lambda linted: first.pop() if first else build(linted))
    done = fit.lint.source or own  # the text of the last build (fitted or not)
    return done, _left(fit.diagnostics) if has_errors(fit.diagnostics) else None


def _left(diagnostics: list[Diagnostic]) -> str:
    """The first refusal of ``diagnostics``, and why the fit did not answer it."""
    from ..core.codes import C314

    why = [x.message for x in diagnostics if x.code == C314 and x.message.startswith(
        "not fitted")]
    return first_error(diagnostics) + "".join(f"; {w}" for w in why)


def _statements(lint: FileResult, keys: set[str]) -> list[Span]:
    """The spans of the file's settings of ``keys`` and of its statements, in order."""
    b = lint.behaviour
    assert b is not None
    spans = [s for k, s in b.settings.spans.items() if k in keys]
    spans += [p.span for p in b.primitives]
    return sorted(set(spans), key=lambda s: (s.line, s.col))


def statement_edits(lint: FileResult, final: str) -> list[dict[str, Any]]:
    """Each statement of ``lint`` written otherwise in ``final`` (the same statements,
    some values changed): its span as written and the text to write there."""
    after = lint_source(final, lint.path)
    if after.behaviour is None or lint.behaviour is None or lint.source is None:
        return []
    keys = {k for k, s in lint.behaviour.settings.spans.items() if s.path == lint.path
            and s.line >= 1} & set(after.behaviour.settings.spans)
    was, now = _statements(lint, keys), _statements(after, keys)
    if len(was) != len(now):
        return []
    added = [s for k, s in after.behaviour.settings.spans.items() if k not in keys
             and k not in lint.behaviour.settings.spans and s.path == lint.path]
    out = []
    for a, b in zip(was, now, strict=True):
        old, new = _text(lint.source, a), _text(final, b)
        for n in added:  # a setting written after a statement (`goal (...); start 21cm`)
            if n.line == b.line and b.col < n.col and not any(
                    c.line == b.line and b.col < c.col < n.col for c in now):
                new = final.split("\n")[b.line - 1][b.col - 1:n.end_col - 1]
        if old != new:
            out.append({"line": a.line, "col": a.col, "end_line": a.end_line,
                        "end_col": a.end_col, "text": new, "was": old})
    return out


def _text(text: str, s: Span) -> str:
    """The source a one-line span covers."""
    return text.split("\n")[s.line - 1][s.col - 1:s.end_col - 1]


def _otherwise(hint: str | None) -> str:
    """What a hint offers instead of its edit (``; or move the goal ...``), kept."""
    return "; or " + hint.split("; or ", 1)[1] if hint and "; or " in hint else ""


def _keys(stmt: str) -> list[str]:
    """A statement's keyed values (``f=1.4Hz``, ``for 2s``), in order."""
    return re.findall(r"\w+=\S+|for\s+\S+", stmt)


def _key_edit(e: dict[str, Any]) -> str | None:
    """The keyed values an edit changes (``f=1.2Hz for 3s``), when it changes nothing
    else (None: it changes a positional value too)."""
    def rest(stmt: str) -> str:
        return " ".join(re.sub(r"\w+=\S+|for\s+\S+", " ", stmt).split())

    if rest(e["was"]) != rest(e["text"]):
        return None
    changed = [k for k in _keys(e["text"]) if k not in _keys(e["was"])]
    return " ".join(changed) or None


def _said(d: Diagnostic, edits: list[dict[str, Any]]) -> str:
    """The hint of every edit. When each changes only keyed values (``f=``, ``a=``,
    ``v=``, ``for``) and the refused statement is among them, it is said as the
    compiler's own (``write `f=1.4Hz```) and the others' (``; and `f=1.2Hz` in the
    shiver at line 7``); otherwise as whole statements (```retreat 0.195m` at line
    5``)."""
    mine = [e for e in edits if (e["line"], e["col"]) == (d.span.line, d.span.col)]
    keyed = {id(e): _key_edit(e) for e in edits}
    if mine and (d.fix is not None or d.code in _KEYED) and all(keyed.values()):
        others = [e for e in edits if e is not mine[0]]
        more = "; ".join(f"`{keyed[id(e)]}` in the {e['text'].split()[0]} at line "
                         f"{e['line']}" for e in others)
        return f"write `{keyed[id(mine[0])]}`" + (f"; and {more}" if more else "")
    return "write " + "; ".join(f"`{e['text']}` at line {e['line']}" for e in edits)
