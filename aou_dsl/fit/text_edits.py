"""A value of a statement changed in the file's text: the one way every fit and hint
edits a file.

A :class:`Change` names the statement (its span), the value (a key: ``a``, ``f``, ``v``,
``for``; or ``angle``, ``length`` for the statement's positional quantity) and the text
to write. :func:`set_value` changes one value in a statement's text (replaced where it is
written, else added after the statement's first words); :func:`splice` writes a
statement back into the file. Pure Python.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..core.diagnostics import Span
from ..lang.primitives import GAZE
from .quantity import first, keyed

__all__ = ["POSITIONAL", "Change", "apply", "apply_edit", "set_value", "splice",
           "statement", "value_text"]

#: Keys of a statement's positional value (its first quantity of that dimension).
POSITIONAL = ("angle", "length")


@dataclass(frozen=True)
class Change:
    """One value of one statement changed.

    Attributes:
        span: the statement.
        key: ``a``, ``f``, ``v`` or ``for``; ``angle`` or ``length`` for the positional
            value of a gaze, tilt, retreat or approach.
        declared: the value as written (``2``, absent as ``""``); fitted: as now written.
        unit: the unit written after the fitted value.
        joint, limit: what binds (the joint, and which of its limits).
        descriptor: the descriptor the value sets (None: none, e.g. a shiver's ``f``).
    """

    span: Span
    key: str
    declared: str
    fitted: str
    unit: str
    joint: str | None = None
    limit: str | None = None
    descriptor: str | None = None

    @property
    def text(self) -> str:
        return value_text(self.key, self.fitted, self.unit)


def value_text(key: str, value: str, unit: str) -> str:
    """A value as a statement writes it: ``46.1deg`` (positional), ``f=1.4Hz``,
    ``for 2.15s``."""
    if key in POSITIONAL:
        return f"{value}{unit}"
    return f"{key}={value}{unit}" if key != "for" else f"for {value}{unit}"


def statement(text: str, line: int, col: int, end_col: int) -> tuple[str, int]:
    """The text of the one-line statement at ``line``, ``col`` (up to ``end_col``, or to
    the end of the line when it is not after ``col``), and the column it stops at
    (exclusive, 0-based)."""
    row = text.split("\n")[line - 1]
    stop = end_col - 1 if end_col > col else len(row)
    return row[col - 1:stop], stop


def splice(text: str, line: int, col: int, stop: int, new: str) -> str:
    """``text`` with the columns ``col`` (1-based) to ``stop`` (0-based, exclusive) of
    ``line`` replaced by ``new``."""
    lines = text.split("\n")
    row = lines[line - 1]
    lines[line - 1] = row[:col - 1] + new + row[stop:]
    return "\n".join(lines)


def _written(stmt: str, key: str) -> tuple[int, int] | None:
    """Where ``stmt`` writes the value of ``key`` (its key included), if it does."""
    if key in POSITIONAL:
        m = first(stmt, key)
        return None if m is None else m.span()
    head = r"for\s+" if key == "for" else re.escape(key) + "="
    m = re.search(rf"(?<![\w=]){head}\S+", stmt)
    return None if m is None else m.span()


def set_value(stmt: str, key: str, value: str) -> str:
    """``stmt`` with ``value`` (``f=1.4Hz``, ``46.1deg``) written for ``key``: in place
    of the one written, else after the statement's first words (its keyword, a gaze's
    direction, and its positional value)."""
    at = _written(stmt, key)
    if at is not None:
        return stmt[:at[0]] + value + stmt[at[1]:]
    words = stmt.split(" ")
    n = 1 if len(words) > 1 and re.match(r"^[-+.\d]", words[1]) and words[0] != GAZE \
        else 0
    if words[0] == GAZE:
        n = 2
    return " ".join([*words[:n + 1], value, *words[n + 1:]])


def apply(text: str, changes: list[Change]) -> str:
    """``text`` with each change made in its statement (:func:`set_value`). Statements
    are edited from the last to the first, so spans stay valid."""
    by_stmt: dict[tuple[int, int, int], list[Change]] = {}
    for c in changes:
        by_stmt.setdefault((c.span.line, c.span.col, c.span.end_col), []).append(c)
    for (line, col, end), group in sorted(by_stmt.items(), reverse=True):
        stmt, stop = statement(text, line, col, end)
        for c in group:
            stmt = set_value(stmt, c.key, c.text)
        text = splice(text, line, col, stop, stmt)
    return text


def apply_edit(text: str, span: Span, edit: str) -> str:
    """``text`` with the edit of a hint (``f=1.4Hz for 2.15s``, ``a=1.2``) made in the
    statement at ``span``."""
    return apply(text, [Change(span, k, "", v, u) for k, v, u in keyed(edit)])
