"""The language server: documents in, diagnostics out, and the requests an editor makes.

Started by ``aouc server`` (stdio). Settings come in the ``initialize`` request's
``initializationOptions`` (every one optional):

- ``robot``: compile against this arm instead of the file's own (``aouc compile
  --robot``); ``aouc server --robot NAME`` sets it too;
- ``compileDelay``: seconds without an edit before a compile (default 0.8; a save
  compiles at once); ``compileOnType``: false to compile on save only.
"""

from __future__ import annotations

import logging
import os
import sys
from typing import Any

from lsprotocol import types
from pygls.lsp.server import LanguageServer
from pygls.uris import to_fs_path

from ..version import __version__
from . import actions, completion, hover, symbols
from . import lsp_engine as engine
from .compiling import Compiles
from .convert import ENCODING, lines_of, to_lsp
from .state import Document

__all__ = ["AouServer", "make_server", "serve"]


class AouServer(LanguageServer):
    """pygls's server with aou's documents and settings."""

    def __init__(self, robot: str | None = None) -> None:
        super().__init__("aouc", __version__)
        self.docs: dict[str, Document] = {}
        self.robot = robot
        self.compile_delay = 0.8
        self.compile_on_type = True
        self.compiles = Compiles(self.publish, self._log)

    def _log(self, message: str) -> None:
        self.window_log_message(types.LogMessageParams(types.MessageType.Error, message))

    def configure(self, options: Any) -> None:
        if not isinstance(options, dict):
            return
        if isinstance(options.get("robot"), str) and options["robot"]:
            self.robot = options["robot"]
        if isinstance(options.get("compileDelay"), int | float):
            self.compile_delay = max(0.0, float(options["compileDelay"]))
        if isinstance(options.get("compileOnType"), bool):
            self.compile_on_type = options["compileOnType"]

    def doc(self, uri: str) -> Document:
        """The document at ``uri``, read from the workspace (opened or not)."""
        doc = self.docs.get(uri)
        if doc is None:
            doc = self.docs[uri] = Document(uri, to_fs_path(uri) or uri)
        wdoc = self.workspace.get_text_document(uri)
        text = wdoc.source
        if text != doc.text or doc.lint is None:
            self.update(doc, text)
        doc.version = wdoc.version  # pygls may run a change's handler after the next one
        return doc

    def update(self, doc: Document, text: str) -> None:
        """New text: lint it at once; any compile of the old text is now stale."""
        doc.text = text
        doc.lines = lines_of(text)
        doc.generation += 1
        doc.lint = engine.lint(text, doc.path)

    def publish(self, doc: Document) -> None:
        if doc.closed:
            return
        self.text_document_publish_diagnostics(types.PublishDiagnosticsParams(
            uri=doc.uri, version=doc.version,
            diagnostics=[to_lsp(d, doc.lines, doc.path) for d in doc.diagnostics]))


def make_server(robot: str | None = None) -> AouServer:
    ls = AouServer(robot)

    @ls.feature(types.INITIALIZE)
    def initialize(ls: AouServer, params: types.InitializeParams) -> None:
        ls.configure(params.initialization_options)
        enc = ls.workspace.position_encoding or "utf-16"
        ENCODING["name"] = str(getattr(enc, "value", enc))

    @ls.feature(types.TEXT_DOCUMENT_DID_OPEN)
    def did_open(ls: AouServer, params: types.DidOpenTextDocumentParams) -> None:
        doc = ls.doc(params.text_document.uri)
        doc.closed = False
        ls.publish(doc)
        ls.compiles.request(doc, 0.0, ls.robot)

    @ls.feature(types.TEXT_DOCUMENT_DID_CHANGE)
    def did_change(ls: AouServer, params: types.DidChangeTextDocumentParams) -> None:
        doc = ls.doc(params.text_document.uri)
        ls.publish(doc)
        if ls.compile_on_type:
            ls.compiles.request(doc, ls.compile_delay, ls.robot)

    @ls.feature(types.TEXT_DOCUMENT_DID_SAVE)
    def did_save(ls: AouServer, params: types.DidSaveTextDocumentParams) -> None:
        ls.compiles.request(ls.doc(params.text_document.uri), 0.0, ls.robot)

    @ls.feature(types.TEXT_DOCUMENT_DID_CLOSE)
    def did_close(ls: AouServer, params: types.DidCloseTextDocumentParams) -> None:
        doc = ls.docs.pop(params.text_document.uri, None)
        if doc is not None:
            doc.closed = True
        ls.compiles.forget(params.text_document.uri)
        ls.text_document_publish_diagnostics(types.PublishDiagnosticsParams(
            uri=params.text_document.uri, diagnostics=[]))

    @ls.feature(types.TEXT_DOCUMENT_HOVER)
    def on_hover(ls: AouServer, params: types.HoverParams) -> types.Hover | None:
        return hover.hover(ls.doc(params.text_document.uri), params.position)

    @ls.feature(types.TEXT_DOCUMENT_COMPLETION,
                types.CompletionOptions(trigger_characters=[" ", "=", ":"]))
    def on_completion(ls: AouServer, params: types.CompletionParams) -> types.CompletionList:
        return completion.complete(ls.doc(params.text_document.uri), params.position)

    @ls.feature(types.TEXT_DOCUMENT_CODE_ACTION, types.CodeActionOptions(
        code_action_kinds=[types.CodeActionKind.QuickFix]))
    def on_code_action(ls: AouServer, params: types.CodeActionParams
                       ) -> list[types.CodeAction]:
        return actions.code_actions(ls.doc(params.text_document.uri), params.range)

    @ls.feature(types.TEXT_DOCUMENT_FORMATTING)
    def on_format(ls: AouServer, params: types.DocumentFormattingParams
                  ) -> list[types.TextEdit] | None:
        return actions.format_edits(ls.doc(params.text_document.uri))

    @ls.feature(types.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
    def on_symbols(ls: AouServer, params: types.DocumentSymbolParams
                   ) -> list[types.DocumentSymbol]:
        return symbols.document_symbols(ls.doc(params.text_document.uri))

    @ls.feature(types.SHUTDOWN)
    def on_shutdown(ls: AouServer, params: None) -> None:
        ls.compiles.shutdown()

    return ls


def serve(robot: str | None = None) -> None:
    """Serve on stdin/stdout until the client says exit.

    The protocol gets its own copy of the standard output; the standard output itself
    then goes to the standard error, so that a library that prints (PyBullet does, from
    C, when it loads) cannot break a message."""
    logging.basicConfig(level=logging.WARNING)
    protocol_out = os.fdopen(os.dup(sys.stdout.fileno()), "wb", buffering=0)
    sys.stdout.flush()
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())
    sys.stdout = sys.stderr
    make_server(robot).start_io(sys.stdin.buffer, protocol_out)
