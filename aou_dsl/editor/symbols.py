"""Document symbols: the header and each statement, for an editor's outline."""

from __future__ import annotations

from lsprotocol import types

from ..core.diagnostics import Span
from ..lang.parse import SequenceBlock, Statement
from . import lsp_engine as engine
from .convert import to_range
from .state import Document

__all__ = ["document_symbols"]

_SETTINGS = {"robot", "goal", "from", "start", "standoff", "effort"}


def _symbol(st: Statement, doc: Document) -> types.DocumentSymbol:
    written = doc.lines[st.span.line - 1][st.span.col - 1:] if st.span.line == \
        st.span.end_line else st.keyword
    if st.span.line == st.span.end_line:
        written = written[:st.span.end_col - st.span.col]
    if st.keyword == "behaviour":
        kind = types.SymbolKind.Class
    elif st.keyword in _SETTINGS:
        kind = types.SymbolKind.Property
    else:
        kind = types.SymbolKind.Event
    return types.DocumentSymbol(
        name=written.strip() or st.keyword, kind=kind, detail=st.keyword,
        range=to_range(st.span, doc.view), selection_range=to_range(st.keyword_span, doc.view))


def document_symbols(doc: Document) -> list[types.DocumentSymbol]:
    """One symbol per statement (a ``sequence`` block holds its statements); none while
    the file does not parse."""
    tree = engine.syntax(doc.text, doc.path)
    if tree is None:
        return []
    out = []
    for item in tree.items:
        if isinstance(item, SequenceBlock):
            head = Span(item.span.path, item.span.line, item.span.col, item.span.line,
                        item.span.col + len("sequence"))
            out.append(types.DocumentSymbol(
                name="sequence", kind=types.SymbolKind.Namespace,
                range=to_range(item.span, doc.view), selection_range=to_range(head, doc.view),
                children=[_symbol(st, doc) for st in item.statements]))
        else:
            out.append(_symbol(item, doc))
    return out
