"""Formatting diagnostics for people and machines: text (with caret), JSON, GitHub."""

from __future__ import annotations

import json

from .diagnostics import Diagnostic

__all__ = ["format_github", "format_json", "format_text"]


def _source_excerpt(d: Diagnostic, source: str | None) -> list[str]:
    if not source or d.span.line < 1:
        return []
    lines = source.splitlines()
    if d.span.line > len(lines):
        return []
    text = lines[d.span.line - 1].expandtabs(1)
    width = (d.span.end_col - d.span.col) if d.span.end_line == d.span.line else len(text)
    width = max(1, min(width, len(text) - d.span.col + 2))
    gutter = f"{d.span.line:>4} | "
    return [gutter + text, " " * (len(gutter) - 2) + "| " + " " * (d.span.col - 1) + "^" * width]


def format_text(d: Diagnostic, source: str | None = None) -> str:
    """``path:line:col: CODE [severity] message``, the source line with a caret, the hint."""
    out = [f"{d.span}: {d.code} [{d.severity}] {d.message}"]
    out += _source_excerpt(d, source)
    if d.hint:
        out.append(f"     = hint: {d.hint}")
    return "\n".join(out)


def format_github(d: Diagnostic) -> str:
    """A GitHub Actions workflow command, shown as an annotation on the pull request."""
    level = {"error": "error", "warning": "warning", "note": "notice"}[str(d.severity)]
    msg = d.message + (f" ({d.hint})" if d.hint else "")
    msg = msg.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")
    return (f"::{level} file={d.span.path},line={d.span.line},col={d.span.col},"
            f"endLine={d.span.end_line},endColumn={d.span.end_col},"
            f"title={d.code} {d.rule.name}::{msg}")


def format_json(payload: object) -> str:
    return json.dumps(payload, indent=2, sort_keys=False)
