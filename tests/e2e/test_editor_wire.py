"""What reaches the server that a good editor never sends: every malformed message gets
the JSON-RPC error its specification names (parse error -32700, invalid request -32600,
method not found -32601, invalid params -32602), a broken ``Content-Length`` does not
leave the server deaf, a request about a document the editor never opened is answered
empty without reading the disk, a document past the analysed bounds gets V132 and the
server goes on, and Ctrl-C ends it with 130.

The fuzz writes frames from those promises (valid requests, broken bodies, wrong ids
and parameters, lengths off by some bytes) and counts: internal errors (-32603), hangs
(a request id never answered), responses to ids never sent. Each must be 0."""

from __future__ import annotations

import json
import os
import random
import signal
import time

import pytest

pytest.importorskip("pygls", reason="the lsp extra (pygls) is not installed")

from tests.lsp_raw import ROOT, Raw, frame, hover, request  # noqa: E402

PARSE, INVALID_REQUEST, NOT_FOUND, INVALID_PARAMS, INTERNAL = -32700, -32600, -32601, \
    -32602, -32603
URI = (ROOT / "wire.aou").as_uri()


@pytest.fixture
def raw():
    server = Raw()
    assert "result" in server.initialize()
    yield server
    server.close()


def _open(raw: Raw, uri: str, text: str, version: int = 1) -> None:
    raw.send(frame({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {
        "textDocument": {"uri": uri, "languageId": "aou", "version": version,
                         "text": text}}}))


def _code(msg: dict) -> int | None:
    return msg.get("error", {}).get("code")


MALFORMED = [  # (body, the id the error answers, its code)
    (b"null", None, INVALID_REQUEST),
    (b'"a string"', None, INVALID_REQUEST),
    (b"42", None, INVALID_REQUEST),
    (b"[]", None, INVALID_REQUEST),
    (b'[{"jsonrpc": "2.0", "id": 5, "method": "shutdown"}]', None, INVALID_REQUEST),
    (b'{"jsonrpc": "2.0", "id": 7, "method": "textDocument/hover", "x": "\xff\xfe"}', 7,
     PARSE),
    (b'\xc3\x28{"jsonrpc": "2.0"}', None, PARSE),
    (b'{"jsonrpc": "2.0", "id": 8, "method": ', 8, PARSE),
    (b"{" * 100_000, None, PARSE),
    (json.dumps({"jsonrpc": "2.0", "id": 9}).encode(), 9, INVALID_REQUEST),
    (json.dumps({"jsonrpc": "2.0", "id": 10, "method": 3}).encode(), 10, INVALID_REQUEST),
    (json.dumps({"jsonrpc": "1.0", "id": 11, "method": "shutdown"}).encode(), 11,
     INVALID_REQUEST),
    (json.dumps(request({"an": "object"}, "textDocument/hover")).encode(), None,
     INVALID_REQUEST),
    (json.dumps(request([1], "textDocument/hover")).encode(), None, INVALID_REQUEST),
    (json.dumps(request(1.5, "textDocument/hover")).encode(), None, INVALID_REQUEST),
    (json.dumps(request(True, "textDocument/hover")).encode(), None, INVALID_REQUEST),
    (json.dumps(request(None, "textDocument/hover")).encode(), None, INVALID_REQUEST),
    (json.dumps(request(12, "no/suchMethod")).encode(), 12, NOT_FOUND),
    (json.dumps(request(13, "textDocument/didOpen", {})).encode(), 13, NOT_FOUND),
    (json.dumps(request(14, "textDocument/hover", "params")).encode(), 14, INVALID_PARAMS),
    (json.dumps(request(15, "textDocument/hover", {})).encode(), 15, INVALID_PARAMS),
    (json.dumps(hover(16, URI, line=-1)).encode(), 16, INVALID_PARAMS),
    (json.dumps(hover(17, URI, character=-5)).encode(), 17, INVALID_PARAMS),
    (json.dumps(hover(18, URI, line=2**40)).encode(), 18, INVALID_PARAMS),
    (json.dumps(hover("s19", URI, line="0")).encode(), "s19", INVALID_PARAMS),
    (json.dumps(request(20, "textDocument/hover", {"textDocument": {"uri": 5},
                                                   "position": {"line": 0, "character": 0}})
                ).encode(), 20, INVALID_PARAMS),
    (json.dumps(request(21, "textDocument/formatting", {"textDocument": {"uri": URI},
                                                        "options": "tabs"})).encode(), 21,
     INVALID_PARAMS),
    (json.dumps(request(22, "aou/documentText", {"uri": 3})).encode(), 22, INVALID_PARAMS),
    (json.dumps(request(23, "initialize", {"capabilities": {}})).encode(), 23,
     INVALID_REQUEST),
]


def test_each_malformed_message_gets_its_error_and_the_server_goes_on(raw):
    seen = 1  # the answer to initialize
    for k, (body, msg_id, code) in enumerate(MALFORMED):
        raw.send(frame(body))
        raw.send(frame(hover(f"after{k}", URI)))
        assert raw.response(f"after{k}").get("result", "missing") is None  # answering
        got = raw.responses()
        answers, seen = got[seen:-1], len(got)
        assert [(m["id"], _code(m)) for m in answers] == [(msg_id, code)], (body, answers)
        assert "traceback" not in json.dumps(answers).lower()


def test_a_huge_position_in_a_notification_is_not_answered_and_breaks_nothing(raw):
    _open(raw, URI, "pause 1s\n")
    raw.send(frame({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": {
        "textDocument": {"uri": URI, "version": 2},
        "contentChanges": [{"range": {"start": {"line": 2**31 - 1, "character": 2**31 - 1},
                                      "end": {"line": 2**31 - 1, "character": 2**31 - 1}},
                            "text": "x"}]}}))
    raw.send(frame(request(1, "aou/documentText", {"uri": URI})))
    assert raw.response(1)["result"]["text"] == "pause 1s\nx"
    raw.send(frame({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": "x"}))
    raw.send(frame(hover(2, URI, 0, 2**31 - 1)))
    assert "error" not in raw.response(2)


def test_requests_before_initialize_are_refused_and_after_shutdown_too():
    server = Raw()
    try:
        server.send(frame(hover(1, URI)))
        assert _code(server.response(1)) == -32002
        server.initialize()
        server.send(frame(request(2, "shutdown")))
        assert server.response(2)["result"] is None
        server.send(frame(hover(3, URI)))
        assert _code(server.response(3)) == INVALID_REQUEST
        server.send(frame({"jsonrpc": "2.0", "method": "exit"}))
        assert server.proc.wait(20) == 0
    finally:
        server.close()


_BODY = json.dumps(request(9, "no/such")).encode()
BAD_LENGTHS = [
    b"Content-Length: %d\r\n\r\n" % (len(_BODY) + 7) + _BODY,  # ends in the next header
    b"Content-Length: %d\r\n\r\n" % (len(_BODY) + 19) + _BODY,
    b"Content-Length: 9999\r\n\r\n" + json.dumps(request(1, "shutdown")).encode(),
    b"Content-Length: 3\r\n\r\n" + json.dumps(request(2, "shutdown")).encode(),
    b"Content-Length: abc\r\n\r\n" + json.dumps(request(3, "shutdown")).encode(),
    b"Content-Length: -20\r\n\r\n" + json.dumps(request(4, "shutdown")).encode(),
    b"Content-Length: 99999999999999999999999\r\n\r\n{}",
    b"Content-Type: application/vscode-jsonrpc\r\n\r\n{}",
    b"garbage without a header\r\n",
    b"Content-Length: 10\r\n",  # the header never ends: the next one starts instead
]


def test_a_bad_content_length_does_not_leave_it_deaf(raw):
    for k, data in enumerate(BAD_LENGTHS):
        raw.send(data)
        raw.send(frame(hover(f"next{k}", URI)))
        assert raw.response(f"next{k}", timeout=10).get("result", "missing") is None, data
    assert not [m for m in raw.responses() if _code(m) == INTERNAL]


def test_a_length_past_the_body_is_answered_after_a_pause(raw):
    """The sender waits for its answer; nothing more comes: the body is whole JSON."""
    raw.send(b"Content-Length: 500\r\n\r\n" + json.dumps(hover(5, URI)).encode())
    assert _code(raw.response(5, timeout=10)) == PARSE
    raw.send(frame(hover(6, URI)))
    assert raw.response(6)["result"] is None


# --- documents never opened -----------------------------------------------------------


def _odd_uris(tmp_path) -> list[str]:
    folder = tmp_path / "folder.aou"
    folder.mkdir()
    latin = tmp_path / "latin.aou"
    latin.write_bytes("# caf\xe9\npause 1s\n".encode("latin-1"))
    fifo = tmp_path / "pipe.aou"
    os.mkfifo(fifo)
    return [(tmp_path / "never.aou").as_uri(), folder.as_uri(), latin.as_uri(),
            fifo.as_uri(), "file:///dev/zero", "file:///proc/self/mem", "Untitled-1",
            "untitled:Untitled-1", "http://example.com/a.aou", "file:///etc/passwd", "",
            "file://%ZZ", (ROOT / "behaviours" / "hesitant.aou").as_uri()]


EMPTY = {"textDocument/hover": [None], "textDocument/completion": [{"isIncomplete": False,
                                                                     "items": []}],
         "textDocument/documentSymbol": [[], None], "textDocument/formatting": [[], None],
         "textDocument/codeAction": [[], None], "aou/documentText": [None]}


def _params(method: str, uri: str) -> dict:
    doc, pos = {"uri": uri}, {"line": 0, "character": 0}
    rng = {"start": pos, "end": pos}
    return {"textDocument/hover": {"textDocument": doc, "position": pos},
            "textDocument/completion": {"textDocument": doc, "position": pos},
            "textDocument/documentSymbol": {"textDocument": doc},
            "textDocument/formatting": {"textDocument": doc,
                                        "options": {"tabSize": 2, "insertSpaces": True}},
            "textDocument/codeAction": {"textDocument": doc, "range": rng,
                                        "context": {"diagnostics": []}},
            "aou/documentText": {"uri": uri}}[method]


def test_an_unopened_document_is_answered_empty_and_never_read(raw, tmp_path):
    """A folder, another encoding, a FIFO no one writes, /dev/zero, /proc/self/mem,
    names without a scheme, other schemes, even a real .aou file: the server knows only
    what the editor sent, so each answer is empty, at once, without a traceback."""
    n = 0
    for uri in _odd_uris(tmp_path):
        for note in ("didSave", "didClose", "didChange"):
            params: dict = {"textDocument": {"uri": uri, "version": 2}}
            if note == "didChange":
                params["contentChanges"] = [{"text": "pause 1s\n"}]
            raw.send(frame({"jsonrpc": "2.0", "method": f"textDocument/{note}",
                            "params": params}))
        for method, empty in EMPTY.items():
            n += 1
            raw.send(frame(request(n, method, _params(method, uri))))
            got = raw.response(n, timeout=10)
            assert "error" not in got and got["result"] in empty, (uri, method, got)
    assert b"Traceback" not in raw.stderr
    published = [m for m in raw.messages if m.get("method") ==
                 "textDocument/publishDiagnostics" and m["params"]["diagnostics"]]
    assert published == []


def test_asking_about_many_documents_keeps_nothing():
    """Requests about unopened documents leave no state behind: nothing to grow."""
    import tracemalloc

    from lsprotocol import types

    from aou_dsl.editor.server import make_server

    ls = make_server()
    hover_ = ls.protocol.fm.features[types.TEXT_DOCUMENT_HOVER]
    symbols = ls.protocol.fm.features[types.TEXT_DOCUMENT_DOCUMENT_SYMBOL]

    def ask(k: int) -> None:
        uri = f"file:///nowhere/doc{k}.aou"
        assert hover_(types.HoverParams(types.TextDocumentIdentifier(uri),
                                        types.Position(0, 0))) is None
        assert symbols(types.DocumentSymbolParams(types.TextDocumentIdentifier(uri))) == []

    for k in range(50):  # warm: caches the first calls fill
        ask(k)
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    for k in range(50, 3050):
        ask(k)
    grown = tracemalloc.get_traced_memory()[0] - before
    tracemalloc.stop()
    assert ls.docs == {}
    assert grown < 100_000, f"{grown} bytes kept for 3000 unopened documents"


# --- bounds ------------------------------------------------------------------------------


def test_a_20_mb_one_line_document_gets_v132_and_the_next_request_is_answered(raw):
    uri = (ROOT / "huge.aou").as_uri()
    _open(raw, uri, "pause 1s; " * 2_000_000)
    raw.send(frame(hover(1, uri, 0, 3)))
    assert raw.response(1, timeout=60)["result"] is None
    (pub,) = [m for m in raw.messages if m.get("method") == "textDocument/publishDiagnostics"
              and m["params"]["uri"] == uri]
    (d,) = pub["params"]["diagnostics"]
    assert d["code"] == "V132" and "larger" in d["message"]
    # an edit that makes it small again is analysed at once
    raw.send(frame({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": {
        "textDocument": {"uri": uri, "version": 2}, "contentChanges": [{"text": "pause 3m\n"}]}}))
    raw.send(frame(hover(2, uri, 0, 1)))
    assert "pause" in json.dumps(raw.response(2)["result"])
    codes = [d["code"] for m in raw.messages if m.get("method") ==
             "textDocument/publishDiagnostics" and m["params"]["uri"] == uri
             and m["params"]["version"] == 2 for d in m["params"]["diagnostics"]]
    assert "V102" in codes and "V132" not in codes


def test_a_line_past_the_bound_gets_v132_with_its_line():
    from aou_dsl.editor.bounds import MAX_LINE

    server = Raw()
    try:
        server.initialize()
        _open(server, URI, "pause 1s\n" + "pause 1s; " * (MAX_LINE // 10 + 1) + "\n")
        server.send(frame(hover(1, URI)))
        server.response(1)
        (pub,) = [m for m in server.messages
                  if m.get("method") == "textDocument/publishDiagnostics"]
        (d,) = pub["params"]["diagnostics"]
        assert d["code"] == "V132" and d["range"]["start"]["line"] == 1
        assert f"{MAX_LINE:,}" in d["message"]
    finally:
        server.close()


def test_the_bounds_are_the_documented_ones():
    from aou_dsl.core.rules import RULES
    from aou_dsl.editor.bounds import MAX_LINE, MAX_MESSAGE, max_document

    docs = (ROOT / "docs" / "editors.md").read_text(encoding="utf-8")
    assert f"lines up to {MAX_LINE:,}" in docs and f"up to {MAX_MESSAGE >> 20} MB" in docs
    assert f"analysed up to the size `aouc lint` reads, {max_document() >> 20} MB" in docs
    assert f"a line over {MAX_LINE:,} characters" in RULES["V132"].what


def test_ctrl_c_ends_the_server_with_130(raw):
    _open(raw, URI, "pause 1s\n")
    raw.send(frame(hover(1, URI)))
    raw.response(1)
    raw.proc.send_signal(signal.SIGINT)
    assert raw.proc.wait(20) == 130
    time.sleep(0.2)
    assert b"Fatal Python error" not in raw.stderr and b"Traceback" not in raw.stderr


# --- the fuzz ----------------------------------------------------------------------------

_METHODS = ["textDocument/hover", "textDocument/completion", "textDocument/documentSymbol",
            "textDocument/formatting", "textDocument/codeAction", "aou/documentText",
            "textDocument/definition", "workspace/symbol", "no/such", "$/cancelRequest"]
_VALUES = [None, True, 0, -1, 2**31, 2**63, 1.5, "", "x", "0", [], {}, [1, 2], {"a": 1},
           "\ud800", "\u2028", 1e308]


def _position(rng: random.Random) -> object:
    if rng.random() < 0.7:
        return {"line": rng.choice([0, 1, 3, 2**31 - 1]),
                "character": rng.choice([0, 2, 50, 2**31 - 1])}
    return rng.choice([{"line": rng.choice(_VALUES), "character": 0},
                       {"line": 0, "character": rng.choice(_VALUES)}, {"line": 0}, [0, 0],
                       rng.choice(_VALUES)])


def _params_fuzz(rng: random.Random, method: str, uris: list[str]) -> object:
    if rng.random() < 0.1:
        return rng.choice(_VALUES)
    params = _params(method, rng.choice(uris)) if method in EMPTY else \
        {"textDocument": {"uri": rng.choice(uris)}, "position": _position(rng)}
    if "position" in params:
        params["position"] = _position(rng)
    if rng.random() < 0.15:
        key = rng.choice(list(params))
        params[key] = rng.choice(_VALUES)
    return params


def _message(rng: random.Random, k: int, uris: list[str]) -> tuple[bytes, object]:
    """One frame's bytes and the id the server must answer (None: none to expect)."""
    what = rng.random()
    msg_id: object = k if rng.random() < 0.7 else f"r{k}"
    method = rng.choice(_METHODS)
    if what < 0.08:  # a notification: an edit, perhaps malformed
        change = {"text": rng.choice(["pause 1s\n", "\u2028\r", "tilt 20deg x3"])}
        if rng.random() < 0.6:
            change["range"] = {"start": _position(rng), "end": _position(rng)}
        body = json.dumps({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": {
            "textDocument": {"uri": rng.choice(uris), "version": k},
            "contentChanges": [change]}}).encode()
        return frame(body), None
    if what < 0.12:  # a body that is not JSON, or not UTF-8
        body = rng.choice([b"{", b"\xff" * 5, b"", b"nul", b'{"id": ' + str(k).encode()])
        return frame(body), None
    if what < 0.18:  # JSON that is not a message
        return frame(json.dumps(rng.choice([None, "s", 3, [], [1], {}])).encode()), None
    if what < 0.24:  # an id that is no id
        msg = request(rng.choice([{"a": k}, [k], 1.5, None, True]), method, {})
        return frame(msg), None
    msg = request(msg_id, method, _params_fuzz(rng, method, uris))
    if method == "$/cancelRequest":
        msg.pop("id")
        msg["params"] = {"id": rng.choice([k - 1, "x", None])}
        return frame(msg), None
    data = json.dumps(msg).encode()
    if rng.random() < 0.1:  # a Content-Length off: the id may or may not be read
        off = rng.choice([-5, -1, 1, 7, 400])
        return b"Content-Length: %d\r\n\r\n" % max(0, len(data) + off) + data, None
    return frame(data), msg_id


def _fuzz(n: int, seed: int, tmp_path) -> None:
    rng = random.Random(seed)
    uris = [URI, *_odd_uris(tmp_path)]
    server = Raw()
    try:
        server.initialize(rng.choice(["utf-8", "utf-16", "utf-32"]))
        _open(server, URI, "behaviour h : hesitant\fx\npause 1s\u2028\rtilt 20deg\n")
        expected, sent = [], set()
        for k in range(1, n + 1):
            data, msg_id = _message(rng, k, uris)
            server.send(data)
            sent.update({k, f"r{k}"})
            if msg_id is not None:
                expected.append(msg_id)
            if k % 50 == 0:  # every answer so far has come (a hang fails here)
                server.send(frame(hover(f"sync{k}", URI)))
                server.response(f"sync{k}", timeout=60)
        server.send(frame(hover("last", URI)))
        server.response("last", timeout=60)
        got = server.responses()
        internal = [m for m in got if _code(m) == INTERNAL]
        answered = {m.get("id") for m in got}
        hangs = [i for i in expected if i not in answered]
        stray = [m["id"] for m in got if m.get("id") is not None and m["id"] not in sent
                 and not str(m["id"]).startswith("sync") and m["id"] not in (0, "last")]
        report = f"{n} frames: {len(internal)} internal errors, {len(hangs)} hangs, " \
                 f"{len(stray)} answers to ids never sent, {server.bad_frames} bad frames out"
        print(report)
        assert (internal, hangs, stray, server.bad_frames) == ([], [], [], 0), report
        assert b"Traceback" not in server.stderr, server.stderr[-3000:]
    finally:
        server.close()


def test_fuzz_frames(tmp_path):
    _fuzz(300, seed=5, tmp_path=tmp_path)


@pytest.mark.slow
def test_fuzz_frames_many(tmp_path):
    _fuzz(20000, seed=6, tmp_path=tmp_path)


def test_frames_are_cut_the_same_however_the_bytes_arrive():
    """The cutting (in-process): the bodies and broken messages found do not depend on
    how the stream is split into reads, and junk without a line end is not kept."""
    from aou_dsl.editor.wire import Frames

    stream = b"".join([frame(hover(1, URI)), b"junk\r\n", frame(hover(2, URI)),
                       b"Content-Length: 900\r\n\r\n" + json.dumps(hover(3, URI)).encode(),
                       frame(hover(4, URI)), b"Content-Length: x\r\n\r\n",
                       frame({"a": "\u2028"})])

    def cut(sizes: random.Random | None) -> list:
        got: list = []
        frames = Frames(lambda b: got.append(b), lambda i, why: got.append((i, why)))
        at = 0
        while at < len(stream):
            n = sizes.randint(1, 40) if sizes else len(stream)
            frames.feed(stream[at:at + n])
            at += n
        return got

    whole = cut(None)
    assert [x if isinstance(x, bytes) else x[0] for x in whole] == [
        json.dumps(hover(1, URI)).encode(), None, json.dumps(hover(2, URI)).encode(), 3,
        json.dumps(hover(4, URI)).encode(), None, json.dumps({"a": "\u2028"}).encode()]
    for seed in range(20):
        assert cut(random.Random(seed)) == whole
    got: list = []
    frames = Frames(got.append, lambda i, why: got.append(why))
    frames.feed(b"Content-Length: 5" + b"x" * 1_000_000)
    assert len(frames.buf) < 10_000 and len(got) == 1
