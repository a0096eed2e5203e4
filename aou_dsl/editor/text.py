"""The tokens of one line, where they are, and the statement around a column: what
hover and completion read (the file need not parse)."""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["Tok", "at", "statement_at", "tokens_of"]

_TOK = re.compile(r"""
    (?P<comment>\#.*)
  | (?P<string>"[^"]*"?)
  | (?P<quantity>[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?
                 ([A-Za-z][A-Za-z0-9]*(/[A-Za-z0-9]+)?(\^[0-9]+)?)?)
  | (?P<word>[A-Za-z_][A-Za-z0-9_-]*)
  | (?P<punct>[=(),:;{}])
""", re.VERBOSE)


@dataclass(frozen=True)
class Tok:
    kind: str
    text: str
    start: int  # character columns, 0-based; end exclusive
    end: int


def tokens_of(line: str) -> list[Tok]:
    """The tokens of ``line``; characters no token starts with are skipped."""
    return [Tok(m.lastgroup or "", m.group(0), m.start(), m.end())
            for m in _TOK.finditer(line)]


def statement_at(toks: list[Tok], col: int) -> list[Tok]:
    """The tokens of the statement (between ``;``, ``{``, ``}`` and a comment) that
    holds ``col``; empty when ``col`` is in a comment."""
    current: list[Tok] = []
    for t in toks:
        if t.kind == "comment":
            return [] if t.start < col else current
        if t.text in (";", "{", "}"):
            if t.end <= col:
                current = []
                continue
            return current
        current.append(t)
    return current


def at(toks: list[Tok], col: int) -> Tok | None:
    """The token under ``col`` (or ending right at it)."""
    for t in toks:
        if t.start <= col < t.end:
            return t
    for t in toks:
        if t.end == col:
            return t
    return None
