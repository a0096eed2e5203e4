"""Stage 1, parse: source text -> a syntax tree whose every node knows its span.

The grammar (``grammar/aou.lark``, shipped as ``aou_dsl.grammar``) is shallow:
a statement is a keyword and its arguments. This stage only checks the shape;
:mod:`aou_dsl.validate` gives the statements their meaning.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import lark
from lark import Lark, Token, Transformer, v_args

from .diagnostics import AouError, Span, diag
from .units import parse_quantity

__all__ = [
    "Colon",
    "KeyVal",
    "Quantity",
    "SequenceBlock",
    "Statement",
    "SyntaxTree",
    "Vector",
    "Word",
    "build_parser",
    "parse",
]


# --- The syntax tree --------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Quantity:
    """A number with its unit as written (``""`` when bare)."""

    value: float
    unit: str
    text: str
    span: Span


@dataclass(frozen=True, slots=True)
class Word:
    """A bare word, or a double-quoted text (``quoted``; ``text`` without the quotes)."""

    text: str
    span: Span
    quoted: bool = False


@dataclass(frozen=True, slots=True)
class KeyVal:
    key: str
    value: Quantity | Word
    span: Span


@dataclass(frozen=True, slots=True)
class Vector:
    items: tuple[Quantity, Quantity, Quantity]
    span: Span


@dataclass(frozen=True, slots=True)
class Colon:
    span: Span


Arg = Quantity | Word | KeyVal | Vector | Colon


@dataclass(frozen=True, slots=True)
class Statement:
    keyword: str
    keyword_span: Span
    args: tuple[Arg, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class SequenceBlock:
    statements: tuple[Statement, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class SyntaxTree:
    path: str
    items: tuple[Statement | SequenceBlock, ...]


# --- Building the parser ----------------------------------------------------------------


@functools.cache
def grammar_text() -> str:
    """The grammar, read from the installed package (``aou_dsl.grammar`` in the wheel).

    In a source checkout that is imported without installing (``python -m pytest`` from
    the repository root), the package maps no ``aou_dsl.grammar``; the grammar is then
    read from the checkout's top-level ``grammar/`` folder, the same file.
    """
    try:
        res = resources.files("aou_dsl.grammar").joinpath("aou.lark")
    except ModuleNotFoundError:
        res = Path(__file__).resolve().parent.parent / "grammar" / "aou.lark"
    return res.read_text(encoding="utf-8")


def build_parser(*, strict: bool = False) -> Lark:
    """A fresh LALR parser. ``strict=True`` fails on any grammar conflict or collision."""
    return Lark(grammar_text(), parser="lalr", propagate_positions=True, strict=strict)


@functools.cache
def _parser() -> Lark:
    return build_parser()


# --- Tree -> syntax tree ----------------------------------------------------------------


def _tok_span(path: str, tok: Token) -> Span:
    return Span(path, tok.line or 1, tok.column or 1, tok.end_line or 1, tok.end_column or 1)


def _meta_span(path: str, meta: lark.tree.Meta) -> Span:
    return Span(path, meta.line, meta.column, meta.end_line, meta.end_column)


class _ToSyntax(Transformer):
    def __init__(self, path: str):
        super().__init__()
        self.path = path

    def quantity(self, children: list[Token]) -> Quantity:
        (tok,) = children
        value, unit = parse_quantity(str(tok))
        return Quantity(value, unit, str(tok), _tok_span(self.path, tok))

    def word(self, children: list[Token]) -> Word:
        (tok,) = children
        return Word(str(tok), _tok_span(self.path, tok))

    def text(self, children: list[Token]) -> Word:
        (tok,) = children
        return Word(str(tok)[1:-1], _tok_span(self.path, tok), quoted=True)

    def colon(self, children: list[Token]) -> Colon:
        return Colon(_tok_span(self.path, children[0]))

    @v_args(meta=True)
    def keyval(self, meta: lark.tree.Meta, children: list) -> KeyVal:
        key, value = children
        return KeyVal(str(key), value, _meta_span(self.path, meta))

    @v_args(meta=True)
    def vector(self, meta: lark.tree.Meta, children: list) -> Vector:
        items = tuple(self.quantity([c]) if isinstance(c, Token) else c for c in children)
        return Vector(items, _meta_span(self.path, meta))  # type: ignore[arg-type]

    @v_args(meta=True)
    def statement(self, meta: lark.tree.Meta, children: list) -> Statement:
        kw, *args = children
        return Statement(str(kw), _tok_span(self.path, kw), tuple(args),
                         _meta_span(self.path, meta))

    @v_args(meta=True)
    def sequence(self, meta: lark.tree.Meta, children: list) -> SequenceBlock:
        stmts = tuple(c for c in children if isinstance(c, Statement))
        return SequenceBlock(stmts, _meta_span(self.path, meta))

    def start(self, children: list) -> tuple:
        return tuple(children)


# --- Syntax errors ----------------------------------------------------------------------

_TERMINAL_TEXT = {
    "QUANTITY": "a number (e.g. 1.67s)",
    "WORD": "a word",
    "_NL": "a new line",
    "SEMICOLON": "`;`",
    "LBRACE": "`{`",
    "RBRACE": "`}`",
    "LPAR": "`(`",
    "RPAR": "`)`",
    "COMMA": "`,`",
    "EQUAL": "`=`",
    "COLON": "`:`",
    "SEQUENCE": "`sequence`",
    "$END": "the end of the file",
}


def _expected_text(expected: set[str]) -> str:
    names = sorted({_TERMINAL_TEXT.get(e, e) for e in expected})
    if len(names) > 5:
        names = names[:5] + ["..."]
    return ", ".join(names)


def _end_span(path: str, text: str) -> Span:
    """Lark reports end-of-file at line -1; point at the last character instead."""
    lines = text.splitlines() or [""]
    line = len(lines)
    return Span.point(path, line, max(1, len(lines[-1])))


def _found_text(tok: Token) -> str:
    if tok.type == "_NL":
        return "the end of the line"
    if tok.type == "$END":
        return "the end of the file"
    return f"`{tok}`"


def _syntax_error(path: str, text: str, err: lark.exceptions.UnexpectedInput) -> AouError:
    if isinstance(err, lark.exceptions.UnexpectedCharacters):
        at = err.pos_in_stream
        ch = text[at] if at is not None and at < len(text) else "?"
        span = Span.point(path, err.line, err.column)
        hint = None
        if ch == "{":
            hint = "a `{` only opens a `sequence { ... }` block"
        return AouError(diag("S003", f"unexpected character `{ch}`", span, hint=hint,
                             found=ch))
    if isinstance(err, lark.exceptions.UnexpectedToken) and err.token.type != "$END":
        tok = err.token
        span = _tok_span(path, tok)
        expected = _expected_text(set(err.expected))
        hint = None
        if tok.type == "SEQUENCE":
            hint = "`sequence` starts a statement of its own: put it on a new line"
        elif tok.type == "RBRACE":
            hint = "a `}` closes a `sequence {` block; is the `{` missing?"
        elif tok.type == "LBRACE":
            hint = "`{` only follows `sequence`"
        return AouError(diag("S001", f"expected {expected}, found {_found_text(tok)}", span,
                             hint=hint, found=str(tok), expected=sorted(err.expected)))
    expected = _expected_text(set(getattr(err, "expected", set()) or set()))
    hint = "is a `sequence {` block missing its closing `}`?" if "RBRACE" in (
        getattr(err, "expected", None) or ()) else None
    return AouError(diag("S002", f"unexpected end of file; expected {expected}",
                         _end_span(path, text), hint=hint))


def parse(text: str, path: str = "<string>") -> SyntaxTree:
    """Parse ``.aou`` source into a :class:`SyntaxTree`.

    Raises:
        AouError: with one ``S`` diagnostic for the first syntax error.
    """
    try:
        tree = _parser().parse(text)
    except lark.exceptions.UnexpectedInput as err:
        raise _syntax_error(path, text, err) from None
    items = _ToSyntax(path).transform(tree)
    return SyntaxTree(path, items)
