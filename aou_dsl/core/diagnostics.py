"""Diagnostics: source spans, the problems found at them, the error root.

Every problem aou reports is a :class:`Diagnostic` with a code from :data:`RULES`
(the registry, in :mod:`aou_dsl.core.rules`: what each code means and an example of it).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .rules import RULES, Rule, Severity

__all__ = [
    "AouError",
    "Diagnostic",
    "Fix",
    "RULES",
    "Rule",
    "Severity",
    "Span",
    "diag",
    "has_errors",
    "refused",
]


@dataclass(frozen=True, slots=True)
class Span:
    """A region of a source file. Lines and columns are 1-based; ``end_*`` is exclusive."""

    path: str
    line: int
    col: int
    end_line: int
    end_col: int

    @classmethod
    def point(cls, path: str, line: int, col: int) -> Span:
        return cls(path, line, col, line, col + 1)

    @classmethod
    def whole_file(cls, path: str) -> Span:
        return cls(path, 1, 1, 1, 1)

    def to(self, other: Span) -> Span:
        """The span from the start of ``self`` to the end of ``other``."""
        return Span(self.path, self.line, self.col, other.end_line, other.end_col)

    def __str__(self) -> str:
        return f"{self.path}:{self.line}:{self.col}"


@dataclass(frozen=True, slots=True)
class Fix:
    """A hint that is an edit: write ``text`` in place of the source at ``span``.

    With ``key`` (C308, C309: ``f=1.4Hz``), ``span`` is the statement's and the edit sets
    that key in it: the written ``key=...`` is replaced, or ``text`` is added after the
    statement's last argument (the compiler has the statement, not its arguments)."""

    span: Span
    text: str
    key: str | None = None


@dataclass(frozen=True, slots=True)
class Diagnostic:
    """One problem found in one place.

    Attributes:
        code: a code of :data:`RULES`.
        severity: usually the rule's; lint may raise warnings to errors.
        message: names the expected and the found value.
        span: where in the source; for trajectories, the file and (line 0) no position.
        hint: how to fix it, where one helps.
        fields: structured data for machine consumers (JSON output).
        fix: the hint as an edit, where it is one (editors apply it; not printed).
        refusal: what the compiler refused, typed, where the fit and the hints read it
            (a record of :mod:`aou_dsl.fit.refusals`; its values are ``fields`` too).
        answer: what the fit found for the refusal (an ``Answer`` of the same module:
            the changes that answer it, or why none does, and the hint's text edits;
            also in ``fields``).
    """

    code: str
    severity: Severity
    message: str
    span: Span
    hint: str | None = None
    fields: dict[str, Any] = field(default_factory=dict)
    fix: Fix | None = None
    refusal: Any = None
    answer: Any = None

    @property
    def rule(self) -> Rule:
        return RULES[self.code]

    def to_json(self) -> dict[str, Any]:
        return {
            "code": self.code,
            "name": self.rule.name,
            "severity": str(self.severity),
            "message": self.message,
            "path": self.span.path,
            "line": self.span.line,
            "col": self.span.col,
            "end_line": self.span.end_line,
            "end_col": self.span.end_col,
            "hint": self.hint,
            "fields": self.fields,
        }


class AouError(Exception):
    """The root of every error aou raises. It carries the diagnostics that explain it."""

    def __init__(self, diagnostics: list[Diagnostic] | Diagnostic):
        self.diagnostics = [diagnostics] if isinstance(diagnostics, Diagnostic) else diagnostics
        super().__init__("; ".join(f"{d.span}: {d.code} {d.message}" for d in self.diagnostics))

    def __reduce__(self) -> tuple[type[AouError], tuple[list[Diagnostic]]]:
        """Pickled by its diagnostics (the message is made from them): an error raised in
        a worker process reaches the parent whole."""
        return (type(self), (self.diagnostics,))


def degree_fix(text: str, at: int, span: Span, n: str, sign: str) -> Fix | None:
    """`20°` (or `20 °`) as an edit, `20deg`: ``n`` is the number before the sign at
    offset ``at`` of ``text``, whose span is ``span``."""
    before = text[:at].rstrip(" \t")
    if sign not in "°º" or not n or not before.endswith(n):
        return None
    col = span.col - (at - (len(before) - len(n)))
    return Fix(Span(span.path, span.line, col, span.line, span.col + 1), f"{n}deg")


def has_errors(diagnostics: list[Diagnostic]) -> bool:
    return any(d.severity is Severity.ERROR for d in diagnostics)




def diag(
    code: str,
    message: str,
    span: Span,
    *,
    hint: str | None = None,
    severity: Severity | None = None,
    fix: Fix | None = None,
    **fields: Any,
) -> Diagnostic:
    """Build a diagnostic of rule ``code``, with the rule's severity unless overridden."""
    rule = RULES[code]
    return Diagnostic(code, severity or rule.severity, message, span, hint, dict(fields), fix)


def refused(code: str, message: str, span: Span, refusal: Any, *, hint: str | None = None,
            fix: Fix | None = None) -> Diagnostic:
    """A diagnostic of the refusal ``refusal`` (a dataclass): its values are the
    diagnostic's ``fields``, in the order of the refusal's own."""
    from dataclasses import asdict

    return Diagnostic(code, RULES[code].severity, message, span, hint, asdict(refusal), fix,
                      refusal)
