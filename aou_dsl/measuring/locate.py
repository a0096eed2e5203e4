"""Where a sample or a field is in a trajectory file, so that a diagnostic points there.

A CSV's samples are its rows (each at its own line). A JSON document's samples are the
elements of its ``t`` and ``q`` arrays, and its header's fields are keys: their line and
column are found from the text when a diagnostic needs them (the decoder's own positions,
never a second parse of the whole file up front). An NPZ has no text: its samples are
named by their index.
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from dataclasses import dataclass

from ..core.diagnostics import Span

__all__ = ["Where", "json_position", "json_span"]

_BLANK = re.compile(r"[ \t\n\r]*")


def _skip(text: str, pos: int) -> int:
    m = _BLANK.match(text, pos)
    return m.end() if m else pos


def _member(text: str, pos: int, key: str, decoder: json.JSONDecoder) -> int | None:
    """The offset of ``key``'s value in the object at ``pos`` (its last one, as the
    decoder keeps the last of repeated keys), or None."""
    if text[pos:pos + 1] != "{":
        return None
    found, pos = None, _skip(text, pos + 1)
    while text[pos:pos + 1] == '"':
        name, pos = json.decoder.scanstring(text, pos + 1)  # type: ignore[attr-defined]
        pos = _skip(text, pos)
        if text[pos:pos + 1] != ":":
            return found
        pos = _skip(text, pos + 1)
        if name == key:
            found = pos
        pos = _skip(text, decoder.raw_decode(text, pos)[1])
        if text[pos:pos + 1] != ",":
            break
        pos = _skip(text, pos + 1)
    return found


def _element(text: str, pos: int, index: int, decoder: json.JSONDecoder) -> int | None:
    """The offset of element ``index`` of the array at ``pos``, or None."""
    if text[pos:pos + 1] != "[":
        return None
    pos = _skip(text, pos + 1)
    for _ in range(index):
        pos = _skip(text, decoder.raw_decode(text, pos)[1])
        if text[pos:pos + 1] != ",":
            return None
        pos = _skip(text, pos + 1)
    return pos if text[pos:pos + 1] not in ("]", "") else None


def json_position(text: str, path: Sequence[str | int]) -> int | None:
    """The offset in ``text`` of the value at ``path`` (keys of objects, indices of
    arrays: ``("q", 12, 3)``) in a JSON document, or None when there is none."""
    decoder = json.JSONDecoder()
    pos: int | None = _skip(text, 0)
    try:
        for step in path:
            if pos is None:
                return None
            pos = (_element(text, pos, step, decoder) if isinstance(step, int)
                   else _member(text, pos, str(step), decoder))
    except (ValueError, IndexError):  # text that does not decode: no position
        return None
    return pos


def _line_col(text: str, pos: int) -> tuple[int, int]:
    """1-based line and column of offset ``pos`` (as the JSON decoder counts them)."""
    return text.count("\n", 0, pos) + 1, pos - text.rfind("\n", 0, pos)


def json_span(path: str, text: str, where: Sequence[str | int]) -> Span | None:
    """The span of the value at ``where`` in the document ``text`` (to the end of its
    first line), or None."""
    pos = json_position(text, where)
    if pos is None:
        return None
    line, col = _line_col(text, pos)
    try:
        end = json.JSONDecoder().raw_decode(text, pos)[1]
    except ValueError:
        end = pos + 1
    newline = text.find("\n", pos, end)
    end_line, end_col = _line_col(text, end if newline < 0 else newline)
    return Span(path, line, col, end_line, end_col)


@dataclass(frozen=True)
class Where:
    """Where sample ``i`` of a file is: a CSV row (``lines``: each sample's line), an
    element of a JSON document's arrays (``text``: the document), else its index."""

    path: str
    lines: Sequence[int] | None = None
    text: str | None = None

    def label(self, i: int) -> str:
        return f"row {self.lines[i]}" if self.lines else f"sample {i}"

    def span(self, i: int, key: str = "q", j: int | None = None) -> Span:
        """Sample ``i``'s row; in a JSON document its element of ``key`` (``t`` or
        ``q``), its value of joint column ``j`` when given."""
        if self.lines:
            return Span.point(self.path, self.lines[i], 1)
        if self.text is not None:
            steps: tuple[str | int, ...] = (key, i) if j is None else (key, i, j)
            span = json_span(self.path, self.text, steps)
            if span is None and j is not None:
                span = json_span(self.path, self.text, (key, i))
            if span is not None:
                return span
        return Span.whole_file(self.path)

    def fields(self, i: int) -> dict:
        return {"sample": i, "row": self.lines[i]} if self.lines else {"sample": i}
