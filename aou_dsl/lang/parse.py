"""Stage 1, parse: source text -> a syntax tree whose every node knows its span.

The grammar (``grammar/aou.lark``, shipped as ``aou_dsl.grammar``) is shallow:
a statement is a keyword and its arguments. This stage only checks the shape;
:mod:`aou_dsl.lang.validate` gives the statements their meaning.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import threading
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import lark
from lark import Lark, Token, Transformer

from ..core.codes import S001, S002, S003
from ..core.diagnostics import AouError, Fix, Span, degree_fix, diag
from ..core.memo import cached
from ..core.units import lookalike_digit, parse_quantity

__all__ = ["Colon", "KeyVal", "Quantity", "SequenceBlock", "Statement", "SyntaxTree",
           "Vector", "Word", "build_parser", "parse", "parse_statement"]


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


@cached(maxsize=1)
def grammar_text() -> str:
    """The grammar, read from the installed package (``aou_dsl.grammar`` in the wheel).

    In a source checkout that is imported without installing (``python -m pytest`` from
    the repository root), the package maps no ``aou_dsl.grammar``; the grammar is then
    read from the checkout's top-level ``grammar/`` folder, the same file.
    """
    try:
        res = resources.files("aou_dsl.grammar").joinpath("aou.lark")
    except ModuleNotFoundError:
        res = Path(__file__).resolve().parents[2] / "grammar" / "aou.lark"
    return res.read_text(encoding="utf-8")


def build_parser(*, strict: bool = False) -> Lark:
    """A fresh LALR parser that builds Lark trees (with positions). ``strict=True`` fails
    on any grammar conflict or collision."""
    return Lark(grammar_text(), parser="lalr", propagate_positions=True, strict=strict)


def cache_dir() -> str | None:
    """Where aou keeps files it can rebuild (the parser's tables): ``$AOU_CACHE_DIR``, else
    the user's cache folder (``$XDG_CACHE_HOME`` or ``~/.cache``, ``%LOCALAPPDATA%`` on
    Windows, ``~/Library/Caches`` on macOS) + ``/aou-dsl``. None when there is no home."""
    if os.environ.get("AOU_CACHE_DIR"):
        return os.environ["AOU_CACHE_DIR"]
    if sys.platform == "win32":
        base = os.environ.get("LOCALAPPDATA")
    elif sys.platform == "darwin":
        base = os.path.expanduser("~/Library/Caches")
    else:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache")
    return os.path.join(base, "aou-dsl") if base and not base.startswith("~") else None


@cached(maxsize=4)
def _parser(start: str = "start") -> Lark:
    """The parser :func:`parse` uses (or, from ``start="statement"``,
    :func:`parse_statement`): LALR, building the syntax tree while it parses.

    Lark's analysis of the grammar (its tables, and the terminal-collision check it runs
    when ``interegular`` is installed) takes most of a cold start; it is cached in
    :func:`cache_dir` under a name that changes with the grammar, Lark and Python. The
    cache is written to a private temporary file and renamed, so concurrent processes
    never read half a file; a folder that cannot be written (read-only, full) only
    means no cache.
    """
    import hashlib

    text = grammar_text()
    options = {"parser": "lalr", "transformer": _ToSyntax(), "start": start}
    where = cache_dir()
    if where is None:
        return Lark(text, **options)
    key = hashlib.sha256(f"{text}|{lark.__version__}|{sys.version_info[:2]}".encode())
    name = key.hexdigest()[:20] + ("" if start == "start" else f"-{start}")
    path = os.path.join(where, f"grammar-{name}.lark-cache")
    if os.path.isfile(path):
        return Lark(text, cache=path, **options)
    tmp = f"{path}.{os.getpid()}.{threading.get_ident()}.tmp"
    try:
        os.makedirs(where, exist_ok=True)
        parser = Lark(text, cache=tmp, **options)  # Lark writes its tables to tmp
        os.replace(tmp, path)
    except OSError:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        return Lark(text, **options)
    return parser


# --- Tokens -> syntax tree, while parsing ------------------------------------------------

#: The file being parsed (its path for spans, its text for a vector's parentheses); per
#: thread, since the parser (and its transformer) is shared.
_CURRENT = threading.local()


def _tok_span(path: str, tok: Token) -> Span:
    return Span(path, tok.line or 1, tok.column or 1, tok.end_line or 1, tok.end_column or 1)


def _join(path: str, first: Token, last: Span | Token) -> Span:
    """From the start of token ``first`` to the end of ``last``."""
    if isinstance(last, Token):
        last = _tok_span(path, last)
    return Span(path, first.line or 1, first.column or 1, last.end_line, last.end_col)


_BLANK = " \t\f\r"


class _ToSyntax(Transformer):
    """Builds each node as the parser reduces its rule (no Lark tree is made). Spans run
    from a node's first token to its last, as Lark's positions would."""

    def quantity(self, children: list[Token]) -> Quantity:
        (tok,) = children
        value, unit = parse_quantity(str(tok))
        return Quantity(value, unit, str(tok), _tok_span(_CURRENT.path, tok))

    def word(self, children: list[Token]) -> Word:
        (tok,) = children
        return Word(str(tok), _tok_span(_CURRENT.path, tok))

    def text(self, children: list[Token]) -> Word:
        (tok,) = children
        return Word(str(tok)[1:-1], _tok_span(_CURRENT.path, tok), quoted=True)

    def colon(self, children: list[Token]) -> Colon:
        return Colon(_tok_span(_CURRENT.path, children[0]))

    def keyval(self, children: list) -> KeyVal:
        key, value = children
        return KeyVal(str(key), value, _join(_CURRENT.path, key, value.span))

    def vector(self, children: list[Token]) -> Vector:
        """``( a, b, c )`` on one line: the span takes in the parentheses, which the
        grammar does not keep, by finding them in the text around the numbers."""
        path, text = _CURRENT.path, _CURRENT.text
        first, last = children[0], children[-1]
        open_at, close_at = (first.start_pos or 0) - 1, last.end_pos or 0
        while open_at > 0 and text[open_at] in _BLANK:
            open_at -= 1
        while close_at < len(text) - 1 and text[close_at] in _BLANK:
            close_at += 1
        line = first.line or 1
        span = Span(path, line, (first.column or 1) - ((first.start_pos or 0) - open_at),
                    last.end_line or line,
                    (last.end_column or 1) + (close_at - (last.end_pos or 0)) + 1)
        items = tuple(self.quantity([c]) for c in children)
        return Vector(items, span)  # type: ignore[arg-type]

    def statement(self, children: list) -> Statement:
        kw, *args = children
        path = _CURRENT.path
        return Statement(str(kw), _tok_span(path, kw), tuple(args),
                         _join(path, kw, args[-1].span if args else kw))

    def sequence(self, children: list) -> SequenceBlock:
        stmts = tuple(c for c in children if isinstance(c, Statement))
        return SequenceBlock(stmts, _join(_CURRENT.path, children[0], children[-1]))

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
    "STRING": "a quoted text",
    "$END": "the end of the file",
}

#: Characters that look right in an editor but are not the language's, and what to
#: write instead ("{n}" is the number before the character, when there is one).
_MINUS, _QUOTES, _SPACE = ("write the minus sign as `-`",
                           'quote a text with straight double quotes: `"..."`',
                           "use an ordinary space")
_LOOKALIKES = {
    "°": ("a degree sign", "write `{n}deg`: the unit is a word after the number"),
    "º": ("an ordinal sign", "write `{n}deg`: the unit is a word after the number"),
    "×": ("a multiplication sign", "write a repeat count with the letter x: `x3`"),
    "−": ("a typographic minus", _MINUS), "–": ("a dash", _MINUS), "—": ("a dash", _MINUS),
    "“": ("a curly quote", _QUOTES), "”": ("a curly quote", _QUOTES),
    "‘": ("a curly quote", _QUOTES), "’": ("a curly quote", _QUOTES),
    "'": ("a single quote", _QUOTES), "\u00a0": ("a non-breaking space", _SPACE),
    "\u202f": ("a narrow non-breaking space", _SPACE), "\u2009": ("a thin space", _SPACE),
    "\ufeff": ("a byte-order mark", "delete it: an invisible character, often left where "
                "two files were joined"),
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


def _number_before(text: str, at: int) -> str:
    """The number that ends at ``at`` in ``text`` (`20` in `tilt 20°`), or ``""``."""
    m = re.search(r"[+-]?(\d+(\.\d*)?|\.\d+)\s*$", text[max(0, at - 40):at])
    return m.group(0).strip() if m else ""


def _unexpected_character(path: str, text: str, err: lark.exceptions.UnexpectedCharacters
                          ) -> AouError:
    at = err.pos_in_stream
    ch = text[at] if at is not None and at < len(text) else "?"
    span = Span.point(path, err.line, err.column)
    hint = fix = None
    shown = f"`{ch}`"
    if ch == "{":
        hint = "a `{` only opens a `sequence { ... }` block"
    elif ch in _LOOKALIKES:
        what, hint = _LOOKALIKES[ch]
        shown = f"`{ch}` ({what}, U+{ord(ch):04X})"
        hint = hint.format(n=_number_before(text, at or 0) or "20")
        fix = degree_fix(text, at or 0, span, _number_before(text, at or 0), ch)
    elif ch.isdecimal() or ch in "．":  # a look-alike digit: `１０s`, `0.٣m`
        shown, hint = lookalike_digit(text, at or 0)
    elif not ch.isprintable() or ch.isspace():
        shown = f"U+{ord(ch):04X} (an invisible character)"
        hint = "delete it, or replace it with an ordinary space"
    return AouError(diag(S003, f"unexpected character {shown}", span, hint=hint, found=ch,
                         fix=fix))


#: `1,5s`: a comma between the digits of a number, with what follows it up to its unit.
_DECIMAL_COMMA = re.compile(r"([+-]?\d+),(\d+([eE][+-]?\d+)?[A-Za-z][A-Za-z0-9]*(/[A-Za-z0-9]+)?"
                            r"(\^[0-9]+)?|\d+([eE][+-]?\d+)?)")


def _comma(path: str, text: str, tok: Token) -> AouError | None:
    """A comma outside a vector: a decimal comma (`1,5s`), or a vector without its
    parentheses (`goal 0.5, 0, 0.3`)."""
    at = tok.start_pos or 0
    line_start = text.rfind("\n", 0, at) + 1
    if text.rfind("(", line_start, at) > text.rfind(")", line_start, at):  # in a vector
        return AouError(diag(
            S001, "a vector has three numbers, `(X, Y, Z)`; this one has more",
            _tok_span(path, tok), found=",",
            hint="the decimal mark is a point: `0.5`, not `0,5`"
            if re.search(r"\d,\d", text[line_start:at + 2]) else None))
    start = at
    while start > 0 and (text[start - 1].isdigit() or text[start - 1] in "+-"):
        start -= 1
    m = _DECIMAL_COMMA.match(text, start)
    if m and m.start(0) == start and text[at - 1:at].isdigit():
        written, meant = m.group(0), f"{m.group(1)}.{m.group(2)}"
        where = Span(path, tok.line or 1, (tok.column or 1) - (at - start), tok.line or 1,
                     (tok.column or 1) + len(written) - (at - start))
        return AouError(diag(
            S001, f"unexpected `,` in `{written}`: the decimal mark is a point",
            where, hint=f"write `{meant}`", found=",", fix=Fix(where, meant)))
    if _number_before(text, at):
        return AouError(diag(S001, "unexpected `,` after a number", _tok_span(path, tok),
                             hint="commas separate the numbers of a vector, written in "
                             "parentheses: `goal (0.5, 0, 0.3)`", found=","))
    return None


def _syntax_error(path: str, text: str, err: lark.exceptions.UnexpectedInput) -> AouError:
    if isinstance(err, lark.exceptions.UnexpectedCharacters):
        return _unexpected_character(path, text, err)
    if isinstance(err, lark.exceptions.UnexpectedToken) and err.token.type != "$END":
        tok = err.token
        if tok.type == "COMMA" and (comma := _comma(path, text, tok)) is not None:
            return comma
        span = _tok_span(path, tok)
        expected = _expected_text(set(err.expected))
        hint = None
        if tok.type == "SEQUENCE":
            hint = "`sequence` starts a statement of its own: put it on a new line"
        elif tok.type == "RBRACE":
            hint = "a `}` closes a `sequence {` block; is the `{` missing?"
        elif tok.type == "LBRACE":
            hint = "`{` only follows `sequence`"
        return AouError(diag(S001, f"expected {expected}, found {_found_text(tok)}", span,
                             hint=hint, found=str(tok), expected=sorted(err.expected)))
    expected = _expected_text(set(getattr(err, "expected", set()) or set()))
    hint = "is a `sequence {` block missing its closing `}`?" if "RBRACE" in (
        getattr(err, "expected", None) or ()) else None
    return AouError(diag(S002, f"unexpected end of file; expected {expected}",
                         _end_span(path, text), hint=hint))


def parse(text: str, path: str = "<string>") -> SyntaxTree:
    """Parse ``.aou`` source into a :class:`SyntaxTree`.

    Raises:
        AouError: with one ``S`` diagnostic for the first syntax error.
    """
    text = text.removeprefix("\ufeff")  # a byte-order mark (Windows editors) is no text
    parser = _parser()
    _CURRENT.path, _CURRENT.text = path, text
    try:
        items = parser.parse(text)
    except lark.exceptions.UnexpectedInput as err:
        raise _syntax_error(path, text, err) from None
    finally:
        _CURRENT.text = None
    return SyntaxTree(path, items)  # type: ignore[arg-type]


def parse_statement(text: str, path: str) -> Statement | None:
    """``text`` as one statement alone (a piece of a file, padded with spaces to its
    column), or None when it is not one: the caller then parses the whole file."""
    _CURRENT.path, _CURRENT.text = path, text
    try:
        return _parser("statement").parse(text)  # type: ignore[return-value]
    except lark.exceptions.UnexpectedInput:
        return None
    finally:
        _CURRENT.text = None
