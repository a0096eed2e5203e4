"""The language server: documents in, diagnostics out, and the requests an editor makes.

Started by ``aouc server`` (stdio). Settings come in the ``initialize`` request's
``initializationOptions`` (every one optional):

- ``robot``: compile against this arm instead of the file's own (``aouc compile
  --robot``); ``aouc server --robot NAME`` sets it too;
- ``compileDelay``: seconds without an edit before a compile (default 0.8; a save
  compiles at once); ``compileOnType``: false to compile on save only.
"""

from __future__ import annotations

import asyncio
import functools
import json
import logging
import math
import os
import sys
import threading
import traceback
from collections.abc import Callable
from typing import Any

from lsprotocol import types
from pygls.exceptions import JsonRpcException, JsonRpcInternalError, JsonRpcInvalidParams
from pygls.io_ import StdoutWriter
from pygls.lsp.server import LanguageServer
from pygls.protocol import LanguageServerProtocol, lsp_method
from pygls.uris import to_fs_path

from ..version import __version__
from . import actions, completion, hover, symbols
from . import lsp_engine as engine
from .bounds import MAX_HELD, refusal, too_large_to_follow
from .compiling import Compiles
from .convert import ENCODING, Text, apply_change, to_lsp
from .state import Document
from .wire import PARSE_ERROR, Frames, Gate, error_message

__all__ = ["DOCUMENT_TEXT", "AouServer", "make_server", "serve"]

#: The request for the text the server holds of a document (``{"uri": URI}``).
DOCUMENT_TEXT = "aou/documentText"


class AouServer(LanguageServer):
    """pygls's server with aou's documents and settings. The documents are aou's own
    (:class:`Document`): pygls's store splits lines as Python does, which the protocol
    does not, so nothing here reads it (:class:`_Protocol` does not fill it)."""

    def __init__(self, robot: str | None = None) -> None:
        super().__init__("aouc", __version__, protocol_cls=_Protocol)
        _strict(self.protocol._converter)
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
        delay = options.get("compileDelay")
        if isinstance(delay, int | float) and not isinstance(delay, bool) \
                and math.isfinite(delay):
            self.compile_delay = min(max(0.0, float(delay)), 3600.0)
        if isinstance(options.get("compileOnType"), bool):
            self.compile_on_type = options["compileOnType"]

    def doc(self, uri: str) -> Document | None:
        """The open document at ``uri``; None for any other (nothing is read from disk:
        the server knows only what the editor sent). None too while it is too large to
        analyse."""
        doc = self.docs.get(uri)
        if doc is None or doc.refused is not None:
            return None
        return doc

    def open(self, item: types.TextDocumentItem) -> Document:
        old = self.docs.pop(item.uri, None)
        if old is not None:
            old.closed = True
        doc = self.docs[item.uri] = Document(item.uri, _path_of(item.uri))
        doc.version = item.version
        self.update(doc, Text(item.text))
        return doc

    def change(self, params: types.DidChangeTextDocumentParams) -> Document | None:
        doc = self.docs.get(params.text_document.uri)
        if doc is None or doc.closed:
            return None
        view = doc.view
        for change in params.content_changes:
            if isinstance(change, types.TextDocumentContentChangePartial):
                view = apply_change(view, change.range, change.text)
            else:
                view = Text(change.text)
            if len(view.text) > MAX_HELD:
                break
        doc.version = params.text_document.version
        self.update(doc, view)
        return doc

    def update(self, doc: Document, view: Text) -> None:
        """New text: lint it at once; any compile of the old text is now stale."""
        doc.generation += 1
        doc.built = None
        if len(view.text) > MAX_HELD:  # no longer followed: closed, its reason shown
            doc.view, doc.lint, doc.refused = Text(""), None, too_large_to_follow(
                doc.path, len(view.text))
            doc.closed = True
            self.publish(doc, force=True)
            self.docs.pop(doc.uri, None)
            self.compiles.forget(doc.uri)
            return
        doc.view = view
        doc.refused = refusal(view, doc.path)
        doc.lint = engine.lint(view.text, doc.path) if doc.refused is None else None

    def publish(self, doc: Document, force: bool = False) -> None:
        if doc.closed and not force:
            return
        self.text_document_publish_diagnostics(types.PublishDiagnosticsParams(
            uri=doc.uri, version=doc.version,
            diagnostics=[to_lsp(d, doc.view, doc.path) for d in doc.diagnostics]))


def _strict(converter: Any) -> None:
    """Numbers, strings and booleans in a message are read as they are typed: cattrs
    would take the string "0" for a line number, or 5 for a URI."""

    def exactly(kind: type) -> Callable[[Any, Any], Any]:
        def read(value: Any, _: Any) -> Any:
            if type(value) is kind or (kind is float and type(value) is int):
                return value
            raise TypeError(f"expected {kind.__name__}, found {type(value).__name__}")
        return read

    for kind in (int, float, str, bool):
        converter.register_structure_hook(kind, exactly(kind))


def _path_of(uri: str) -> str:
    """The path aou gives a document: the file's, for a ``file:`` URI (relative robot
    files are found beside it), else the URI itself."""
    if uri.startswith("file:"):
        try:
            return to_fs_path(uri) or uri
        except Exception:  # noqa: BLE001 - a URI the parser cannot take is kept as it is
            return uri
    return uri


class _Protocol(LanguageServerProtocol):
    """pygls's protocol, with the documents kept by :class:`AouServer` alone: opening,
    changing and closing go straight to the server's handlers."""

    @lsp_method(types.TEXT_DOCUMENT_DID_OPEN)
    def lsp_text_document__did_open(self, params: types.DidOpenTextDocumentParams) -> None:
        self.fm.features[types.TEXT_DOCUMENT_DID_OPEN](params)

    @lsp_method(types.TEXT_DOCUMENT_DID_CHANGE)
    def lsp_text_document__did_change(self, params: types.DidChangeTextDocumentParams
                                      ) -> None:
        self.fm.features[types.TEXT_DOCUMENT_DID_CHANGE](params)

    @lsp_method(types.TEXT_DOCUMENT_DID_CLOSE)
    def lsp_text_document__did_close(self, params: types.DidCloseTextDocumentParams
                                     ) -> None:
        self.fm.features[types.TEXT_DOCUMENT_DID_CLOSE](params)


def _guarded(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` whose failure is logged (with its traceback, on the standard error) and
    answered as an internal error without one."""

    @functools.wraps(fn)
    def run(ls: AouServer, params: Any) -> Any:
        try:
            return fn(ls, params)
        except JsonRpcException:  # an answer already: invalid params, say
            raise
        except Exception as exc:  # noqa: BLE001 - a bug must not stop the server
            print(f"aouc server: internal error in {fn.__name__}:\n"
                  + traceback.format_exc(), file=sys.stderr, flush=True)
            raise JsonRpcInternalError(
                f"aouc server: internal error ({type(exc).__name__}); please report it"
            ) from None

    return run


def make_server(robot: str | None = None) -> AouServer:
    ls = AouServer(robot)

    @ls.feature(types.INITIALIZE)
    @_guarded
    def initialize(ls: AouServer, params: types.InitializeParams) -> None:
        ls.configure(params.initialization_options)
        enc = ls.workspace.position_encoding or "utf-16"
        ENCODING["name"] = str(getattr(enc, "value", enc))

    @ls.feature(types.TEXT_DOCUMENT_DID_OPEN)
    @_guarded
    def did_open(ls: AouServer, params: types.DidOpenTextDocumentParams) -> None:
        doc = ls.open(params.text_document)
        ls.publish(doc)
        if doc.refused is None:
            ls.compiles.request(doc, 0.0, ls.robot)

    @ls.feature(types.TEXT_DOCUMENT_DID_CHANGE)
    @_guarded
    def did_change(ls: AouServer, params: types.DidChangeTextDocumentParams) -> None:
        doc = ls.change(params)
        if doc is None or doc.closed:
            return
        ls.publish(doc)
        if ls.compile_on_type and doc.refused is None:
            ls.compiles.request(doc, ls.compile_delay, ls.robot)

    @ls.feature(types.TEXT_DOCUMENT_DID_SAVE)
    @_guarded
    def did_save(ls: AouServer, params: types.DidSaveTextDocumentParams) -> None:
        doc = ls.doc(params.text_document.uri)
        if doc is not None:
            ls.compiles.request(doc, 0.0, ls.robot)

    @ls.feature(types.TEXT_DOCUMENT_DID_CLOSE)
    @_guarded
    def did_close(ls: AouServer, params: types.DidCloseTextDocumentParams) -> None:
        doc = ls.docs.pop(params.text_document.uri, None)
        if doc is None:
            return
        doc.closed = True
        ls.compiles.forget(params.text_document.uri)
        ls.text_document_publish_diagnostics(types.PublishDiagnosticsParams(
            uri=params.text_document.uri, diagnostics=[]))

    @ls.feature(types.TEXT_DOCUMENT_HOVER)
    @_guarded
    def on_hover(ls: AouServer, params: types.HoverParams) -> types.Hover | None:
        doc = ls.doc(params.text_document.uri)
        return hover.hover(doc, params.position) if doc is not None else None

    @ls.feature(types.TEXT_DOCUMENT_COMPLETION,
                types.CompletionOptions(trigger_characters=[" ", "=", ":"]))
    @_guarded
    def on_completion(ls: AouServer, params: types.CompletionParams) -> types.CompletionList:
        doc = ls.doc(params.text_document.uri)
        if doc is None:
            return types.CompletionList(is_incomplete=False, items=[])
        return completion.complete(doc, params.position)

    @ls.feature(types.TEXT_DOCUMENT_CODE_ACTION, types.CodeActionOptions(
        code_action_kinds=[types.CodeActionKind.QuickFix]))
    @_guarded
    def on_code_action(ls: AouServer, params: types.CodeActionParams
                       ) -> list[types.CodeAction]:
        doc = ls.doc(params.text_document.uri)
        return actions.code_actions(doc, params.range) if doc is not None else []

    @ls.feature(types.TEXT_DOCUMENT_FORMATTING)
    @_guarded
    def on_format(ls: AouServer, params: types.DocumentFormattingParams
                  ) -> list[types.TextEdit] | None:
        doc = ls.doc(params.text_document.uri)
        return actions.format_edits(doc) if doc is not None else None

    @ls.feature(types.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
    @_guarded
    def on_symbols(ls: AouServer, params: types.DocumentSymbolParams
                   ) -> list[types.DocumentSymbol]:
        doc = ls.doc(params.text_document.uri)
        return symbols.document_symbols(doc) if doc is not None else []

    @ls.feature(DOCUMENT_TEXT)
    @_guarded
    def on_text(ls: AouServer, params: Any) -> dict[str, Any] | None:
        """The text the server holds of an open document, exactly: for checking that a
        client and the server agree on it."""
        uri = params.get("uri") if isinstance(params, dict) else getattr(params, "uri", None)
        if not isinstance(uri, str):
            raise JsonRpcInvalidParams(f"{DOCUMENT_TEXT} takes {{\"uri\": STRING}}")
        doc = ls.docs.get(uri)
        return None if doc is None else {"uri": uri, "version": doc.version,
                                         "text": doc.text}

    @ls.feature(types.SHUTDOWN)
    @_guarded
    def on_shutdown(ls: AouServer, params: None) -> None:
        ls.compiles.shutdown()

    return ls


#: The exit status on Ctrl-C, as every command's.
EXIT_INTERRUPTED = 130
#: Seconds without a byte after which a body that is whole JSON, but shorter than its
#: Content-Length said, is taken as a broken message.
STALL = 0.5


def serve(robot: str | None = None) -> int:
    """Serve on stdin/stdout until the client says exit or closes the stream; 130 on
    Ctrl-C (the process ends there: a compile under way is not waited for).

    The protocol gets its own copy of the standard output; the standard output itself
    then goes to the standard error, so that a library that prints (PyBullet does, from
    C, when it loads) cannot break a message. The standard input is read in a thread of
    its own, straight from its file descriptor, and handed to the event loop a piece at a
    time (the next piece is read once the last is taken in)."""
    logging.basicConfig(level=logging.WARNING)
    logging.getLogger("pygls").setLevel(logging.CRITICAL)  # what goes wrong is answered
    protocol_out = os.fdopen(os.dup(sys.stdout.fileno()), "wb", buffering=0)
    sys.stdout.flush()
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())
    sys.stdout = sys.stderr
    ls = make_server(robot)
    writer = StdoutWriter(protocol_out)
    ls.protocol.set_writer(writer)

    def send(msg_id: Any, code: int, message: str) -> None:
        body = json.dumps(error_message(msg_id, code, message)).encode("ascii")
        writer.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)

    gate = Gate(ls.protocol, send, ls._log)
    frames = Frames(gate.body, lambda msg_id, why: send(
        msg_id, PARSE_ERROR, f"Parse error: a broken message: {why}"))
    loop = asyncio.new_event_loop()
    asyncio.set_event_loop(loop)
    stall: list[asyncio.TimerHandle] = []

    def take(data: bytes, taken: threading.Event) -> None:
        try:
            for timer in stall:
                timer.cancel()
            stall.clear()
            if not data:
                loop.stop()
                return
            frames.feed(data)
            if frames.length is not None:
                stall.append(loop.call_later(STALL, frames.stalled))
        finally:
            taken.set()

    def pump() -> None:
        fd = sys.stdin.fileno()
        while True:
            try:
                data = os.read(fd, 1 << 16)
            except OSError:
                data = b""
            taken = threading.Event()
            try:
                loop.call_soon_threadsafe(take, data, taken)
            except RuntimeError:  # the loop is closed: the server is ending
                return
            while not taken.wait(0.5):
                if loop.is_closed():
                    return
            if not data:
                return

    threading.Thread(target=pump, name="aou-stdin", daemon=True).start()
    try:
        loop.run_forever()
    except KeyboardInterrupt:
        print("aouc: interrupted", file=sys.stderr, flush=True)
        os._exit(EXIT_INTERRUPTED)
    finally:
        ls.compiles.shutdown()
    return 0
