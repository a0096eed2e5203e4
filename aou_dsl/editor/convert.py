"""Positions: aou's spans (1-based, in characters) and LSP's (0-based, in UTF-16 code
units), clamped to the document so that no range lies outside it."""

from __future__ import annotations

from lsprotocol import types

from ..core.diagnostics import Diagnostic, Severity, Span

__all__ = ["ENCODING", "SEVERITY", "char_col", "lines_of", "offset_of", "to_lsp", "to_range",
           "utf16_col"]

SEVERITY = {Severity.ERROR: types.DiagnosticSeverity.Error,
            Severity.WARNING: types.DiagnosticSeverity.Warning,
            Severity.NOTE: types.DiagnosticSeverity.Information}


def lines_of(text: str) -> list[str]:
    """The document's lines without their line ends (an empty last line kept)."""
    return text.replace("\r\n", "\n").split("\n")


#: The position encoding the client and the server agreed on (``initialize``).
ENCODING = {"name": "utf-16"}


def _width(ch: str) -> int:
    """How many units of the agreed encoding a character takes."""
    enc = ENCODING["name"]
    if enc == "utf-8":
        return len(ch.encode("utf-8"))
    if enc == "utf-32":
        return 1
    return 2 if ord(ch) > 0xFFFF else 1


def utf16_col(line: str, chars: int) -> int:
    """The column, in the agreed encoding's units, of the character column ``chars``
    (0-based) of ``line``."""
    return sum(_width(ch) for ch in line[:max(0, chars)])


def char_col(line: str, units: int) -> int:
    """The character column of a column in the agreed encoding's units."""
    n = 0
    for i, ch in enumerate(line):
        if n >= units:
            return i
        n += _width(ch)
    return len(line)


def _position(lines: list[str], line: int, col: int) -> types.Position:
    """1-based ``line``/``col`` (characters) as an LSP position inside the document."""
    li = min(max(0, line - 1), len(lines) - 1)
    text = lines[li]
    if line - 1 > li:  # past the end: the end of the last line
        return types.Position(li, utf16_col(text, len(text)))
    bom = int(li == 0 and text.startswith("\ufeff"))  # aou's columns start after it
    return types.Position(li, utf16_col(text, min(max(0, col - 1 + bom), len(text))))


def to_range(span: Span, lines: list[str]) -> types.Range:
    start = _position(lines, span.line, span.col)
    end = _position(lines, span.end_line, span.end_col)
    if (end.line, end.character) < (start.line, start.character):
        end = start
    return types.Range(start, end)


def offset_of(lines: list[str], pos: types.Position) -> tuple[int, int]:
    """An LSP position as (0-based line, character column) inside the document."""
    li = min(max(0, pos.line), len(lines) - 1)
    return li, char_col(lines[li], pos.character)


def to_lsp(d: Diagnostic, lines: list[str], path: str | None = None) -> types.Diagnostic:
    """``d`` as LSP's diagnostic; one about another file (``path`` given: a robot file,
    say) is shown at the document's start, its own place named in the message."""
    message = d.message + (f"\nhint: {d.hint}" if d.hint else "")
    span = d.span
    if path is not None and span.path != path:
        message = f"{span}: {message}" if span.line else f"{span.path}: {message}"
        span = Span(path, 1, 1, 1, 1)
    return types.Diagnostic(
        range=to_range(span, lines), message=message, severity=SEVERITY[d.severity],
        code=d.code, source="aou",
        code_description=None)
