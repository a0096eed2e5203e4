"""A document's text as the editor and as aou see it, and positions between the two.

The editor (the Language Server Protocol) ends a line at ``\\n``, ``\\r\\n`` or a lone
``\\r``, and nowhere else: not at a form feed, a vertical tab, NEL, U+2028 or U+2029,
which Python's ``str.splitlines`` also splits at. Its positions are 0-based, with
columns in the units of the encoding agreed at ``initialize`` (UTF-16 code units unless
the client asks for UTF-8 bytes or UTF-32 code points). aou's spans are 1-based, in
characters, on the lines the language has: ended by ``\\n`` only (a lone ``\\r`` is a
blank to it). A span goes to the editor through its offset in the text, so a position
is the same character for both, whatever the text holds; every range is clamped to the
document and to its line.
"""

from __future__ import annotations

import re
from bisect import bisect_right

from lsprotocol import types

from ..core.diagnostics import Diagnostic, Severity, Span

__all__ = ["ENCODING", "SEVERITY", "Text", "apply_change", "char_col", "to_lsp", "to_range",
           "units"]

SEVERITY = {Severity.ERROR: types.DiagnosticSeverity.Error,
            Severity.WARNING: types.DiagnosticSeverity.Warning,
            Severity.NOTE: types.DiagnosticSeverity.Information}

#: The position encoding the client and the server agreed on (``initialize``).
ENCODING = {"name": "utf-16"}

#: The longest text whose line starts are kept in a list [characters].
_INDEXED = 4 << 20
#: The line ends of the protocol, the longest first.
_EOL = re.compile(r"\r\n|\r|\n")


def _width(ch: str) -> int:
    """How many units of the agreed encoding a character takes. A lone surrogate (a
    JSON string may hold one) counts as what it is in UTF-16, one unit, and as the three
    bytes an editor working in UTF-8 writes it with."""
    enc, cp = ENCODING["name"], ord(ch)
    if enc == "utf-32":
        return 1
    if enc == "utf-8":
        return 1 if cp < 0x80 else 2 if cp < 0x800 else 3 if cp < 0x10000 else 4
    return 2 if cp > 0xFFFF else 1


def units(line: str, chars: int | None = None) -> int:
    """The length, in the agreed encoding's units, of the first ``chars`` characters
    of ``line`` (all of it when None)."""
    part = line if chars is None else line[:max(0, chars)]
    if part.isascii() or ENCODING["name"] == "utf-32":
        return len(part)
    return sum(_width(ch) for ch in part)


def char_col(line: str, col: int) -> int:
    """The character column of ``col`` units into ``line``: the line's length past its
    end, and the character a unit belongs to when ``col`` falls inside one."""
    if col <= 0:
        return 0
    if line.isascii() or ENCODING["name"] == "utf-32":
        return min(col, len(line))
    n = 0
    for i, ch in enumerate(line):
        n += _width(ch)
        if n > col:
            return i
        if n == col:
            return i + 1
    return len(line)


def _ends(text: str, a: int, b: int) -> int:
    """How many line ends ``text[a:b]`` holds (no ``\r\n`` cut by ``b``)."""
    return text.count("\n", a, b) + text.count("\r", a, b) - text.count("\r\n", a, b)


def _skip_lines(text: str, start: int, lines: int | None, before: int | None = None
                ) -> tuple[int, int]:
    """From line start ``start``, the start of the line ``lines`` on (or of the line
    holding offset ``before``), and how many lines were passed: counted by the string's
    own methods a block at a time, so a text of millions of lines takes no list."""
    n, limit = 0, len(text) if before is None else before
    block = 1 << 16
    while start < limit:
        b = min(limit, start + block)
        if text.startswith("\r\n", b - 1):  # do not cut a \r\n in two
            b += 1
        k = _ends(text, start, b)
        if b > limit:  # the \r of a \r\n that holds `before`
            k -= 1
        if lines is not None and n + k >= lines or b >= limit:
            break
        n, start = n + k, b
    for m in _EOL.finditer(text, start, limit + (1 if before is not None else 0)):
        if (lines is not None and n == lines) or (before is not None and m.end() > before):
            break
        n, start = n + 1, m.end()
    return start, n


class Text:
    """One version of a document's text, with both line models worked out when first
    needed (each in one pass over the text)."""

    def __init__(self, text: str) -> None:
        self.text = text
        self._starts: list[int] | None = None  # the editor's line starts
        self._aou: list[int] | None = None  # aou's line starts
        self._aou_lines: list[str] | None = None

    # --- the editor's lines -------------------------------------------------------------

    @property
    def starts(self) -> list[int]:
        if self._starts is None:
            self._starts = [0, *(m.end() for m in _EOL.finditer(self.text))]
        return self._starts

    def _content_end(self, li: int) -> int:
        """Where line ``li``'s text ends (before its line end)."""
        starts = self.starts
        if li + 1 >= len(starts):
            return len(self.text)
        end = starts[li + 1]
        return end - 2 if self.text.startswith("\r\n", end - 2) else end - 1

    def line(self, li: int) -> tuple[int, int] | None:
        """Where line ``li`` starts and where its text ends; None past the last line. A
        text too large to index (one not analysed) is looked through instead: a list
        of its line starts could take many times its own memory."""
        if li < 0:
            return None
        if self._starts is not None or len(self.text) <= _INDEXED:
            if li >= len(self.starts):
                return None
            return self.starts[li], self._content_end(li)
        start, n = _skip_lines(self.text, 0, li)
        if n < li:
            return None
        m = _EOL.search(self.text, start)
        return start, m.start() if m is not None else len(self.text)

    def offset(self, pos: types.Position) -> int:
        """The character offset of an editor's position: a line past the last is the
        end of the text, a column past a line's end that end."""
        if pos.line < 0:
            return 0
        found = self.line(pos.line)
        if found is None:
            return len(self.text)
        start, end = found
        return start + char_col(self.text[start:end], pos.character)

    def position(self, offset: int) -> types.Position:
        """The editor's position of a character offset (one inside a line end is the
        end of that line)."""
        offset = min(max(0, offset), len(self.text))
        if self._starts is None and len(self.text) > _INDEXED:
            start, li = _skip_lines(self.text, 0, None, offset)
            m = _EOL.search(self.text, start)
            end = min(offset, m.start()) if m is not None else offset
            return types.Position(li, units(self.text[start:end]))
        li = bisect_right(self.starts, offset) - 1
        start = self.starts[li]
        end = min(offset, self._content_end(li))
        return types.Position(li, units(self.text[start:end]))

    def end(self) -> types.Position:
        return self.position(len(self.text))

    # --- aou's lines ----------------------------------------------------------------------

    @property
    def lines(self) -> list[str]:
        """aou's lines (ended by ``\\n``; an empty last line kept)."""
        if self._aou_lines is None:
            self._aou_lines = self.text.split("\n")
        return self._aou_lines

    @property
    def aou_starts(self) -> list[int]:
        if self._aou is None:
            starts, at = [0], 0
            for line in self.lines[:-1]:
                at += len(line) + 1
                starts.append(at)
            self._aou = starts
        return self._aou

    def aou_offset(self, line: int, col: int) -> int:
        """The offset of aou's 1-based ``line`` and ``col``, inside that line (a line past
        the last is the end of the text). aou's columns on the first line start after a
        byte-order mark."""
        if line < 1:
            return 0
        if line == 1:  # without splitting the text: it may be too large to analyse
            end = self.text.find("\n")
            length = end if end >= 0 else len(self.text)
            bom = int(self.text.startswith("\ufeff"))
            return min(max(0, col - 1 + bom), length)
        starts = self.aou_starts
        if line > len(starts):
            return len(self.text)
        text = self.lines[line - 1]
        bom = int(line == 1 and text.startswith("\ufeff"))
        return starts[line - 1] + min(max(0, col - 1 + bom), len(text))

    def aou_at(self, pos: types.Position) -> tuple[int, int]:
        """An editor's position as aou's (0-based line, character column)."""
        offset = self.offset(pos)
        li = bisect_right(self.aou_starts, offset) - 1
        return li, offset - self.aou_starts[li]

    def range(self, span: Span) -> types.Range:
        start = self.position(self.aou_offset(span.line, span.col))
        end = self.position(self.aou_offset(span.end_line, span.end_col))
        if (end.line, end.character) < (start.line, start.character):
            end = start
        return types.Range(start, end)


def _join_pairs(text: str, at: int) -> str:
    """``text`` with a high and a low surrogate that meet at ``at`` made one character
    again (an editor counting UTF-16 units can split a pair and join it back)."""
    if 0 < at < len(text) and "\ud800" <= text[at - 1] <= "\udbff" \
            and "\udc00" <= text[at] <= "\udfff":
        pair = (text[at - 1] + text[at]).encode("utf-16-le", "surrogatepass")
        return text[:at - 1] + pair.decode("utf-16-le") + text[at + 1:]
    return text


def _halves(ch: str) -> str:
    """A character beyond U+FFFF as its two UTF-16 surrogates."""
    cp = ord(ch) - 0x10000
    return chr(0xD800 + (cp >> 10)) + chr(0xDC00 + (cp & 0x3FF))


def apply_change(text: Text, rng: types.Range, new: str) -> Text:
    """The text after the editor replaced ``rng`` with ``new``. A UTF-16 column inside a
    character of two units splits that character into its surrogates, as the editor's
    own text then does."""

    def offset(t: Text, pos: types.Position) -> tuple[Text, int]:
        if pos.line < 0:
            return t, 0
        found = t.line(pos.line)
        if found is None:
            return t, len(t.text)
        start, end = found
        line = t.text[start:end]
        i = char_col(line, pos.character)
        if ENCODING["name"] == "utf-16" and i < len(line) and 0 < pos.character \
                and units(line, i) < pos.character:  # inside the character at i
            at = start + i
            return Text(t.text[:at] + _halves(t.text[at]) + t.text[at + 1:]), at + 1
        return t, start + i

    a_pos, b_pos = rng.start, rng.end
    if (b_pos.line, b_pos.character) < (a_pos.line, a_pos.character):
        a_pos, b_pos = b_pos, a_pos
    text, b = offset(text, b_pos)  # the end first: its split leaves the start where it was
    split, a = offset(text, a_pos)
    if split is not text:  # a split before the end moves the end one character on
        b += 1
    out = split.text[:a] + new + split.text[b:]
    return Text(_join_pairs(_join_pairs(out, a + len(new)), a))


def to_range(span: Span, text: Text) -> types.Range:
    return text.range(span)


def to_lsp(d: Diagnostic, text: Text, path: str | None = None) -> types.Diagnostic:
    """``d`` as LSP's diagnostic; one about another file (``path`` given: a robot file,
    say) is shown at the document's start, its own place named in the message."""
    message = d.message + (f"\nhint: {d.hint}" if d.hint else "")
    span = d.span
    if path is not None and span.path != path:
        message = f"{span}: {message}" if span.line else f"{span.path}: {message}"
        span = Span(path, 1, 1, 1, 1)
    return types.Diagnostic(
        range=text.range(span), message=message, severity=SEVERITY[d.severity],
        code=d.code, source="aou", code_description=None)
