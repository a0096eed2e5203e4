"""Linting again after an edit, for tools that lint the same files on every change (the
language server, the warm :class:`~aou_dsl.driver.session.Session`).

:class:`Relinter` gives exactly what :func:`~aou_dsl.lang.linter.lint_source` gives for
the same text (the same diagnostics, behaviour, timeline and C-V point), but keeps each
file's statements (:mod:`.pieces`): an edit parses and reads only the statements it
changed. The behaviour as a whole (settings, layout, the whole-file checks, the model's
judgement) is made again from them every time, as a full lint makes it, the layout of a
sequence taking again the episodes of each statement whose node and starting pose are
as before (:class:`~aou_dsl.lang.layout.Laid`). A text the pieces cannot be sure of (a
syntax error, most often) is linted whole.
"""

from __future__ import annotations

from collections import OrderedDict

from ..core.diagnostics import AouError
from .cv import DEFAULT_WEIGHTS, CVWeights
from .linter import FileResult, judge, load_validated
from .parse import SyntaxTree, parse
from .pieces import Pieces
from .validate import primitive, validate_tree

__all__ = ["Relinter"]


class Relinter:
    """The statements of the last ``files`` files linted, kept to lint them again.

    Not shared between threads without a lock of the caller's."""

    def __init__(self, files: int = 16):
        self.files = files
        self._pieces: OrderedDict[str, Pieces] = OrderedDict()

    def pieces(self, path: str) -> Pieces:
        """What is kept of the file at ``path`` (made empty the first time)."""
        kept = self._pieces.get(path)
        if kept is None:
            kept = self._pieces[path] = Pieces(path)
            while len(self._pieces) > self.files:
                self._pieces.popitem(last=False)
        self._pieces.move_to_end(path)
        return kept

    def tree(self, text: str, path: str = "<string>") -> SyntaxTree | None:
        """The syntax tree of ``text`` (a leading byte-order mark dropped) as
        :func:`~aou_dsl.lang.parse.parse` gives it, from what is kept; None on a syntax
        error."""
        text = text.removeprefix("\ufeff")
        tree = self.pieces(path).tree(text)
        if tree is not None:
            return tree
        try:
            return parse(text, path)
        except AouError:
            return None

    def lint(self, text: str, path: str = "<string>", *,
             weights: CVWeights = DEFAULT_WEIGHTS) -> FileResult:
        """:func:`~aou_dsl.lang.linter.lint_source` of ``text``, from what is kept."""
        text = text.removeprefix("\ufeff")
        pieces = self.pieces(path)
        tree = pieces.tree(text)
        if tree is None:
            v = load_validated(text, path)
        else:
            v = validate_tree(tree, lambda ctx, st, seq: pieces.read(primitive, ctx, st, seq),
                              pieces.laid)
        return judge(text, path, v, weights)
