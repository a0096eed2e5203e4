"""``aouc fmt``: one canonical layout for ``.aou`` source, comments kept.

The formatter only moves blanks: it never adds, drops or rewrites a token, so a formatted
file parses to the same statements and compiles to the same trajectory. The layout:

- one space between the words and quantities of a statement; ``key=value`` and the
  numbers of a vector, ``(X, Y, Z)``, written tight; the header's colon between spaces;
- statements stay on the lines they were written on (a file written on one line keeps
  its one-line form); two on one line are separated by ``; ``, and extra ``;`` go;
- the lines of a ``sequence { ... }`` block indented by two spaces;
- a comment keeps its text; one after a statement follows it after two spaces;
- no blanks at the end of a line, at most one empty line in a row, none at the start
  and the end, and one line end after the last line (the file's own: ``\\n`` or ``\\r\\n``).

A file with a syntax error is not formatted: :func:`format_source` raises the error.
Pure Python, like lint: nothing numerical is imported.
"""

from __future__ import annotations

import difflib
import os
import re
import tempfile
from dataclasses import dataclass

from ..core.codes import I501, I502
from ..core.diagnostics import AouError, Diagnostic, Span, diag
from .parse import parse

__all__ = ["FormatResult", "diff", "format_file", "format_source", "tokens", "write_in_place"]

INDENT = "  "
_GLUE = "\x00"  # marks a token written with no blank after a word or number

#: The tokens of the grammar (grammar/aou.lark), and the blanks between them.
_TOKEN = re.compile(r"""
    (?P<comment>\#[^\n]*)
  | (?P<string>"[^"\n]*")
  | (?P<quantity>[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?
                 ([A-Za-z][A-Za-z0-9]*(/[A-Za-z0-9]+)?(\^[0-9]+)?)?)
  | (?P<word>[A-Za-z_][A-Za-z0-9_-]*)
  | (?P<punct>[=(),:;{}])
  | (?P<newline>\r?\n)
  | (?P<blank>[ \t\f\r]+)
""", re.VERBOSE)


def tokens(text: str) -> list[tuple[str, str]]:
    """``(kind, text)`` of each token, blanks and line ends included.

    Raises:
        ValueError: a character no token starts with (the parser reports it as S003).
    """
    out: list[tuple[str, str]] = []
    at = 0
    while at < len(text):
        m = _TOKEN.match(text, at)
        if m is None or m.end() == at:
            raise ValueError(f"unexpected character at offset {at}")
        kind = m.lastgroup or ""
        out.append((kind, m.group(0)))
        at = m.end()
    return out


def _statement_text(parts: list[str]) -> str:
    """The tokens of one statement, spaced canonically. A word or number written glued
    to the one before (``x1.5``: the word ``x1`` and the number ``.5``) stays glued: the
    validator reads the two together."""
    out = ""
    prev = ""
    for tok in parts:
        tight = prev in ("=", "(") or tok in ("=", ")", ",") or tok.startswith(_GLUE)
        tok = tok.removeprefix(_GLUE)
        if out and not tight:
            out += " "
        out += tok
        prev = tok
    return out


def _line_text(parts: list[str]) -> str:
    """The tokens of one line (statements, ``;``, braces), spaced canonically."""
    pieces: list[str] = []  # statement texts, "{" and "}"
    current: list[str] = []

    def close() -> None:
        if current:
            pieces.append(_statement_text(current))
            current.clear()

    for tok in parts:
        if tok == ";":
            close()
            pieces.append(";")
        elif tok in ("{", "}"):
            close()
            pieces.append(tok)
        else:
            current.append(tok)
    close()
    out = ""
    for i, piece in enumerate(pieces):
        if piece == ";":
            # a separator between two statements of the line; the others go
            nxt = next((p for p in pieces[i + 1:] if p != ";"), None)
            if out and not out.endswith(("; ", "{ ")) and nxt not in (None, "}"):
                out += "; "
            continue
        if out and not out.endswith(("; ", " ")):
            out += " "
        out += piece
    return out.rstrip()


def _depth_change(parts: list[str]) -> tuple[int, int]:
    """How many blocks the line closes before its first other token, and its net change."""
    lead = 0
    for tok in parts:
        if tok != "}":
            break
        lead += 1
    return lead, parts.count("{") - parts.count("}")


def _layout(text: str) -> str:
    newline = "\r\n" if "\r\n" in text.split("\n", 1)[0] + "\n" else "\n"
    lines: list[str] = []
    depth = 0
    parts: list[str] = []
    comment: str | None = None
    toks = tokens(text) + [("newline", "\n")]
    prev_kind = ""
    for kind, tok in toks:
        glued = prev_kind in ("word", "quantity") and kind in ("word", "quantity")
        prev_kind = kind
        if kind == "blank":
            continue
        if kind == "comment":
            comment = tok.rstrip()
        elif kind == "newline":
            lead, change = _depth_change(parts)
            body = _line_text(parts)
            indent = INDENT * max(0, depth - lead)
            if body and comment:
                lines.append(f"{indent}{body}  {comment}")
            elif body or comment:
                lines.append(f"{indent}{body or comment}")
            else:
                lines.append("")
            depth = max(0, depth + change)
            parts, comment = [], None
        else:
            parts.append(_GLUE + tok if glued else tok)
    out: list[str] = []
    for line in lines:
        if line == "" and (not out or out[-1] == ""):
            continue
        out.append(line)
    while out and out[-1] == "":
        out.pop()
    return newline.join(out) + newline if out else ""


def format_source(text: str, path: str = "<string>") -> str:
    """``text`` laid out canonically (see the module's docstring).

    Raises:
        AouError: the file's first syntax error (the text is then not formatted).
    """
    bom = "\ufeff" if text.startswith("\ufeff") else ""
    body = text.removeprefix("\ufeff")
    parse(body, path)  # a syntax error stops here, with its diagnostic
    return bom + _layout(body)


@dataclass
class FormatResult:
    """One file: its text, the formatted text (None on errors) and the diagnostics."""

    path: str
    source: str | None
    formatted: str | None
    diagnostics: list[Diagnostic]

    @property
    def changed(self) -> bool:
        return self.formatted is not None and self.formatted != self.source


def format_file(path: str) -> FormatResult:
    """Read and format one file (nothing is written). A file lint cannot read (I501) or
    that has a syntax error comes back with its diagnostics and no formatted text."""
    from .linter import read_source

    try:
        read_source(path)  # the same refusals as lint: a folder, not UTF-8, ...
        with open(path, encoding="utf-8", newline="") as f:
            raw = f.read()
    except AouError as err:
        return FormatResult(path, None, None, err.diagnostics)
    except (OSError, UnicodeDecodeError) as exc:
        return FormatResult(path, None, None, [diag(
            I501, f"cannot read `{path}`: {exc}", Span.whole_file(path))])
    try:
        return FormatResult(path, raw, format_source(raw, path), [])
    except AouError as err:
        return FormatResult(path, raw, None, err.diagnostics)


def write_in_place(path: str, text: str) -> None:
    """Replace ``path``'s text whole or not at all (a temporary file renamed over it),
    keeping its permissions, its owner and its group.

    Raises:
        AouError: I502 when it cannot be written, or when its owner or group cannot be
            kept (a file of another user's, rewritten without the right to give it back).
    """
    folder = os.path.dirname(os.path.realpath(path))
    try:
        fd, tmp = tempfile.mkstemp(prefix=".aouc-fmt-", suffix=".aou", dir=folder)
    except OSError as exc:
        raise AouError(diag(I502, f"cannot write `{path}`: {exc.strerror}",
                            Span.whole_file(path))) from None
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        was, now = os.stat(path), os.stat(tmp)
        if (was.st_uid, was.st_gid) != (now.st_uid, now.st_gid):
            os.chown(tmp, was.st_uid, was.st_gid)
        os.chmod(tmp, was.st_mode & 0o7777)  # after chown, which clears set-id bits
        os.replace(tmp, os.path.realpath(path))
    except OSError as exc:
        raise AouError(diag(I502, f"cannot write `{path}`: {exc.strerror}",
                            Span.whole_file(path))) from None
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def diff(r: FormatResult) -> str:
    return "".join(difflib.unified_diff(
        (r.source or "").splitlines(keepends=True), (r.formatted or "").splitlines(keepends=True),
        fromfile=r.path, tofile=r.path))
