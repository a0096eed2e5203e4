"""The server's side of the wire: messages in from the editor's stream, checked, each
handed to pygls's protocol or answered with the JSON-RPC error it earns.

A message is a header (``Content-Length: N`` and maybe other fields, each line ended
by ``\\r\\n``, then an empty line) and N bytes of JSON in UTF-8. What goes wrong, and what
the server does:

- a header without a usable ``Content-Length``, bytes between messages, a body that is
  not UTF-8 or not JSON: -32700 (parse error);
- JSON that is not a request, a notification or a response (``null``, a string, a list,
  an ``id`` that is not a number or a string, no ``method``): -32600 (invalid request);
- a method the server does not have: -32601; a known one with parameters of the wrong
  shape or type (a negative position, a string for a number): -32602 (invalid params);
- a request before ``initialize``: -32002; after ``shutdown``: -32600.

Each error answers the request's ``id`` when it can be read, else ``null``; a
notification gets no answer (JSON-RPC has none for it), only a line in the editor's log.
A ``Content-Length`` that says more than was sent does not leave the server waiting: a
header inside what should be the body starts the next message (JSON never holds one),
and a body that is whole JSON followed by a pause is answered as a broken message.
Messages over :data:`~aou_dsl.editor.bounds.MAX_MESSAGE` are skipped unread.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from typing import Any

from lsprotocol import types
from pygls.protocol import JsonRPCNotification, JsonRPCRequestMessage

from .bounds import MAX_MESSAGE

__all__ = ["INVALID_PARAMS", "INVALID_REQUEST", "METHOD_NOT_FOUND", "NOT_INITIALIZED",
           "PARSE_ERROR", "Frames", "Gate", "error_message"]

PARSE_ERROR, INVALID_REQUEST, METHOD_NOT_FOUND, INVALID_PARAMS = -32700, -32600, -32601, -32602
NOT_INITIALIZED = -32002

#: A header line that gives the length (the rest of the line may be anything).
_LENGTH = re.compile(rb"content-length[ \t]*:", re.IGNORECASE)
#: A header of the next message inside a body: never in JSON (a raw line end cannot be
#: in a string, and the words cannot be outside one).
_NEXT = re.compile(rb"content-length[ \t]*:[ \t]*\d+[ \t]*\r?\n", re.IGNORECASE)
#: A field line of a header.
_FIELD = re.compile(rb"[A-Za-z][A-Za-z0-9-]*[ \t]*:[^\r\n]*")
#: The id at the start of a body, when the body cannot be read whole.
_ID = re.compile(rb'^\s*\{\s*(?:"jsonrpc"\s*:\s*"2\.0"\s*,\s*)?"id"\s*:\s*'
                 rb'(-?\d{1,18}|"(?:[^"\\\r\n]|\\.){0,200}")(?=\s*[,}])')
#: Most bytes kept of a header line or of the junk between messages.
_MAX_LINE = 8192


#: What the end of a body cut inside the next message's header ends with.
_HEADER_START = re.compile(rb"content-length[ \t]*:[ \t]*\d*\r?", re.IGNORECASE)


def _header_at_end(body: bytes) -> int | None:
    """Where the start of a header that runs past the end of ``body`` begins, if the
    body ends in one (a JSON body ends in ``}`` or ``]``, so one that does cannot)."""
    if body.rstrip()[-1:] in (b"}", b"]"):
        return None
    for at in range(max(0, len(body) - 40), len(body)):
        tail = body[at:]
        if b"content-length".startswith(tail.lower()) or _HEADER_START.fullmatch(tail):
            return at
    return None


def _id_from(body: bytes) -> int | str | None:
    """The request id written at the start of ``body``, if there is one to read."""
    m = _ID.match(body[:512])
    if m is None:
        return None
    try:
        value = json.loads(m.group(1).decode("utf-8"))
    except (ValueError, UnicodeDecodeError):
        return None
    return value if isinstance(value, int | str) else None


class Frames:
    """Cuts the editor's byte stream into message bodies. ``feed`` takes bytes as they
    come and calls ``on_body(bytes)`` for each whole message and ``on_broken(id,
    reason)`` for each broken one; ``stalled`` is called when no byte has come for a
    while."""

    def __init__(self, on_body: Callable[[bytes], None],
                 on_broken: Callable[[int | str | None, str], None],
                 max_message: int = MAX_MESSAGE) -> None:
        self.on_body, self.on_broken, self.max_message = on_body, on_broken, max_message
        self.buf = bytearray()
        self.length: int | None = None  # of the body being read, once its header is in
        self.bad_header: str | None = None  # why the header being read is no good
        self.in_header = False  # a field line of a header has been read
        self.skipping = 0  # bytes of an oversized body still to skip
        self.head = b""  # the start of the body being skipped (for its id)
        self.scanned = 0  # bytes of the body looked through for a next header
        self.length_seen: int | None = None  # the header's Content-Length, so far

    # --- feeding ------------------------------------------------------------------------

    def feed(self, data: bytes) -> None:
        self.buf += data
        while self._step():
            pass

    def _step(self) -> bool:
        """Take one thing out of the buffer; False when more bytes are needed."""
        if self.skipping:
            return self._skip()
        if self.length is not None:
            return self._body()
        return self._header_line()

    def _header_line(self) -> bool:
        end = self.buf.find(b"\n")
        if end < 0:
            if len(self.buf) > _MAX_LINE:  # a line too long to be a header: junk
                m = _LENGTH.search(self.buf, 1)
                if m is not None:
                    self._junk(self.buf[:m.start()])
                    del self.buf[:m.start()]
                    return True
                self._junk(self.buf[:-32])
                del self.buf[:-32]  # keep a tail: a header may start in it
            return False
        line = bytes(self.buf[:end]).rstrip(b"\r")
        del self.buf[:end + 1]
        if not line.strip():
            if self.in_header:
                self._header_done()
            return True
        m = _LENGTH.search(line)
        if m is not None and m.start() > 0 and not _FIELD.fullmatch(line):
            # the rest of a broken body, then the next header on the same line
            self._junk(line[:m.start()])
            line = line[m.start():]
        if not _FIELD.fullmatch(line):
            self._junk(line)
            return True
        self.in_header = True
        name, _, value = line.partition(b":")
        if name.strip().lower() == b"content-length":
            text = value.strip()
            if not text.isdigit() or len(text) > 15:
                self.bad_header = f"its Content-Length is not a number of bytes: {text[:40]!r}"
                self.length = None
            else:
                self.length_seen = int(text)
                self.bad_header = None
        return True

    def _header_done(self) -> None:
        self.in_header = False
        length, self.length_seen = self.length_seen, None
        if self.bad_header is not None or length is None:
            self.on_broken(None, self.bad_header or "its header has no Content-Length")
            self.bad_header = None
            return
        if length > self.max_message:
            self.skipping, self.head, self.scanned = length, b"", 0
            return
        self.length, self.scanned = length, 0

    def _junk(self, data: bytes | bytearray) -> None:
        if data.strip():
            self.on_broken(_id_from(bytes(data)), "bytes outside a message (no header "
                           "before them)")

    def _next_header(self, upto: int) -> int | None:
        """Where a header starts inside the first ``upto`` bytes of the buffer, if one
        does (looked for once in each byte, a little overlap kept)."""
        start = max(0, self.scanned - 64)
        m = _NEXT.search(self.buf, start, upto)
        self.scanned = max(self.scanned, upto)
        return None if m is None else m.start()

    def _body(self) -> bool:
        assert self.length is not None
        upto = min(self.length, len(self.buf))
        at = self._next_header(upto)
        if at is not None:  # the length said more than the body held
            body = bytes(self.buf[:at])
            del self.buf[:at]
            self.length = None
            self.on_broken(_id_from(body), "its Content-Length is longer than its body: the "
                           "next message's header is inside it")
            return True
        if len(self.buf) < self.length:
            return False
        body = bytes(self.buf[:self.length])
        cut = _header_at_end(body)
        if cut is not None:  # the length ends inside the next message's header
            del self.buf[:cut]
            self.length = None
            self.on_broken(_id_from(body), "its Content-Length is longer than its body: "
                           "the next message's header starts inside it")
            return True
        del self.buf[:self.length]
        self.length = None
        self.on_body(body)
        return True

    def _skip(self) -> bool:
        if len(self.head) < 512:
            self.head += bytes(self.buf[:512 - len(self.head)])
        at = self._next_header(min(self.skipping, len(self.buf)))
        if at is not None:
            del self.buf[:at]
            self.skipping, self.scanned = 0, 0
            self.on_broken(_id_from(self.head), "its Content-Length is longer than its "
                           "body: the next message's header is inside it")
            return True
        n = min(self.skipping, max(0, len(self.buf) - 64)) if len(self.buf) < self.skipping \
            else self.skipping
        del self.buf[:n]
        self.skipping -= n
        self.scanned = max(0, self.scanned - n)
        if self.skipping == 0:
            self.on_broken(_id_from(self.head), f"it is larger than the server reads "
                           f"({self.max_message:,} bytes)")
            return True
        return False

    def stalled(self) -> None:
        """No byte has come for a while: a body that is whole JSON already, whose
        Content-Length says more, is a broken message (its sender is waiting)."""
        if self.length is None or not self.buf or len(self.buf) >= self.length:
            return
        body = bytes(self.buf)
        try:
            json.loads(body.decode("utf-8"))
        except (ValueError, UnicodeDecodeError, RecursionError):
            return
        self.buf.clear()
        self.length = None
        self.on_broken(_id_from(body), "its Content-Length is longer than its body")


# --- the messages ----------------------------------------------------------------------


def _valid_id(value: object) -> bool:
    return (isinstance(value, int) and not isinstance(value, bool)) or isinstance(value, str)


class Gate:
    """Checks each message and hands the good ones to pygls's ``protocol``; answers the
    others with ``send(id, code, message)`` and logs what cannot be answered with
    ``log(message)``."""

    def __init__(self, protocol: Any, send: Callable[[Any, int, str], None],
                 log: Callable[[str], None]) -> None:
        self.protocol, self.send, self.log = protocol, send, log
        self.initialized = False
        self.shut_down = False

    def body(self, raw: bytes) -> None:
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            self.send(_id_from(raw), PARSE_ERROR, f"Parse error: the message is not UTF-8 "
                      f"(byte {exc.start})")
            return
        try:
            data = json.loads(text)
        except (ValueError, RecursionError) as exc:
            self.send(_id_from(raw), PARSE_ERROR, f"Parse error: the message is not JSON "
                      f"({str(exc)[:200]})")
            return
        self.message(data)

    def message(self, data: object) -> None:
        if not isinstance(data, dict):
            what = "a list (batches are not part of the protocol)" if isinstance(data, list) \
                else f"JSON {json.dumps(data)[:40]}"
            self.send(None, INVALID_REQUEST, f"Invalid request: a message is an object, "
                      f"not {what}")
            return
        has_id = "id" in data
        msg_id = data.get("id")
        if has_id and not _valid_id(msg_id):
            self.send(None, INVALID_REQUEST, "Invalid request: an id is a number or a "
                      f"string, not {type(msg_id).__name__}")
            return
        if data.get("jsonrpc") != "2.0":
            self._refuse(data, INVALID_REQUEST, 'Invalid request: "jsonrpc" must be "2.0"')
            return
        method = data.get("method")
        if "method" not in data:
            if has_id and ("result" in data or "error" in data):
                self._response(data)
            else:
                self._refuse(data, INVALID_REQUEST, "Invalid request: no method")
            return
        if not isinstance(method, str):
            self._refuse(data, INVALID_REQUEST, "Invalid request: the method is not a string")
            return
        self._call(data, method, has_id)

    def _refuse(self, data: dict, code: int, message: str) -> None:
        if "id" in data:
            self.send(data["id"], code, message)
        else:
            self.log(f"aouc server: ignored a notification: {message}")

    def _response(self, data: dict) -> None:
        """A response to one of the server's own requests."""
        try:
            msg = self.protocol.structure_message(data)
            self.protocol.handle_message(msg)
        except Exception as exc:  # noqa: BLE001 - a bad response is the client's to fix
            self.log(f"aouc server: ignored a malformed response ({type(exc).__name__})")

    def _known(self, method: str) -> bool:
        fm = self.protocol.fm
        return method in fm.builtin_features or method in fm.features or \
            method == types.CANCEL_REQUEST

    def _call(self, data: dict, method: str, is_request: bool) -> None:
        if method == types.EXIT:
            self.protocol.handle_message(self.protocol.structure_message(
                {"jsonrpc": "2.0", "method": method}))
            return
        if not self.initialized and method != types.INITIALIZE:
            self._refuse(data, NOT_INITIALIZED, f"Server not initialized: {method} before "
                         "initialize")
            return
        if self.shut_down:
            self._refuse(data, INVALID_REQUEST, f"Invalid request: {method} after shutdown")
            return
        if method == types.INITIALIZE and self.initialized:
            self._refuse(data, INVALID_REQUEST, "Invalid request: initialize was already sent")
            return
        if not self._known(method):
            if is_request:
                self.send(data["id"], METHOD_NOT_FOUND, f"Method not found: {method[:200]}")
            return  # an unknown notification is ignored, as the protocol says
        kind = self.protocol.get_message_type(method)
        fields = getattr(kind, "__attrs_attrs__", None)
        takes_id = fields is None or any(f.name == "id" for f in fields)
        if is_request != takes_id:
            if is_request:
                self.send(data["id"], METHOD_NOT_FOUND, f"Method not found: {method} is a "
                          "notification, not a request")
            else:
                self.log(f"aouc server: ignored {method}: a request sent without an id")
            return
        if "params" in data and not isinstance(data["params"], dict | list) and \
                data["params"] is not None:
            self._refuse(data, INVALID_PARAMS, f"Invalid params: the params of {method} are "
                         "an object")
            return
        if kind is None:
            kind = JsonRPCRequestMessage if is_request else JsonRPCNotification
        try:
            msg = self.protocol._converter.structure(data, kind)
        except Exception:  # noqa: BLE001 - cattrs says what; the client gets the code
            self._refuse(data, INVALID_PARAMS, f"Invalid params: {method}'s params are not "
                         "of the shape or types the protocol gives them")
            return
        if method == types.INITIALIZE:
            self.initialized = True
        elif method == types.SHUTDOWN:
            self.shut_down = True
        self.protocol.handle_message(msg)


def error_message(msg_id: Any, code: int, message: str) -> dict[str, Any]:
    """A JSON-RPC error response."""
    return {"jsonrpc": "2.0", "id": msg_id, "error": {"code": code, "message": message}}

