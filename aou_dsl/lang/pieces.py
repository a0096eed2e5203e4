"""Parsing again after an edit: a file cut into its statements, each parsed alone and
kept, with what the validator read from it, by its text and its place.

A file is a header and statements between separators (``;`` or a new line), at the top
or in one ``sequence { ... }`` block, with comments; no token runs over a line's end. So
the text can be cut where Lark would see a separator, a brace or a comment (a quoted
text is skipped whole: its ``;`` or ``#`` is no separator), and each piece between two
cuts parsed as one statement. A piece whose text and column are as before is not parsed
again; on another line it is the same statement moved, its spans shifted. The pieces
are put together in the grammar's shape (:class:`_Shape`).

Whenever the cutting cannot be sure it sees what the grammar sees (an unclosed quote, a
brace out of place, a piece that is not a statement, ``sequence`` where a statement
starts in a block), :meth:`Pieces.tree` gives None and the caller parses the whole file:
its syntax error, or its tree, is then exactly the full parse's.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..core.diagnostics import Diagnostic, Span
from ..core.memo import cached
from .ir import Node
from .layout import Laid
from .parse import SequenceBlock, Statement, SyntaxTree, parse_statement
from .values import Ctx

__all__ = ["Piece", "Pieces", "shifted"]

#: A quoted text (skipped whole), a comment or a separator or brace (group 1), or a
#: quote that does not close on its line.
_CUT = re.compile(r'"[^"\n]*"|(#[^\n]*|[;{}\n])|"')
#: Whitespace Lark ignores between tokens (grammar/aou.lark); any other is a character.
_BLANK = " \t\f\r"
#: A piece that starts with the keyword ``sequence`` (a longer word is not it).
_SEQUENCE = re.compile(r"[ \t\f\r]*sequence(?![A-Za-z0-9_-])")

#: A line the cutting finds nothing in: one piece, the whole line.
_PLAIN = re.compile(r'[^;{}"#\n]*')

Read = tuple[Node | None, tuple[Diagnostic, ...]]


def _alone(line: str) -> bool:
    """``line`` holds one statement and nothing else (it may not parse)."""
    return _PLAIN.fullmatch(line) is not None and bool(line.strip(_BLANK)) and \
        _SEQUENCE.match(line) is None


@cached(maxsize=512)
def _field_names(cls: type) -> tuple[str, ...]:
    return tuple(f.name for f in dataclasses.fields(cls))


def shifted(obj: Any, lines: int, cols: int = 0) -> Any:
    """``obj`` with every :class:`Span` in it moved down by ``lines`` and right by
    ``cols``: syntax nodes, IR nodes, diagnostics and their fixes are rebuilt field by
    field (an IR node's checks are not run again: its values are those already checked).
    A shift right is for a statement parsed alone, whose spans all lie on its one line."""
    if lines == 0 and cols == 0:
        return obj
    if isinstance(obj, Span):
        return Span(obj.path, obj.line + lines, obj.col + cols, obj.end_line + lines,
                    obj.end_col + cols)
    if isinstance(obj, tuple | list):
        return type(obj)(shifted(x, lines, cols) for x in obj)
    if isinstance(obj, dict):
        return {k: shifted(v, lines, cols) for k, v in obj.items()}
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        new = object.__new__(type(obj))
        for name in _field_names(type(obj)):
            object.__setattr__(new, name, shifted(getattr(obj, name), lines, cols))
        return new
    return obj


@dataclass
class Piece:
    """One statement of the file: the line it is on, its syntax and what the validator
    read from it (by whether it is in a ``sequence`` block): the node and diagnostics."""

    line: int
    statement: Statement
    reads: dict[bool, Read] = field(default_factory=dict)

    def moved(self, line: int) -> Piece:
        """The same statement on ``line``."""
        d = line - self.line
        return Piece(line, shifted(self.statement, d),
                     {k: (shifted(n, d), shifted(ds, d)) for k, (n, ds) in self.reads.items()})


_TOP, _AFTER, _SEQ, _BLOCK, _BLOCK_AFTER = range(5)


class _Shape:
    """The grammar's top level over the cut pieces: items between separators, one of
    them possibly ``sequence`` (separators) ``{`` statements ``}``. Each method returns
    False where the text leaves that shape (the whole file is then parsed)."""

    def __init__(self, path: str, statement: Callable[[str, int, int], Statement | None]):
        self.path, self.statement = path, statement
        self.items: list[Statement | SequenceBlock] = []
        self.block: list[Statement] = []
        self.state = _TOP
        self.opened = (0, 0)
        #: Where each line's (last) statement went: (index in items, index in the block
        #: or -1 at the top level).
        self.where: dict[int, tuple[int, int]] = {}

    def sep(self) -> None:
        if self.state in (_AFTER, _BLOCK_AFTER):  # the next statement may start
            self.state -= 1

    def text(self, piece: str, line: int, col: int) -> bool:
        keyword = _SEQUENCE.match(piece)
        if self.state == _TOP and keyword is not None:
            if piece[keyword.end():].strip(_BLANK):
                return False
            self.opened, self.state = (line, col + keyword.end() - len("sequence")), _SEQ
            return True
        if self.state not in (_TOP, _BLOCK) or keyword is not None:
            return False
        st = self.statement(piece, line, col)
        if st is None:
            return False
        at_top = self.state == _TOP
        self.where[line] = (len(self.items), -1 if at_top else len(self.block))
        (self.items if at_top else self.block).append(st)
        self.state += 1  # to _AFTER or _BLOCK_AFTER: a separator must follow
        return True

    def brace(self, which: str, line: int, col: int) -> bool:
        if which == "{" and self.state == _SEQ:
            self.state = _BLOCK
            return True
        if which == "}" and self.state in (_BLOCK, _BLOCK_AFTER):
            span = Span(self.path, *self.opened, line, col + 1)
            self.items.append(SequenceBlock(tuple(self.block), span))
            self.state = _AFTER
            return True
        return False

    def done(self) -> bool:
        return self.state in (_TOP, _AFTER)


class Pieces:
    """The pieces of one file's last parse, to parse its next text from.

    Two generations are kept: the pieces of the last text, and those of the text being
    parsed; a piece no longer in the file is forgotten at the next parse."""

    def __init__(self, path: str):
        self.path = path
        self._at: dict[tuple[str, int, int], Piece] = {}  # (text, line, col)
        self._anywhere: dict[tuple[str, int], Piece] = {}  # (text, col), on any line
        self._new_at: dict[tuple[str, int, int], Piece] = {}
        self._new_anywhere: dict[tuple[str, int], Piece] = {}
        self._by_statement: dict[int, Piece] = {}
        self.parsed = 0  # pieces parsed (not found kept), for tests and benchmarks
        self.laid = Laid()  # the episodes of the last layout, by statement
        self._last: SyntaxTree | None = None  # the last tree, of the text of _lines
        self._lines: list[str] = []
        self._where: dict[int, tuple[int, int]] = {}

    def tree(self, text: str) -> SyntaxTree | None:
        """The syntax tree of ``text`` (no byte-order mark), or None when only a parse
        of the whole file can tell."""
        self.laid.turn()
        tree = self._one_line(text)
        if tree is not None:
            return tree
        self._new_at, self._new_anywhere, self._by_statement = {}, {}, {}
        shape = _Shape(self.path, self._statement)
        ok = self._cut(text, shape) and shape.done()
        self._at, self._anywhere = self._new_at, self._new_anywhere
        self._last = SyntaxTree(self.path, tuple(shape.items)) if ok else None
        self._lines, self._where = text.split("\n"), shape.where
        return self._last

    def _one_line(self, text: str) -> SyntaxTree | None:
        """The last tree with one statement replaced, when ``text`` differs from the
        last text in one line, which both before and after is one statement with nothing
        the cutting looks for (no separator, brace, quote or comment): the file's shape is
        then as it was, and only that statement is new."""
        lines = text.split("\n")
        if self._last is None or len(lines) != len(self._lines):
            return None
        changed = [k for k, (a, b) in enumerate(zip(lines, self._lines, strict=True))
                   if a != b]
        if not changed:
            return self._last  # the same text: the same tree
        if len(changed) != 1:
            return None
        k = changed[0]
        was, now = self._lines[k], lines[k]
        where = self._where.get(k + 1)
        if where is None or not (_alone(was) and _alone(now)):
            return None
        self._new_at, self._new_anywhere = self._at, self._anywhere  # one generation on
        st = self._statement(now, k + 1, 1)
        if st is None:
            return None
        gone = self._at.pop((was, k + 1, 1), None)
        if gone is not None:
            self._by_statement.pop(id(gone.statement), None)
            if self._anywhere.get((was, 1)) is gone:
                del self._anywhere[was, 1]
        items = list(self._last.items)
        i, j = where
        block = items[i]
        if isinstance(block, SequenceBlock):
            items[i] = SequenceBlock((*block.statements[:j], st, *block.statements[j + 1:]),
                                     block.span)
        else:
            items[i] = st
        self._last, self._lines = SyntaxTree(self.path, tuple(items)), lines
        return self._last

    def _cut(self, text: str, shape: _Shape) -> bool:
        """Feed ``shape`` the pieces and cuts of ``text``; False at the first doubt,
        after which the later pieces are only kept (not parsed) for the next text."""
        line, line_start, start, ok = 1, 0, 0, True
        for m in _CUT.finditer(text):
            cut = m.group(1)
            if cut is None:
                ok = ok and m.end() - m.start() > 1  # a quote that does not close
                continue
            ok = self._piece(shape, ok, text[start:m.start()], line, start - line_start + 1)
            if ok and cut in ";\n":
                shape.sep()
            elif ok and cut in "{}":
                ok = shape.brace(cut, line, m.start() - line_start + 1)
            if cut == "\n":
                line, line_start = line + 1, m.end()
            start = m.end()
        return self._piece(shape, ok, text[start:], line, start - line_start + 1)

    def _piece(self, shape: _Shape, ok: bool, piece: str, line: int, col: int) -> bool:
        if not piece.strip(_BLANK):
            return ok
        if ok:
            return shape.text(piece, line, col)
        self._keep(piece, line, col)
        return False

    def _keep(self, piece: str, line: int, col: int) -> None:
        p = self._at.get((piece, line, col))
        if p is not None:
            self._new_at[piece, line, col] = p
            self._new_anywhere.setdefault((piece, col), p)

    def _statement(self, piece: str, line: int, col: int) -> Statement | None:
        p = self._at.get((piece, line, col))
        if p is None:
            q = self._new_anywhere.get((piece, col)) or self._anywhere.get((piece, col))
            if q is not None:
                p = q.moved(line)
            else:
                # parsed at column 1 and moved to its own: padding it with spaces to
                # its column would make each piece of a long line cost the line so far
                st = parse_statement(piece, self.path)
                if st is None:
                    return None
                self.parsed += 1
                p = Piece(1, shifted(st, 0, col - 1)).moved(line)
        self._new_at[piece, line, col] = p
        self._new_anywhere.setdefault((piece, col), p)
        self._by_statement[id(p.statement)] = p
        return p.statement

    def read(self, read: Callable[[Ctx, Statement, bool], Node | None], ctx: Ctx,
             st: Statement, in_sequence: bool) -> Node | None:
        """``read(ctx, st, in_sequence)``, done once per piece: its node, and its
        diagnostics added to ``ctx`` again (in the order a full validation adds them)."""
        p = self._by_statement.get(id(st))
        if p is None or p.statement is not st:
            return read(ctx, st, in_sequence)
        got = p.reads.get(in_sequence)
        if got is None:
            own = Ctx(ctx.path)
            node = read(own, st, in_sequence)
            got = p.reads[in_sequence] = (node, tuple(own.diags))
        ctx.diags.extend(got[1])
        return got[0]
